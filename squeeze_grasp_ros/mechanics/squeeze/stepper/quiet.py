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

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    INVERSION_AREA_RATIO,
    ContactModel,
    Solution,
    SolveFailure,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, StepResult
from squeeze_grasp_ros.mechanics.squeeze.stepper.area_watch import AreaWatch
from squeeze_grasp_ros.mechanics.squeeze.stepper.run import TERMINATION_ORDER, _Call, advance
from squeeze_grasp_ros.mechanics.squeeze.stepper.substeps import SubstepControl
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
        if (state.fresh or state.undetermined or not state.contacts
                or any(c.mode != ContactMode.STICK for c in state.contacts)):
            return None
        call = _Call(self.model, state, translations, self.step, min(self.event_tol, self.step),
                     self.terminate_on)
        rate = call.motion.rate
        if rate == 0 or SubstepControl(call.step / rate, False, call.step / rate).end(0.0) < 1.0:
            return None
        ev, solver, functions = call.events, call.solver, call.functions
        depth = call.motion.depth_at(0.0)
        rows = functions.free_rows(ev.contacts, call.chatter.held_nodes(depth))
        watched = ~call.chatter.held(ev.contacts.nodes, depth)
        sol_a = solver.solve(ev.contacts, 0.0)
        if state is not self._checked and not self._clear(call, sol_a, 0.0, rows, watched):
            return None
        sol_b = solver.continue_to(ev.contacts, sol_a, 0.0, 1.0)
        if isinstance(sol_b, SolveFailure) or not self._clear(call, sol_b, 1.0, rows, watched):
            return None
        call.record(sol_a)
        call.counters.substeps += 1
        call.integrate_work(sol_a, sol_b, 0.0, 1.0)
        ev.move_to(1.0, sol_b.theta.copy())
        call.record(sol_b)
        result = call.result(sol_b, None, self.step)
        self._checked = result.state
        return result

    def _clear(self, call: _Call, sol: Solution, s: float, rows: np.ndarray,
               watched: np.ndarray) -> bool:
        """Whether every function the call watches at ``sol`` (point s; the boundary ``rows``,
        the contacts not held) and every termination it checks is above :data:`QUIET_MARGIN`.
        """
        functions, contacts = call.functions, call.events.contacts
        v = functions.values(contacts, sol, s, rows, terminations=False)
        lowest = min(v.fn[watched].min(initial=np.inf), v.c_plus[watched].min(initial=np.inf),
                     v.c_minus[watched].min(initial=np.inf), v.gaps.min(initial=np.inf))
        if not lowest > QUIET_MARGIN:
            return False
        strain, pickup = functions.termination_values(contacts, sol)
        return (strain > QUIET_MARGIN and pickup > QUIET_MARGIN
                and self.area.above(contacts.data, sol.delta, sol.F,
                                    INVERSION_AREA_RATIO + QUIET_MARGIN))
