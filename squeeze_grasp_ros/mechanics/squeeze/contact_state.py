# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Frozen contact state, events and samples of the incremental stepper (paper Sec. 5.2-5.3).

All quantities are SI in the object frame (x right, y up, origin of the mesh coordinates):
positions and displacements in m, forces in N (applied by the finger on the object), work and
energy in J, contact coordinates in rad (for a circular tip the polar angle about its centre;
see :mod:`.tip_shapes`).
"""

from __future__ import annotations

import functools
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from operator import attrgetter

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.event_key import EventFunction, EventKey
from squeeze_grasp_ros.mechanics.squeeze.fingertips import Fingertip
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry, tangent, unit
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, EventType, Finger, Termination


@dataclass(frozen=True)
class FingerState:
    """One rigid fingertip during the squeeze.

    Attributes
    ----------
    name : Finger
    center : (2,) ndarray
        Current tip reference point (a circle's centre), m.
    radius : float
        Tip radius (a pad's edge radius), m.
    translation : (2,) ndarray
        Accumulated translation since the initial placement, m.
    work : float
        Work done by this finger on the object, J (integral of its total contact force along
        its path).
    dissipation : float
        Energy dissipated by friction at this finger's sliding contacts, J (integral of
        -f_t r d theta over them: the friction force against the slip along the tip).
    flat : float
        Half the width of the tip's flat face, m (0 for a circle; :mod:`.tip_shapes`).
    facing : float
        Angle of the tip's facing direction, rad.
    """

    name: Finger
    center: np.ndarray
    radius: float
    translation: np.ndarray
    work: float = 0.0
    dissipation: float = 0.0
    flat: float = 0.0
    facing: float = 0.0


def tip_geometry(fingers: tuple[FingerState, ...]) -> TipGeometry:
    """The tips of ``fingers`` (m), in their order."""
    return TipGeometry(np.array([f.radius for f in fingers], float),
                       np.array([f.flat for f in fingers], float),
                       np.array([f.facing for f in fingers], float))


@dataclass(frozen=True)
class ContactNode:
    """A boundary node in contact with a fingertip.

    Attributes
    ----------
    node : int
        Mesh node index.
    finger : Finger
        The finger it touches.
    mode : ContactMode
        Sticking (moves with the finger, eq. 46) or sliding (force on a cone edge, eq. 47).
    slip : int
        Slip direction for sliding nodes: +1 if its contact coordinate increases relative to
        the tip, -1 if it decreases (the friction force opposes it: the force lies on edge
        e(nu - slip*phi)); 0 for sticking nodes.
    theta : float
        Contact coordinate q on the tip, rad (a circle's polar angle about its centre).
    displacement : (2,) ndarray
        Node displacement from the undeformed configuration, m.
    force : (2,) ndarray
        Contact force of the finger on the node, N.
    normal_angle : float
        Angle nu of the contact normal e(nu) into the object, rad (default ``theta``: a
        circle's).
    """

    node: int
    finger: Finger
    mode: ContactMode
    slip: int
    theta: float
    displacement: np.ndarray
    force: np.ndarray
    normal_angle: float | None = None

    def __post_init__(self) -> None:
        if self.normal_angle is None:
            object.__setattr__(self, "normal_angle", self.theta)

    def normal_force(self) -> float:
        """F . e(nu), N (> 0 while pressing)."""
        return float(self.force @ unit(self.normal_angle))

    def tangential_force(self) -> float:
        """F . t(nu), N."""
        return float(self.force @ tangent(self.normal_angle))


@dataclass(frozen=True)
class ContactArrays:
    """A state's contact nodes as arrays, in the state's order (by node index): what the
    simulated sensors and the ground truth's message read of them at every tick, gathered from
    the nodes once per state (:attr:`ContactState.arrays`).

    Attributes
    ----------
    fingers : tuple of Finger
        Each node's finger.
    thetas : (k,) ndarray
        Contact coordinates, rad.
    forces : (k, 2) ndarray
        Forces of the fingers on the nodes, N.
    normal_angles : (k,) ndarray
        Contact normal angles nu, rad.
    """

    fingers: tuple[Finger, ...]
    thetas: np.ndarray
    forces: np.ndarray
    normal_angles: np.ndarray

    @classmethod
    def of(cls, contacts: Iterable[ContactNode]) -> ContactArrays:
        """The arrays of ``contacts``."""
        contacts = tuple(contacts)
        return cls(tuple(map(_FINGER, contacts)),
                   np.array(list(map(_THETA, contacts)), float),
                   np.array(list(map(_FORCE, contacts)), float).reshape(-1, 2),
                   np.array(list(map(_NORMAL_ANGLE, contacts)), float))

    def rows(self, finger: Finger | str) -> np.ndarray:
        """Indices of ``finger``'s nodes, in order."""
        return _finger_rows(self.fingers, finger)


_FINGER, _THETA, _FORCE, _NORMAL_ANGLE = map(attrgetter, ("finger", "theta", "force",
                                                         "normal_angle"))


@functools.lru_cache(maxsize=256)
def _finger_rows(fingers: tuple[Finger, ...], finger: Finger | str) -> np.ndarray:
    """Indices of ``finger`` in ``fingers`` (kept: the same contact set tick after tick)."""
    rows = np.array([k for k, f in enumerate(fingers) if f == finger], dtype=np.intp)
    rows.flags.writeable = False
    return rows


@dataclass(frozen=True)
class ContactState:
    """Everything the stepper needs to continue a squeeze; immutable.

    Attributes
    ----------
    fingers : tuple of FingerState
        In canonical finger order (F1, F2, A).
    contacts : tuple of ContactNode
        Sorted by node index.
    depth : float
        Accumulated squeeze depth, m: the sum over steps of the norm of the stacked finger
        translations (rho of docs/design.md §2 for a unit squeeze direction).
    relative_per_depth : float
        Relative depth per unit depth, 1/m (approach per depth / initial contact distance);
        0 when the motion is not a squeeze.
    undetermined : tuple of int
        Contact nodes whose mode is decided by hypothesis-and-test at the next motion (initial
        contacts have zero force, so their mode depends on the direction of motion).
    fresh : tuple of EventKey
        Event functions that are zero by construction at this state (e.g. the cone margin of a
        node that just stuck); their sign is judged by their derivative along the next motion.
        Keys without a finger (:attr:`~.event_key.EventKey.at_node`).
    history : tuple of (int, float)
        Recent (node, depth in m) events, kept for the chattering bound.
    holds : tuple of (int, float)
        (node, depth in m until which its contact mode is frozen after chattering).
    """

    fingers: tuple[FingerState, ...]
    contacts: tuple[ContactNode, ...]
    depth: float = 0.0
    relative_per_depth: float = 0.0
    undetermined: tuple[int, ...] = ()
    fresh: tuple[EventKey, ...] = ()
    history: tuple[tuple[int, float], ...] = ()
    holds: tuple[tuple[int, float], ...] = ()

    def finger(self, name: Finger) -> FingerState:
        """The finger called ``name``."""
        for f in self.fingers:
            if f.name == name:
                return f
        raise KeyError(f"no finger {name!r} in the state (have {[f.name for f in self.fingers]})")

    def segment(self, name: Finger) -> tuple[ContactNode, ...]:
        """Contact nodes of finger ``name``, ordered by contact coordinate."""
        return tuple(sorted((c for c in self.contacts if c.finger == name), key=lambda c: c.theta))

    def finger_force(self, name: Finger) -> np.ndarray:
        """Total force (2,) of finger ``name`` on the object, N."""
        forces = [c.force for c in self.contacts if c.finger == name]
        return np.sum(forces, axis=0) if forces else np.zeros(2)

    @property
    def relative_depth(self) -> float:
        """Depth * relative_per_depth (fraction)."""
        return self.depth * self.relative_per_depth

    @functools.cached_property
    def arrays(self) -> ContactArrays:
        """The contact nodes as arrays (computed once: the state is immutable)."""
        return ContactArrays.of(self.contacts)


def initial_state(tips: list[Fingertip], relative_per_depth: float = 0.0) -> ContactState:
    """The state at depth 0: each fingertip touching its initial node (and any other node it
    touches where it was placed, :attr:`~.fingertips.Fingertip.touching`) with zero force.

    Initial modes are undetermined: the stepper decides them by hypothesis-and-test along the
    first motion (Algorithm 1, line 2).

    Raises
    ------
    InvalidInputError
        If two fingertips touch the same boundary node where they are placed (two pads on one
        side of the object, wider than the gap between their nodes): one node cannot be held by
        two fingers (its two contacts made the set's reduced compliance singular).
    """
    order = {name: k for k, name in enumerate(Finger.values())}
    tips = sorted(tips, key=lambda t: order[t.name])
    fingers = tuple(
        FingerState(t.name, np.asarray(t.center, float), t.radius, np.zeros(2), flat=t.flat,
                    facing=t.facing)
        for t in tips
    )
    geometry = tip_geometry(fingers)
    touching = [(k, t.name, node, q) for k, t in enumerate(tips)
                for node, q in ((t.node, t.theta), *t.touching)]
    shared = sorted(n for n, count in Counter(c[2] for c in touching).items() if count > 1)
    if shared:  # a tip lists each node it touches once
        names = dict.fromkeys(name for _, name, node, _ in touching if node in shared)
        raise InvalidInputError(
            f"fingers {' and '.join(names)} both touch boundary node(s) {shared} where they "
            "are placed: one node cannot be held by two fingers; place them farther apart or "
            "use narrower tips")
    contacts = tuple(
        sorted(
            (
                ContactNode(node, name, ContactMode.STICK, 0, q, np.zeros(2), np.zeros(2),
                            float(geometry.normal_angle(np.array([q]), np.array([k]))[0]))
                for k, name, node, q in touching
            ),
            key=lambda c: c.node,
        )
    )
    fresh = tuple(EventKey(function, node) for _, _, node, _ in touching for function in (
        EventFunction.NORMAL_FORCE, EventFunction.CONE_PLUS, EventFunction.CONE_MINUS))
    return ContactState(
        fingers, contacts, 0.0, relative_per_depth, tuple(c.node for c in contacts), fresh
    )


@dataclass(frozen=True)
class Event:
    """A located contact event.

    Attributes
    ----------
    type : EventType
        A (new contact), B (break), C (stick to slip) or D (slip to stick); a plain letter is
        converted.
    node : int
        Mesh node index.
    finger : Finger
        The finger involved.
    depth : float
        Squeeze depth at the event, m.
    relative_depth : float
        Relative squeeze depth at the event (fraction; 0 when not a squeeze).
    mode : str
        Contact mode of the node after the event ("stick", "slip" or "none" after B).
    slip : int
        Slip direction after the event (see :class:`ContactNode`).
    """

    type: EventType
    node: int
    finger: Finger
    depth: float
    relative_depth: float
    mode: str
    slip: int = 0

    def __post_init__(self) -> None:
        # numpy scalars from either fixed-set route become Python's: one type per field
        for name, kind in (("node", int), ("depth", float), ("relative_depth", float),
                           ("slip", int)):
            object.__setattr__(self, name, kind(getattr(self, name)))
        object.__setattr__(self, "type", EventType(self.type))
        object.__setattr__(self, "finger", Finger(self.finger))

    def to_json(self) -> dict:
        """``{"type", "node", "finger", "depth", "relative_depth", "mode", "slip"}``."""
        return {
            "type": self.type.value,
            "node": self.node,
            "finger": self.finger,
            "depth": self.depth,
            "relative_depth": self.relative_depth,
            "mode": self.mode,
            "slip": self.slip,
        }


def event_counts(events: Iterable[Event]) -> dict[str, int]:
    """Events of each type, ``{"A": n, "B": n, "C": n, "D": n}`` (keyed by the letters, as in
    JSON).
    """
    counted = Counter(e.type for e in events)
    return {t.value: counted[t] for t in EventType}


@dataclass(frozen=True)
class Sample:
    """The configuration at one accepted point of the stepper (substep end or event).

    Attributes
    ----------
    depth : float
        Squeeze depth, m.
    nodes : tuple of int
        Contact nodes.
    thetas : tuple of float
        Their polar angles, rad.
    finger_forces : mapping
        Finger -> total force (fx, fy) on the object, N.
    """

    depth: float
    nodes: tuple[int, ...]
    thetas: tuple[float, ...]
    finger_forces: Mapping[Finger, tuple[float, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class Chatter:
    """A node whose contact mode was frozen by the chattering bound.

    Attributes
    ----------
    node : int
    finger : Finger
    depth : float
        Depth at which it was frozen, m.
    until : float
        Depth until which its mode stays frozen, m.
    """

    node: int
    finger: Finger
    depth: float
    until: float

    def to_json(self) -> dict:
        """``{"node", "finger", "depth", "until"}``."""
        return {"node": self.node, "finger": self.finger, "depth": self.depth, "until": self.until}


@dataclass(frozen=True)
class StepResult:
    """Outcome of one :func:`~.stepper.advance` call.

    Attributes
    ----------
    state : ContactState
        The state reached.
    events : tuple of Event
        Events located during the call, in processing order.
    fraction : float
        Fraction of the requested translations applied (< 1 after a termination or when
        stopping at the first event).
    termination : Termination or None
        The termination that ended the motion, if one did.
    samples : tuple of Sample
        Accepted points (substep ends and event points), for trajectories.
    chatter : tuple of Chatter
        Nodes frozen by the chattering bound during the call.
    diagnostics : mapping
        Newton iterations and residuals, root-finding evaluations, condition numbers.
    next_substep : float
        The substep the call would have taken next, relative to the object size (the ``step``
        grid unless the model adapts its substeps): pass it as ``first_substep`` to the next
        call.
    """

    state: ContactState
    events: tuple[Event, ...]
    fraction: float
    termination: Termination | None
    samples: tuple[Sample, ...]
    chatter: tuple[Chatter, ...]
    diagnostics: Mapping[str, float]
    next_substep: float
