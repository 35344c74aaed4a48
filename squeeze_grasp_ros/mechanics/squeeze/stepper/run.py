# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
""":func:`advance`: one stepper call, the substep loop that joins the stepper's units.

Each substep: solve at its end by continuation (:class:`~.solving.SetSolver`), evaluate the
event functions there (:class:`~.functions.EventFunctions`), find those that crossed zero
(:func:`~.location.crossings`), locate the earliest (:func:`~.location.earliest_crossing`),
integrate the fingers' work, process the events at that point
(:class:`~.processing.EventProcessor`) and check the terminations; the next substep's length
comes from :class:`~.substeps.SubstepControl`.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel, Solution, SolveFailure
from squeeze_grasp_ros.mechanics.squeeze.contact_state import (
    ContactNode,
    ContactState,
    FingerState,
    Sample,
    StepResult,
)
from squeeze_grasp_ros.mechanics.squeeze.event_key import EventFunction, EventKey
from squeeze_grasp_ros.mechanics.squeeze.stepper.chatter import ChatterBound
from squeeze_grasp_ros.mechanics.squeeze.stepper.compiled import CompiledSubsteps
from squeeze_grasp_ros.mechanics.squeeze.stepper.compiled_location import CompiledLocation
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions
from squeeze_grasp_ros.mechanics.squeeze.stepper.location import (
    Values,
    crossings,
    dips_inside,
    earliest_crossing,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.motion import FingerMotion
from squeeze_grasp_ros.mechanics.squeeze.stepper.processing import EventProcessor
from squeeze_grasp_ros.mechanics.squeeze.stepper.solving import Counters, SetSolver, SolvedPoints
from squeeze_grasp_ros.mechanics.squeeze.stepper.substeps import SubstepControl
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, Termination

__all__ = ["MIN_EVENT_TOL", "MIN_STEP", "TERMINATION_ORDER", "advance"]

TERMINATION_ORDER: tuple[Termination, ...] = (
    Termination.STRAIN_LIMIT,
    Termination.FINGER_SLIP,
    Termination.PICKED_UP,
)
"""The terminations a caller may switch (element_inverted and contact_lost always apply)."""
MIN_STEP = 1e-6
"""Smallest substep, relative to the object size: below it a squeeze to a usual depth needs
millions of steps (``squeeze.step: 1e-12`` ran for ever)."""
MIN_EVENT_TOL = 1e-15
"""Smallest event tolerance, relative to the object size (near the float resolution)."""


@dataclass(frozen=True)
class _Watched:
    """The watched functions at one end of a substep: free boundary rows, values, slopes
    (None when only the grid is used and slopes are computed for a location only).
    """

    rows: np.ndarray
    values: Values
    slopes: Values | None


class _Call:
    """The units of one :func:`advance` call and what it accumulates (dimensionless)."""

    def __init__(self, model: ContactModel, state: ContactState,
                 translations: Mapping[str, tuple[float, float]], step: float,
                 event_tol: float, terminate_on: tuple[str, ...], *,
                 motion: FingerMotion | None = None, contacts: ContactSet | None = None,
                 checkpoint: Callable[[], None] | None = None) -> None:
        """``motion`` and ``contacts``, when given, are those of ``state`` and
        ``translations`` (a caller that keeps them across calls); ``checkpoint``: see
        :func:`advance`.
        """
        L, fu = model.length, model.force_unit
        self.model, self.step, self.tol = model, step, event_tol
        self.motion = FingerMotion.of(state, translations, L) if motion is None else motion
        self.counters = Counters()
        self.solver = SetSolver(model, self.motion, self.counters, checkpoint=checkpoint)
        self.functions = EventFunctions(model, self.motion, terminate_on)
        self.chatter = ChatterBound(state, step * L, model.max_events_per_depth)
        self.events = EventProcessor(state, ContactSet.of_state(model, state) if contacts is None
                                     else contacts, self.functions, self.solver, self.chatter,
                                     event_tol)
        self.t0 = np.array([f.translation for f in state.fingers], float) / L
        self.work = np.array([f.work for f in state.fingers], float) / (fu * L)
        self.dissipation = np.array([f.dissipation for f in state.fingers], float) / (fu * L)
        self.samples: list[Sample] = []
        self.compiled_location = CompiledLocation.of(self)

    # ------------------------------------------------------------------ the loop
    def run(self, stop_on_event: bool, planned: float) -> tuple[Solution, str | None, float]:
        """Advance s from 0 to 1 (or to a termination / the first event point).

        Returns the last solution, the termination (or None) and the next planned substep
        (relative to L). The call's checkpoint is called before every substep and every
        fixed-set solve (it may raise to abandon the motion).
        """
        ev, rate, checkpoint = self.events, self.motion.rate, self.solver.checkpoint
        sol = ev.resolve()
        self.record(sol)
        term = ev.termination(sol)
        if term or rate == 0 or (stop_on_event and ev.events):
            return sol, term, planned
        adaptive = self.model.adaptive_steps and not self.model.reference
        control = SubstepControl(self.step / rate, adaptive, planned / rate)
        start, compiled = None, CompiledSubsteps.of(self)
        python_next = False
        while ev.s < 1.0:
            if checkpoint is not None:
                checkpoint()
            a = ev.s
            depth_a = self.motion.depth_at(a)
            start = self._watched_at(sol, a, depth_a, start, adaptive)
            if compiled is not None and not python_next and not ev.fresh:
                chunk = compiled.run(sol, a, start, self.chatter.expiry(depth_a))
                python_next = chunk.python_next
                if chunk.count:
                    sol = chunk.sol
                    ev.move_to(chunk.s, sol.theta.copy())
                    start = self._watched(sol, chunk.s, depth_a, start.rows, adaptive)
                    continue
            python_next = False
            b, sol_b = self.solver.substep(ev.contacts, sol, a, control.end(a))
            if isinstance(sol_b, SolveFailure):
                self.counters.inversion = sol_b.reason
                return sol, Termination.ELEMENT_INVERTED, planned
            end = self._watched(sol_b, b, depth_a, start.rows, adaptive)
            crossed = crossings(start.values, end.values, ev.fresh)
            if (not crossed and control.may_reject(a, b)
                    and dips_inside(a, b, start.values, end.values, start.slopes, end.slopes,
                                    ev.fresh)):
                self.counters.substep_rejections += 1
                control.reject(a, b)
                continue
            self.counters.substeps += 1
            control.accept(sol, sol_b, a, b, start.values, end.values,
                           bool(ev.contacts.stick.all()))
            if adaptive:
                planned = control.h * rate
            if crossed and not self.model.reference:
                b, sol_b = self.locate(crossed, sol, sol_b, a, b, start, end)
            start = None if crossed else end
            self.integrate_work(sol, sol_b, a, b)
            ev.move_to(1.0 if b >= 1.0 else b, sol_b.theta.copy())
            sol = ev.resolve() if crossed else sol_b
            self.record(sol)
            term = ev.termination(sol) if crossed else None
            if term or (stop_on_event and ev.events):
                break
        return sol, term, planned

    def _watched(self, sol: Solution, s: float, depth: float, rows: np.ndarray,
                 slopes: bool) -> _Watched:
        """The watched functions at ``sol`` (contacts held at ``depth`` left out)."""
        f, contacts = self.functions, self.events.contacts
        values = f.watched(contacts, sol, s, rows, self.chatter.held(contacts.nodes, depth))
        return _Watched(rows, values, f.slopes(contacts, sol, s, rows) if slopes else None)

    def _watched_at(self, sol: Solution, a: float, depth: float, known: _Watched | None,
                    slopes: bool) -> _Watched:
        """The functions at the start a of a substep: ``known`` (the last substep's end) unless
        none is known or the free boundary rows changed (a hold expired).
        """
        rows = self.functions.free_rows(self.events.contacts, self.chatter.held_nodes(depth))
        if known is not None and np.array_equal(rows, known.rows):
            return known
        return self._watched(sol, a, depth, rows, slopes)

    def locate(self, crossed: list[EventKey], sol_a: Solution, sol_b: Solution, a: float,
               b: float, start: _Watched, end: _Watched) -> tuple[float, Solution]:
        """The earliest event point in [a, b] and the solution there."""
        if self.compiled_location is not None:
            located = self.compiled_location.locate(crossed, (a, sol_a, start), (b, sol_b, end))
            if located is not None:
                return located
        contacts, f = self.events.contacts, self.functions
        start_slopes, end_slopes = start.slopes, end.slopes
        if start_slopes is None:
            rows = f.rows_of(sorted({k.node for k in crossed if k.function == EventFunction.GAP}))
            start_slopes = f.slopes(contacts, sol_a, a, rows)
            end_slopes = f.slopes(contacts, sol_b, b, rows)
        points = SolvedPoints(self.solver, contacts, [(a, sol_a), (b, sol_b)])
        s_e, evaluations = earliest_crossing(
            crossed, a, b, self.tol / self.motion.rate, start=start.values, end=end.values,
            start_slopes=start_slopes, end_slopes=end_slopes, fresh=self.events.fresh,
            value=lambda key, s: f.value(key, contacts, points.at(s), s),
            slope=lambda key, s: f.slope(key, contacts, points.at(s), s),
            order=self.events.order, skip_sure=self.model.dear_evaluations)
        self.counters.root_evaluations += evaluations
        return s_e, points.at(s_e)

    # ------------------------------------------------------------------ accumulation
    def integrate_work(self, sa: Solution, sb: Solution, a: float, b: float) -> None:
        """Add the work of every finger over [a, b] (cubic Hermite in s) and the frictional
        dissipation at its contacts (trapezoid in s; modes are fixed within [a, b]).

        A contact node sits on its tip at coordinate theta (a circle's polar angle), so it moves
        relative to the tip by r d theta along the face (:mod:`..tip_shapes`, any shape): the
        finger's force does F . dc = F . dx - f_t r d theta, and -f_t r d theta (>= 0 against
        the slip, 0 while sticking) is what friction dissipates.
        """
        h = b - a
        tips, D = self.motion.contact_tips(self.events.contacts.finger), self.motion.translation
        # no node slides at either end: the dissipation adds zeros (it is never -0.0)
        sliding = sa.dtheta.any() or sb.dtheta.any()
        if sliding:
            r = tips.tip.radius
            pa = -sa.tangential * r * sa.dtheta
            pb = -sb.tangential * r * sb.dtheta
        # the four loads side by side (m, 4, 2): one masked sum per finger gives the finger's
        # F(a), F(b), dF(a), dF(b), each summed over its contacts in order as alone, and the
        # products with D are the 2-vector dot's terms
        loads = np.stack([sa.F, sb.F, sa.dF, sb.dF], axis=1)
        for f, (mine, present) in enumerate(zip(tips.masks, tips.present)):
            if not present:
                continue
            total = loads[mine].sum(axis=0)
            ya, yb, ra, rb = (total[:, 0] * D[f, 0] + total[:, 1] * D[f, 1]).tolist()
            self.work[f] += 0.5 * h * (ya + yb) + h * h / 12.0 * (ra - rb)
            if sliding:
                self.dissipation[f] += 0.5 * h * (pa[mine].sum() + pb[mine].sum())

    def record(self, sol: Solution) -> None:
        """Append a trajectory sample at the current point."""
        contacts, fu = self.events.contacts, self.model.force_unit
        masks = self.motion.contact_tips(contacts.finger).masks
        forces = {name: tuple((sol.F[mine].sum(axis=0) * fu).tolist())
                  for name, mine in zip(self.motion.names, masks)}
        self.samples.append(Sample(self.events.depth, tuple(contacts.nodes.tolist()),
                                   tuple(sol.theta.tolist()), forces))

    def result(self, sol: Solution, termination: str | None,
               next_substep: float) -> StepResult:
        """The call's :class:`StepResult`, ending at the current point with ``sol``."""
        model = self.model
        diag = self.counters.as_dict()
        diag["sets_factored"] = model._cache.get("sets_factored", 0)
        diag["reduced_max_condition"] = model._cache.get("max_condition", 1.0)
        return StepResult(
            self.to_state(sol),
            tuple(self.events.events),
            float(self.events.s),
            termination,
            tuple(self.samples),
            tuple(self.chatter.chatter),
            diag,
            next_substep,
        )

    def to_state(self, sol: Solution) -> ContactState:
        """The frozen SI state at the current point, with the solution ``sol`` there."""
        L, fu = self.model.length, self.model.force_unit
        ev, motion = self.events, self.motion
        s, c = ev.s, ev.contacts
        fingers = tuple(
            FingerState(
                n,
                (motion.start[f] + s * motion.translation[f]) * L,
                motion.radius[f] * L,
                (self.t0[f] + s * motion.translation[f]) * L,
                float(self.work[f] * fu * L),
                float(self.dissipation[f] * fu * L),
                float(motion.tip.flat[f] * L),
                float(motion.tip.facing[f]),
            )
            for f, n in enumerate(motion.names)
        )
        signs = c.slip_signs(sol.dtheta, self.functions.frictionless).tolist()
        delta, F = sol.delta * L, sol.F * fu
        contacts = tuple(
            ContactNode(
                node,
                motion.names[finger],
                ContactMode.STICK if stick else ContactMode.SLIP,
                0 if stick else sign,
                theta,
                delta[k],
                F[k],
                normal,
            )
            for k, (node, finger, stick, sign, theta, normal) in enumerate(zip(
                c.nodes.tolist(), c.finger.tolist(), c.stick.tolist(), signs,
                sol.theta.tolist(), sol.normal_angle.tolist()))
        )
        depth = ev.depth
        return ContactState(fingers, contacts, depth, ev.relative_per_depth,
                            tuple(sorted(ev.undetermined)), tuple(sorted(ev.fresh)),
                            tuple(self.chatter.history), self.chatter.state_holds(depth))


def _check(step: float, event_tol: float, terminate_on, first_substep: float | None) -> None:
    """Raise InvalidInputError for an argument of :func:`advance` out of range."""
    if not (np.isfinite(step) and step >= MIN_STEP):
        raise InvalidInputError(
            f"step must be finite and >= {MIN_STEP} (relative to the object size), got {step}"
        )
    if not (np.isfinite(event_tol) and event_tol >= MIN_EVENT_TOL):
        raise InvalidInputError(
            f"event_tol must be finite and >= {MIN_EVENT_TOL} (relative to the object size), "
            f"got {event_tol}"
        )
    bad = sorted(set(terminate_on) - set(TERMINATION_ORDER))
    if bad:
        raise InvalidInputError(f"unknown termination {bad[0]!r} (allowed: {TERMINATION_ORDER})")
    if first_substep is not None and not (np.isfinite(first_substep) and first_substep > 0):
        raise InvalidInputError(f"first_substep must be finite and > 0 (relative to the object "
                                f"size), got {first_substep}")


def advance(
    model: ContactModel,
    state: ContactState,
    translations: Mapping[str, tuple[float, float]],
    *,
    step: float = 1e-3,
    event_tol: float = 1e-9,
    stop_on_event: bool = False,
    terminate_on: tuple[str, ...] = TERMINATION_ORDER,
    first_substep: float | None = None,
    checkpoint: Callable[[], None] | None = None,
) -> StepResult:
    """Translate fingertips from ``state`` and locate the contact events on the way.

    Parameters
    ----------
    model : ContactModel
        Object, friction and termination criteria.
    state : ContactState
        Start state (e.g. :func:`~..contact_state.initial_state`).
    translations : mapping
        Finger name -> translation (dx, dy), m, object frame, for this call; fingers not named
        stay still. Any number of fingers.
    step : float
        Largest depth substep, relative to the object size L (the bracketing grid: events
        closer than this to each other in one function can be missed).
    event_tol : float
        Event location tolerance in depth, relative to L.
    stop_on_event : bool
        Return right after the first point at which events were processed.
    terminate_on : tuple of str
        Which of "strain_limit", "finger_slip", "picked_up" end the motion (strain and pickup
        are only evaluated if the model's limits declare them).
    first_substep : float, optional
        First substep of a model that adapts its substeps, relative to L (default ``step``):
        a previous call's ``StepResult.next_substep``, to go on where its adaptation ended.
    checkpoint : callable, optional
        Called with no arguments before every substep and every fixed-set solve (of a
        substep, an event location or a mode hypothesis): it may raise (e.g. a cancellation)
        to abandon the motion, which then stops within one solve, and the exception
        propagates. The numba route's compiled substeps call it between the kernel's calls
        (each at most 256 substeps, :data:`~.compiled.CHUNK`).

    Returns
    -------
    StepResult
        New state, events, fraction of the translations applied, termination (or None),
        trajectory samples, chattering record and diagnostics.

    Raises
    ------
    InvalidInputError
        For bad arguments, a lost grasp (fewer than 2 contacts) or a solve that fails.
    NumericalError
        If a solve or an event location does not converge; its ``depth`` (and message) says
        where: the depth of the last point the motion had solved, m.
    """
    _check(step, event_tol, terminate_on, first_substep)
    call = _Call(model, state, translations, step, min(event_tol, step), tuple(terminate_on),
                 checkpoint=checkpoint)
    try:
        sol, termination, next_substep = call.run(
            stop_on_event, step if first_substep is None else first_substep)
    except NumericalError as error:  # where: the last point solved
        raise error.located(call.events.depth) from error
    return call.result(sol, termination, next_substep)
