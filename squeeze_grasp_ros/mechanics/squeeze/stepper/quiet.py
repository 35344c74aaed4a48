# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Quiet calls: a stepper call that crosses no event, answered without the event machinery.

A caller that moves the fingers in many small translations (the simulated world: one
:func:`~.run.advance` call per 1 ms tick) pays, in every call, for what a call must do when it
knows nothing of the one before: re-solving and re-processing the start point (pending events,
terminations), the watched functions at both ends, keyed tables of every function. When

* the contact model has a constant reduced stiffness (the linear material: the forces are a
  product with the set's cached stiffness, no factorisation) and keeps the ``step`` grid,
* every contact sticks (so no function watched at the start depends on the direction of the
  new motion, and no Newton iteration runs), nothing is zero by construction (``fresh``) and no
  mode is undetermined,
* the translation is at most one grid substep (the call is one substep from s = 0 to 1),

such a call makes exactly two solves (at s = 0 and s = 1), finds no event and ends at s = 1.
:class:`QuietSteps` makes those same two solves (the same operations on the same arrays, so
the same forces bit for bit), makes sure every watched function is above :data:`QUIET_MARGIN`
at both ends, and returns the same :class:`~..contact_state.StepResult`. Anything else (a
function at or below the margin, a sliding contact, a nonlinear material, a long translation)
is handed to :func:`~.run.advance` whole, so events are located exactly as before.

Within one sticking mode everything but the finger positions stays: the set's stiffness and tip
offsets, the watched rows and contacts, each contact's node, finger and angles. The first quiet
call of a mode keeps them (:class:`_Mode`, until the next full call or until a hold of the
chattering bound expires), and the calls after it compute only what moves: the two solves, the
work integral, the samples' finger forces, the contacts' displacements and forces. The
contacts' normal forces and cone margins are linear in the forces (one product with the mode's
``margins`` per call); the free rows' gaps and the area check change by at most a rate the mode
fixes times the fingers' translation (:class:`~.travel.TravelRates`): where they are evaluated
(the mode's first call, and whenever the fingers leave the last reach) they give a travel
within which neither can reach the margin, and a call that ends within it evaluates neither.
The strain limit and the pickup margin, when declared, are evaluated at every call.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    INVERSION_AREA_RATIO,
    ContactModel,
    Solution,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_state import (
    ContactNode,
    ContactState,
    FingerState,
    Sample,
    StepResult,
    tip_geometry,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.area_watch import AreaWatch
from squeeze_grasp_ros.mechanics.squeeze.stepper.chatter import ChatterBound
from squeeze_grasp_ros.mechanics.squeeze.stepper.compiled import QUIET_MARGIN
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions
from squeeze_grasp_ros.mechanics.squeeze.stepper.motion import FingerMotion
from squeeze_grasp_ros.mechanics.squeeze.stepper.run import TERMINATION_ORDER, advance
from squeeze_grasp_ros.mechanics.squeeze.stepper.solving import Counters
from squeeze_grasp_ros.mechanics.squeeze.stepper.travel import TravelRates
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry, tangent, unit
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, MaterialModel, Termination

__all__ = ["QUIET_MARGIN", "QuietSteps"]

_STILL = (0.0, 0.0)
_ENDS = np.array([0.0, 1.0])[:, None, None]
"""The path parameter s at a quiet call's two ends, to broadcast over the fingers (f, 2)."""


class QuietSteps:
    """Stepper calls of one caller, each quiet when it can be (see the module).

    Parameters
    ----------
    model : ContactModel
    step, event_tol : float
        As for :func:`~.run.advance` (relative to the object size).
    terminate_on : tuple of str
        As for :func:`~.run.advance`.
    quiet : bool
        False: every call goes through :func:`~.run.advance` (to compare the two paths).

    Attributes
    ----------
    calls : dict
        ``{"quiet": n, "full": n}``: how many calls took each path.
    evaluations : int
        Quiet calls that evaluated the watched functions (the others ended within the reach of
        the last evaluation).
    """

    def __init__(self, model: ContactModel, step: float, event_tol: float,
                 terminate_on: tuple[str, ...] = TERMINATION_ORDER, *,
                 quiet: bool = True) -> None:
        self.model, self.step, self.event_tol = model, step, event_tol
        self.terminate_on = tuple(terminate_on)
        self.calls = {"quiet": 0, "full": 0}
        self.evaluations = 0
        self._checked: ContactState | None = None
        self._fingers: tuple[np.ndarray, np.ndarray] | None = None
        self._tips: tuple | None = None
        self._set: _Sticking | None = None
        self._mode: _Mode | None = None
        self._reach: tuple[np.ndarray, float] | None = None
        self._boundary = model.positions(model.boundary_nodes)
        self._length = model.length
        self._applies = (quiet and model.constitutive_model == MaterialModel.LINEAR
                         and not model.reference and not model.adaptive_steps
                         and model.mu > 0.0)
        limits = model.limits
        self._terminations = (
            (limits.strain is not None and Termination.STRAIN_LIMIT in self.terminate_on)
            or (limits.weight is not None and Termination.PICKED_UP in self.terminate_on))
        self.area = AreaWatch(model) if self._applies else None

    def advance(self, state: ContactState,
                translations: Mapping[str, tuple[float, float]]) -> StepResult:
        """:func:`~.run.advance` of ``state`` by ``translations`` (m): the same result."""
        result = self._quiet(state, translations) if self._applies else None
        if result is None:
            self.calls["full"] += 1
            self._mode = None
            return advance(self.model, state, translations, step=self.step,
                           event_tol=self.event_tol, terminate_on=self.terminate_on)
        self.calls["quiet"] += 1
        return result

    def _quiet(self, state: ContactState,
               translations: Mapping[str, tuple[float, float]]) -> StepResult | None:
        """The quiet call's result, or None when the call is not quiet."""
        mode = self._mode
        if mode is not None and state is self._checked and state.depth < mode.expiry:
            return self._next(mode, state, translations)
        self._mode = None
        if (state.fresh or state.undetermined or len(state.contacts) < 2
                or any(c.mode != ContactMode.STICK for c in state.contacts)):
            return None
        motion = self._motion(state, translations)
        if motion is None or not _one_substep(self.step, motion.rate):
            return None
        mode = self._enter(state, motion)
        start, D = motion.start, motion.translation
        ends = mode.sticking.ends(start, D)
        reach = (0.0 if ends is None
                 else self._evaluate(mode, start, ends[1][0], ends[2][0], D))
        if reach <= 0.0:
            return None
        self._mode, self._reach = mode, (start, reach * reach)
        if not self._within(ends[0][1], ends[1][1], ends[2][1], D):
            return None
        t0 = np.array([f.translation for f in state.fingers], float) / self._length
        return self._result(mode, state, (D, motion.rate, t0), ends)

    def _next(self, mode: _Mode, state: ContactState,
              translations: Mapping[str, tuple[float, float]]) -> StepResult | None:
        """The next quiet call of ``mode`` from ``state`` (the state its last call returned),
        or None when it is not quiet.
        """
        L = self._length
        if not translations.keys() <= mode.known:
            return None
        D = np.array([translations.get(n, _STILL) for n in mode.names], float) / L
        d = D.ravel()
        # the norm as np.linalg.norm computes it (sqrt of the dot product: math.sqrt rounds
        # as np.sqrt), without its checks; a translation with a value that is not finite has a
        # rate that is not
        rate = math.sqrt(d.dot(d))
        if not (math.isfinite(rate) and _one_substep(self.step, rate)):
            return None
        centers, moved = self._fingers
        ends = mode.sticking.ends(centers / L, D)
        if ends is None or not self._within(ends[0][1], ends[1][1], ends[2][1], D):
            return None
        return self._result(mode, state, (D, rate, moved / L), ends)

    def _within(self, end: np.ndarray, delta: np.ndarray, F: np.ndarray, D: np.ndarray) -> bool:
        """Whether every watched function of the mode is above :data:`QUIET_MARGIN` at the end
        of the call (tips at ``end``, the set at ``delta``, ``F``): the contact functions (affine
        along the call, so above it all along when above at both ends) and the terminations
        declared evaluated; the gaps and the area check from the reach of their last evaluation
        when the end lies within it, else evaluated there (and the reach renewed).
        """
        mode = self._mode
        ref, reach2 = self._reach
        off = (end - ref).ravel()
        if off @ off < reach2:
            return (_clear(mode.margins, F)
                    and (not self._terminations or self._terminations_clear(mode, delta, F, D)))
        reach = self._evaluate(mode, end, delta, F, D)
        if reach <= 0.0:
            return False
        self._reach = (end, reach * reach)
        return True

    def _enter(self, state: ContactState, motion: FingerMotion) -> _Mode:
        """The constants of the state's sticking mode (its contact set, the functions watched,
        the results' fixed parts, the functions' rates), until a hold of the chattering bound
        expires.
        """
        model = self.model
        sticking = self._sticking(state, motion)
        contacts = sticking.contacts
        chatter = ChatterBound(state, self.step * model.length, model.max_events_per_depth)
        depth = motion.depth_at(0.0)
        held = chatter.held_nodes(depth)
        functions = EventFunctions(model, motion, self.terminate_on)
        watched = ~chatter.held(contacts.nodes, depth)
        expiry = min((until for until in chatter.holds.values() if until > depth),
                     default=np.inf)
        names, fingers, L = motion.names, contacts.finger, model.length
        rows = functions.free_rows(contacts, held)
        thetas = np.array(contacts.theta, float).tolist()
        radius, flat, facing = (motion.radius * L, (motion.tip.flat * L).tolist(),
                                motion.tip.facing.tolist())
        return _Mode(
            sticking, names, frozenset(names), motion.tip, functions, rows,
            _margins(sticking, watched, model.mu), expiry,
            tuple((names[f], _rows_of(fingers == f), bool((fingers == f).any()), radius[f],
                   flat[f], facing[f]) for f in range(len(names))),
            tuple(ContactNode(node, names[f], ContactMode.STICK, 0, theta, None, None, nu)
                  for node, f, theta, nu in zip(contacts.nodes.tolist(), fingers.tolist(),
                                                thetas, sticking.nu.tolist())),
            tuple(contacts.nodes.tolist()), tuple(thetas),
            TravelRates.of(model, contacts, len(names), rows, self.area),
            L, model.force_unit, model._cache)

    def _motion(self, state: ContactState,
                translations: Mapping[str, tuple[float, float]]) -> FingerMotion | None:
        """:meth:`FingerMotion.of` (the tips kept while they are the same), or None for a
        translation :func:`~.run.advance` would refuse (it then says why).
        """
        L = self._length
        fingers = state.fingers
        if self._tips is None or self._tips[0] is not fingers:
            key = tuple((f.name, f.radius, f.flat, f.facing) for f in fingers)
            if self._tips is None or self._tips[1] != key:
                names = tuple(f.name for f in fingers)
                self._tips = (fingers, key, names, frozenset(names),
                              tip_geometry(fingers).scaled(L))
            else:
                self._tips = (fingers, *self._tips[1:])
        names, known, tips = self._tips[2:]
        if not translations.keys() <= known:
            return None
        D = np.array([translations.get(n, _STILL) for n in names], float) / L
        if not np.isfinite(D).all():
            return None
        d = D.ravel()
        return FingerMotion(names, np.array([f.center for f in fingers], float) / L, D,
                            tips.radius, float(np.sqrt(d.dot(d))), state.depth, L, tips.flat,
                            tips.facing)

    def _sticking(self, state: ContactState, motion: FingerMotion) -> _Sticking:
        """The state's contact set and its constants (kept while the set and angles stay)."""
        key = (self._tips[1], tuple((c.node, c.finger, c.theta) for c in state.contacts))
        if self._set is None or self._set.key != key:
            contacts = ContactSet.of_state(self.model, state)
            tip = motion.tip.take(contacts.finger)
            nu = tip.normal_angle(contacts.theta)
            dtheta, t = np.zeros(len(contacts)), tangent(nu)
            self._set = _Sticking(key, contacts, contacts.data.C, tip.offset(contacts.theta),
                                  contacts.positions, nu, tip.curvature(contacts.theta),
                                  unit(nu), t, np.array(contacts.theta, float), dtheta,
                                  (tip.radius * dtheta)[:, None] * t)
        return self._set

    def _evaluate(self, mode: _Mode, centers: np.ndarray, delta: np.ndarray, F: np.ndarray,
                  D: np.ndarray) -> float:
        """Evaluate every function a call watches at the configuration ``delta``, ``F`` with
        the tips at ``centers`` (the mode's contacts not held, its free boundary rows, the
        terminations checked): the travel within which neither the gaps nor the area check
        reaches :data:`QUIET_MARGIN` (:meth:`~.travel.TravelRates.travel`), 0.0 when a function
        is at or below it already.
        """
        self.evaluations += 1
        if self._terminations and not self._terminations_clear(mode, delta, F, D):
            return 0.0
        if not _clear(mode.margins, F):
            return 0.0
        sd, rows = mode.sticking.contacts.data, mode.rows
        points = self._boundary[rows] + self.model.boundary_displacement(sd, delta, F, rows)
        gaps = mode.tip.gaps(points, centers)
        if not np.minimum.reduce(gaps, axis=None, initial=np.inf) > QUIET_MARGIN:
            return 0.0  # (the area check's reserve is not needed then)
        reserve = self.area.reserve(sd, delta, F, INVERSION_AREA_RATIO + QUIET_MARGIN)
        return mode.rates.travel(gaps, reserve, QUIET_MARGIN)

    def _terminations_clear(self, mode: _Mode, delta: np.ndarray, F: np.ndarray,
                            D: np.ndarray) -> bool:
        """Whether the strain limit's and the pickup margin's functions (those declared) are
        above :data:`QUIET_MARGIN` at ``delta``, ``F`` (evaluated: they have no rate here).
        """
        sol = mode.sticking.solution(delta, F, D)
        strain, pickup = mode.functions.termination_values(mode.sticking.contacts, sol)
        return strain > QUIET_MARGIN and pickup > QUIET_MARGIN

    def _result(self, mode: _Mode, state: ContactState, motion: tuple,
                ends: tuple[np.ndarray, ...]) -> StepResult:
        """The :class:`StepResult` :func:`~.run.advance` returns for a call of one substep
        with no event (``motion``: translation (f, 2), rate, the fingers' translations so far
        (f, 2), all / L; ``ends``: :meth:`_Sticking.ends`): the same operations on the same
        numbers as its ``integrate_work``, ``record`` and ``to_state``.
        """
        D, rate, t0 = motion
        tips, delta, both = ends
        L, fu, old = mode.length, mode.force_unit, state.fingers
        forces_a, forces_b, fingers = {}, {}, []
        # FingerMotion.depth_at(s): depth0 + s * rate * length
        depth = state.depth + 1.0 * rate * L
        centers, moved = tips[1] * L, (t0 + 1.0 * D) * L
        # the finger forces, their products and the work in Python floats: the same IEEE
        # operations as advance()'s float64 arrays (a 2-vector's dot product in BLAS ddot's
        # order, as substeps_numba._dot2)
        for (name, mine, touching, radius, flat, facing), f_old, center, move, (d0, d1) in zip(
                mode.fingers, old, centers, moved, D.tolist()):
            # each end's finger force, summed over the same rows in the same order (the
            # reduction ndarray.sum makes)
            (a0, a1), (b0, b1) = np.add.reduce(both[:, mine], axis=1).tolist()
            forces_a[name], forces_b[name] = (a0 * fu, a1 * fu), (b0 * fu, b1 * fu)
            # the work as advance() keeps it (/ (fu L))
            work = f_old.work / (fu * L)
            if touching:
                # h = 1; the set and the motion are those of both ends, so dF / ds is the same
                # there and the Hermite term h^2 / 12 (ra - rb) is 0.0 exactly (ra, rb finite)
                work += 0.5 * ((0.0 + ((0.0 + a0 * d0) + a1 * d1))
                               + (0.0 + ((0.0 + b0 * d0) + b1 * d1))) + 0.0
            fingers.append(_finger(name, center, radius, move, work * fu * L,
                                   f_old.dissipation / (fu * L) * fu * L, flat, facing))
        samples = (Sample(state.depth + 0.0 * rate * L, mode.nodes, mode.thetas, forces_a),
                   Sample(depth, mode.nodes, mode.thetas, forces_b))
        contacts = tuple(map(_moved, mode.contacts, delta[1] * L, both[1] * fu))
        holds = tuple(sorted((n, u) for n, u in state.holds if u > depth))
        new = ContactState(tuple(fingers), contacts, depth, state.relative_per_depth, (), (),
                           state.history, holds)
        diagnostics = {**_DIAGNOSTICS, "sets_factored": mode.cache.get("sets_factored", 0),
                       "reduced_max_condition": mode.cache.get("max_condition", 1.0)}
        self._checked, self._fingers = new, (centers, moved)
        return StepResult(new, (), 1.0, None, samples, (), diagnostics, self.step)


def _margins(sticking: _Sticking, watched: np.ndarray, mu: float) -> np.ndarray:
    """The ``watched`` contacts' (mask: not held) normal forces f_n = u . F_k and every
    contact's cone margins mu f_n -+ f_t (f_t = t . F_k; a held node that sticks still watches
    its cone) as rows of one map of the set's forces (m, 2) flattened: (w + 2m, 2m), w the
    contacts watched, normal forces first.
    """
    rows, every = np.flatnonzero(watched), np.arange(len(watched))
    u, t = sticking.unit, sticking.tangent
    normal = np.zeros((len(rows), len(watched), 2))
    normal[np.arange(len(rows)), rows] = u[rows]
    cones = np.zeros((2, len(watched), len(watched), 2))
    cones[0, every, every], cones[1, every, every] = mu * u - t, mu * u + t
    return np.concatenate((normal.reshape(len(rows), -1), cones.reshape(2 * len(watched), -1)))


def _clear(margins: np.ndarray, F: np.ndarray) -> bool:
    """Whether every contact function of ``margins`` (:func:`_margins`) is above
    :data:`QUIET_MARGIN` at the forces ``F`` (m, 2).
    """
    return bool(np.minimum.reduce(margins @ F.reshape(-1), initial=np.inf) > QUIET_MARGIN)


def _one_substep(step: float, rate: float) -> bool:
    """Whether a call at ``rate`` is one grid substep (SubstepControl's end(0.0) is 1.0)."""
    return rate > 0.0 and step / rate >= 1.0


@dataclass(frozen=True)
class _Mode:
    """What stays fixed while calls stay quiet in one sticking mode: the set's constants, the
    finger names (and as a set), the tips, the functions watched (the free boundary ``rows``;
    the contacts' normal forces, of those not held, and cone margins, ``margins``:
    :func:`_margins`), the depth (m) at which a hold of the chattering bound ``expiry`` ends,
    and the parts of a result that do not move: per finger its name, its contact rows (a slice
    when they are consecutive), whether it has any, its radius, flat and facing; each contact's
    node, finger, mode, angle and normal angle, as a ContactNode without its displacement and
    force. ``rates``: how fast the gaps and the area check change with the fingers' translation.
    """

    sticking: _Sticking
    names: tuple[str, ...]
    known: frozenset
    tip: TipGeometry
    functions: EventFunctions
    rows: np.ndarray
    margins: np.ndarray
    expiry: float
    fingers: tuple[tuple, ...]
    contacts: tuple[ContactNode, ...]
    nodes: tuple[int, ...]
    thetas: tuple[float, ...]
    rates: TravelRates
    length: float
    force_unit: float
    cache: dict


def _rows_of(mask: np.ndarray) -> slice | np.ndarray:
    """The rows of a boolean ``mask`` as a slice when they are consecutive (indexing by it
    gives the same rows in the same order, without a copy), else the mask.
    """
    rows = np.flatnonzero(mask)
    if len(rows) and rows[-1] - rows[0] + 1 == len(rows):
        return slice(int(rows[0]), int(rows[-1]) + 1)
    return mask


def _finger(name: str, center: np.ndarray, radius: float, translation: np.ndarray,
            work: float, dissipation: float, flat: float, facing: float) -> FingerState:
    """The FingerState of these fields, set at once (as :func:`_moved` does for a contact)."""
    finger = object.__new__(FingerState)
    finger.__dict__.update(name=name, center=center, radius=radius, translation=translation,
                           work=work, dissipation=dissipation, flat=flat, facing=facing)
    return finger


def _moved(contact: ContactNode, displacement: np.ndarray, force: np.ndarray) -> ContactNode:
    """``contact`` with another ``displacement`` and ``force``: the fields ContactNode's
    __init__ would set, set at once (a quiet tick makes one per contact; the frozen dataclass's
    __init__ and ``dataclasses.replace`` cost three times as much).
    """
    moved = object.__new__(ContactNode)
    moved.__dict__.update(contact.__dict__, displacement=displacement, force=force)
    return moved


_DIAGNOSTICS = {**Counters().as_dict(), "substeps": 1}
"""The counters of a quiet call (one substep, no Newton iteration, no root evaluation)."""


@dataclass(frozen=True)
class _Sticking:
    """One contact set with every node sticking, at its polar angles: what the fixed-set
    solve of :func:`~..contact_model.attempt_fixed_set` computes once for the set (the nodes
    ride on their tips, so only the tips' positions change): the tips' ``offset`` and the
    nodes' undeformed ``positions`` (/ L), ``theta`` as an array, ``dtheta`` zero, and
    ``slide`` the nodes' motion along their tips (r dtheta t, zeros) that d delta / ds adds to
    the tips' translation.
    """

    key: tuple
    contacts: ContactSet
    C: np.ndarray
    offset: np.ndarray
    positions: np.ndarray
    nu: np.ndarray
    kappa: np.ndarray
    unit: np.ndarray
    tangent: np.ndarray
    theta: np.ndarray
    dtheta: np.ndarray
    slide: np.ndarray

    def ends(self, start: np.ndarray, D: np.ndarray) -> tuple[np.ndarray, ...] | None:
        """(tips (2, f, 2), delta (2, m, 2), F (2, m, 2)) at s = 0 and at s = 1 of the tips
        moving from ``start`` by ``D`` (f, 2), as :func:`~..contact_model.attempt_fixed_set`
        computes them with no sliding node (c(s) = start + s D, delta = c(s) + offset - X,
        F = C delta), or None if a force is not finite. Both ends at once: the same
        elementwise operations, and a stacked product that makes the same matrix-vector
        product per end.
        """
        tips = start + _ENDS * D
        delta = tips[:, self.contacts.finger] + self.offset - self.positions
        F = np.matmul(self.C, delta.reshape(2, -1, 1)).reshape(delta.shape)
        # a sum of values is finite only if they all are (or it overflows: then not quiet)
        if not math.isfinite(np.add.reduce(F, axis=None)):
            return None
        return tips, delta, F

    def solution(self, delta: np.ndarray, F: np.ndarray, D: np.ndarray) -> Solution:
        """The fixed-set solve's :class:`~..contact_model.Solution` at ``delta``, ``F`` of the
        motion by ``D`` (its rates: dF / ds = C d delta / ds, d delta / ds = D + slide).
        """
        dirs = D[self.contacts.finger]
        dF = (self.C @ dirs.reshape(-1)).reshape(-1, 2)
        return Solution(self.theta, delta, F, self.dtheta, dF, dirs + self.slide, 0, 0.0, 1.0,
                        self.nu, self.kappa)
