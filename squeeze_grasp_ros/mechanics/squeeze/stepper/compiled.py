# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The substeps between events in one compiled call (the numba route of the linear model).

:class:`CompiledSubsteps` hands the substep loop of a :func:`~.run.advance` call to
:func:`..substeps_numba.advance_quiet` while nothing needs Python: the model's response is the
linear F = C delta with the fast model's boundary compliance, the substeps keep the grid, no
function is zero by construction at the start (``fresh``) and no strain limit is checked (a
``checkpoint`` of the call runs between the kernel's calls, each at most :data:`CHUNK`
substeps). It gathers the contact set's tables (the fixed-set problem, the rows of
the boundary operator for the free rows, the area bounds, where each watched value is), calls
the kernel, and applies what it returns to the call: the accepted substeps' samples, work,
dissipation and counters, the solution at the last point and the watched values there
(recomputed by the numpy code, so the next substep starts from the same floats). The substep
the kernel stops before is then run by the Python loop, which locates and processes its events.
With ``SQUEEZE_GRASP_KERNEL=numpy`` (or without numba) none of this runs: the Python loop is
the reference path.
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    GRADIENT_BOUND_EXACT,
    INVERSION_AREA_RATIO,
    NEWTON_BACKTRACKS,
    NEWTON_MAX_ITERATIONS,
    NEWTON_TOL,
    ContactModel,
    Solution,
    jacobian_condition,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_state import Sample
from squeeze_grasp_ros.mechanics.squeeze.event_key import SHARED_KEYS, EventFunction
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import (
    Kernel,
    compiled_substeps,
    selected,
)
from squeeze_grasp_ros.mechanics.squeeze.kept import kept_for
from squeeze_grasp_ros.mechanics.squeeze.stepper.solving import (
    CONTINUATION_ITERATIONS,
    MAX_ANGLE_JUMP,
)
from squeeze_grasp_ros.mechanics.vocabulary import Termination

__all__ = ["CHUNK", "QUIET_MARGIN", "Chunk", "CompiledSubsteps", "quiet_area_tables"]

QUIET_MARGIN = 1e-12
"""Dimensionless value (gap / L, force / (E h L), area ratio) every watched function must
exceed for a call to be quiet. The start of the next call re-solves the state from its SI
values, which moves the functions by round-off (about 1e-16); a function within this margin of
zero goes through the full stepper, so that round-off can never hide or invent an event. The
compiled substeps take a substep as quiet on the same margin (their watched values are the
numpy code's floats, but an element near inversion has its det F summed in the kernel's own
order)."""
QUIET_AREA_SHARE = 0.1
"""An element is watched one by one in a substep's quiet area check when its gradient bound per
unit load at some contact is at least this share of that contact's largest (about an eighth of
the foam square's elements); the others are bounded together
(:func:`..substeps_numba._area_lower`)."""
QUIET_AREA_TABLES_KEPT = 64
"""Contact sets whose :func:`quiet_area_tables` an object keeps."""
CHUNK = 256
"""Substeps the compiled loop runs before it returns its samples (it is called again)."""
_END_KEYS = (SHARED_KEYS.get(EventFunction.AREA), SHARED_KEYS.get(EventFunction.PICKUP))
"""The terminations the kernel watches, in its order (a strain limit runs in Python)."""


def quiet_area_tables(bounds: np.ndarray, rigid_gradients: np.ndarray) -> tuple:
    """The tables of a contact set's quiet area check (:func:`..substeps_numba._area_lower`)
    from its gradient bounds (t, m) and the object's rigid gradients (4t, 3): the watched
    elements (:data:`QUIET_AREA_SHARE`), their bounds (w, m) and rigid gradients (w, 4, 3), the
    other elements' bounds' column maxima (m,), and the largest Frobenius norm of an element's
    rigid gradients.

    >>> bounds = np.array([[1.0, 0.0], [0.05, 0.02], [0.0, 2.0]])
    >>> watched, _, _, rest_top, rigid_top = quiet_area_tables(bounds, np.full((12, 3), 0.5))
    >>> watched.tolist(), rest_top.tolist(), rigid_top
    ([0, 2], [0.05, 0.02], 1.7320508075688772)
    """
    watched = np.flatnonzero((bounds >= QUIET_AREA_SHARE * bounds.max(axis=0)).any(axis=1))
    rest = np.delete(bounds, watched, axis=0)
    rigid = rigid_gradients.reshape(-1, 4, 3)
    return (watched, np.ascontiguousarray(bounds[watched]), np.ascontiguousarray(rigid[watched]),
            rest.max(axis=0) if len(rest) else np.zeros(bounds.shape[1]),
            float(np.sqrt((rigid * rigid).sum(axis=(1, 2))).max()))


class Chunk:
    """What one compiled run did: ``count`` accepted substeps ending at ``s`` with ``sol``,
    and whether the next substep must run in Python (``python_next``).
    """

    __slots__ = ("count", "python_next", "s", "sol")

    def __init__(self, count: int, python_next: bool, s: float, sol: Solution | None) -> None:
        self.count, self.python_next, self.s, self.sol = count, python_next, s, sol


class CompiledSubsteps:
    """The compiled substeps of one :func:`~.run.advance` call (see the module).

    Use :meth:`of`, which returns None when the call cannot use them.
    """

    def __init__(self, call) -> None:
        self.call = call
        self.kernel = compiled_substeps()
        model, motion = call.model, call.motion
        lim = model.limits
        self.weight = (lim.weight / model.force_unit
                       if lim.weight is not None and Termination.PICKED_UP in call.functions
                       .terminate_on else np.nan)
        self.tip_tables = (np.ascontiguousarray(motion.tip.radius, float),
                           np.ascontiguousarray(motion.tip.flat, float),
                           np.ascontiguousarray(motion.tip._facing_tangent, float))
        self.rigid_gradients = np.ascontiguousarray(model.obj.rigid_gradients)
        self.D = np.ascontiguousarray(motion.translation, float)
        self.origin = np.ascontiguousarray(motion.start, float)
        self._tables: tuple | None = None

    @classmethod
    def of(cls, call) -> CompiledSubsteps | None:
        """The compiled substeps of ``call``, or None when it must run in Python."""
        model = call.model
        lim = model.limits
        if (selected() != Kernel.NUMBA or model.reference
                or model.adaptive_steps or type(model).response is not ContactModel.response
                or call.motion.rate == 0
                or (lim.strain is not None
                    and Termination.STRAIN_LIMIT in call.functions.terminate_on)):
            return None
        return cls(call)

    def _set_tables(self, contacts, rows: np.ndarray, held: np.ndarray) -> tuple:
        """The contact set's tables for the kernel (kept while the set, rows and holds are)."""
        key = (contacts.stick.tobytes(), contacts.slip.tobytes(), rows.tobytes(),
               held.tobytes())
        kept = self._tables
        if kept is not None and kept[0] is contacts.data and kept[1] == key:
            return kept[2]
        model, functions, motion = self.call.model, self.call.functions, self.call.motion
        sd = contacts.data
        tip = motion.contact_tips(contacts.finger).tip
        A_rows, R_rows = model._boundary_rows(sd, rows)
        _, pick = functions._contact_entries(contacts, held)
        # E in the set's own layout: the kernel's E.T @ delta is then numpy's product
        tables = (
            (np.ascontiguousarray(sd.C), np.ascontiguousarray(contacts.positions, float),
             np.ascontiguousarray(contacts.stick), np.ascontiguousarray(contacts.slip),
             float(model.phi), np.ascontiguousarray(tip.radius, float),
             np.ascontiguousarray(tip.flat, float), np.ascontiguousarray(tip.facing, float),
             np.ascontiguousarray(contacts.finger),
             np.array(sorted(set(contacts.finger.tolist())), int)),
            (np.ascontiguousarray(pick, int), np.ascontiguousarray(A_rows),
             np.ascontiguousarray(R_rows), sd.E,
             np.ascontiguousarray(functions._boundary[rows])),
        )
        self._tables = (sd, key, tables)
        return tables

    def run(self, sol: Solution, a: float, start, expiry: float) -> Chunk:
        """Accepted substeps from a (the call's current point, solution ``sol``, watched
        values ``start``) until one needs Python; their samples, work and counters are
        applied to the call.
        """
        call = self.call
        ev, model, motion = call.events, call.model, call.motion
        contacts = ev.contacts
        held = call.chatter.held(contacts.nodes, motion.depth_at(a))
        keys, _ = call.functions._contact_entries(contacts, held)
        if getattr(start.values, "order", None) is not call.functions._order(keys, start.rows):
            # ``start`` was taken while another contact was held (a hold expired since, the
            # free rows unchanged): the kernel compares values by position, so this substep
            # runs in Python, which compares them by key (before: writes past the kernel's
            # values array, an abort or a corrupted heap)
            return Chunk(0, True, a, None)
        problem, watched = self._set_tables(contacts, start.rows, held)
        bounds, loads = model.area_tables(contacts.data)  # loads: kept once an element neared
        area = (np.ascontiguousarray(bounds), self.kernel.NO_LOADS if loads is None else loads)
        quiet_area = kept_for(model.obj._shared.setdefault("quiet_area", {}), contacts.data,
                              None, lambda: quiet_area_tables(bounds, self.rigid_gradients),
                              QUIET_AREA_TABLES_KEPT)
        m, nf = len(contacts), len(motion.names)
        n = int(np.count_nonzero(~contacts.stick))
        ends = start.values.ends
        start_ends = np.array([ends.get(key, np.inf) for key in _END_KEYS])
        s_out, theta_out = np.empty(CHUNK), np.empty((CHUNK, m))
        forces_out, jacobians = np.empty((CHUNK, nf, 2)), np.empty((CHUNK, n, n))
        c = np.ascontiguousarray
        (count, why, most_it, most_res, theta, delta, F, dtheta, dF, ddelta, nu, kappa, J, it,
         res) = self.kernel.advance_quiet(
            a, call.step / motion.rate, c(sol.theta), c(sol.dtheta), c(sol.F), c(sol.dF),
            c(sol.tangential), c(start.values.values, float), start_ends, *problem,
            self.origin, self.D, NEWTON_TOL, NEWTON_MAX_ITERATIONS, NEWTON_BACKTRACKS,
            CONTINUATION_ITERATIONS, MAX_ANGLE_JUMP, watched[0], float(model.mu),
            float(motion.rate), *watched[1:], *self.tip_tables, self.rigid_gradients, *area,
            GRADIENT_BOUND_EXACT, INVERSION_AREA_RATIO, quiet_area, self.weight,
            float(motion.depth0), float(motion.length), expiry, QUIET_MARGIN,
            float(model.force_unit), call.work, call.dissipation, s_out, theta_out, forces_out,
            jacobians)
        python_next = why != self.kernel.FULL
        if count == 0:
            return Chunk(0, python_next, a, None)
        counters = call.counters
        counters.substeps += count
        counters.newton_max_iterations = max(counters.newton_max_iterations, most_it)
        counters.newton_max_residual = max(counters.newton_max_residual, most_res)
        if n:
            counters.jacobian_max_condition = max(
                counters.jacobian_max_condition, jacobian_condition(jacobians[:count]))
        nodes, names = tuple(contacts.nodes.tolist()), motion.names
        for s, th, forces in zip(s_out[:count].tolist(), theta_out[:count].tolist(),
                                 forces_out[:count].tolist()):
            call.samples.append(Sample(motion.depth_at(s), nodes, tuple(th),
                                       {name: tuple(f) for name, f in zip(names, forces)}))
        b = float(s_out[count - 1])
        return Chunk(count, python_next, b, Solution(theta, delta, F, dtheta, dF, ddelta, it, res,
                                                     jacobian_condition(J), nu, kappa))
