# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event-driven squeeze to a depth with rounded fingertips or flat pads under Coulomb friction
(Algorithm 1).

:func:`squeeze_to_depth` is Algorithm 1 as a loop over the incremental stepper
(:func:`~.stepper.advance`, one call per event point); :func:`event_squeeze` sets it up from
initial contact nodes (fingertips on the outward normals, stable/pure squeeze directions from
:func:`~.squeeze.plan_squeeze` or user-given directions) and collects the output: event log,
final segments, forces, energy, work, polar-angle trajectories and grasp-health numbers.
SI units at the interface, object frame.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.hyperelastic import plane_stress_tensor
from squeeze_grasp_ros.mechanics.elastic.strain_measures import log_strain, max_principal_strains
from squeeze_grasp_ros.mechanics.elastic.stress_measures import element_stresses, von_mises
from squeeze_grasp_ros.mechanics.errors import (
    InvalidInputError,
    NumericalError,
    node_indices,
    require_finite,
    require_relative_depth,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    ContactModel,
    SetData,
    SolveOptions,
    TerminationLimits,
    strain_tables,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_state import (
    Chatter,
    ContactNode,
    ContactState,
    Event,
    Sample,
    event_counts,
    initial_state,
)
from squeeze_grasp_ros.mechanics.squeeze.fingertips import Fingertip, place_fingertip
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import Kernel, compiled_health, selected
from squeeze_grasp_ros.mechanics.squeeze.kept import kept_for
from squeeze_grasp_ros.mechanics.squeeze.nonlinear_model import (
    NonlinearContactModel,
    contact_model,
)
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import FingerMotion, finger_motion
from squeeze_grasp_ros.mechanics.squeeze.stepper import TERMINATION_ORDER, advance
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipShape
from squeeze_grasp_ros.mechanics.ties import TIE, first_max
from squeeze_grasp_ros.mechanics.vocabulary import (
    SQUEEZING_FINGERS,
    ContactMode,
    Finger,
    MaterialModel,
    SqueezeKind,
    StrainCriterion,
    StrainMeasure,
    StressMeasure,
    Termination,
)

MAX_STALLED_CALLS = 3


@dataclass(frozen=True)
class SqueezeRun:
    """Raw outcome of :func:`squeeze_to_depth`.

    Attributes
    ----------
    state : ContactState
        Final state.
    events : tuple of Event
    samples : tuple of Sample
        Accepted points (substep ends and event points), including the start.
    chatter : tuple of Chatter
    termination : str
        "depth_reached" or the stepper's termination.
    diagnostics : dict
        Merged stepper diagnostics (maxima and sums) plus ``advance_calls``.
    """

    state: ContactState
    events: tuple[Event, ...]
    samples: tuple[Sample, ...]
    chatter: tuple[Chatter, ...]
    termination: Termination
    diagnostics: Mapping[str, float]


def _merge(total: dict, new: dict) -> None:
    """Merge stepper diagnostics: counts add up, maxima stay maxima."""
    for key, value in new.items():
        if key in ("root_evaluations", "substeps", "substep_halvings", "substep_rejections",
                   "ambiguous_modes"):
            total[key] = total.get(key, 0) + value
        else:
            total[key] = max(total.get(key, value), value)


def squeeze_to_depth(
    model: ContactModel,
    state: ContactState,
    directions: Mapping[str, tuple[float, float]],
    depth: float,
    step: float = 1e-3,
    event_tol: float = 1e-9,
    progress: Callable[[float], None] | None = None,
    terminate_on: tuple[str, ...] = TERMINATION_ORDER,
    checkpoint: Callable[[], None] | None = None,
) -> SqueezeRun:
    """Algorithm 1: advance the fingers along ``directions`` until ``depth`` or a termination.

    Parameters
    ----------
    model : ContactModel
    state : ContactState
        Start state (its ``depth`` is the start depth).
    directions : mapping
        Finger name -> translation per unit depth (m/m); the stacked vector should have norm 1
        so that depth is rho of docs/design.md §2.
    depth : float
        Depth to add, m (>= 0).
    step, event_tol : float
        Substep and event tolerance relative to the object size (see :func:`advance`).
    progress : callable, optional
        Called with the completed fraction after every stepper call.
    terminate_on : tuple of str
        Terminations that end the squeeze besides the depth.
    checkpoint : callable, optional
        Called before every substep and every fixed-set solve; may raise to abandon the
        squeeze (see :func:`advance`).
    """
    if not (np.isfinite(depth) and depth >= 0):
        raise InvalidInputError(f"squeeze depth must be >= 0 m, got {depth}")
    dirs = {k: np.asarray(v, float) for k, v in directions.items()}
    start = state.depth
    events: list[Event] = []
    samples: list[Sample] = []
    chatter: list[Chatter] = []
    diag: dict = {"advance_calls": 0}
    termination, stalled, substep = Termination.DEPTH_REACHED, 0, None
    while True:
        remaining = depth - (state.depth - start)
        result = advance(
            model,
            state,
            {k: remaining * v for k, v in dirs.items()},
            step=step,
            event_tol=event_tol,
            stop_on_event=True,
            terminate_on=terminate_on,
            first_substep=substep,
            checkpoint=checkpoint,
        )
        substep = result.next_substep
        diag["advance_calls"] += 1
        _merge(diag, result.diagnostics)
        events += result.events
        samples += result.samples
        chatter += result.chatter
        state = result.state
        if progress is not None:  # exactly 1 once the depth is reached, whatever the rounding
            reached = result.fraction >= 1.0 or depth <= 0
            progress(1.0 if reached else min(1.0, (state.depth - start) / depth))
        if result.termination is not None:
            termination = result.termination
            break
        if result.fraction >= 1.0 or remaining <= 0:
            break
        stalled = stalled + 1 if result.fraction == 0 and not result.events else 0
        if stalled >= MAX_STALLED_CALLS:
            raise InvalidInputError(f"the squeeze stalled at depth {state.depth:.6g} m")
    return SqueezeRun(state, tuple(events), tuple(samples), tuple(chatter), termination, diag)


@dataclass(frozen=True)
class SegmentNode:
    """A contact node of a final segment.

    Attributes
    ----------
    node : int
    mode : ContactMode
    slip : int
        Slip direction (see :class:`~.contact_state.ContactNode`).
    force : (2,) ndarray
        Contact force on the object, N.
    normal_force, tangential_force : float
        f . e(nu) and f . t(nu), N (nu: the contact normal's angle).
    slip_margin : float
        mu f_n - |f_t|, N (0 on the cone edge).
    theta : float
        Contact coordinate (a circle's polar angle), rad.
    """

    node: int
    mode: ContactMode
    slip: int
    force: np.ndarray
    normal_force: float
    tangential_force: float
    slip_margin: float
    theta: float

    def to_json(self) -> dict:
        """All fields as a JSON-able dict (force as [fx, fy])."""
        return {
            "node": self.node,
            "mode": self.mode,
            "slip": self.slip,
            "force": self.force.tolist(),
            "normal_force": self.normal_force,
            "tangential_force": self.tangential_force,
            "slip_margin": self.slip_margin,
            "theta": self.theta,
        }


@dataclass(frozen=True)
class GraspHealth:
    """Grasp-health numbers of the final configuration; every strain and stress names its
    measure.

    Attributes
    ----------
    max_strain : float
        Largest element strain by ``criterion`` (principal: max |eps_1|, |eps_2|) in
        ``strain_measure``: the number the strain limit is tested on.
    max_strain_element : int
    criterion : StrainCriterion
    strain_measure : StrainMeasure
        The material model's own measure: small (linear), biot (corotational) or log
        (neo_hookean).
    max_principal_strain : mapping
        StrainMeasure -> largest max(|eps_1|, |eps_2|) of the same field in that measure (every
        measure, to compare fields of different models like for like).
    max_von_mises : float
        Largest plane-stress von Mises stress of ``stress_measure``, Pa.
    max_von_mises_element : int
    stress_measure : StressMeasure
        small_strain (linear: C : eps) or cauchy (the nonlinear models).
    max_displacement : float
        Largest nodal displacement magnitude, m.
    max_displacement_node : int
    slip_margin : mapping
        Finger -> min over its contacts of mu f_n - |f_t|, N.
    """

    max_strain: float
    max_strain_element: int
    criterion: StrainCriterion
    strain_measure: StrainMeasure
    max_principal_strain: Mapping[StrainMeasure, float]
    max_von_mises: float
    max_von_mises_element: int
    stress_measure: StressMeasure
    max_displacement: float
    max_displacement_node: int
    slip_margin: Mapping[Finger, float]

    def to_json(self) -> dict:
        """All fields as a JSON-able dict (measures as their names)."""
        return {
            "max_strain": self.max_strain,
            "max_strain_element": self.max_strain_element,
            "strain_measure": str(self.strain_measure),
            "criterion": str(self.criterion),
            "max_principal_strain": {str(m): v for m, v in self.max_principal_strain.items()},
            "max_von_mises": self.max_von_mises,
            "max_von_mises_element": self.max_von_mises_element,
            "stress_measure": str(self.stress_measure),
            "max_displacement": self.max_displacement,
            "max_displacement_node": self.max_displacement_node,
            "slip_margin": dict(self.slip_margin),
        }


@dataclass(frozen=True)
class EventSqueeze:
    """Result of :func:`event_squeeze` (SI, object frame).

    Attributes
    ----------
    termination : Termination
    depth, relative_depth : float
        Depth reached, m, and relative depth (fraction).
    target_depth : float
        Requested depth, m.
    kind : SqueezeKind
        Stable, pure or custom (user-given directions).
    contacts : tuple of int
        Initial contact nodes (F1, F2).
    directions : mapping
        Finger -> unit translation per depth (m/m).
    mu : float
    tip_radius : mapping
        Finger -> tip radius (a pad's edge radius), m.
    events : tuple of Event
    segments : mapping
        Finger -> tuple of SegmentNode, ordered by polar angle.
    energy : float
        Strain energy 1/2 delta . F, J.
    work : mapping
        Finger -> work done on the object, J (sum = energy + frictional dissipation).
    dissipation : mapping
        Finger -> energy dissipated by friction at its sliding contacts, J.
    finger_force : mapping
        Finger -> (start, end) force along its motion direction, N.
    trajectories : mapping
        Node -> ((relative depth, theta rad), ...) while in contact.
    health : GraspHealth
    chatter : tuple of Chatter
    displacement : (n, 2) ndarray
        Final displacement field, m.
    state : ContactState
        Final state (to continue with the stepper).
    step, event_tol : float
        Substep and event tolerance used, relative to the object size.
    reference : bool
        Computed by the paper's literal fixed-step route.
    diagnostics : mapping
        Stepper and solver counts, residuals and conditions (docs/events.md).
    force_curve : mapping
        Finger -> ((relative depth, force along its motion N), ...) at every accepted point.
    material_model : MaterialModel
        Constitutive model of the object.
    strain_limit : float or None
        The strain limit epsilon* the squeeze tested (in ``health.strain_measure``, by
        ``health.criterion``); None without one.
    tips : mapping
        Finger -> TipShape (circle or pad).
    """

    termination: Termination
    depth: float
    relative_depth: float
    target_depth: float
    kind: SqueezeKind
    contacts: tuple[int, ...]
    directions: Mapping[Finger, np.ndarray]
    mu: float
    tip_radius: Mapping[Finger, float]
    events: tuple[Event, ...]
    segments: Mapping[Finger, tuple[SegmentNode, ...]]
    energy: float
    work: Mapping[Finger, float]
    finger_force: Mapping[Finger, tuple[float, float]]
    trajectories: Mapping[int, tuple[tuple[float, float], ...]]
    health: GraspHealth
    chatter: tuple[Chatter, ...]
    displacement: np.ndarray = field(repr=False)
    state: ContactState = field(repr=False)
    step: float = 1e-3
    event_tol: float = 1e-9
    reference: bool = False
    diagnostics: Mapping[str, object] = field(default_factory=dict)
    force_curve: Mapping[Finger, tuple[tuple[float, float], ...]] = field(default_factory=dict)
    dissipation: Mapping[Finger, float] = field(default_factory=dict)
    material_model: MaterialModel = MaterialModel.LINEAR
    strain_limit: float | None = None
    tips: Mapping[Finger, TipShape] = field(default_factory=dict)

    @property
    def event_counts(self) -> dict[str, int]:
        """{"A": n, "B": n, "C": n, "D": n}."""
        return event_counts(self.events)

    def to_json(self) -> dict:
        """JSON-able dict with the keys and names of docs/design.md §2 and docs/events.md."""
        radii = list(self.tip_radius.values())
        return {
            "termination": self.termination,
            "depth": self.depth,
            "relative_depth": self.relative_depth,
            "target_depth": self.target_depth,
            "squeeze": self.kind,
            "contacts": list(self.contacts),
            "directions": {k: v.tolist() for k, v in self.directions.items()},
            "events": [e.to_json() for e in self.events],
            "event_counts": self.event_counts,
            "segments": {k: [s.to_json() for s in v] for k, v in self.segments.items()},
            "energy": self.energy,
            "work": dict(self.work),
            "dissipation": dict(self.dissipation),
            "finger_force": {
                k: {"start": v[0], "end": v[1]} for k, v in self.finger_force.items()
            },
            "mu": self.mu,
            "tip_radius": radii[0] if len(set(radii)) == 1 else max(radii),
            "tip_radii": dict(self.tip_radius),
            "tips": {k: v.to_json() for k, v in self.tips.items()},
            "material_model": str(self.material_model),
            "strain_limit": None if self.strain_limit is None else {
                "epsilon": self.strain_limit, "measure": str(self.health.strain_measure),
                "criterion": str(self.health.criterion)},
            "health": self.health.to_json(),
            "chatter": [c.to_json() for c in self.chatter],
            "trajectories": {str(k): [list(p) for p in v] for k, v in self.trajectories.items()},
            "step": self.step,
            "event_tol": self.event_tol,
            "reference": self.reference,
            "diagnostics": self.diagnostics,
        }


def segment_node(c: ContactNode, mu: float) -> SegmentNode:
    """Summary of a contact node (forces in N)."""
    fn, ft = c.normal_force(), c.tangential_force()
    return SegmentNode(
        c.node, c.mode, c.slip, np.asarray(c.force, float), fn, ft, mu * fn - abs(ft), c.theta
    )


def grasp_health(model: ContactModel, state: ContactState, *,
                 summaries: Sequence[SegmentNode] | None = None
                 ) -> tuple[GraspHealth, np.ndarray]:
    """Grasp-health numbers and the full displacement field (n, 2), m, of ``state``.

    One sparse solve (K+ F + R g) for the field (the nonlinear models keep theirs); strains in
    every measure and the model's stress per element. ``summaries``: the :func:`segment_node`
    of each of the state's contacts, in its order, when the caller has them.
    """
    return _health(model, state, _contact_loads(model, state), summaries)


def _contact_loads(model: ContactModel, state: ContactState
                   ) -> tuple[SetData, np.ndarray, np.ndarray]:
    """The set data of ``state``'s contacts and their displacements and forces (k, 2) / L and
    / (E h L), as the contact model takes them.
    """
    sd = model.set_data(tuple(c.node for c in state.contacts))
    delta = np.array([c.displacement for c in state.contacts]) / model.length
    F = np.array([c.force for c in state.contacts]) / model.force_unit
    return sd, delta, F


def _health(model: ContactModel, state: ContactState,
            loads: tuple[SetData, np.ndarray, np.ndarray],
            summaries: Sequence[SegmentNode] | None) -> tuple[GraspHealth, np.ndarray]:
    """:func:`grasp_health` of the :func:`_contact_loads` ``loads`` of ``state``."""
    obj = model.obj
    u_hat = model.full_displacement(*loads)
    fields = _compiled_fields(model, u_hat)
    if fields is None:
        strain, element = model.field_strain(u_hat)
        deformation = model.field_deformation(u_hat)
        stress, stress_measure = element_stresses(model.constitutive_model, deformation,
                                                  E=obj.material.E, nu=obj.material.nu)
        vm = von_mises(stress)
        k_vm = first_max(vm)
        max_vm, max_principal = float(vm[k_vm]), max_principal_strains(deformation)
    else:
        strain, element, max_vm, k_vm, max_principal = fields
        stress_measure = model.constitutive_model.stress_measure
    u = u_hat.reshape(-1, 2) * model.length
    norms = np.sqrt((u * u).sum(axis=1))  # np.linalg.norm(u, axis=1), without its checks
    if summaries is None:
        summaries = [segment_node(c, model.mu) for c in state.contacts]
    margins: dict[str, list[float]] = {}
    for c, n in zip(state.contacts, summaries):
        margins.setdefault(c.finger, []).append(n.slip_margin)
    k_u = first_max(norms)  # a mirror twin: the first, on any machine
    health = GraspHealth(
        max_strain=strain,
        max_strain_element=element,
        criterion=StrainCriterion(model.limits.criterion),
        strain_measure=model.strain_measure,
        max_principal_strain=max_principal,
        max_von_mises=max_vm,
        max_von_mises_element=k_vm,
        stress_measure=stress_measure,
        max_displacement=float(norms[k_u]),
        max_displacement_node=k_u,
        slip_margin={f.name: float(min(margins[f.name])) for f in state.fingers
                     if f.name in margins},
    )
    checks = {f"max strain ({health.strain_measure.label} strain)": strain,
              **{f"max principal {m.label} strain": v for m, v in max_principal.items()},
              f"max von Mises stress ({stress_measure.label} stress, Pa)": health.max_von_mises,
              "max displacement (m)": health.max_displacement}
    for name, value in checks.items():  # the first one that is not finite, by name and measure
        if not math.isfinite(value):  # (the check once per squeeze, without an array each)
            require_finite(f"grasp health: {name}", value)
    return health, u


@functools.lru_cache(maxsize=16)
def _plane_stress(nu: float) -> np.ndarray:
    """:func:`~..elastic.hyperelastic.plane_stress_tensor` of ``nu``, kept (read-only)."""
    C = plane_stress_tensor(nu)
    C.flags.writeable = False
    return C


KEPT_STARTS = 256
"""Squeeze starts (tips, motion, initial state) an object keeps (:func:`_start`)."""


def _start(obj: ElasticObject, placements: Mapping[str, tuple], kind: str,
           directions: Mapping[str, tuple[float, float]] | None
           ) -> tuple[list[Fingertip], FingerMotion, ContactState]:
    """The placed tips, the finger motion and the initial state of a squeeze of ``obj`` from
    ``placements`` (finger -> (node, tip, facing, origin) as :func:`event_squeeze` takes
    them). A start of planned directions is kept on the object, its arrays read-only (the state
    is immutable): a sweep squeezes each placement and tip at several frictions and depths,
    from the same start. Inputs that cannot be a key are not kept (they fail as they did).
    """
    def make() -> tuple[list[Fingertip], FingerMotion, ContactState]:
        tips = [place_fingertip(obj.mesh, n, *placement) for n, placement in placements.items()]
        motion = finger_motion(obj, tuple(t.node for t in tips), kind=kind,
                               directions=directions)
        return tips, motion, initial_state(tips, motion.relative_per_depth)

    if directions is not None:
        return make()
    try:
        tag = (str(kind), tuple((str(n), node, tip, facing, None if origin is None else tuple(
            float(x) for x in np.asarray(origin, float).reshape(-1)))
            for n, (node, tip, facing, origin) in placements.items()))
        hash(tag)
    except (TypeError, ValueError):  # no key (an origin that is not numbers): make() says why
        return make()
    kept = obj._shared.setdefault("squeeze_starts", {})
    return kept_for(kept, obj, tag, lambda: _frozen(make()), KEPT_STARTS)


def _frozen(start: tuple[list[Fingertip], FingerMotion, ContactState]) -> tuple:
    """``start`` with every array it holds made read-only (it is shared by the squeezes that
    start there).
    """
    tips, motion, state = start
    arrays = [t.center for t in tips] + list(motion.directions.values())
    arrays += [a for f in state.fingers for a in (f.center, f.translation)]
    arrays += [a for c in state.contacts for a in (c.displacement, c.force)]
    for a in arrays:
        a.flags.writeable = False
    return start


def _compiled_fields(model: ContactModel, u_hat: np.ndarray) -> tuple | None:
    """The linear model's health fields of the displacement ``u_hat`` (2n,) / L by the
    compiled pass (:mod:`.health_numba`; the same floats as the numpy route): (strain, its
    element, von Mises stress Pa, its element, the largest principal strain by measure); None
    on the numpy route or for a nonlinear model.
    """
    if model.constitutive_model != MaterialModel.LINEAR or selected() != Kernel.NUMBA:
        return None
    obj = model.obj
    B, dofs = strain_tables(obj, model.length)
    G = obj.gradient
    strain, element, vm, k_vm, small, biot, green, two_e = compiled_health().linear_fields(
        u_hat, G.data, G.indices, G.indptr, B, dofs,
        model.limits.criterion == StrainCriterion.COMPONENTWISE,
        _plane_stress(float(obj.material.nu)), float(obj.material.E), TIE)
    return strain, element, vm, k_vm, {
        StrainMeasure.SMALL: small, StrainMeasure.BIOT: biot,
        StrainMeasure.LOG: float(np.abs(log_strain(two_e)).max()),
        StrainMeasure.GREEN_LAGRANGE: green}  # StrainMeasure's order, as the numpy route's


def _segment(state: ContactState, summaries: Sequence[SegmentNode],
             name: str) -> tuple[SegmentNode, ...]:
    """The :func:`segment_node` ``summaries`` of the state's contacts on finger ``name``, in
    the order of :meth:`~.contact_state.ContactState.segment`.
    """
    mine = [(c, n) for c, n in zip(state.contacts, summaries) if c.finger == name]
    return tuple(n for _, n in sorted(mine, key=lambda pair: pair[0].theta))


def polar_trajectories(samples: tuple[Sample, ...], relative_per_depth: float) -> dict:
    """Node -> ((relative depth, theta), ...) from the stepper samples."""
    out: dict[int, list] = {}
    for s in samples:
        rel = s.depth * relative_per_depth
        for node, theta in zip(s.nodes, s.thetas):
            out.setdefault(node, []).append((rel, theta))
    return {k: tuple(v) for k, v in out.items()}


def _force_curves(samples: tuple[Sample, ...], dirs: Mapping[str, np.ndarray],
                  relative_per_depth: float) -> dict[str, tuple[tuple[float, float], ...]]:
    """Finger -> ((relative depth, force along its motion direction N), ...) at ``samples``.

    One product per finger over the samples: f_x d_x + f_y d_y is what the dot product of two
    2-vectors computes, term for term.
    """
    depths = [s.depth * relative_per_depth for s in samples]
    curves = {}
    for name in SQUEEZING_FINGERS:
        d = dirs[name]
        f = np.array([s.finger_forces[name] for s in samples], float).reshape(-1, 2)
        along = (f[:, 0] * d[0] + f[:, 1] * d[1]) / max(float(np.linalg.norm(d)), 1e-300)
        curves[name] = tuple(zip(depths, along.tolist()))
    return curves


def event_squeeze(
    obj: ElasticObject,
    contacts: tuple[int, int],
    tip: float | TipShape | Mapping[str, float | TipShape],
    mu: float,
    *, kind: str = SqueezeKind.STABLE,
    depth: float | None = None,
    relative_depth: float | None = None,
    limits: TerminationLimits | None = None,
    step: float = 1e-3,
    event_tol: float = 1e-9,
    reference: bool = False,
    max_events_per_depth: int = 4,
    directions: Mapping[str, tuple[float, float]] | None = None,
    progress: Callable[[float], None] | None = None,
    material_model: MaterialModel | str = MaterialModel.LINEAR,
    checkpoint: Callable[[], None] | None = None,
    options: SolveOptions | None = None,
    facing: Mapping[str, float] | None = None,
    origins: Mapping[str, Sequence[float]] | None = None,
) -> EventSqueeze:
    """Event-driven two-finger squeeze of ``obj`` from initial contact nodes (F1, F2).

    Parameters
    ----------
    obj : ElasticObject
    contacts : (int, int)
        Initial contact nodes of F1 and F2 on the outer boundary.
    tip : float, TipShape or mapping
        Fingertip: a circle's radius, m, or a :class:`~.tip_shapes.TipShape` (circle or
        pad), one for both fingers or per finger.
    mu : float
        Friction coefficient.
    kind : {"stable", "pure"}
        Squeeze directions from :func:`plan_squeeze` (ignored when ``directions`` is given).
    depth, relative_depth : float
        Exactly one: squeeze depth rho, m, or the finger approach over the initial contact
        distance (docs/design.md §2).
    limits : TerminationLimits, optional
        Strain limit and pickup weight.
    step, event_tol : float
        Substep and event tolerance relative to the object size.
    reference : bool
        Use the paper's literal route (fixed step, events at step ends, full solves).
    max_events_per_depth : int
        Chattering bound (see :mod:`.stepper`).
    directions : mapping, optional
        User-given finger translation directions (normalised so the stacked vector has norm 1).
    progress : callable, optional
        Called with the completed fraction.
    material_model : MaterialModel or str
        ``linear`` (the paper's small-strain model, default), ``corotational`` or
        ``neo_hookean`` (finite deformation: :mod:`.nonlinear_model`).
    checkpoint : callable, optional
        Called before every substep and every fixed-set solve; may raise to abandon the
        squeeze (a cancellation).
    options : SolveOptions, optional
        Switches of the large-deformation savings (adaptive substeps, factorisation reuse),
        for measuring them; default both on.
    facing : mapping, optional
        Finger -> the angle (rad) of the direction its tip faces, into the object (a gripper's
        closing direction); default the inward normal at its contact node. A tip given a
        facing, or a pad, approaches along it until it touches the object
        (:func:`~.fingertips.place_fingertip`); the node it touches first is its initial
        contact (``contacts`` of the result).
    origins : mapping, optional
        Finger -> where a tip given a facing starts its approach (its reference point, m; a
        gripper jaw on its closing line); default on its contact node.

    Returns
    -------
    EventSqueeze
        The termination, the events (depths in m and relative), the final contact segments,
        forces (N), work and energy (J), grasp health and the displacement field (m).

    Raises
    ------
    InvalidInputError
        For bad arguments (named): contacts not two distinct outer-boundary nodes, a tip
        missing for a finger, not exactly one of ``depth`` and ``relative_depth``, a relative
        depth outside [0, 1), an unknown ``kind`` or ``material_model``, ...
    InfeasibleError
        If the stable squeeze of ``contacts`` is not unique (a repeated eigenvalue of C).
    NumericalError
        If a solve or an event location does not converge; the message starts with the
        depth, m, and relative depth of the last point solved (``depth`` and
        ``relative_depth`` of the error).

    Examples
    --------
    >>> from squeeze_grasp_ros.api import finger_nodes, load_scene, scene_file, scene_solid
    >>> scene = load_scene(scene_file("foam_square"))
    >>> obj = scene_solid(scene)
    >>> res = event_squeeze(obj, finger_nodes(scene, obj.mesh), 0.02, 0.4, relative_depth=0.05)
    >>> print(res.termination, sorted({e.type for e in res.events}))
    depth_reached ['A']
    """
    if (depth is None) == (relative_depth is None):
        raise InvalidInputError("give exactly one of depth (m) and relative_depth")
    if relative_depth is not None:
        require_relative_depth(relative_depth)
    names = SQUEEZING_FINGERS
    contacts = tuple(node_indices("contacts", contacts).tolist())
    if len(contacts) != len(names):
        raise InvalidInputError(f"contacts must be {len(names)} nodes (F1, F2), got "
                                f"{len(contacts)}")
    shapes = dict(tip) if isinstance(tip, Mapping) else dict.fromkeys(names, tip)
    missing = [str(n) for n in names if n not in shapes]
    if missing:
        raise InvalidInputError(f"tip gives no fingertip for {', '.join(missing)}")
    facing, origins = dict(facing or {}), dict(origins or {})
    tips, motion, start = _start(obj, {n: (int(c), shapes[n], facing.get(n), origins.get(n))
                                       for n, c in zip(names, contacts)}, kind, directions)
    contacts = tuple(t.node for t in tips)
    radii = {t.name: t.radius for t in tips}
    shapes = {n: s if isinstance(s, TipShape) else TipShape.circle(radii[n])
              for n, s in shapes.items() if n in names}
    dirs, relative_per_depth, kind = motion.directions, motion.relative_per_depth, motion.kind
    if depth is None:
        if not relative_per_depth > 0:
            raise InvalidInputError(
                "the fingers do not approach each other: relative depth undefined"
            )
        depth = relative_depth / relative_per_depth
    require_relative_depth(depth * relative_per_depth, depth)
    model = contact_model(material_model, obj, mu, limits or TerminationLimits(), reference,
                          max_events_per_depth, options or SolveOptions())
    try:
        run = squeeze_to_depth(model, start, dirs, depth, step, event_tol, progress,
                               checkpoint=checkpoint)
    except NumericalError as error:  # where, also as a relative depth
        relative = None if error.depth is None else error.depth * relative_per_depth
        raise error.located(error.depth, relative) from error
    state = run.state
    summaries = [segment_node(c, mu) for c in state.contacts]
    loads = _contact_loads(model, state)
    health, u_field = _health(model, state, loads, summaries)
    energy = model.strain_energy(*loads) * model.force_unit * model.length
    forces_along = {}
    for name in names:
        d = dirs[name] / max(np.linalg.norm(dirs[name]), 1e-300)
        forces_along[name] = (
            float(np.asarray(run.samples[0].finger_forces[name]) @ d),
            float(state.finger_force(name) @ d),
        )
    diag = dict(run.diagnostics)
    diag["compliance"] = obj.diagnostics()
    if isinstance(model, NonlinearContactModel):
        diag["nonlinear"] = model.diagnostics()
    diag["work_minus_energy"] = sum(f.work for f in state.fingers) - energy
    diag["energy_balance"] = diag["work_minus_energy"] - sum(f.dissipation for f in state.fingers)
    return EventSqueeze(
        termination=run.termination,
        depth=state.depth,
        relative_depth=state.depth * relative_per_depth,
        target_depth=float(depth),
        kind=kind,
        contacts=tuple(int(c) for c in contacts),
        directions={k: v.copy() for k, v in dirs.items()},
        mu=float(mu),
        tip_radius=radii,
        events=run.events,
        segments={n: _segment(state, summaries, n) for n in names},
        energy=energy,
        work={f.name: f.work for f in state.fingers},
        dissipation={f.name: f.dissipation for f in state.fingers},
        finger_force=forces_along,
        trajectories=polar_trajectories(run.samples, relative_per_depth),
        force_curve=_force_curves(run.samples, dirs, relative_per_depth),
        health=health,
        chatter=run.chatter,
        displacement=u_field,
        state=state,
        step=step,
        event_tol=event_tol,
        reference=reference,
        diagnostics=diag,
        material_model=model.constitutive_model,
        strain_limit=model.limits.strain,
        tips=shapes,
    )
