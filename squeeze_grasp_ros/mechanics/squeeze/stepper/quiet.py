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
:class:`QuietSteps` makes those same two solves (the same functions on the same arrays, so the
same forces bit for bit), checks that every watched function is above :data:`QUIET_MARGIN` at
the end (and at the start, unless the state is the one its last quiet call returned), and
returns the same :class:`~..contact_state.StepResult`. Anything else (a function at or below
the margin, a sliding contact, a nonlinear material, a long translation) is handed to
:func:`~.run.advance` whole, so events are located exactly as before.

Within one sticking mode everything but the finger positions stays: the set's stiffness and tip
offsets, the watched rows and contacts, each contact's node, finger and angles. The first quiet
call of a mode keeps them (:class:`_Mode`, until the next full call or until a hold of the
chattering bound expires), and the calls after it compute only what moves: the two solves, the
work integral, the samples' finger forces, the new contacts' displacements and forces. The
checks at the end answer from bounds on the change since their last evaluation where they can:
the contact functions (each moves by at most (1 + mu) ||dF||), the gaps (1-Lipschitz in the
boundary point and the tip), the area ratio (:class:`~.area_watch.AreaWatch`); a bound that
does not clear its functions has them evaluated.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import node_dofs
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
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions
from squeeze_grasp_ros.mechanics.squeeze.stepper.motion import FingerMotion
from squeeze_grasp_ros.mechanics.squeeze.stepper.run import TERMINATION_ORDER, advance
from squeeze_grasp_ros.mechanics.squeeze.stepper.solving import Counters
from squeeze_grasp_ros.mechanics.squeeze.stepper.substeps import SubstepControl
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry, tangent, unit
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, MaterialModel

__all__ = ["QUIET_MARGIN", "QuietSteps"]

QUIET_MARGIN = 1e-12
"""Dimensionless value (gap / L, force / (E h L), area ratio) every watched function must
exceed for a call to be quiet. The start of the next call re-solves the state from its SI
values, which moves the functions by round-off (about 1e-16); a function within this margin of
zero goes through the full stepper, so that round-off can never hide or invent an event."""


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
    """

    def __init__(self, model: ContactModel, step: float, event_tol: float,
                 terminate_on: tuple[str, ...] = TERMINATION_ORDER, *,
                 quiet: bool = True) -> None:
        self.model, self.step, self.event_tol = model, step, event_tol
        self.terminate_on = tuple(terminate_on)
        self.calls = {"quiet": 0, "full": 0}
        self._checked: ContactState | None = None
        self._tips: tuple | None = None
        self._set: _Sticking | None = None
        self._gap_ref: dict | None = None
        self._mode: _Mode | None = None
        self._contact_ref: tuple | None = None
        self._boundary = model.positions(model.boundary_nodes)
        self._length = model.length
        self._applies = (quiet and model.constitutive_model == MaterialModel.LINEAR
                         and not model.reference and not model.adaptive_steps
                         and model.mu > 0.0)
        self.area = AreaWatch(model) if self._applies else None

    def advance(self, state: ContactState,
                translations: Mapping[str, tuple[float, float]]) -> StepResult:
        """:func:`~.run.advance` of ``state`` by ``translations`` (m): the same result."""
        result = self._quiet(state, translations) if self._applies else None
        if result is None:
            self.calls["full"] += 1
            self._mode = None
            return advance(self.model, state, translations, self.step, self.event_tol,
                           terminate_on=self.terminate_on)
        self.calls["quiet"] += 1
        return result

    def _quiet(self, state: ContactState,
               translations: Mapping[str, tuple[float, float]]) -> StepResult | None:
        """The quiet call's result, or None when the call is not quiet."""
        mode = self._mode
        if mode is not None and not (state is self._checked and state.depth < mode.expiry):
            mode = None
        if mode is None and (state.fresh or state.undetermined or len(state.contacts) < 2
                             or any(c.mode != ContactMode.STICK for c in state.contacts)):
            return None
        motion = self._motion(state, translations)
        if motion is None:
            return None
        rate = motion.rate
        if rate == 0 or SubstepControl(self.step / rate, False, self.step / rate).end(0.0) < 1.0:
            return None
        if mode is None:
            mode = self._enter(state, motion)
        solutions = mode.sticking.solutions(motion)
        if solutions is None:
            return None
        sol_a, sol_b = solutions
        if mode is not self._mode and not self._clear(mode, motion, sol_a, 0.0):
            return None
        self._mode = mode
        if not self._clear(mode, motion, sol_b, 1.0):
            return None
        result = mode.result(state, motion, sol_a, sol_b, self.step)
        self._checked = result.state
        return result

    def _enter(self, state: ContactState, motion: FingerMotion) -> _Mode:
        """The constants of the state's sticking mode (its contact set, the functions watched,
        the results' fixed parts), until a hold of the chattering bound expires.
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
        names, fingers = motion.names, contacts.finger
        thetas = np.array(contacts.theta, float).tolist()
        return _Mode(
            sticking, names, motion.tip, functions, functions.free_rows(contacts, held),
            None if watched.all() else watched, sticking.unit[watched],
            sticking.tangent[watched], expiry,
            tuple((_rows_of(fingers == f), bool((fingers == f).any()))
                  for f in range(len(names))),
            tuple(ContactNode(node, names[f], ContactMode.STICK, 0, theta, None, None, nu)
                  for node, f, theta, nu in zip(contacts.nodes.tolist(), fingers.tolist(),
                                                thetas, sticking.nu.tolist())),
            tuple(contacts.nodes.tolist()), tuple(thetas),
            model.length, model.force_unit, model._cache)

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
        D = np.array([translations.get(n, (0.0, 0.0)) for n in names], float) / L
        if not np.isfinite(D).all():
            return None
        d = D.ravel()
        # the norm as np.linalg.norm computes it (sqrt of the dot product), without its checks
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
                                  nu, tip.curvature(contacts.theta), unit(nu), t, tip.radius,
                                  np.array(contacts.theta, float), dtheta,
                                  (tip.radius * dtheta)[:, None] * t)
        return self._set

    def _clear(self, mode: _Mode, motion: FingerMotion, sol: Solution, s: float) -> bool:
        """Whether every function a call watches at ``sol`` (point s; the mode's free boundary
        rows and contacts not held) and every termination it checks is above
        :data:`QUIET_MARGIN`.
        """
        contacts = mode.sticking.contacts
        if not (self._contacts_clear(mode, sol.F)
                and self._gaps_clear(mode, motion.centers(s), sol)):
            return False
        strain, pickup = mode.functions.termination_values(contacts, sol)
        return (strain > QUIET_MARGIN and pickup > QUIET_MARGIN
                and self.area.above(contacts.data, sol.delta, sol.F,
                                    INVERSION_AREA_RATIO + QUIET_MARGIN))

    def _contacts_clear(self, mode: _Mode, F: np.ndarray) -> bool:
        """Whether the normal force f_n and both cone margins mu f_n -+ f_t of every contact
        not held are above :data:`QUIET_MARGIN` at the forces ``F``: from the lowest value
        computed last for the mode while a bound allows (each moves by at most
        (1 + mu) ||F - F_ref||), else computed (and kept).
        """
        mu, ref = self.model.mu, self._contact_ref
        if ref is not None and ref[0] is mode:
            dF = F - ref[1]
            if ref[2] - (1.0 + mu) * np.sqrt(np.vdot(dF, dF)) * (1.0 + 1e-12) > QUIET_MARGIN:
                return True
        watched = F[mode.watched] if mode.watched is not None else F
        fn = np.einsum("ij,ij->i", watched, mode.unit)
        ft = np.einsum("ij,ij->i", watched, mode.tangent)
        lowest = min(fn.min(initial=np.inf), (mu * fn - np.abs(ft)).min(initial=np.inf))
        self._contact_ref = (mode, F, lowest)
        return lowest > QUIET_MARGIN

    def _gaps_clear(self, mode: _Mode, centers: np.ndarray, sol: Solution) -> bool:
        """Whether every gap of the mode's free boundary rows to every tip (at ``centers``) is
        above :data:`QUIET_MARGIN` at ``sol``: from the last gaps computed for the set and rows
        while a bound allows, else computed (and kept).

        A gap is 1-Lipschitz in the boundary point and in the tip's position (a distance to a
        convex shape), and a boundary point moves by u_i = A_i F + R_i g (the set's boundary
        compliance rows and rigid modes, g = E^T delta), so a gap is at least its kept value
        less max_i(||A_i|| ||F - F_ref|| + ||R_i|| ||g - g_ref||) less the tips' travel.
        """
        model, sd, rows = self.model, mode.sticking.contacts.data, mode.rows
        g = sd.E.T @ sol.delta.reshape(-1)
        ref = self._gap_ref
        if ref is None or ref["set"] is not mode.sticking or not np.array_equal(ref["rows"], rows):
            ref = None
        else:
            dF, dg, dc = sol.F - ref["F"], g - ref["g"], centers - ref["centers"]
            moved = (ref["a_norm"] * np.sqrt(np.vdot(dF, dF))
                     + ref["r_norm"] * np.sqrt(np.vdot(dg, dg))
                     + np.sqrt((dc * dc).sum(axis=1).max()))
            if ref["lowest"] - moved * (1.0 + 1e-12) > QUIET_MARGIN:
                return True
        points = self._boundary[rows] + model.boundary_displacement(sd, sol.delta, sol.F, rows)
        lowest = float(mode.tip.gaps(points, centers).min(initial=np.inf))
        if ref is None:
            A = sd.A_bc[node_dofs(rows)].reshape(len(rows), -1)
            R = model.obj.rigid[node_dofs(model.boundary_nodes[rows])].reshape(len(rows), -1)
            ref = {"set": mode.sticking, "rows": rows,
                   "a_norm": float(np.sqrt((A * A).sum(axis=1)).max(initial=0.0)),
                   "r_norm": float(np.sqrt((R * R).sum(axis=1)).max(initial=0.0))}
        self._gap_ref = {**ref, "F": sol.F, "g": g, "centers": centers, "lowest": lowest}
        return lowest > QUIET_MARGIN


@dataclass(frozen=True)
class _Mode:
    """What stays fixed while calls stay quiet in one sticking mode: the set's constants, the
    functions watched (the free boundary ``rows``; the contacts not held, their normals'
    ``unit`` and ``tangent``), the depth (m) at which a hold of the chattering bound ``expiry``
    ends, and the parts of a result that do not move (each finger's contact rows, a slice
    when they are consecutive, and whether it has any; each
    contact's node, finger, mode, angle and normal angle, as a ContactNode without its
    displacement and force).
    """

    sticking: _Sticking
    names: tuple[str, ...]
    tip: TipGeometry
    functions: EventFunctions
    rows: np.ndarray
    watched: np.ndarray | None
    unit: np.ndarray
    tangent: np.ndarray
    expiry: float
    masks: tuple[tuple[slice | np.ndarray, bool], ...]
    contacts: tuple[ContactNode, ...]
    nodes: tuple[int, ...]
    thetas: tuple[float, ...]
    length: float
    force_unit: float
    cache: dict

    def result(self, state: ContactState, motion: FingerMotion, sol_a: Solution,
               sol_b: Solution, step: float) -> StepResult:
        """The :class:`StepResult` :func:`~.run.advance` returns for a call of one substep
        from ``sol_a`` (s = 0) to ``sol_b`` (s = 1) with no event: the same operations on the
        same numbers as its ``integrate_work``, ``record`` and ``to_state``.
        """
        L, fu = self.length, self.force_unit
        D, names, old = motion.translation, self.names, state.fingers
        work = np.array([f.work for f in old], float) / (fu * L)
        t0 = np.array([f.translation for f in old], float) / L
        forces_a, forces_b = {}, {}
        for f, (mine, touching) in enumerate(self.masks):
            ya, yb = sol_a.F[mine].sum(axis=0), sol_b.F[mine].sum(axis=0)
            forces_a[names[f]] = tuple((ya * fu).tolist())
            forces_b[names[f]] = tuple((yb * fu).tolist())
            if touching:
                # h = 1; sol_a.dF is sol_b.dF (one motion, one set), so the Hermite term
                # h^2 / 12 (ra - rb) is 0.0 exactly (ra, rb finite)
                work[f] += 0.5 * (ya @ D[f] + yb @ D[f]) + 0.0
        depth = motion.depth_at(1.0)
        samples = (Sample(motion.depth_at(0.0), self.nodes, self.thetas, forces_a),
                   Sample(depth, self.nodes, self.thetas, forces_b))
        radius, flat, facing = (motion.radius * L, (motion.tip.flat * L).tolist(),
                                motion.tip.facing.tolist())
        centers, moved = (motion.start + 1.0 * D) * L, (t0 + 1.0 * D) * L
        fingers = tuple(
            FingerState(n, centers[f], radius[f], moved[f], float(work[f] * fu * L),
                        float(f_old.dissipation / (fu * L) * fu * L), flat[f], facing[f])
            for f, (n, f_old) in enumerate(zip(names, old)))
        delta, F = sol_b.delta * L, sol_b.F * fu
        contacts = tuple(_moved(c, delta[k], F[k]) for k, c in enumerate(self.contacts))
        holds = tuple(sorted((n, u) for n, u in state.holds if u > depth))
        new = ContactState(fingers, contacts, depth, state.relative_per_depth, (), (),
                           state.history, holds)
        diagnostics = {**_DIAGNOSTICS, "sets_factored": self.cache.get("sets_factored", 0),
                       "reduced_max_condition": self.cache.get("max_condition", 1.0)}
        return StepResult(new, (), 1.0, None, samples, (), diagnostics, step)


def _rows_of(mask: np.ndarray) -> slice | np.ndarray:
    """The rows of a boolean ``mask`` as a slice when they are consecutive (indexing by it
    gives the same rows in the same order, without a copy), else the mask.
    """
    rows = np.flatnonzero(mask)
    if len(rows) and rows[-1] - rows[0] + 1 == len(rows):
        return slice(int(rows[0]), int(rows[-1]) + 1)
    return mask


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
    ride on their tips, so only the tips' positions change): ``theta`` as an array, ``dtheta``
    zero, and ``slide`` the nodes' motion along their tips (r dtheta t, zeros) that
    d delta / ds adds to the tips' translation.
    """

    key: tuple
    contacts: ContactSet
    C: np.ndarray
    offset: np.ndarray
    nu: np.ndarray
    kappa: np.ndarray
    unit: np.ndarray
    tangent: np.ndarray
    radius: np.ndarray
    theta: np.ndarray
    dtheta: np.ndarray
    slide: np.ndarray

    def solutions(self, motion: FingerMotion) -> tuple[Solution, Solution] | None:
        """:func:`~..contact_model.attempt_fixed_set` of the set at s = 0 and s = 1 of
        ``motion`` with no sliding node (the same operations: F = C delta, dF/ds = C d delta/ds,
        the same along the motion), or None if a value is not finite.
        """
        c, m = self.contacts, len(self.contacts)
        f = c.finger
        start, dirs = motion.start[f], motion.translation[f]
        dF = (self.C @ dirs.reshape(-1)).reshape(m, 2)
        ddelta = dirs + self.slide
        out = []
        for s in (0.0, 1.0):
            delta = start + s * dirs + self.offset - c.positions
            F = (self.C @ delta.reshape(-1)).reshape(m, 2)
            out.append(Solution(self.theta, delta, F, self.dtheta, dF, ddelta, 0, 0.0, 1.0,
                                self.nu, self.kappa))
        if not np.isfinite((out[0].F, out[1].F, dF)).all():
            return None
        return out[0], out[1]
