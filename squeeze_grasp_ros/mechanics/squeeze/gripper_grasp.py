# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Squeezes for a parallel-jaw gripper: two flat pads on one line, closing symmetrically.

A gripper grasp starts from a placement pair (i, j) of the grasp map (Sec. 4) taken as the
closing line: jaw F1 faces d = (p_j - p_i) / |p_j - p_i| from p_i's side, jaw F2 faces -d from
p_j's side, and both close along that line at equal speeds. Per pair, without a solve:

- the jaws' first contact: each pad, facing the line, advances until its face (flat and
  rounded edges) first touches the outline (:meth:`~.tip_shapes.TipShape.clearance`); of the
  nodes it then touches, the one nearest the closing line is its first contact. The aperture
  at first contact is the distance between the two faces then, and the gripper centre is the
  midpoint between them on the closing line. Only the pads are modelled: the jaws' bodies
  behind them are assumed clear of the object.
- the quality of the placement the pads make: the pair of first contacts (t1, t2) must be
  inward and force closing in the grasp map (a pad tilted against the outline touches with
  its edge, elsewhere than p_i), and candidates are ranked by the paper's energy quality of
  the stable squeeze there: the work the fingers do per squared depth, W / depth^2 = k / 2
  with k = 1 / (u^T A u) the grasp map's stiffness at (t1, t2) (point contacts; compare
  placements on one mesh). Apertures outside the jaws' opening range are left out.

and, for the best ``evaluate`` candidates, an event-driven squeeze with the pads
(:func:`~.events.event_squeeze`, directions +-d): the jaw force at the planned closing, and the
closing at which a jaw would slip or the strain limit (or an element inversion) would stop it.

Closing c is the reduction of the aperture beyond first contact, m: both jaws move c/2. In
:func:`~.events.event_squeeze`'s terms the stacked depth is c / sqrt(2).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, shown
from squeeze_grasp_ros.mechanics.squeeze.contact_model import TerminationLimits
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze, event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.fingertips import TOUCH_TOLERANCE
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipShape, tangent, unit
from squeeze_grasp_ros.mechanics.vocabulary import Finger, MaterialModel, Termination

__all__ = ["GripperCandidate", "GripperEvaluation", "ParallelJaws", "gripper_candidates",
           "evaluate_candidate"]

SQRT2 = float(np.sqrt(2.0))


@dataclass(frozen=True)
class ParallelJaws:
    """What the mechanics needs of a parallel-jaw gripper (SI).

    Attributes
    ----------
    min_aperture, max_aperture : float
        Range of the distance between the two pad faces, m.
    max_force : float
        Largest grip force one jaw exerts, N.
    pad : TipShape
        Each jaw's pad (a flat pad, or a circle for round fingertips).
    """

    min_aperture: float
    max_aperture: float
    max_force: float
    pad: TipShape

    def __post_init__(self) -> None:
        if not (np.isfinite(self.min_aperture) and self.min_aperture >= 0):
            raise InvalidInputError(f"opening.min must be finite and >= 0 m, got "
                                    f"{self.min_aperture}")
        if not (np.isfinite(self.max_aperture) and self.max_aperture > self.min_aperture):
            raise InvalidInputError(f"opening.max must be > opening.min ({self.min_aperture} m), "
                                    f"got {self.max_aperture}")
        if not (np.isfinite(self.max_force) and self.max_force > 0):
            raise InvalidInputError(f"max_force must be finite and > 0 N, got {self.max_force}")
        if not self.pad.radius > 0:
            raise InvalidInputError("the jaws' pads need a rounded part: edge_radius > 0 m")


@dataclass(frozen=True)
class GripperCandidate:
    """One ranked gripper placement, before any squeeze (object frame, SI).

    Attributes
    ----------
    rank : int
        0 for the best.
    nodes : (int, int)
        The grasp map's placement pair (i, j) that defines the closing line.
    center : (2,) ndarray
        Gripper centre at first contact: midway between the pad faces on the closing line, m.
    yaw : float
        Angle of the closing direction d (jaw F1's motion, from p_i towards p_j), rad in
        (-pi, pi].
    aperture : float
        Distance between the pad faces at first contact, m.
    first_contacts : (int, int)
        Boundary nodes the F1 and F2 pads touch first.
    stiffness : float
        The grasp map's stable-squeeze stiffness k at ``first_contacts``, N/m (point contacts,
        this mesh).
    """

    rank: int
    nodes: tuple[int, int]
    center: np.ndarray
    yaw: float
    aperture: float
    first_contacts: tuple[int, int]
    stiffness: float

    @property
    def work_quality(self) -> float:
        """Work of the stable squeeze per squared depth, k / 2, J/m^2."""
        return 0.5 * self.stiffness

    @property
    def closing_direction(self) -> np.ndarray:
        """The closing direction d (2,): the direction jaw F1 moves (F2 moves along -d)."""
        return np.array([np.cos(self.yaw), np.sin(self.yaw)])

    def to_json(self) -> dict:
        """JSON-able summary (m, rad, N/m)."""
        return {"rank": self.rank, "nodes": list(self.nodes),
                "center": [float(v) for v in self.center], "yaw": self.yaw,
                "aperture_at_contact": self.aperture, "first_contacts": list(self.first_contacts),
                "stiffness": self.stiffness, "work_quality": self.work_quality}


def _in_yaw_range(yaw: np.ndarray, yaw_range: tuple[float, float] | None) -> np.ndarray:
    """Yaws (mod pi: swapping the jaws is the same gripper pose) within [lo, hi]."""
    if yaw_range is None:
        return np.ones(len(yaw), bool)
    lo, hi = yaw_range
    if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
        raise InvalidInputError(f"yaw range must be finite with min <= max, got "
                                f"{shown(yaw_range)} rad")
    if hi - lo >= np.pi:
        return np.ones(len(yaw), bool)
    return np.mod(yaw - lo, np.pi) <= hi - lo


def gripper_candidates(obj: ElasticObject, gmap: GraspMap, jaws: ParallelJaws, *,
                       count: int = 10,
                       yaw_range: tuple[float, float] | None = None) -> list[GripperCandidate]:
    """The ``count`` best gripper placements of ``obj`` by work quality (see the module).

    Parameters
    ----------
    obj : ElasticObject
    gmap : GraspMap
        The object's grasp map (:func:`~.graspmap.grasp_map`) at the friction coefficient.
    jaws : ParallelJaws
    count : int
        Most candidates returned (>= 1).
    yaw_range : (float, float), optional
        Allowed closing directions, rad, modulo pi (the jaws are interchangeable).

    Returns
    -------
    list of GripperCandidate
        Best first; placements whose aperture at first contact lies outside the jaws'
        opening range are left out. Empty when no placement fits.
    """
    if not (isinstance(count, (int, np.integer)) and count >= 1):
        raise InvalidInputError(f"count must be an integer >= 1, got {count!r}")
    boundary = np.asarray(gmap.boundary)
    pts = obj.mesh.nodes[boundary]
    rows, cols = np.nonzero(np.triu(gmap.feasible, 1))
    d = pts[cols] - pts[rows]
    yaw = np.arctan2(d[:, 1], d[:, 0])
    keep = _in_yaw_range(yaw, yaw_range)
    rows, cols, yaw = rows[keep], cols[keep], yaw[keep]
    touch = [_first_touch(obj, pts, jaws, rows[k:k + CHUNK], cols[k:k + CHUNK], yaw[k:k + CHUNK])
             for k in range(0, len(rows), CHUNK)]
    if not touch:
        return []
    center, aperture, t1, t2 = (np.concatenate(parts) for parts in zip(*touch))
    # the quality and feasibility of the placement the pads actually make
    ok = ((aperture >= jaws.min_aperture) & (aperture <= jaws.max_aperture)
          & gmap.feasible[t1, t2])
    quality = np.where(ok, gmap.stiffness[t1, t2], -np.inf)
    order = np.argsort(-quality, kind="mergesort")[:count]
    order = order[np.isfinite(quality[order])]
    return [GripperCandidate(rank, (int(boundary[rows[k]]), int(boundary[cols[k]])), center[k],
                             float(yaw[k]), float(aperture[k]),
                             (int(boundary[t1[k]]), int(boundary[t2[k]])),
                             float(quality[k]))
            for rank, k in enumerate(order)]


CHUNK = 2048
"""Placement pairs whose first contacts are computed at once (memory: CHUNK x b)."""


def _first_touch(obj: ElasticObject, pts: np.ndarray, jaws: ParallelJaws, i: np.ndarray,
                 j: np.ndarray, yaw: np.ndarray):
    """Centre (k, 2), aperture (k,) and the boundary indices the F1 and F2 pads touch first
    (k,), for jaws closing on the lines through boundary points ``i``, ``j`` along ``yaw``.

    Each jaw starts far back on the line and advances until its face touches; of the nodes it
    then touches (within TOUCH_TOLERANCE, e.g. a whole straight side), its first contact is the
    one nearest the closing line.
    """
    mid, d = 0.5 * (pts[i] + pts[j]), unit(yaw)
    far = 10.0 * obj.scale
    faces, firsts = [], []
    for sign, facing in ((-1.0, yaw), (1.0, yaw + np.pi)):
        clear = jaws.pad.clearance(pts, mid + sign * far * d, facing)
        least = clear.min(axis=1)
        lateral = np.abs(np.einsum("kpi,ki->kp", pts[None] - mid[:, None], tangent(yaw)))
        touching = clear <= least[:, None] + TOUCH_TOLERANCE * obj.scale
        firsts.append(np.argmin(np.where(touching, lateral, np.inf), axis=1))
        faces.append(sign * (far - least - jaws.pad.radius))  # the face along d, from mid
    aperture = faces[1] - faces[0]
    return mid + 0.5 * (faces[0] + faces[1])[:, None] * d, aperture, firsts[0], firsts[1]


@dataclass(frozen=True)
class GripperEvaluation:
    """A candidate squeezed by the pads (event-driven, SI).

    Attributes
    ----------
    candidate : GripperCandidate
    closing : float
        Planned closing beyond first contact, m.
    aperture : float
        Aperture at the planned closing, m.
    jaw_force : float
        Each jaw's force along its motion at the planned closing, N (mean of the two).
    termination : Termination
        Why the planned squeeze ended (``depth_reached`` if it got there).
    limit_closing : float or None
        Closing at which a jaw would slip, the strain limit would be reached or an element
        would invert, m; None if none happens up to ``limit_search`` closing.
    limit : Termination or None
        Which of them.
    limit_search : float
        How far the limit was searched, m of closing.
    command_force : float
        Jaw force to command: ``jaw_force`` times ``margin``, N.
    margin : float
        The force margin applied.
    exceeds_max_force : bool
        ``command_force`` is beyond the jaws' ``max_force``.
    lift_force : float or None
        Each jaw's force that carries the object's weight w by friction on both pads,
        w / (2 mu), N (closing line horizontal, gravity along the pad faces); None without a
        weight.
    squeeze : EventSqueeze
        The planned squeeze itself.
    """

    candidate: GripperCandidate
    closing: float
    aperture: float
    jaw_force: float
    termination: Termination
    limit_closing: float | None
    limit: Termination | None
    limit_search: float
    command_force: float
    margin: float
    exceeds_max_force: bool
    lift_force: float | None
    squeeze: EventSqueeze = field(repr=False)

    @property
    def holds_weight(self) -> bool | None:
        """The planned jaw force carries the weight (None without one)."""
        return None if self.lift_force is None else self.jaw_force >= self.lift_force

    def to_json(self) -> dict:
        """JSON-able summary (m, N)."""
        return {**self.candidate.to_json(), "closing": self.closing,
                "aperture_planned": self.aperture, "jaw_force": self.jaw_force,
                "termination": str(self.termination),
                "limit": None if self.limit is None else {
                    "closing": self.limit_closing, "termination": str(self.limit)},
                "limit_searched_to": self.limit_search,
                "command_force": self.command_force, "force_margin": self.margin,
                "exceeds_max_force": self.exceeds_max_force, "lift_force": self.lift_force,
                "holds_weight": self.holds_weight,
                "events": self.squeeze.event_counts}


LIMITS = (Termination.FINGER_SLIP, Termination.STRAIN_LIMIT, Termination.ELEMENT_INVERTED)
"""The terminations that bound how far a gripper may close."""


def evaluate_candidate(obj: ElasticObject, candidate: GripperCandidate, jaws: ParallelJaws,
                       mu: float, *, closing: float, margin: float = 1.25,
                       weight: float | None = None, limit_search: float | None = None,
                       strain_limit: float | None = None,
                       material_model: MaterialModel | str = MaterialModel.LINEAR,
                       ) -> GripperEvaluation:
    """Squeeze ``candidate`` with the pads to ``closing`` (m), and find its limit closing.

    Parameters
    ----------
    closing : float
        Planned closing beyond first contact, m (> 0, at most the aperture at first contact
        less the jaws' ``min_aperture``).
    margin : float
        Commanded force / predicted force (>= 1).
    weight : float, optional
        The object's weight, N, if it is to be lifted.
    limit_search : float, optional
        How far to search for the limit closing, m; default the smaller of half the aperture
        at first contact and the jaws' travel left.
    strain_limit : float, optional
        The strain limit epsilon* (the material model's measure), if any.
    """
    travel = candidate.aperture - jaws.min_aperture
    if not (np.isfinite(closing) and 0 < closing <= travel):
        raise InvalidInputError(f"closing must be in (0, {travel:.6g}] m (the jaws' travel "
                                f"from first contact), got {closing}")
    if not (np.isfinite(margin) and margin >= 1):
        raise InvalidInputError(f"force margin must be finite and >= 1, got {margin}")
    if weight is not None and not (np.isfinite(weight) and weight > 0):
        raise InvalidInputError(f"weight must be finite and > 0 N, got {weight}")
    search = min(0.5 * candidate.aperture, travel) if limit_search is None else limit_search
    d = candidate.closing_direction
    far = candidate.aperture + 10.0 * obj.scale  # each jaw starts clear, on the closing line
    kw = dict(directions={Finger.F1: d, Finger.F2: -d},
              facing={Finger.F1: candidate.yaw, Finger.F2: candidate.yaw + np.pi},
              origins={Finger.F1: candidate.center - far * d,
                       Finger.F2: candidate.center + far * d},
              material_model=material_model)
    nodes = candidate.first_contacts
    planned = event_squeeze(obj, nodes, jaws.pad, mu, depth=closing / SQRT2,
                            limits=TerminationLimits(strain=strain_limit), **kw)
    limit_run = event_squeeze(obj, nodes, jaws.pad, mu, depth=max(search, closing) / SQRT2,
                              limits=TerminationLimits(strain=strain_limit), **kw)
    stopped = limit_run.termination in LIMITS
    force = 0.5 * (planned.finger_force[Finger.F1][1] + planned.finger_force[Finger.F2][1])
    reached = planned.depth * SQRT2
    command = margin * force
    return GripperEvaluation(
        candidate, reached, candidate.aperture - reached, float(force), planned.termination,
        limit_run.depth * SQRT2 if stopped else None,
        limit_run.termination if stopped else None, max(search, closing), float(command),
        float(margin), bool(command > jaws.max_force),
        None if weight is None else float(weight) / (2.0 * mu) if mu > 0 else float("inf"),
        planned)
