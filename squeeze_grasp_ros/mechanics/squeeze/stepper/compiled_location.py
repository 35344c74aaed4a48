# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event location by the compiled kernel (the numba route of the linear model).

:class:`CompiledLocation` hands :func:`~.location.earliest_crossing` of a substep to
:func:`..location_numba.earliest_crossing`, one call per event with the fixed-set solve of every
trial point inside, when the kernel values every crossed function: a contact's normal force,
cone margins and slip rate, a free boundary row's gap (the fast model's boundary compliance),
the pickup margin.
It gathers the crossed keys' values, slopes and tables, and the two solved ends, and returns
the event point, the evaluations and the solution there, with the Newton counters of the
points it solved: the Python location's brackets, counts and floats. The location stays in
Python for a crossed area or strain limit, on the numpy
route, for the reference and the nonlinear models, and when the kernel reports a failed solve,
a location that does not converge or more points than :data:`CAPACITY` (the Python location
then raises or goes on).
"""
from __future__ import annotations

from functools import cache

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    NEWTON_BACKTRACKS,
    NEWTON_MAX_ITERATIONS,
    NEWTON_TOL,
    ContactModel,
    Solution,
)
from squeeze_grasp_ros.mechanics.squeeze.event_key import EventFunction, EventKey
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import Kernel, selected
from squeeze_grasp_ros.mechanics.squeeze.stepper.location import (
    MAX_ROOT_ITERATIONS,
    SURE_MARGIN,
    Values,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.solving import (
    CONTINUATION_ITERATIONS,
    MAX_ANGLE_JUMP,
)
from squeeze_grasp_ros.mechanics.vocabulary import Termination

__all__ = ["CAPACITY", "CompiledLocation"]

_SLOPED = (EventFunction.NORMAL_FORCE, EventFunction.CONE_PLUS, EventFunction.CONE_MINUS)
"""The per-contact functions with slopes, in the order of a contact's rates."""

CAPACITY = 64
"""Solved points (the substep's two ends included) the kernel has room for; a location that
needs more runs in Python."""


@cache
def _kernel():
    """The compiled module :mod:`..location_numba` (imported on first use: numba), or None
    when this numba lacks the LAPACK binding it calls dgeev through (``numba.np.linalg``'s
    ``_LAPACK``, not a public API: present in the numba versions tested, 0.68): every event
    is then located in Python, with the same result.
    """
    try:
        from squeeze_grasp_ros.mechanics.squeeze import location_numba
    except (ImportError, AttributeError):
        return None
    return location_numba


class CompiledLocation:
    """The compiled event location of one :func:`~.run.advance` call (see the module).

    Use :meth:`of`, which returns None when the call locates in Python.
    """

    def __init__(self, call) -> None:
        self.call = call
        self.kernel = _kernel()
        self.kinds = {EventFunction.NORMAL_FORCE: self.kernel.NORMAL_FORCE,
                      EventFunction.CONE_PLUS: self.kernel.CONE_PLUS,
                      EventFunction.CONE_MINUS: self.kernel.CONE_MINUS,
                      EventFunction.SLIP_RATE: self.kernel.SLIP_RATE,
                      EventFunction.GAP: self.kernel.GAP,
                      EventFunction.PICKUP: self.kernel.PICKUP}
        motion = call.motion
        tip = motion.tip
        self.fingers = (np.ascontiguousarray(motion.start, float),
                        np.ascontiguousarray(motion.translation, float),
                        np.ascontiguousarray(tip.radius, float),
                        np.ascontiguousarray(tip.flat, float),
                        np.ascontiguousarray(tip._facing_tangent, float))
        lim = call.model.limits
        self.weight = (lim.weight / call.model.force_unit
                       if lim.weight is not None
                       and Termination.PICKED_UP in call.functions.terminate_on else np.nan)

    @classmethod
    def of(cls, call) -> CompiledLocation | None:
        """The compiled location of ``call``, or None when it locates in Python."""
        model = call.model
        if (selected() != Kernel.NUMBA or _kernel() is None or model.reference
                or type(model).response is not ContactModel.response
                or type(model).boundary_displacement
                is not ContactModel.boundary_displacement):
            return None
        return cls(call)

    def _slopes(self, crossed: list[EventKey], index: np.ndarray, s: float, sol: Solution,
                known: Values | None) -> tuple[list[bool], list[float]] | None:
        """Whether each crossed key has a slope at s, and the slope (0 without): from
        ``known``, else by :meth:`~.compiled_functions.CompiledFunctions.slopes` at ``sol`` for
        the crossed gaps' rows, as the Python location asks them (arrays, no mapping by key);
        None when the functions are not compiled.
        """
        if known is not None:
            return [key in known for key in crossed], [known.get(key, 0.0) for key in crossed]
        functions, contacts = self.call.functions, self.call.events.contacts
        compiled = functions._compiled
        if compiled is None:
            return None
        nodes = sorted({key.node for key in crossed if key.function == EventFunction.GAP})
        gaps, rates = compiled.slopes(contacts, sol, s, functions.rows_of(nodes))
        fingers = len(self.call.motion.names)
        has, out = [], []
        for key, k in zip(crossed, index.tolist()):
            function = key.function
            if function == EventFunction.GAP:
                out.append(float(gaps[nodes.index(key.node) * fingers + k]))
            elif function in _SLOPED:
                out.append(float(rates[3 * k + _SLOPED.index(function)]))
            else:
                out.append(0.0)
            has.append(function == EventFunction.GAP or function in _SLOPED)
        return has, out

    def locate(self, crossed: list[EventKey], start: tuple, end: tuple
               ) -> tuple[float, Solution] | None:
        """(the event point, the solution there) of the crossings ``crossed`` in [a, b]
        (``start`` and ``end``: s, the solution and the watched functions at a and b), with
        the root evaluations and the Newton counters of the points solved; None when the
        location must run in Python.
        """
        call = self.call
        contacts, model, motion = call.events.contacts, call.model, call.motion
        sd = contacts.data
        kinds = [self.kinds.get(key.function) for key in crossed]
        if sd.A_bc is None or None in kinds:
            return None
        (a, sol_a, watched_a), (b, sol_b, watched_b) = start, end
        k = len(crossed)
        index = np.empty(k, int)
        GA, GR, B0 = (np.zeros((k, 2, 2 * len(contacts))), np.zeros((k, 2, sd.E.shape[1])),
                      np.zeros((k, 2)))
        boundary = call.functions._boundary
        for i, key in enumerate(crossed):
            if key.function == EventFunction.GAP:
                rows = call.functions.rows_of([key.node])
                GA[i], GR[i] = model._boundary_rows(sd, rows)
                B0[i] = boundary[rows[0]]
                index[i] = key.finger
            elif key.function == EventFunction.PICKUP:
                index[i] = 0
            else:
                index[i] = contacts.index(key.node)
        slopes_a = self._slopes(crossed, index, a, sol_a, watched_a.slopes)
        slopes_b = self._slopes(crossed, index, b, sol_b, watched_b.slopes)
        if slopes_a is None or slopes_b is None:
            return None
        fresh = call.events.fresh
        columns = np.array([[watched_a.values[key] for key in crossed],
                            [watched_b.values[key] for key in crossed], *slopes_a, *slopes_b,
                            [key.at_node in fresh for key in crossed]], float)
        order = np.array([call.events.order(key) for key in crossed], float)
        tip = motion.contact_tips(contacts.finger).tip
        origin, D, radius_f, flat_f, t0_f = self.fingers
        m, n = len(contacts), int(np.count_nonzero(~contacts.stick))
        pts = (np.empty(CAPACITY), np.empty((CAPACITY, m)), np.empty((CAPACITY, m, 2)),
               np.empty((CAPACITY, m, 2)), np.empty((CAPACITY, m)), np.empty((CAPACITY, m, 2)),
               np.empty((CAPACITY, m, 2)), np.empty((CAPACITY, m)), np.empty((CAPACITY, m)),
               np.zeros(CAPACITY, int), np.zeros(CAPACITY), np.empty((CAPACITY, n, n)))
        for p, (s, sol) in enumerate(((a, sol_a), (b, sol_b))):
            pts[0][p] = s
            for array, x in zip(pts[1:9], (sol.theta, sol.delta, sol.F, sol.dtheta, sol.dF,
                                           sol.ddelta, sol.normal_angle,
                                           1.0 if sol.kappa is None else sol.kappa)):
                array[p] = x
        fun = (float(model.mu), contacts.slip,
               np.ascontiguousarray(tip.radius, float), float(motion.rate),
               GA, GR, B0, sd.E, origin, D, radius_f, flat_f, t0_f, contacts.stick,
               contacts.finger, np.unique(contacts.finger), self.weight)
        prob = (np.ascontiguousarray(sd.C), np.ascontiguousarray(contacts.positions, float),
                contacts.stick, contacts.slip, float(model.phi),
                np.ascontiguousarray(tip.radius, float), np.ascontiguousarray(tip.flat, float),
                np.ascontiguousarray(tip.facing, float), contacts.finger, origin, D,
                NEWTON_TOL, NEWTON_MAX_ITERATIONS, NEWTON_BACKTRACKS, CONTINUATION_ITERATIONS,
                MAX_ANGLE_JUMP)
        s_e, evaluations, solved = self.kernel.earliest_crossing(
            a, b, call.tol / motion.rate, bool(model.dear_evaluations),
            (SURE_MARGIN, MAX_ROOT_ITERATIONS), np.array(kinds, int), index, columns[0],
            columns[1], columns[2] != 0, columns[3], columns[4] != 0, columns[5],
            columns[6] != 0, order, 2, pts, fun, prob)
        if evaluations < 0:
            return None
        at, theta, delta, F, dtheta, dF, ddelta, nu, kappa, its, res, Js = pts
        counters = call.counters
        conditions = (np.linalg.cond(Js[2:solved]) if n and solved > 2
                      else np.ones(solved - 2))
        for p in range(2, solved):
            counters.newton_max_iterations = max(counters.newton_max_iterations, int(its[p]))
            counters.newton_max_residual = max(counters.newton_max_residual, float(res[p]))
            counters.jacobian_max_condition = max(counters.jacobian_max_condition,
                                                  float(conditions[p - 2]))
        counters.root_evaluations += evaluations
        p = int(np.flatnonzero(at[:solved] == s_e)[0])
        if p < 2:
            return s_e, (sol_a, sol_b)[p]
        return s_e, Solution(
            theta[p].copy(), delta[p].copy(), F[p].copy(), dtheta[p].copy(), dF[p].copy(),
            ddelta[p].copy(), int(its[p]), float(res[p]), float(conditions[p - 2]),
            nu[p].copy(), kappa[p].copy())
