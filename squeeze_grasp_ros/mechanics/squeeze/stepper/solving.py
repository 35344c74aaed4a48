# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Solving the fixed-set problem along a stepper call, and the call's counters.

:class:`SetSolver` solves a :class:`~.contact_set.ContactSet` at a point s of the call's
:class:`~.motion.FingerMotion` (:func:`~..contact_model.attempt_fixed_set`), continues a
solution from one point to another and halves a substep whose continuation fails.
:class:`Counters` collects what every unit of a call counts (``StepResult.diagnostics``).
"""
from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field, fields

import numpy as np

from squeeze_grasp_ros.mechanics.errors import NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    NEWTON_BACKTRACKS,
    NEWTON_MAX_ITERATIONS,
    NEWTON_TOL,
    Configuration,
    ContactModel,
    LinearResponse,
    Solution,
    SolveFailure,
    attempt_fixed_set,
    jacobian_condition,
)
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import Kernel, compiled, selected
from squeeze_grasp_ros.mechanics.squeeze.kept import kept_property
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.motion import FingerMotion

__all__ = ["CONTINUATION_ITERATIONS", "Counters", "MAX_ANGLE_JUMP", "MAX_SUBSTEP_HALVINGS",
           "SetSolver", "SolvedPoints"]

MAX_SUBSTEP_HALVINGS = 12
CONTINUATION_ITERATIONS = 12
MAX_ANGLE_JUMP = 0.05
"""Continuation safeguards: Newton iterations and distance (rad) from the predicted angles
beyond which a substep is halved."""


@dataclass
class Counters:
    """Diagnostics of one stepper call (maxima over its solves, counts of its work).

    Attributes
    ----------
    newton_max_iterations, newton_max_residual, jacobian_max_condition
        Of the fixed-set Newton solves (sliding angles).
    root_evaluations : int
        Solves spent locating events.
    substeps, substep_halvings, substep_rejections : int
        Accepted substeps, halvings of a failed continuation, adaptive substeps rejected for
        a dip of an event function inside.
    ambiguous_modes : int
        Mode decisions with no consistent hypothesis (the fewest violations won).
    inversion : str or None
        Why no state beyond the last point exists (the call ended ``element_inverted``).
    min_area_ratio, inverted_element
        Smallest det F and its element when the inversion threshold was reached.
    """

    newton_max_iterations: int = 0
    newton_max_residual: float = 0.0
    jacobian_max_condition: float = 1.0
    root_evaluations: int = 0
    substeps: int = 0
    substep_halvings: int = 0
    substep_rejections: int = 0
    ambiguous_modes: int = 0
    inversion: str | None = None
    min_area_ratio: float | None = None
    inverted_element: int | None = None

    def note(self, sol: Solution) -> None:
        """Take a solution's Newton iterations, residual and Jacobian condition into the maxima."""
        self.noted(sol.iterations, sol.residual, sol.jacobian_condition)

    def noted(self, iterations: int, residual: float, condition: float) -> None:
        """Take one solve's Newton iterations, residual and Jacobian condition into the maxima."""
        self.newton_max_iterations = max(self.newton_max_iterations, iterations)
        self.newton_max_residual = max(self.newton_max_residual, residual)
        self.jacobian_max_condition = max(self.jacobian_max_condition, condition)

    def as_dict(self) -> dict:
        """The counters that apply (the inversion ones only when it happened)."""
        return {f.name: v for f in fields(self) if (v := getattr(self, f.name)) is not None}


def _checked(response: Callable, checkpoint: Callable[[], None]) -> Callable:
    """``response`` (a nonlinear model's, with its attributes) calling ``checkpoint`` before
    each of its evaluations.
    """
    @functools.wraps(response)  # its __dict__ too: tolerance, stall_halvings
    def checked(delta: np.ndarray):
        checkpoint()
        return response(delta)
    return checked


@dataclass(frozen=True)
class SetSolver:
    """Fixed-set solves of one call (model, finger motion; counts into ``counters``; the
    route of the linear model's solve, ``kernel``, is read once for the call; ``checkpoint``,
    the call's, runs before every solve and, for a nonlinear model, before every equilibrium
    solve of its Newton: a cancellation waits for one of them, not for a substep's halvings,
    which on hard nonlinear squeezes took up to 12 s of CPU).
    """

    model: ContactModel
    motion: FingerMotion
    counters: Counters
    kernel: Kernel = field(default_factory=selected)
    checkpoint: Callable[[], None] | None = None

    @kept_property
    def phi(self) -> float:
        """The model's friction angle, rad (read once for the call's solves)."""
        return self.model.phi

    def attempt(self, contacts: ContactSet, s: float,
                theta: np.ndarray | None = None) -> Solution | SolveFailure:
        """The solution of ``contacts`` at s (from ``theta``, default the set's), or why none."""
        response = self.model.response(contacts.data)
        if self.checkpoint is not None:
            self.checkpoint()
            if not isinstance(response, LinearResponse):
                response = _checked(response, self.checkpoint)
        tips = self.motion.contact_tips(contacts.finger)
        sol = attempt_fixed_set(
            response,
            Configuration(contacts.positions, contacts.stick, contacts.slip, tips.tip),
            tips.start + s * tips.translation,
            tips.translation,
            contacts.theta if theta is None else theta,
            self.phi,
            kernel=self.kernel,
        )
        if not isinstance(sol, SolveFailure):
            self.counters.note(sol)
        return sol

    def decide(self, contacts: ContactSet, idx: list[int], options: np.ndarray,
               zero: np.ndarray, *, s: float, mu: float, rate_floor: float,
               by_node: bool) -> tuple | None:
        """The mode decision's search over the ``options`` of contacts ``idx``, ``zero`` the
        functions zero by construction (:func:`~.modes.decide_modes`, jointly or ``by_node``),
        at s in one compiled call (:func:`..fixed_set_numba.decide_linear`), each solve
        counted as :meth:`attempt` counts it: (stick, slip, theta, violations) of the choice,
        or None off the numba route, for a model that is not linear, or when no hypothesis
        could be solved (the search in Python then says why).
        """
        response = self.model.response(contacts.data)
        if self.kernel != Kernel.NUMBA or not isinstance(response, LinearResponse):
            return None
        kernel, tips = compiled(), self.motion.contact_tips(contacts.finger)
        tip = tips.tip
        solved, bad, stick, slip, theta, log, Js = kernel.decide_linear(
            response.C, contacts.positions, tips.start + s * tips.translation,
            tips.translation, np.asarray(contacts.theta, float), contacts.stick, contacts.slip,
            float(self.phi), tip.radius, tip.flat, tip.facing, NEWTON_TOL,
            NEWTON_MAX_ITERATIONS, NEWTON_BACKTRACKS, NEWTON_TOL, np.asarray(idx, np.int64),
            options, zero, float(mu), float(rate_floor), by_node)
        if not solved:
            return None
        for (status, iterations, residual, n), J in zip(log.tolist(), Js):
            if status == kernel.SOLVED:
                n = int(n)
                self.counters.noted(int(iterations), residual, jacobian_condition(J[:n, :n]))
        return stick, slip, theta, int(bad)

    def solve(self, contacts: ContactSet, s: float) -> Solution:
        """:meth:`attempt`, raising the failure's error."""
        sol = self.attempt(contacts, s)
        if isinstance(sol, SolveFailure):
            raise sol.error()
        return sol

    def continue_to(self, contacts: ContactSet, sol_a: Solution, a: float,
                    b: float) -> Solution | SolveFailure:
        """Solve at b by continuation from the solution at a (predictor theta + dtheta/ds (b-a)).

        Fails if Newton fails, needs more than CONTINUATION_ITERATIONS iterations or lands more
        than MAX_ANGLE_JUMP (rad) from the prediction (another solution branch).
        """
        guess = sol_a.theta + sol_a.dtheta * (b - a)
        sol = self.attempt(contacts, b, theta=guess)
        if isinstance(sol, SolveFailure):
            return sol
        if (
            sol.iterations > CONTINUATION_ITERATIONS
            or np.abs(sol.theta - guess).max() > MAX_ANGLE_JUMP
        ):
            return SolveFailure(
                f"continuation from s = {a:.6g} to {b:.6g} left the solution branch", sol.residual
            )
        return sol

    def substep(self, contacts: ContactSet, sol_a: Solution, a: float,
                b: float) -> tuple[float, Solution | SolveFailure]:
        """(b, solution at b) by continuation from a, halving the substep while it fails.

        A failure because every state beyond a inverts an element is returned as (a, failure):
        the squeeze ends there. Any other failure after MAX_SUBSTEP_HALVINGS raises.
        """
        for _ in range(MAX_SUBSTEP_HALVINGS):
            sol = self.continue_to(contacts, sol_a, a, b)
            if not isinstance(sol, SolveFailure):
                return b, sol
            self.counters.substep_halvings += 1
            b = a + 0.5 * (b - a)
        if sol.inverted:
            return a, sol
        raise NumericalError(f"the fixed-set solve failed after {MAX_SUBSTEP_HALVINGS} substep "
                             f"halvings: {sol.reason}", residuals={sol.measure: sol.residual})


class SolvedPoints:
    """Solutions of one contact set at points of a substep; a new point is solved by
    continuation from the nearest one solved so far (root location).
    """

    def __init__(self, solver: SetSolver, contacts: ContactSet,
                 points: list[tuple[float, Solution]]) -> None:
        self.solver, self.contacts, self.points = solver, contacts, list(points)

    def at(self, s: float) -> Solution:
        """The solution at s; NumericalError (or InvalidInputError) if none is found."""
        for at, sol in self.points:
            if at == s:
                return sol
        near, sol_near = min(self.points, key=lambda p: abs(p[0] - s))
        sol = self.solver.continue_to(self.contacts, sol_near, near, s)
        if isinstance(sol, SolveFailure):
            raise sol.error()
        self.points.append((s, sol))
        return sol
