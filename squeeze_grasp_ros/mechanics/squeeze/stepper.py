# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The incremental event stepper (paper Sec. 5.2-5.4, Algorithm 1 lines 4-15; docs/design.md §2).

:func:`advance` moves any number of fingertips by given translations from a frozen
:class:`~.contact_state.ContactState` and returns the new state with the events it located.
Squeezes, resistance and the simulated hardware are loops over it.

Within one call the motion is parametrised by s in [0, 1] (finger f at o_f + s d_f). The
interval is cut into substeps of ``step`` (depth, relative to the object size L), the grid; a
model whose evaluations are dear (``ContactModel.adaptive_steps``: the large-deformation models)
adapts them between events instead (:meth:`_Run.next_step`: up to ADAPTIVE_MAX_STEPS grid steps
while the force slope changes little, the grid while a contact slides; a substep on whose cubic
Hermite interpolants a gap, force or cone function dips to zero inside is halved, so a double
root the end values would miss is caught). At each substep end the fixed-set problem is solved
(:func:`~.contact_model.solve_fixed_set`) and the event functions are evaluated:

=====  ===========================================  ===============  =====================
type   function (positive = no event)               nodes            paper
=====  ===========================================  ===============  =====================
A      gap |x_k - o_f| - r_f                         non-contact      eq. 48
B      normal force f_n = f . e(theta)               contact          eq. 49 (|f| -> 0)
C      cone margin mu f_n -/+ f_t                    sticking         eq. 50
D      slip . d theta / ds (slip rate)               sliding          eq. 51
=====  ===========================================  ===============  =====================

plus the termination functions eps* - max strain (eq. 45; only with a strain limit),
w/n_f - min_f sum_k c_k (pickup; see :func:`pickup_margin`) and min det F - J_min, the
smallest element area ratio above INVERSION_AREA_RATIO (always checked: an element squashed to
that fraction of its area is about to turn inside out, and the squeeze ends
``element_inverted``; a nonlinear model that finds no equilibrium without an inverted element
ends the same way at the last state it solved). A function that changes sign in a
substep is located to a bracket [a, b] of depth width <= ``event_tol`` * L: A, B and C, whose
slopes d/ds are known at every solution (:meth:`_Run.rates`), on their cubic Hermite
interpolants (2-3 solves per event), D and the terminations by a safeguarded Illinois (regula
falsi) iteration. The crossings of a substep are taken in the order of their interpolated
roots, and one still positive at the start of the earliest bracket needs no location of its
own. The earliest bracket end b wins, so the state at an event has the condition just met (a
new contact penetrates by at most the tolerance; b lands about a quarter tolerance past the
root, never on it, where functions crossing at the same point would have round-off signs).
Results therefore depend on ``step`` only through missed double roots inside one substep, and
on ``event_tol`` to within the tolerance. The reference model (``ContactModel.reference``) skips
the location: events are taken at the end of the fixed step, as in the paper.

Processing at an event point (deterministic). Pending events are those whose function is
<= 0, or, for functions that are zero by construction at that point (a new contact's force and
cone margins, a freed node's gap, a just-stuck node's cone margin: the ``fresh`` keys of the
state), whose derivative along the motion is negative. They are processed in the order

    B (break)  <  D (slip -> stick)  <  C (stick -> slip)  <  A (new contact),

then by finger (F1, F2, A) and node index, re-solving after each:

* all new contacts pending at the point are added together and their modes decided jointly
  by hypothesis-and-test along the motion (Algorithm 1 lines 2 and 13): stick if the force
  rate stays inside the cone, else slide in the direction whose slip rate and normal-force
  rate are consistent; options stick, slip +1, slip -1 in that order, every combination for up
  to three nodes (the first consistent wins, else the fewest violations), node by node beyond;
* a node whose C/D event would flip back at the same point has no consistent mode on its
  own: the nodes with C/D events at the point are then decided jointly the same way, and
  their events at the point are replaced by the net mode change;
* finger slip (all contact nodes of a finger sliding the same way, Sec. 5.1) is checked after
  every event and stops the processing; a break that would leave a finger without contact is
  not applied and ends the call as ``contact_lost``.

Then the terminations are checked in the order element_inverted < strain_limit < finger_slip <
picked_up.

Chattering bound: a node that would exceed ``model.max_events_per_depth`` events within one
depth step, flips again after a joint decision, or has a second A/B event at one point, is
frozen in its current state for one depth step (its events are not processed; reported as
:class:`~.contact_state.Chatter`). Every loop advances s strictly or processes a bounded
number of events, so a call always ends.

Between substeps the sliding angles are continued from the previous point (predictor
theta + dtheta/ds ds, Newton with line search); a substep whose Newton solve is slow or lands
off the predicted branch is halved.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    INVERSION_AREA_RATIO,
    Configuration,
    ContactModel,
    Solution,
    SolveFailure,
    attempt_fixed_set,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_state import (
    Chatter,
    ContactNode,
    ContactState,
    Event,
    FingerState,
    Sample,
    StepResult,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError, require_finite
from squeeze_grasp_ros.mechanics.squeeze.event_functions import (EventValues, event_values,
                                                                  hermite_dips, hermite_root,
                                                                  locate_sign_change,
                                                                  mode_violations, pickup_margin)
from squeeze_grasp_ros.mechanics.squeeze.fingertips import tip_gaps
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, EventType, Termination

EVENT_ORDER = {"B": 0, "D": 1, "C+": 2, "C-": 2, "A": 3}
"""Processing order of simultaneous events (C+ and C- never coexist on one node)."""
TERMINATION_ORDER: tuple[str, ...] = (
    Termination.STRAIN_LIMIT,
    Termination.FINGER_SLIP,
    Termination.PICKED_UP,
)
SLIP_RATE_ZERO = 1e-10
"""Frictionless contacts: polar-angle rates (rad per unit motion) below this have no slip
direction, so round-off in a symmetric contact cannot fake a one-way finger slip."""
ADAPTIVE_GROWTH = 2.0
ADAPTIVE_SLOPE_CHANGE = 0.1
ADAPTIVE_MAX_STEPS = 4
"""Adaptive substeps (models with ``adaptive_steps``, :meth:`_Run.next_step`): growth per
substep, the relative change of the force slope over one substep they aim at, and their
largest length in grid steps."""
_ADAPT = [True]


@contextmanager
def substep_adaptation(enabled: bool) -> Iterator[None]:
    """Within the block, models that adapt their substeps (``adaptive_steps``) keep the
    ``step`` grid instead: for measuring what the adaptation saves.
    """
    before, _ADAPT[0] = _ADAPT[0], enabled
    try:
        yield
    finally:
        _ADAPT[0] = before


MAX_SUBSTEP_HALVINGS = 12
CONTINUATION_ITERATIONS = 12
MAX_ANGLE_JUMP = 0.05
"""Continuation safeguards: Newton iterations and distance (rad) from the predicted angles
beyond which a substep is halved."""
class _Run:
    """Mutable working copy of a state during one :func:`advance` call (dimensionless)."""

    def __init__(
        self,
        model: ContactModel,
        state: ContactState,
        translations: Mapping[str, tuple[float, float]],
        step: float,
        event_tol: float,
        terminate_on: tuple[str, ...],
    ) -> None:
        self.model = model
        L = model.length
        self.names = [f.name for f in state.fingers]
        unknown = sorted(set(translations) - set(self.names))
        if unknown:
            raise InvalidInputError(
                f"translation given for unknown finger {unknown[0]!r} (state has {self.names})"
            )
        self.c0 = np.array([f.center for f in state.fingers], float) / L
        self.D = np.array([translations.get(n, (0.0, 0.0)) for n in self.names], float) / L
        require_finite("finger translations", self.D)
        self.radius_f = np.array([f.radius for f in state.fingers], float) / L
        self.t0 = np.array([f.translation for f in state.fingers], float) / L
        self.work = np.array([f.work for f in state.fingers], float) / (model.force_unit * L)
        self.dissipation = np.array([f.dissipation for f in state.fingers], float) / (
            model.force_unit * L
        )
        self.rate = float(np.linalg.norm(self.D))
        self.depth0 = state.depth
        self.relative_per_depth = state.relative_per_depth
        self.step, self.tol = step, event_tol
        self.planned_substep = step
        self.terminate_on = terminate_on
        order = {n: k for k, n in enumerate(self.names)}
        self.nodes = np.array([c.node for c in state.contacts], int)
        self.fidx = np.array([order[c.finger] for c in state.contacts], int)
        self.stick = np.array([c.mode == ContactMode.STICK for c in state.contacts], bool)
        self.slip = np.array([c.slip for c in state.contacts], int)
        self.theta = np.array([c.theta for c in state.contacts], float)
        self.undetermined = set(state.undetermined)
        self.fresh = set(state.fresh)
        self.history = list(state.history)
        self.holds = dict(state.holds)
        self.frictionless = model.mu == 0.0
        self.boundary = model.boundary_nodes
        self.p_b = model.positions(self.boundary)
        self.s = 0.0
        self.lost: str | None = None
        self.events: list[Event] = []
        self.chatter: list[Chatter] = []
        self.samples: list[Sample] = []
        self.diag = {
            "newton_max_iterations": 0,
            "newton_max_residual": 0.0,
            "jacobian_max_condition": 1.0,
            "root_evaluations": 0,
            "substeps": 0,
            "substep_halvings": 0,
            "substep_rejections": 0,
            "ambiguous_modes": 0,
        }
        self._refresh_set()

    # ----------------------------------------------------------------- contact set and solve
    def _refresh_set(self) -> None:
        order = np.argsort(self.nodes, kind="mergesort")
        for name in ("nodes", "fidx", "stick", "slip", "theta"):
            setattr(self, name, getattr(self, name)[order])
        self.sd = self.model.set_data(tuple(self.nodes.tolist()))
        self.p0 = self.model.positions(self.nodes)
        self.contact_rows = self.model.obj.boundary_positions(self.nodes)

    def depth_at(self, s: float) -> float:
        """Depth (m) at step parameter s."""
        return self.depth0 + s * self.rate * self.model.length

    def solve(self, s: float, theta: np.ndarray | None = None) -> Solution:
        """Fixed-set solution at parameter s with the current modes; NumericalError if none."""
        sol = self.attempt(s, theta)
        if isinstance(sol, SolveFailure):
            raise sol.error()
        return sol

    def attempt(
        self,
        s: float,
        theta: np.ndarray | None = None,
        stick: np.ndarray | None = None,
        slip: np.ndarray | None = None,
    ) -> Solution | SolveFailure:
        """Fixed-set solution at parameter s (modes default to the current ones), or why not."""
        stick = self.stick if stick is None else stick
        slip = self.slip if slip is None else slip
        cfg = Configuration(self.p0, stick, slip, self.radius_f[self.fidx])
        centers = self.c0[self.fidx] + s * self.D[self.fidx]
        sol = attempt_fixed_set(
            self.model.response(self.sd),
            cfg,
            centers,
            self.D[self.fidx],
            self.theta if theta is None else theta,
            self.model.phi,
        )
        if isinstance(sol, SolveFailure):
            return sol
        d = self.diag
        d["newton_max_iterations"] = max(d["newton_max_iterations"], sol.iterations)
        d["newton_max_residual"] = max(d["newton_max_residual"], sol.residual)
        d["jacobian_max_condition"] = max(d["jacobian_max_condition"], sol.jacobian_condition)
        return sol

    # ----------------------------------------------------------------- event functions
    def held(self, depth: float) -> np.ndarray:
        """Boolean mask over contacts of nodes whose mode is frozen at ``depth``."""
        return np.array([self.holds.get(int(k), -np.inf) > depth for k in self.nodes], bool)

    def free_rows(self, depth: float) -> np.ndarray:
        """Boundary loop positions checked for Event A (not in contact, not held)."""
        mask = np.ones(len(self.boundary), bool)
        mask[self.contact_rows] = False
        for node, until in self.holds.items():
            if until > depth:
                mask[self.model.obj.boundary_positions([node])[0]] = False
        return np.flatnonzero(mask)

    def gaps(self, sol: Solution, s: float, rows: np.ndarray) -> np.ndarray:
        """Gaps (k, f) of boundary positions ``rows`` to every fingertip."""
        u = self.model.boundary_displacement(self.sd, sol.delta, sol.F, rows)
        return tip_gaps(self.p_b[rows] + u, self.c0 + s * self.D, self.radius_f)

    def termination_values(self, sol: Solution) -> tuple[float, float]:
        """(eps* - max strain, pickup margin); inf for criteria not declared or not enabled."""
        lim = self.model.limits
        strain = pickup = np.inf
        if lim.strain is not None and Termination.STRAIN_LIMIT in self.terminate_on:
            strain = lim.strain - self.model.max_strain(self.sd, sol.delta, sol.F)[0]
        if lim.weight is not None and Termination.PICKED_UP in self.terminate_on:
            pickup = pickup_margin(
                self.model.mu,
                sol.normal(),
                sol.tangential(),
                self.stick,
                self.fidx,
                sorted(set(self.fidx.tolist())),
                lim.weight / self.model.force_unit,
            )
        return strain, pickup

    def area_value(self, sol: Solution) -> float:
        """The smallest area ratio det F less INVERSION_AREA_RATIO (element_inverted at <= 0)."""
        return self.model.area_ratio(self.sd, sol.delta, sol.F)[0] - INVERSION_AREA_RATIO

    def values(
        self, sol: Solution, s: float, rows: np.ndarray, terminations: bool = True
    ) -> EventValues:
        """All event functions at ``sol`` (and the termination functions if asked)."""
        strain, pickup = self.termination_values(sol) if terminations else (np.inf, np.inf)
        area = self.area_value(sol) if terminations and self.rate > 0 else np.inf
        return event_values(mu=self.model.mu, fn=sol.normal(), ft=sol.tangential(),
                            slip=self.slip, dtheta=sol.dtheta, radius=self.radius_f[self.fidx],
                            rate=self.rate, gaps=self.gaps(sol, s, rows), strain=strain,
                            pickup=pickup, area=area)

    def _key_value(self, key: tuple, sol: Solution, s: float) -> float:
        """Value of one event function (for root location)."""
        kind, node = key[0], key[1]
        if kind == "inverted":
            return self.area_value(sol)
        if kind in ("strain", "pickup"):
            return self.termination_values(sol)[0 if kind == "strain" else 1]
        if kind == "A":
            return float(self.gaps(sol, s, self.model.obj.boundary_positions([node]))[0, key[2]])
        v = self.values(sol, s, np.zeros(0, int), terminations=False)
        k = int(np.searchsorted(self.nodes, node))
        return float({"B": v.fn, "C+": v.c_plus, "C-": v.c_minus, "D": v.d}[kind][k])

    def _key_slope(self, key: tuple, sol: Solution, s: float) -> float:
        """Derivative d/ds of one event function that has one (A, B, C; see :meth:`rates`)."""
        if key[0] == "A":
            return self.rates(sol, s, self.model.obj.boundary_positions([key[1]]))[key]
        return self.rates(sol, s, np.zeros(0, int))[key]

    def entries(self, v: EventValues, rows: np.ndarray, depth: float):
        """Active (key, value) pairs of the contact and termination functions, in order."""
        held = self.held(depth)
        out = []
        for k, node in enumerate(self.nodes.tolist()):
            if held[k]:
                continue
            out.append((("B", node), v.fn[k]))
            if self.frictionless:
                continue
            if self.stick[k]:
                out.append((("C+", node), v.c_plus[k]))
                out.append((("C-", node), v.c_minus[k]))
            else:
                out.append((("D", node), v.d[k]))
        for r, node in enumerate(self.boundary[rows].tolist()):
            for f in range(len(self.names)):
                out.append((("A", node, f), v.gaps[r, f]))
        if np.isfinite(v.area):
            out.append((("inverted", -1), v.area))
        if np.isfinite(v.strain):
            out.append((("strain", -1), v.strain))
        if np.isfinite(v.pickup):
            out.append((("pickup", -1), v.pickup))
        return out

    # ----------------------------------------------------------------- processing at a point
    def rates(self, sol: Solution, s: float, rows: np.ndarray) -> dict:
        """Derivatives d/ds at ``sol`` of the gaps (Event A) of boundary positions ``rows`` and
        of every contact's normal force and cone margins (B, C); D and the terminations have
        none (their derivative needs the second derivative of the sliding angles / the field).
        """
        fn_r, ft_r = sol.normal_rate(), sol.tangential_rate()
        mu = self.model.mu
        out = {}
        if len(rows):
            x = self.p_b[rows] + self.model.boundary_displacement(self.sd, sol.delta, sol.F, rows)
            dx = self.model.boundary_rate(self.sd, sol, rows)
            rel = x[:, None, :] - (self.c0 + s * self.D)[None]
            rel_rate = dx[:, None, :] - self.D[None]
            g_rate = np.einsum("rfi,rfi->rf", rel, rel_rate) / np.linalg.norm(rel, axis=2)
            for j, node in enumerate(self.boundary[rows].tolist()):
                for f in range(len(self.names)):
                    out[("A", node, f)] = float(g_rate[j, f])
        for k, node in enumerate(self.nodes.tolist()):
            out[("B", node)] = float(fn_r[k])
            out[("C+", node)] = float(mu * fn_r[k] + ft_r[k])
            out[("C-", node)] = float(mu * fn_r[k] - ft_r[k])
        return out

    def _fresh_rates(self, sol: Solution) -> dict:
        """Derivatives d/ds of the fresh functions at the current point."""
        a_nodes = [node for kind, node in self.fresh if kind == "A"]
        return self.rates(sol, self.s, self.model.obj.boundary_positions(a_nodes)
                          if a_nodes else np.zeros(0, int))

    def pending(self, sol: Solution) -> list[tuple]:
        """Pending contact events at the current point, in processing order."""
        depth = self.depth_at(self.s)
        rows = self.free_rows(depth)
        v = self.values(sol, self.s, rows, terminations=False)
        rates = self._fresh_rates(sol)
        out = []
        for key, value in self.entries(v, rows, depth):
            fresh_key = key[:2]
            if fresh_key in self.fresh and key in rates:
                if key[0] == "A" and value > self.tol:
                    continue  # a freed node is at zero gap only to the finger that released it
                if rates[key] < 0:
                    out.append(key)
            elif value <= 0:
                out.append(key)
        finger_of = dict(zip(self.nodes.tolist(), self.fidx.tolist()))
        return sorted(
            out, key=lambda k: (EVENT_ORDER[k[0]], k[2] if k[0] == "A" else finger_of[k[1]], k[1])
        )

    def zero_keys(self) -> set:
        """Functions zero by construction now: the fresh ones and each sliding node's cone
        margin on its slip side (its force lies on that cone edge).
        """
        zero = set(self.fresh)
        for node, stick, slip in zip(self.nodes.tolist(), self.stick, self.slip):
            if not stick and slip:
                zero.add(("C+" if slip > 0 else "C-", node))
        return zero

    def violations(self, sol: Solution, k: int, stick: bool, slip: int, zero: set) -> int:
        """Violated conditions of a mode hypothesis for contact k (:func:`mode_violations`)."""
        node = int(self.nodes[k])
        return mode_violations(
            mu=self.model.mu, fn=float(sol.normal()[k]), ft=float(sol.tangential()[k]),
            fn_rate=float(sol.normal_rate()[k]), ft_rate=float(sol.tangential_rate()[k]),
            dtheta=float(sol.dtheta[k]), stick=bool(stick), slip=int(slip),
            frictionless=self.frictionless, zero={kind for kind, n in zero if n == node})

    def decide(self, nodes: list[int]) -> None:
        """Joint hypothesis-and-test for the modes of ``nodes`` (Algorithm 1 lines 2 and 13).

        Options per node in the order stick, slip +1, slip -1; every combination for up to
        three nodes (the first consistent one wins, else the one with fewest violations),
        node by node in two passes for more.
        """
        idx = [int(np.searchsorted(self.nodes, n)) for n in sorted(nodes)]
        zero = self.zero_keys()
        options = [(False, 0)] if self.frictionless else [(True, 0), (False, 1), (False, -1)]
        if len(idx) <= 3:
            candidates = itertools.product(options, repeat=len(idx))
        else:
            candidates = [self._greedy(idx, options, zero)]
        best, failures = None, []
        for combo in candidates:
            stick, slip = self.stick.copy(), self.slip.copy()
            for k, (st, sl) in zip(idx, combo):
                stick[k], slip[k] = st, sl
            sol = self.attempt(self.s, stick=stick, slip=slip)
            if isinstance(sol, SolveFailure):
                failures.append(sol)
                continue
            bad = sum(self.violations(sol, k, stick[k], slip[k], zero) for k in idx)
            if best is None or bad < best[0]:
                best = (bad, stick, slip, sol.theta)
            if bad == 0:
                break
        if best is None:
            if failures and all(f.indeterminate for f in failures):
                raise failures[-1].error()
            residual = min((f.residual for f in failures), default=float("inf"))
            raise NumericalError(f"no contact mode of nodes {sorted(nodes)} can be solved",
                                 residuals={"cone": residual})
        if best[0] > 0:
            self.diag["ambiguous_modes"] += 1
        _, self.stick, self.slip, self.theta = best
        for k in idx:
            node = int(self.nodes[k])
            if self.stick[k]:
                self.fresh |= {key for key in (("C+", node), ("C-", node)) if key in zero}
            else:
                self.fresh -= {("C+", node), ("C-", node)}
        self.undetermined -= set(nodes)

    def _greedy(self, idx: list[int], options: list, zero: set) -> tuple:
        """Node-by-node hypothesis-and-test (two passes) for many undecided nodes."""
        stick, slip = self.stick.copy(), self.slip.copy()
        choice = {k: options[0] for k in idx}
        for _ in range(2):
            for k in idx:
                for st, sl in options:
                    stick[k], slip[k] = st, sl
                    sol = self.attempt(self.s, stick=stick, slip=slip)
                    if isinstance(sol, SolveFailure):
                        continue
                    if self.violations(sol, k, st, sl, zero) == 0:
                        choice[k] = (st, sl)
                        break
                stick[k], slip[k] = choice[k]
        return tuple(choice[k] for k in idx)

    def _chatters(self, node: int, finger: int) -> bool:
        """Count an event of ``node`` in the depth window; True if the bound froze it instead."""
        depth = self.depth_at(self.s)
        window = self.step * self.model.length
        self.history = [(n, d) for n, d in self.history if d > depth - window]
        if sum(1 for n, _ in self.history if n == node) < self.model.max_events_per_depth:
            self.history.append((node, depth))
            return False
        self.hold(node, finger)
        return True

    def hold(self, node: int, finger: int) -> None:
        """Freeze the contact state of ``node`` for one depth step (chattering bound)."""
        depth = self.depth_at(self.s)
        until = depth + self.step * self.model.length
        self.holds[node] = until
        self.chatter.append(Chatter(node, self.names[finger], depth, until))

    def log(self, kind: str, k: int) -> None:
        """Append an event of contact k (mode and slip after the event)."""
        depth = self.depth_at(self.s)
        mode = ContactMode.STICK if self.stick[k] else ContactMode.SLIP
        self.events.append(
            Event(
                kind,
                int(self.nodes[k]),
                self.names[self.fidx[k]],
                depth,
                depth * self.relative_per_depth,
                mode,
                int(self.slip[k]),
            )
        )

    def add_contacts(self, keys: list[tuple], sol: Solution) -> None:
        """Event A for every key (one per node): put the nodes on their tips, decide jointly."""
        added = []
        self.theta = sol.theta.copy()
        for _, node, f in keys:
            if self._chatters(node, f):
                continue
            row = self.model.obj.boundary_positions([node])
            x = (
                self.p_b[row[0]]
                + self.model.boundary_displacement(self.sd, sol.delta, sol.F, row)[0]
            )
            rel_x = x - (self.c0[f] + self.s * self.D[f])
            theta = float(np.arctan2(rel_x[1], rel_x[0]))
            same = self.fidx == f
            if same.any():
                ref = float(np.mean(self.theta[same]))
                theta = ref + float(np.angle(np.exp(1j * (theta - ref))))
            self.nodes = np.append(self.nodes, node)
            self.fidx = np.append(self.fidx, f)
            self.stick = np.append(self.stick, True)
            self.slip = np.append(self.slip, 0)
            self.theta = np.append(self.theta, theta)
            self.fresh = {k for k in self.fresh if k[1] != node} | {
                ("B", node),
                ("C+", node),
                ("C-", node),
            }
            added.append(node)
        if not added:
            return
        self._refresh_set()
        self.undetermined |= set(added)
        self.decide(added)
        for node in sorted(added):
            self.log("A", int(np.searchsorted(self.nodes, node)))

    def apply(self, key: tuple, sol: Solution) -> None:
        """Process one B, C or D event (updates modes, the contact set and the fresh keys)."""
        kind, node = key[0], key[1]
        k = int(np.searchsorted(self.nodes, node))
        f = int(self.fidx[k])
        if self._chatters(node, f):
            return
        self.theta = sol.theta.copy()
        if kind == "B" and np.count_nonzero(self.fidx == f) == 1:
            self.lost = self.names[f]
        elif kind == "B":
            self.log("B", k)
            self.events[-1] = Event(
                "B",
                node,
                self.names[f],
                self.events[-1].depth,
                self.events[-1].relative_depth,
                "none",
                0,
            )
            keep = np.arange(len(self.nodes)) != k
            for name in ("nodes", "fidx", "stick", "slip", "theta"):
                setattr(self, name, getattr(self, name)[keep])
            self._refresh_set()
            self.fresh = {fk for fk in self.fresh if fk[1] != node} | {("A", node)}
        elif kind in ("C+", "C-"):
            self.stick[k] = False
            self.slip[k] = 1 if kind == "C+" else -1
            self.fresh -= {("C+", node), ("C-", node)}
            self.log("C", k)
        else:
            side = "C+" if self.slip[k] > 0 else "C-"
            self.stick[k], self.slip[k] = True, 0
            self.fresh.add((side, node))
            self.log("D", k)

    def resettle(self, nodes: set, before: dict, first_event: int) -> None:
        """Joint hypothesis-and-test for nodes whose C/D events at this point flip back.

        Their C/D events at this point are replaced by the net mode change from the start of
        the point (C for stick -> slip, D for slip -> stick, D then C for a slip reversal).
        """
        self.decide(sorted(nodes))
        kept = [e for e in self.events[first_event:]
                if not (e.node in nodes and e.type in (EventType.C, EventType.D))]
        self.events[first_event:] = kept
        for node in sorted(nodes):
            k = int(np.searchsorted(self.nodes, node))
            old_stick, old_slip = before.get(node, (True, 0))
            new = (bool(self.stick[k]), int(self.slip[k]))
            if new == (old_stick, old_slip):
                continue
            if not old_stick:
                self.stick[k], self.slip[k] = True, 0
                self.log("D", k)
                self.stick[k], self.slip[k] = new
            if not new[0]:
                self.log("C", k)
        for i, e in enumerate(self.events[first_event:], first_event):
            if e.type == EventType.A and e.node in nodes:
                k = int(np.searchsorted(self.nodes, e.node))
                self.events[i] = Event(
                    "A",
                    e.node,
                    e.finger,
                    e.depth,
                    e.relative_depth,
                    ContactMode.STICK if self.stick[k] else ContactMode.SLIP,
                    int(self.slip[k]),
                )

    def resolve(self) -> Solution:
        """Process every pending event at the current point; returns the final solution.

        New contacts pending together are added as one batch with a joint mode decision. A
        node whose C/D event would flip back at the same point triggers a joint decision over
        the nodes with C/D events here; a node that flips again after that, or has a second
        A/B event here, is frozen by the chattering bound.
        """
        if self.rate == 0:
            return self.solve(self.s)
        if self.undetermined:
            self.decide(sorted(self.undetermined))
        before = {
            int(n): (bool(st), int(sl)) for n, st, sl in zip(self.nodes, self.stick, self.slip)
        }
        first_event = len(self.events)
        mode_events: set = set()
        contact_events: set = set()
        settled: set = set()
        limit = 4 * (len(self.nodes) + 8) * self.model.max_events_per_depth
        for _ in range(limit):
            sol = self.solve(self.s)
            if self.lost is not None or self.slipping_finger(sol) is not None:
                return sol
            todo = self.pending(sol)
            if not todo:
                return sol
            key = todo[0]
            kind, node = key[0], key[1]
            finger = key[2] if kind == "A" else int(self.fidx[np.searchsorted(self.nodes, node)])
            if node in settled or (kind in ("A", "B") and node in contact_events):
                self.hold(node, finger)
            elif kind == "A":
                batch = {}
                for k in todo:
                    if k[0] == "A" and k[1] not in contact_events:
                        batch.setdefault(k[1], k)
                self.add_contacts(sorted(batch.values(), key=lambda k: (k[2], k[1])), sol)
                contact_events |= set(batch)
            elif kind != "B" and node in mode_events:
                group = mode_events | {node}
                self.resettle(group, before, first_event)
                settled |= group
            else:
                (contact_events if kind == "B" else mode_events).add(node)
                self.apply(key, sol)
        raise NumericalError(
            "event processing at one point did not settle (chattering bound "
            "exceeded); lower squeeze.max_events_per_depth"
        )

    def termination(self, sol: Solution) -> str | None:
        """First termination that holds at the current point (TERMINATION_ORDER)."""
        if self.rate == 0:
            return None
        det, element = self.model.area_ratio(self.sd, sol.delta, sol.F)
        if det <= INVERSION_AREA_RATIO:
            self.diag["min_area_ratio"], self.diag["inverted_element"] = det, element
            return Termination.ELEMENT_INVERTED
        strain, pickup = self.termination_values(sol)
        if strain <= 0:
            return Termination.STRAIN_LIMIT
        if self.lost is not None:
            return Termination.CONTACT_LOST
        if Termination.FINGER_SLIP in self.terminate_on and self.slipping_finger(sol) is not None:
            return Termination.FINGER_SLIP
        if pickup <= 0:
            return Termination.PICKED_UP
        return None

    def slipping_finger(self, sol: Solution) -> str | None:
        """A finger whose contact nodes all slide the same way (Sec. 5.1), or None."""
        if Termination.FINGER_SLIP not in self.terminate_on:
            return None
        signs = self._slip_signs(sol)
        for f in sorted(set(self.fidx.tolist())):
            mine = self.fidx == f
            if not self.stick[mine].any() and (np.all(signs[mine] > 0) or np.all(signs[mine] < 0)):
                return self.names[f]
        return None

    def _slip_signs(self, sol: Solution) -> np.ndarray:
        """Slip direction of each contact (from the slip rate when frictionless)."""
        if self.frictionless:
            rate = np.where(np.abs(sol.dtheta) > SLIP_RATE_ZERO, sol.dtheta, 0.0)
            return np.sign(rate).astype(int)
        return self.slip

    # ----------------------------------------------------------------- motion
    def integrate_work(self, sa: Solution, sb: Solution, a: float, b: float) -> None:
        """Add the work of every finger over [a, b] (cubic Hermite in s) and the frictional
        dissipation at its contacts (trapezoid in s; modes are fixed within [a, b]).

        A contact node sits on its tip at polar angle theta, so it moves relative to the tip by
        r d theta: the finger's force does F . dc = F . dx - f_t r d theta, and
        -f_t r d theta (>= 0 against the slip, 0 while sticking) is what friction dissipates.
        """
        h = b - a
        r = self.radius_f[self.fidx]
        pa = -sa.tangential() * r * sa.dtheta
        pb = -sb.tangential() * r * sb.dtheta
        for f in range(len(self.names)):
            mine = self.fidx == f
            if not mine.any():
                continue
            ya, yb = sa.F[mine].sum(axis=0) @ self.D[f], sb.F[mine].sum(axis=0) @ self.D[f]
            ra, rb = sa.dF[mine].sum(axis=0) @ self.D[f], sb.dF[mine].sum(axis=0) @ self.D[f]
            self.work[f] += 0.5 * h * (ya + yb) + h * h / 12.0 * (ra - rb)
            self.dissipation[f] += 0.5 * h * (pa[mine].sum() + pb[mine].sum())

    def record(self, sol: Solution) -> None:
        """Append a trajectory sample at the current point."""
        unit_force = self.model.force_unit
        forces = {
            name: tuple((sol.F[self.fidx == f].sum(axis=0) * unit_force).tolist())
            for f, name in enumerate(self.names)
        }
        self.samples.append(
            Sample(
                self.depth_at(self.s),
                tuple(self.nodes.tolist()),
                tuple(sol.theta.tolist()),
                forces,
            )
        )

    def crossings(self, va: dict, vb: dict, fresh_at_a: set) -> list[tuple]:
        """Keys whose function went from > 0 (or fresh zero) at a to <= 0 at b."""
        out = []
        for key, value in vb.items():
            if value > 0 or key not in va:
                continue
            if va[key] > 0 or key[:2] in fresh_at_a:
                out.append(key)
        return out

    def continue_to(self, sol_a: Solution, a: float, b: float) -> Solution | SolveFailure:
        """Solve at b by continuation from the solution at a (predictor theta + dtheta/ds (b-a)).

        Fails if Newton fails, needs more than CONTINUATION_ITERATIONS iterations or lands more
        than MAX_ANGLE_JUMP (rad) from the prediction (another solution branch).
        """
        guess = sol_a.theta + sol_a.dtheta * (b - a)
        sol = self.attempt(b, theta=guess)
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

    def substep(
        self, sol_a: Solution, a: float, b: float
    ) -> tuple[float, Solution | SolveFailure]:
        """(b, solution at b) by continuation from a, halving the substep while it fails.

        A failure because every state beyond a inverts an element is returned as (a, failure):
        the squeeze ends there. Any other failure after MAX_SUBSTEP_HALVINGS raises.
        """
        for _ in range(MAX_SUBSTEP_HALVINGS):
            sol = self.continue_to(sol_a, a, b)
            if not isinstance(sol, SolveFailure):
                return b, sol
            self.diag["substep_halvings"] += 1
            b = a + 0.5 * (b - a)
        if sol.inverted:
            return a, sol
        raise NumericalError(
            f"the fixed-set solve failed near depth {self.depth_at(a):.6g} m "
            f"after {MAX_SUBSTEP_HALVINGS} substep halvings: {sol.reason}",
            residuals={"cone": sol.residual},
        )

    def run(self, stop_on_event: bool, checkpoint: Callable[[], None] | None = None) -> str | None:
        """Advance s from 0 to 1 (or to a termination / first event); returns the termination.

        ``checkpoint`` is called before every substep (it may raise to abandon the motion).
        """
        sol = self.resolve()
        self.record(sol)
        term = self.termination(sol)
        if term or self.rate == 0 or (stop_on_event and self.events):
            self.final = sol
            return term
        hs = self.step / self.rate
        tol_s = self.tol / self.rate
        adaptive = self.model.adaptive_steps and not self.model.reference and _ADAPT[0]
        h = hs
        if adaptive:
            h = min(ADAPTIVE_MAX_STEPS * hs, max(hs, self.planned_substep / self.rate))
        rows, va, rates_a = None, None, None
        while self.s < 1.0:
            if checkpoint is not None:
                checkpoint()
            a = self.s
            depth_a = self.depth_at(a)
            free = self.free_rows(depth_a)
            if va is None or not np.array_equal(free, rows):
                rows = free
                va = dict(self.entries(self.values(sol, a, rows), rows, depth_a))
                rates_a = self.rates(sol, a, rows) if adaptive else None
            b, sol_b = self.substep(sol, a, min(a + h, 1.0))
            if isinstance(sol_b, SolveFailure):
                self.diag["inversion"] = sol_b.reason
                term = Termination.ELEMENT_INVERTED
                break
            vb = dict(self.entries(self.values(sol_b, b, rows), rows, depth_a))
            rates_b = self.rates(sol_b, b, rows) if adaptive else None
            crossed = self.crossings(va, vb, self.fresh)
            if adaptive and not crossed and b - a > hs and self.dips(va, vb, rates_a, rates_b,
                                                                     a, b):
                self.diag["substep_rejections"] += 1
                h = max(hs, 0.5 * (b - a))
                continue
            self.diag["substeps"] += 1
            if adaptive:
                h = self.next_step(sol, sol_b, a, b, h, hs, va, vb)
                self.planned_substep = h * self.rate
            if crossed and not self.model.reference:
                if not adaptive:
                    gap_rows = self.model.obj.boundary_positions(
                        sorted({key[1] for key in crossed if key[0] == "A"}))
                    rates_a = self.rates(sol, a, gap_rows)
                    rates_b = self.rates(sol_b, b, gap_rows)
                b, sol_b = self.earliest(crossed, sol, sol_b, a, b, tol_s, va, vb, rates_a,
                                         rates_b)
            va, rates_a = (None, None) if crossed else (vb, rates_b)
            self.integrate_work(sol, sol_b, a, b)
            self.s = 1.0 if b >= 1.0 else b
            self.fresh = set()
            self.theta = sol_b.theta.copy()
            sol = self.resolve() if crossed else sol_b
            self.record(sol)
            term = self.termination(sol) if crossed else None
            if term or (stop_on_event and self.events):
                break
        self.final = sol
        return term

    def dips(self, va: dict, vb: dict, ra: dict, rb: dict, a: float, b: float) -> bool:
        """Whether a function with slopes, positive at both ends of [a, b] (and not zero by
        construction at a), goes to zero inside on its cubic Hermite interpolant.
        """
        keys = [key for key in rb if key in ra and key in va and key in vb
                and va[key] > 0 and vb[key] > 0 and key[:2] not in self.fresh]
        return bool(hermite_dips(a, b, *(np.array([v[key] for key in keys])
                                         for v in (va, vb, ra, rb))).any())

    def next_step(self, sol_a: Solution, sol_b: Solution, a: float, b: float, h: float,
                  hs: float, va: dict, vb: dict) -> float:
        """The next substep of an adaptive run (from ``h``, the last one planned, and the
        accepted [a, b]).

        It grows by up to ADAPTIVE_GROWTH while the slope of the contact forces changes by less
        than ADAPTIVE_SLOPE_CHANGE of their change over a substep (so the cubic interpolants
        of the event functions and of the work stay accurate), shrinks when it changes more,
        and stays within [hs, ADAPTIVE_MAX_STEPS hs] (hs = the ``step`` grid). It stays on the
        grid while a contact slides (the slip rates have no slopes; the dissipation is
        integrated by the trapezoid rule), and within half the distance at which a
        termination function without slope (strain, inversion, pickup) would reach zero at
        its last rate of change.
        """
        if not self.stick.all():
            return hs
        change = np.linalg.norm(sol_b.F - sol_a.F)
        slope_change = (b - a) * np.linalg.norm(sol_b.dF - sol_a.dF)
        if slope_change <= ADAPTIVE_SLOPE_CHANGE * change / ADAPTIVE_GROWTH:
            grow = ADAPTIVE_GROWTH
        else:
            grow = max(0.5, ADAPTIVE_SLOPE_CHANGE * change / slope_change)
        h = min(ADAPTIVE_MAX_STEPS * hs, max(hs, h * grow))
        for key in ("inverted", -1), ("strain", -1), ("pickup", -1):
            if key in va and key in vb and vb[key] < va[key]:
                h = min(h, max(hs, 0.5 * vb[key] * (b - a) / (va[key] - vb[key])))
        return h

    def earliest(self, crossed, sol_a, sol_b, a, b, tol_s, va, vb, ra, rb):
        """Locate the earliest crossed function; return its bracket end and the solution there.

        Functions with slopes at both ends (``ra``, ``rb``) are located on their cubic Hermite
        interpolants, the others by regula falsi. The crossings are taken in the order of their
        interpolated roots: once one is bracketed in [lo, hi], another that is still positive
        at lo crosses no earlier than the bracket (it is pending at hi if it has crossed
        there) and needs no location of its own; one that is not is located in [a, lo].
        """
        solved = [(a, sol_a), (b, sol_b)]
        best = None
        finger_of = dict(zip(self.nodes.tolist(), self.fidx.tolist()))

        def solve_near(s: float) -> Solution:
            """Solve at s by continuation from the nearest point solved so far."""
            for at, sol in solved:
                if at == s:
                    return sol
            near, sol_near = min(solved, key=lambda p: abs(p[0] - s))
            sol = self.continue_to(sol_near, near, s)
            if isinstance(sol, SolveFailure):
                raise sol.error()
            solved.append((s, sol))
            return sol

        def estimate(key) -> float:
            if key in ra and key in rb and va[key] > 0:
                root = hermite_root(a, b, va[key], vb[key], ra[key], rb[key])
                if root is not None:
                    return root
            return b if not va[key] > vb[key] else a + (b - a) * va[key] / (va[key] - vb[key])

        for key in sorted(crossed, key=estimate):
            hi_end, g_hi, r_hi = b, vb[key], rb.get(key)
            if best is not None:
                lo_best = best[-1]
                g_hi = self._key_value(key, solve_near(lo_best), lo_best)
                if g_hi > 0 or lo_best <= a:
                    continue
                hi_end = lo_best
                r_hi = (self._key_slope(key, solve_near(lo_best), lo_best)
                        if key in rb else None)
            sloped = key in ra and r_hi is not None

            def g(s, key=key, sloped=sloped):
                sol = solve_near(s)
                value = self._key_value(key, sol, s)
                return (value, self._key_slope(key, sol, s)) if sloped else value

            lo, glo, r_lo = a, va[key], ra.get(key)
            if key[:2] in self.fresh or not glo > 0:
                lo = min(a + tol_s, hi_end)
                glo = g(lo)
                if sloped:
                    glo, r_lo = glo
                self.diag["root_evaluations"] += 1
            if glo <= 0:
                lo = hi = lo
            else:
                lo, hi, n = locate_sign_change(g, lo, hi_end, glo, g_hi, tol_s,
                                               slopes=(r_lo, r_hi) if sloped else None)
                self.diag["root_evaluations"] += n
            fidx = key[2] if key[0] == "A" else finger_of.get(key[1], 0)
            rank = (hi, EVENT_ORDER.get(key[0], 4), fidx, key[1], lo)
            best = rank if best is None or rank < best else best
        s_e = best[0]
        return s_e, solve_near(s_e)

    def to_state(self) -> ContactState:
        """The frozen SI state at the current point."""
        L, fu = self.model.length, self.model.force_unit
        sol = self.final
        s = self.s
        fingers = tuple(
            FingerState(
                n,
                (self.c0[f] + s * self.D[f]) * L,
                self.radius_f[f] * L,
                (self.t0[f] + s * self.D[f]) * L,
                float(self.work[f] * fu * L),
                float(self.dissipation[f] * fu * L),
            )
            for f, n in enumerate(self.names)
        )
        signs = self._slip_signs(sol)
        contacts = tuple(
            ContactNode(
                int(node),
                self.names[self.fidx[k]],
                ContactMode.STICK if self.stick[k] else ContactMode.SLIP,
                0 if self.stick[k] else int(signs[k]),
                float(sol.theta[k]),
                sol.delta[k] * L,
                sol.F[k] * fu,
            )
            for k, node in enumerate(self.nodes.tolist())
        )
        depth = self.depth_at(s)
        return ContactState(
            fingers,
            contacts,
            depth,
            self.relative_per_depth,
            tuple(sorted(self.undetermined)),
            tuple(sorted(self.fresh)),
            tuple(self.history),
            tuple(sorted((n, u) for n, u in self.holds.items() if u > depth)),
        )


MIN_STEP = 1e-6
"""Smallest substep, relative to the object size: below it a squeeze to a usual depth needs
millions of steps (``squeeze.step: 1e-12`` ran for ever)."""
MIN_EVENT_TOL = 1e-15
"""Smallest event tolerance, relative to the object size (near the float resolution)."""


def advance(
    model: ContactModel,
    state: ContactState,
    translations: Mapping[str, tuple[float, float]],
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
        Start state (e.g. :func:`~.contact_state.initial_state`).
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
        Called with no arguments before every substep; it may raise (e.g. a cancellation) to
        abandon the motion, and the exception propagates.

    Returns
    -------
    StepResult
        New state, events, fraction of the translations applied, termination (or None),
        trajectory samples, chattering record and diagnostics.

    Raises
    ------
    InvalidInputError
        For bad arguments, a lost grasp (fewer than 2 contacts) or a solve that fails.
    """
    if not (np.isfinite(step) and step >= MIN_STEP):
        raise InvalidInputError(
            f"step must be >= {MIN_STEP} (relative to the object size), got {step}"
        )
    if not (np.isfinite(event_tol) and event_tol >= MIN_EVENT_TOL):
        raise InvalidInputError(
            f"event_tol must be >= {MIN_EVENT_TOL} (relative to the object size), got {event_tol}"
        )
    bad = sorted(set(terminate_on) - set(TERMINATION_ORDER))
    if bad:
        raise InvalidInputError(f"unknown termination {bad[0]!r} (allowed: {TERMINATION_ORDER})")
    if first_substep is not None and not (np.isfinite(first_substep) and first_substep > 0):
        raise InvalidInputError(f"first_substep must be > 0 (relative to the object size), got "
                                f"{first_substep}")
    run = _Run(model, state, translations, step, min(event_tol, step), tuple(terminate_on))
    if first_substep is not None:
        run.planned_substep = first_substep
    termination = run.run(stop_on_event, checkpoint)
    new_state = run.to_state()
    diag = dict(run.diag)
    diag["sets_factored"] = model._cache.get("sets_factored", 0)
    diag["reduced_max_condition"] = model._cache.get("max_condition", 1.0)
    return StepResult(
        new_state,
        tuple(run.events),
        float(run.s),
        termination,
        tuple(run.samples),
        tuple(run.chatter),
        diag,
        run.planned_substep,
    )
