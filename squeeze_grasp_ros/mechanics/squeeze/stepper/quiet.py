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
    ContactState,
    StepResult,
    tip_geometry,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.area_watch import AreaWatch
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.motion import FingerMotion
from squeeze_grasp_ros.mechanics.squeeze.stepper.run import TERMINATION_ORDER, _Call, advance
from squeeze_grasp_ros.mechanics.squeeze.stepper.substeps import SubstepControl
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import tangent, unit
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
        self._rows: tuple | None = None
        self._boundary = model.positions(model.boundary_nodes)
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
            return advance(self.model, state, translations, self.step, self.event_tol,
                           terminate_on=self.terminate_on)
        self.calls["quiet"] += 1
        return result

    def _quiet(self, state: ContactState,
               translations: Mapping[str, tuple[float, float]]) -> StepResult | None:
        """The quiet call's result, or None when the call is not quiet."""
        if (state.fresh or state.undetermined or len(state.contacts) < 2
                or any(c.mode != ContactMode.STICK for c in state.contacts)):
            return None
        motion = self._motion(state, translations)
        if motion is None:
            return None
        rate = motion.rate
        if rate == 0 or SubstepControl(self.step / rate, False, self.step / rate).end(0.0) < 1.0:
            return None
        sticking = self._sticking(state, motion)
        call = _Call(self.model, state, translations, self.step,
                     min(self.event_tol, self.step), self.terminate_on, motion=motion,
                     contacts=sticking.contacts)
        rows, watched = self._watched(call, sticking, motion.depth_at(0.0))
        solutions = sticking.solutions(motion)
        if solutions is None:
            return None
        sol_a, sol_b = solutions
        if state is not self._checked and not self._clear(call, sticking, sol_a, 0.0, rows,
                                                          watched):
            return None
        if not self._clear(call, sticking, sol_b, 1.0, rows, watched):
            return None
        call.record(sol_a)
        call.counters.substeps += 1
        call.integrate_work(sol_a, sol_b, 0.0, 1.0)
        call.events.move_to(1.0, sol_b.theta.copy())
        call.record(sol_b)
        result = call.result(sol_b, None, self.step)
        self._checked = result.state
        return result

    def _watched(self, call: _Call, sticking: _Sticking,
                 depth: float) -> tuple[np.ndarray, np.ndarray]:
        """(free boundary rows, mask of the contacts not held) at ``depth``, as the call's
        full path watches them (kept while the set and the held nodes stay).
        """
        held = call.chatter.held_nodes(depth)
        key = (sticking.key, tuple(held))
        if self._rows is None or self._rows[0] != key:
            self._rows = (key, call.functions.free_rows(sticking.contacts, held),
                          ~call.chatter.held(sticking.contacts.nodes, depth))
        return self._rows[1], self._rows[2]

    def _motion(self, state: ContactState,
                translations: Mapping[str, tuple[float, float]]) -> FingerMotion | None:
        """:meth:`FingerMotion.of` (the tips kept while they are the same), or None for a
        translation :func:`~.run.advance` would refuse (it then says why).
        """
        L = self.model.length
        names = tuple(f.name for f in state.fingers)
        if not set(translations) <= set(names):
            return None
        key = tuple((f.name, f.radius, f.flat, f.facing) for f in state.fingers)
        if self._tips is None or self._tips[0] != key:
            self._tips = (key, tip_geometry(state.fingers).scaled(L))
        tips = self._tips[1]
        D = np.array([translations.get(n, (0.0, 0.0)) for n in names], float) / L
        if not np.all(np.isfinite(D)):
            return None
        return FingerMotion(names, np.array([f.center for f in state.fingers], float) / L, D,
                            tips.radius, float(np.linalg.norm(D)), state.depth, L, tips.flat,
                            tips.facing)

    def _sticking(self, state: ContactState, motion: FingerMotion) -> _Sticking:
        """The state's contact set and its constants (kept while the set and angles stay)."""
        key = (self._tips[0], tuple((c.node, c.finger, c.theta) for c in state.contacts))
        if self._set is None or self._set.key != key:
            contacts = ContactSet.of_state(self.model, state)
            tip = motion.tip.take(contacts.finger)
            nu = tip.normal_angle(contacts.theta)
            self._set = _Sticking(key, contacts, contacts.data.C, tip.offset(contacts.theta),
                                  nu, tip.curvature(contacts.theta), unit(nu), tangent(nu),
                                  tip.radius)
        return self._set

    def _clear(self, call: _Call, sticking: _Sticking, sol: Solution, s: float,
               rows: np.ndarray, watched: np.ndarray) -> bool:
        """Whether every function the call watches at ``sol`` (point s; the boundary ``rows``,
        the contacts not held) and every termination it checks is above :data:`QUIET_MARGIN`.
        """
        model, contacts = self.model, sticking.contacts
        fn = np.einsum("ij,ij->i", sol.F[watched], sticking.unit[watched])
        ft = np.einsum("ij,ij->i", sol.F[watched], sticking.tangent[watched])
        cone = model.mu * fn - np.abs(ft)
        if not (min(fn.min(initial=np.inf), cone.min(initial=np.inf)) > QUIET_MARGIN
                and self._gaps_clear(call.motion, sticking, sol, s, rows)):
            return False
        strain, pickup = call.functions.termination_values(contacts, sol)
        return (strain > QUIET_MARGIN and pickup > QUIET_MARGIN
                and self.area.above(contacts.data, sol.delta, sol.F,
                                    INVERSION_AREA_RATIO + QUIET_MARGIN))

    def _gaps_clear(self, motion: FingerMotion, sticking: _Sticking, sol: Solution, s: float,
                    rows: np.ndarray) -> bool:
        """Whether every gap of the boundary ``rows`` to every tip is above :data:`QUIET_MARGIN`
        at ``sol``: from the last gaps computed for the set and rows while a bound allows, else
        computed (and kept).

        A gap is 1-Lipschitz in the boundary point and in the tip's position (a distance to a
        convex shape), and a boundary point moves by u_i = A_i F + R_i g (the set's boundary
        compliance rows and rigid modes, g = E^T delta), so a gap is at least its kept value
        less max_i(||A_i|| ||F - F_ref|| + ||R_i|| ||g - g_ref||) less the tips' travel.
        """
        model, sd = self.model, sticking.contacts.data
        g = sd.E.T @ sol.delta.reshape(-1)
        centers = motion.centers(s)
        ref = self._gap_ref
        if ref is None or ref["set"] is not sticking or not np.array_equal(ref["rows"], rows):
            ref = None
        else:
            moved = (ref["a_norm"] * np.linalg.norm(sol.F - ref["F"])
                     + ref["r_norm"] * np.linalg.norm(g - ref["g"])
                     + np.sqrt(((centers - ref["centers"]) ** 2).sum(axis=1)).max())
            if ref["lowest"] - moved * (1.0 + 1e-12) > QUIET_MARGIN:
                return True
        points = self._boundary[rows] + model.boundary_displacement(sd, sol.delta, sol.F, rows)
        lowest = float(motion.gaps(points, s).min(initial=np.inf))
        if ref is None:
            A = sd.A_bc[node_dofs(rows)].reshape(len(rows), -1)
            R = model.obj.rigid[node_dofs(model.boundary_nodes[rows])].reshape(len(rows), -1)
            ref = {"set": sticking, "rows": rows,
                   "a_norm": float(np.sqrt((A * A).sum(axis=1)).max(initial=0.0)),
                   "r_norm": float(np.sqrt((R * R).sum(axis=1)).max(initial=0.0))}
        self._gap_ref = {**ref, "F": sol.F, "g": g, "centers": centers, "lowest": lowest}
        return lowest > QUIET_MARGIN


@dataclass(frozen=True)
class _Sticking:
    """One contact set with every node sticking, at its polar angles: what the fixed-set
    solve of :func:`~..contact_model.attempt_fixed_set` computes once for the set (the nodes
    ride on their tips, so only the tips' positions change).
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

    def solutions(self, motion: FingerMotion) -> tuple[Solution, Solution] | None:
        """:func:`~..contact_model.attempt_fixed_set` of the set at s = 0 and s = 1 of
        ``motion`` with no sliding node (the same operations: F = C delta, dF/ds = C d delta/ds,
        the same along the motion), or None if a value is not finite.
        """
        c, m = self.contacts, len(self.contacts)
        f = c.finger
        dirs = motion.translation[f]
        theta = np.array(c.theta, float)
        dF = (self.C @ dirs.reshape(-1)).reshape(m, 2)
        dtheta = np.zeros(m)
        ddelta = dirs + (self.radius * dtheta)[:, None] * self.tangent
        out = []
        for s in (0.0, 1.0):
            delta = motion.start[f] + s * motion.translation[f] + self.offset - c.positions
            F = (self.C @ delta.reshape(-1)).reshape(m, 2)
            out.append(Solution(theta, delta, F, dtheta, dF, ddelta, 0, 0.0, 1.0, self.nu,
                                self.kappa))
        if not (np.isfinite(out[0].F).all() and np.isfinite(out[1].F).all()
                and np.isfinite(dF).all()):
            return None
        return out[0], out[1]
