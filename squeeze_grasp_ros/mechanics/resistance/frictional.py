# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Resistance under frictional segment contacts (paper Sec. 6.3, Algorithm 2).

A loop over the incremental stepper (:func:`~.stepper.advance`) with three fingertips. It
starts from a squeeze computed by the event-driven squeeze
(:func:`~.squeeze_events.event_squeeze`);
the adversary A (a rounded tip of its own radius) then touches the *deformed* boundary at its
contact node on the deformed outward normal, with zero force and its mode decided along its
first motion. At every stage, with the current contact sets I, J, K:

1. the directions psi1, psi2 of F1 and F2 per unit push of A along a_hat = a / ||a|| minimise the
   approximate extra work (eqs. 67-68): every contact node, sliding or not, is treated as
   moving with its finger, which is the fixed-segment resistance of Sec. 6.2 with a_hat in place
   of a (:func:`~.resistance.optimal_resistance`, stable or pure);
2. the three fingers translate by (psi1, psi2, a_hat) times the remaining push until the next
   event point (``advance(..., stop_on_event=True)``, the event machinery of Algorithm 1 with
   three fingers);
3. the stepper integrates each finger's work along its path (the actual W'_F of line 8) and
   updates I, J, K, the stick/slip sets and the contact forces (lines 9-11).

The loop ends when A has completed a (success), when A's contacts all slide the same way (the
adversary slips: success), or when all contacts of F1 or F2 slide the same way (that finger
slips: failure), as in Algorithm 2 and Sec. 6.3. Only the directions of a stage use the
linearised Sec. 6.2 model; the motion, events, forces and work are the stepper's. SI units at
the interface, object frame.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.mesh import vertex_normals
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    optimal_resistance,
    require_push_range,
    resistance_grasp,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.contact_state import (
    ContactState,
    Event,
    event_counts,
    initial_state,
)
from squeeze_grasp_ros.mechanics.squeeze.fingertips import Fingertip
from squeeze_grasp_ros.mechanics.squeeze.stepper import advance
from squeeze_grasp_ros.mechanics.vocabulary import (
    ContactKind,
    ContactMode,
    Finger,
    SqueezeKind,
    Termination,
)

MAX_STALLED_CALLS = 3
"""Stepper calls in a row without progress or events after which the loop stops with an error."""


@dataclass(frozen=True)
class ResistanceStage:
    """One stage of Algorithm 2: fixed directions between two event points.

    Attributes
    ----------
    start, end : float
        Distance travelled by A at the stage's start and end, m.
    psi : (4,) ndarray
        (psi1, psi2): translations of F1 and F2 per unit translation of A (dimensionless).
    segments : mapping
        Finger -> contact nodes of F1, F2, A during the stage (I, J, K).
    events : tuple of Event
        Events located at the stage's end.
    """

    start: float
    end: float
    psi: np.ndarray
    segments: Mapping[Finger, tuple[int, ...]]
    events: tuple[Event, ...]

    def to_json(self) -> dict:
        """``{"start", "end", "psi": {"F1", "F2"}, "segments", "events"}``."""
        return {
            "start": self.start,
            "end": self.end,
            "psi": {Finger.F1: self.psi[:2].tolist(), Finger.F2: self.psi[2:].tolist()},
            "segments": {f: list(v) for f, v in self.segments.items()},
            "events": [e.type.value for e in self.events],
        }


@dataclass(frozen=True)
class FrictionalResistance:
    """Outcome of :func:`frictional_resistance` (SI, object frame).

    Attributes
    ----------
    success : bool
        A completed a, or A slipped, while F1 and F2 held.
    reason : str
        "adversary completed a", "adversary slips", "F1 slips", "F2 slips", "F1 and F2 slip"
        (both at once), or a lost contact.
    mode : SqueezeKind
        How each stage's directions were chosen (stable or pure).
    contacts : list of int
        Initial contact nodes [i, j, k] of F1, F2 (before the squeeze) and A.
    a : (2,) ndarray
        Requested translation of A, m.
    travelled : float
        Distance A translated, m.
    d1, d2 : (2,) ndarray
        Total translations of F1 and F2 during the resistance, m.
    work : mapping
        Work of F1, F2, A during the resistance, J; "total" = F1 + F2 (W_F).
    forces : mapping
        Finger -> (start, end) resultant force on the object, N (each (2,)).
    force_along : mapping
        F1, F2 -> (start, end) force component along the finger's total translation, N
        (Table 3); A -> along a.
    trajectories : mapping
        Finger -> (k, 2) translation since the start of the resistance at each stage end, m
        (the paths are straight between these points).
    events : tuple of Event
        Events during the resistance, in order (``depth`` is the stepper's depth, m).
    event_travel : tuple of float
        Distance travelled by A at each event, m.
    stages : tuple of ResistanceStage
    state : ContactState
        Final state (F1, F2, A).
    start_state : ContactState
        State at the start of the resistance (A just touching).
    diagnostics : mapping
        Stage counts, conditions and the stepper's counts.
    """

    success: bool
    reason: str
    mode: SqueezeKind
    contacts: list
    a: np.ndarray
    travelled: float
    d1: np.ndarray
    d2: np.ndarray
    work: Mapping[str, float]
    forces: Mapping[Finger, tuple[np.ndarray, np.ndarray]]
    force_along: Mapping[Finger, tuple[float, float]]
    trajectories: Mapping[Finger, np.ndarray]
    events: tuple[Event, ...]
    event_travel: tuple[float, ...]
    stages: tuple[ResistanceStage, ...]
    state: ContactState = field(repr=False)
    start_state: ContactState = field(repr=False)
    diagnostics: Mapping[str, object] = field(default_factory=dict)

    @property
    def event_counts(self) -> dict[str, int]:
        """{"A": n, "B": n, "C": n, "D": n} during the resistance."""
        return event_counts(self.events)

    def to_json(self) -> dict:
        """JSON-able dict with the keys of the fixed-contact resistance plus trajectories."""
        return {
            "success": self.success,
            "reason": self.reason,
            "mode": self.mode,
            "contact_model": ContactKind.FRICTION,
            "contacts": list(self.contacts),
            "segments": {
                f: [
                    {"node": c.node, "mode": c.mode, "force": c.force.tolist()}
                    for c in self.state.segment(f)
                ]
                for f in tuple(Finger)
            },
            "a": self.a.tolist(),
            "travelled": self.travelled,
            "d1": self.d1.tolist(),
            "d2": self.d2.tolist(),
            "work": dict(self.work),
            "forces": {f: v[1].tolist() for f, v in self.forces.items()},
            "forces_start": {f: v[0].tolist() for f, v in self.forces.items()},
            "force_along": {f: {"start": v[0], "end": v[1]} for f, v in self.force_along.items()},
            "trajectories": {f: v.tolist() for f, v in self.trajectories.items()},
            "events": [
                {**e.to_json(), "travel": t} for e, t in zip(self.events, self.event_travel)
            ],
            "event_counts": self.event_counts,
            "stages": [s.to_json() for s in self.stages],
            "diagnostics": dict(self.diagnostics),
        }


def add_adversary(
    state: ContactState, model: ContactModel, displacement: np.ndarray, node: int, radius: float
) -> ContactState:
    """``state`` with the adversary tip touching boundary ``node`` of the deformed object.

    Parameters
    ----------
    state : ContactState
        State of F1 and F2 (e.g. after the squeeze).
    model : ContactModel
    displacement : (n, 2) ndarray
        Displacement field of ``state``, m.
    node : int
        A's contact node on the outer boundary (not in contact with F1 or F2).
    radius : float
        A's tip radius, m (> 0).

    Returns
    -------
    ContactState
        With A placed on the deformed outward normal at ``node`` (zero force, mode decided
        along its first motion) and ``relative_per_depth`` = 0 (the motion is not a squeeze).
    """
    if not (np.isfinite(radius) and radius > 0):
        raise InvalidInputError(
            f"adversary.tip_radius must be > 0 m for frictional contact, got {radius}"
        )
    if any(c.node == node for c in state.contacts):
        raise InvalidInputError(f"the adversary's node {node} already touches F1 or F2")
    mesh = model.obj.mesh
    loop = mesh.boundary
    deformed = mesh.nodes[loop] + displacement[loop]
    k = mesh.boundary_position(int(node))
    n = vertex_normals(deformed)[k]
    tip = Fingertip(Finger.A, int(node), deformed[k] + radius * n, float(radius),
                    float(np.arctan2(-n[1], -n[0])))
    touch = initial_state([tip])
    contact = replace(touch.contacts[0], displacement=np.asarray(displacement[node], float))
    return replace(
        state,
        fingers=state.fingers + touch.fingers,
        contacts=tuple(sorted(state.contacts + (contact,), key=lambda c: c.node)),
        relative_per_depth=0.0,
        undetermined=tuple(sorted(state.undetermined + touch.undetermined)),
        fresh=state.fresh + touch.fresh,
    )


def slipping_fingers(state: ContactState) -> list[Finger]:
    """Fingers whose contact nodes all slide the same way (Sec. 5.1)."""
    out = []
    for f in state.fingers:
        signs = {
            c.slip if c.mode == ContactMode.SLIP else 0
            for c in state.contacts
            if c.finger == f.name
        }
        if len(signs) == 1 and 0 not in signs:
            out.append(f.name)
    return out


def _lost_finger(state: ContactState) -> Finger:
    """The finger whose last contact lost its normal force (after a contact_lost termination)."""
    pressing = {
        f.name: sum(c.normal_force() for c in state.contacts if c.finger == f.name)
        for f in state.fingers
    }
    return min(pressing, key=pressing.get)


def _outcome(termination: str | None, state: ContactState) -> tuple[bool, str] | None:
    """(success, reason) if the stepper's termination ends Algorithm 2, else None."""
    if termination == Termination.FINGER_SLIP:
        slipping = slipping_fingers(state)
        if Finger.A in slipping:
            return True, "adversary slips"
        if len(slipping) > 1:
            return False, f"{' and '.join(slipping)} slip"
        return False, f"{slipping[0] if slipping else 'a grasping finger'} slips"
    if termination == Termination.CONTACT_LOST:
        finger = _lost_finger(state)
        return finger == Finger.A, f"{finger} lost contact"
    if termination is not None:
        return False, f"stopped by {termination}"
    return None


def frictional_resistance(
    model: ContactModel,
    state: ContactState,
    a,
    *, mode: SqueezeKind = SqueezeKind.STABLE,
    step: float = 1e-3,
    event_tol: float = 1e-9,
    contacts: Sequence[int] | None = None,
    progress: Callable[[float], None] | None = None,
    checkpoint: Callable[[], None] | None = None,
) -> FrictionalResistance:
    """Algorithm 2: F1 and F2 resist A's translation ``a`` from ``state`` (with A touching).

    Parameters
    ----------
    model : ContactModel
        Object and friction (the squeeze's model).
    state : ContactState
        F1, F2 and A, e.g. from :func:`add_adversary` after an event-driven squeeze.
    a : (2,) array_like
        Translation of A, m, object frame (nonzero).
    mode : {"stable", "pure"}
        Resistance type of each stage's directions (Sec. 6.2 with a_hat).
    step, event_tol : float
        Substep and event tolerance of the stepper, relative to the object size.
    contacts : sequence of 3 int, optional
        Initial contact nodes of F1, F2 (before the squeeze) and A, for the report; default:
        the first node of each finger's segment in ``state``.
    progress : callable, optional
        Called after every stage with the fraction of a travelled by A.
    checkpoint : callable, optional
        Called before every stepper substep and fixed-set solve; may raise to abandon the
        computation.

    Raises
    ------
    InvalidInputError
        If ``a`` is not a finite [x, y] from :data:`~.optimal.MIN_RELATIVE_PUSH` to
        :data:`~.optimal.MAX_RELATIVE_PUSH` of the object size long, the state's fingers are not
        F1, F2 and A, or the loop stalls.
    NumericalError
        If the stepper fails (a solve or an event location that does not converge).

    Examples
    --------
    Fig. 10's scene: after its squeeze, the adversary pushes and F2 slips before A's full travel.

    >>> from squeeze_grasp_ros.api import GraspSetup, load_scene, scene_file
    >>> setup = GraspSetup.build(load_scene(scene_file("resist_fig10")))
    >>> squeeze = setup.event_squeeze()
    >>> model, adv = setup.contact_model(terminations=False), setup.scene.adversary
    >>> state = add_adversary(squeeze.state, model, squeeze.displacement, setup.adversary_node,
    ...                       adv.tip_radius)
    >>> res = frictional_resistance(model, state, adv.a)
    >>> print(res.success, res.reason)
    False F2 slips

    The same in one call: :meth:`~squeeze_grasp_ros.scene.setup.GraspSetup.frictional_resistance`.
    """
    a = np.asarray(a, float).reshape(-1)
    require_finite("adversary translation a", a)
    if a.shape != (2,) or not np.any(a):
        raise InvalidInputError(
            f"adversary translation a must be a nonzero [x, y] in m, got {a.tolist()}"
        )
    require_push_range(a, model.obj.scale)
    length = float(np.hypot(*a))
    if [f.name for f in state.fingers] != list(tuple(Finger)):
        raise InvalidInputError(
            f"the state needs fingers {list(tuple(Finger))}, has {[f.name for f in state.fingers]}"
        )
    a_hat = a / length
    start_state = state
    if contacts is None:
        contacts = [state.segment(f)[0].node for f in tuple(Finger)]
    contacts = [int(c) for c in contacts]
    travelled, stalled = 0.0, 0
    stages, events, travel = [], [], []
    path = {f: [np.zeros(2)] for f in tuple(Finger)}
    diag = {"advance_calls": 0, "stage_reduced_condition_max": 1.0}
    outcome = None
    while outcome is None:
        segments = {f: tuple(c.node for c in state.segment(f)) for f in tuple(Finger)}
        stage = optimal_resistance(resistance_grasp(model.obj, segments), a_hat, mode=mode,
                                   per_unit_push=True)
        if not stage.success:
            outcome = (False, stage.reason)
            break
        diag["stage_reduced_condition_max"] = max(
            diag["stage_reduced_condition_max"], stage.diagnostics["reduced_condition"]
        )
        remaining = length - travelled
        moves = {Finger.F1: remaining * stage.d1, Finger.F2: remaining * stage.d2,
                 Finger.A: remaining * a_hat}
        depth0 = state.depth
        rate = float(np.linalg.norm(np.concatenate(list(moves.values()))))
        result = advance(
            model,
            state,
            moves,
            step=step,
            event_tol=event_tol,
            stop_on_event=True,
            terminate_on=(Termination.FINGER_SLIP,),
            checkpoint=checkpoint,
        )
        diag["advance_calls"] += 1
        state = result.state
        start = travelled
        travelled += result.fraction * remaining
        travel += [start + (e.depth - depth0) / rate * remaining for e in result.events]
        events += result.events
        stages.append(
            ResistanceStage(
                start, travelled, np.concatenate([stage.d1, stage.d2]), segments, result.events
            )
        )
        for f in tuple(Finger):
            path[f].append(state.finger(f).translation - start_state.finger(f).translation)
        if progress is not None:
            progress(min(travelled / length, 1.0))
        outcome = _outcome(result.termination, state)
        if outcome is None and result.fraction >= 1.0:
            outcome = (True, "adversary completed a")
        stalled = stalled + 1 if result.fraction == 0 and not result.events else 0
        if outcome is None and stalled >= MAX_STALLED_CALLS:
            raise InvalidInputError(f"the resistance stalled after A travelled {travelled:.6g} m")
    return _summary(
        outcome,
        mode,
        contacts,
        a,
        travelled,
        start_state,
        state,
        events,
        travel,
        stages,
        path,
        diag,
    )


def _summary(
    outcome: tuple[bool, str],
    mode: str,
    contacts: list,
    a: np.ndarray,
    travelled: float,
    start: ContactState,
    end: ContactState,
    events: list,
    travel: list,
    stages: list,
    path: dict,
    diag: dict,
) -> FrictionalResistance:
    moved = {f: end.finger(f).translation - start.finger(f).translation for f in tuple(Finger)}
    work = {f: end.finger(f).work - start.finger(f).work for f in tuple(Finger)}
    work["total"] = work[Finger.F1] + work[Finger.F2]
    forces = {f: (start.finger_force(f), end.finger_force(f)) for f in tuple(Finger)}
    along = {}
    for f in tuple(Finger):
        d = a if f == Finger.A else moved[f]
        unit = d / max(float(np.linalg.norm(d)), 1e-300)
        along[f] = (float(forces[f][0] @ unit), float(forces[f][1] @ unit))
    success, reason = outcome
    return FrictionalResistance(
        success=success,
        reason=reason,
        mode=mode,
        contacts=contacts,
        a=a,
        travelled=travelled,
        d1=moved[Finger.F1],
        d2=moved[Finger.F2],
        work=work,
        forces=forces,
        force_along=along,
        trajectories={f: np.array(v) for f, v in path.items()},
        events=tuple(events),
        event_travel=tuple(travel),
        stages=tuple(stages),
        state=end,
        start_state=start,
        diagnostics=diag,
    )
