# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The mode decision: hypothesis-and-test of contact modes along the motion (Algorithm 1 lines
2 and 13).

Where a node's mode is not fixed by its past (a new contact, an initial contact, nodes whose
C/D events at one point would flip back), each hypothesis is solved and tested: stick needs a
positive normal force inside the cone, slide needs a positive normal force and a slip rate of
the assumed sign. A function that is zero by construction at the point (a new contact's normal
force and cone margins, a sliding node's margin on its slip side) must grow along the motion
instead of being positive, faster than a noise floor (:data:`RATE_NOISE`): where a hypothesis
leaves such a function's rate an exact zero in exact arithmetic (a node of an object that
slides rigidly along its fingers), the computed rate is round-off of about 1e-15 whose sign
depends on the factoriser, and it must not decide the mode. :func:`decide_modes` is a function
of the contact set and a solver, so it can be tested with any solver.
"""
from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from squeeze_grasp_ros.mechanics.errors import NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import Solution, SolveFailure
from squeeze_grasp_ros.mechanics.squeeze.event_key import EventFunction, EventKey
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet

__all__ = ["MAX_JOINT_NODES", "MAX_SEARCHED_NODES", "RATE_NOISE", "ModeChoice", "decide_modes",
           "mode_violations", "zero_functions"]

MAX_JOINT_NODES = 3
"""Up to this many undecided nodes every combination of modes is tried; beyond, node by node."""
MAX_SEARCHED_NODES = 5
"""Up to this many undecided nodes whose node-by-node choice is inconsistent, every combination
is tried after it (at most 3^5 = 243 solves; a consistent choice node by node is kept)."""
RATE_NOISE = 1e-10
"""Noise floor of the rate of a function zero by construction, relative to the force rate a
stuck contact would see (the fingers' motion per unit s, forces / (E h L)): a rate at or below
it does not count as growing (:func:`mode_violations`). Round-off rates are about 1e-14 of
that scale; a stuck contact's rates in the shipped scenes are 1e-2 to 1 of it."""

Attempt = Callable[[ContactSet], "Solution | SolveFailure"]
"""A solver of a contact set at the current point (the modes it is given, its own angles)."""
Search = Callable[..., "tuple | None"]
"""The search of :func:`decide_modes` in one compiled call (:meth:`~.solving.SetSolver.decide`):
of a contact set, the positions to decide, the options (rows (stick, slip)) and which of their
functions are zero by construction (:func:`_zero_flags`), given ``mu``, ``rate_floor`` and
``by_node``, the search's (stick, slip, theta, violations), or None where it does not apply."""


def mode_violations(*, mu: float, fn: float, ft: float, fn_rate: float, ft_rate: float,
                    dtheta: float, stick: bool, slip: int, frictionless: bool,
                    zero: set[EventFunction], rate_floor: float = 0.0) -> int:
    """Violated conditions of a mode hypothesis for one contact (0 = consistent).

    A function in ``zero`` (normal force or a cone margin that is zero by construction now)
    must grow along the motion, at a rate above ``rate_floor`` (force per unit s, the units of
    the rates); any other must be positive. Stick: normal force and both cone
    margins; slip: normal force and slip rate of the assumed sign.

    >>> mode_violations(mu=0.5, fn=1.0, ft=0.8, fn_rate=0.0, ft_rate=0.0, dtheta=0.0,
    ...                 stick=True, slip=0, frictionless=False, zero=set())  # outside the cone
    1
    """
    def ok(function: EventFunction, value: float, rate: float) -> bool:
        return rate > rate_floor if function in zero else value > 0

    bad = int(not ok(EventFunction.NORMAL_FORCE, fn, fn_rate))
    if stick:
        bad += int(not ok(EventFunction.CONE_PLUS, mu * fn + ft, mu * fn_rate + ft_rate))
        bad += int(not ok(EventFunction.CONE_MINUS, mu * fn - ft, mu * fn_rate - ft_rate))
    elif not frictionless:
        bad += int(slip * dtheta <= 0)
    return bad


def zero_functions(contacts: ContactSet, fresh: set[EventKey]) -> set[EventKey]:
    """Functions zero by construction now: the ``fresh`` ones and each sliding node's cone
    margin on its slip side (its force lies on that cone edge).
    """
    zero = set(fresh)
    for node, stick, slip in zip(contacts.nodes.tolist(), contacts.stick, contacts.slip):
        if not stick and slip:
            zero.add(EventKey(EventFunction.cone_edge(slip), node))
    return zero


@dataclass(frozen=True)
class ModeChoice:
    """The modes a decision chose (of the whole set) and the solution in them.

    Attributes
    ----------
    stick, slip : (m,) ndarray
    theta : (m,) ndarray
        Polar angles of the solution in these modes, rad.
    violations : int
        Violated conditions of the chosen hypothesis (0: consistent).
    """

    stick: np.ndarray
    slip: np.ndarray
    theta: np.ndarray
    violations: int


def _violations(sol: Solution, idx: list[int], zero: dict[int, set[EventFunction]],
                mu: float, stick: np.ndarray, slip: np.ndarray, rate_floor: float) -> int:
    """:func:`mode_violations` of contacts ``idx`` summed, in the hypothesis (``stick``,
    ``slip``); ``zero`` holds each contact's functions zero by construction
    (:func:`_zero_by_contact`).
    """
    fn, ft = sol.normal[idx].tolist(), sol.tangential[idx].tolist()
    fn_rate, ft_rate = sol.normal_rate[idx].tolist(), sol.tangential_rate[idx].tolist()
    dtheta = sol.dtheta[idx].tolist()
    frictionless, none = mu == 0.0, frozenset()
    return sum(mode_violations(mu=mu, fn=fn[i], ft=ft[i], fn_rate=fn_rate[i],
                               ft_rate=ft_rate[i], dtheta=dtheta[i], stick=bool(stick[k]),
                               slip=int(slip[k]), frictionless=frictionless,
                               zero=zero.get(k, none), rate_floor=rate_floor)
               for i, k in enumerate(idx))


def _zero_by_contact(contacts: ContactSet, zero: set[EventKey]) -> dict[int, set[EventFunction]]:
    """The functions of ``zero`` by the position of their contact node in the set."""
    position = {node: k for k, node in enumerate(contacts.nodes.tolist())}
    out: dict[int, set[EventFunction]] = {}
    for key in zero:
        k = position.get(key.node)
        if k is not None:
            out.setdefault(k, set()).add(key.function)
    return out


def _zero_flags(idx: list[int], zero: dict[int, set[EventFunction]]) -> np.ndarray:
    """Whether the normal force and the cone margins (+, -) of each contact ``idx`` are zero
    by construction, (len(idx), 3) of bool.
    """
    functions = (EventFunction.NORMAL_FORCE, EventFunction.CONE_PLUS, EventFunction.CONE_MINUS)
    return np.array([[f in zero.get(k, ()) for f in functions] for k in idx], bool).reshape(
        len(idx), 3)


def _options(mu: float) -> list[tuple[bool, int]]:
    """Hypotheses per node in the order tried: stick, slip +1, slip -1 (slide if mu = 0)."""
    return [(False, 0)] if mu == 0.0 else [(True, 0), (False, 1), (False, -1)]


def _node_by_node(contacts: ContactSet, idx: list[int], zero: dict[int, set[EventFunction]],
                  attempt: Attempt, mu: float, rate_floor: float) -> tuple:
    """Node-by-node hypothesis-and-test (two passes) for many undecided nodes."""
    options = _options(mu)
    stick, slip = contacts.stick.copy(), contacts.slip.copy()
    choice = {k: options[0] for k in idx}
    for _ in range(2):
        for k in idx:
            for st, sl in options:
                stick[k], slip[k] = st, sl
                sol = attempt(contacts.with_modes(stick, slip))
                if isinstance(sol, SolveFailure):
                    continue
                if _violations(sol, [k], zero, mu, stick, slip, rate_floor) == 0:
                    choice[k] = (st, sl)
                    break
            stick[k], slip[k] = choice[k]
    return tuple(choice[k] for k in idx)


def _no_mode(nodes: list[int], failures: list[SolveFailure]) -> Exception:
    """The error when no hypothesis could be solved."""
    if failures and all(f.indeterminate for f in failures):
        return failures[-1].error()
    residual = min((f.residual for f in failures), default=float("inf"))
    return NumericalError(f"no contact mode of nodes {sorted(nodes)} can be solved",
                          residuals={"cone": residual})


def decide_modes(contacts: ContactSet, nodes: list[int], zero: set[EventKey], attempt: Attempt,
                 *, mu: float, rate_floor: float = 0.0,
                 search: Search | None = None) -> ModeChoice:
    """Joint hypothesis-and-test for the modes of contact ``nodes``.

    Options per node in the order stick, slip +1, slip -1; every combination for up to
    MAX_JOINT_NODES nodes (the first consistent one wins, else the one with fewest
    violations), node by node in two passes for more, and then, when that choice is
    inconsistent and there are at most MAX_SEARCHED_NODES nodes, every combination: the
    node-by-node search changes one node at a time, so it misses nodes that can only change
    together (a finger's contacts that all start to slide one way). The other contacts keep
    their modes.

    Parameters
    ----------
    contacts : ContactSet
    nodes : list of int
        The nodes to decide (contacts of the set).
    zero : set of EventKey
        Functions zero by construction at the point (:func:`zero_functions`).
    attempt : callable
        Solves a contact set at the point, or returns why not.
    mu : float
        Friction coefficient (0: every node slides).
    rate_floor : float
        Rates of functions in ``zero`` at or below it do not count as growing (the stepper
        passes :data:`RATE_NOISE` x its force-rate scale).
    search : callable, optional
        The same search in one compiled call (the numba route's linear model), whose choice
        is taken; where it returns None (another model or route, or no hypothesis solved)
        the search runs here.

    Raises
    ------
    InvalidInputError, NumericalError
        If no hypothesis can be solved.
    """
    idx = [contacts.index(n) for n in sorted(nodes)]
    zero_at = _zero_by_contact(contacts, zero)
    decide = partial(_decide, contacts, nodes, idx, zero_at, attempt, mu, rate_floor, search)
    jointly = len(idx) <= MAX_JOINT_NODES
    choice = decide(jointly=jointly)
    if choice.violations and not jointly and len(idx) <= MAX_SEARCHED_NODES:
        joint = decide(jointly=True)
        if joint.violations < choice.violations:
            return joint
    return choice


def _decide(contacts: ContactSet, nodes: list[int], idx: list[int],
            zero_at: dict[int, set[EventFunction]], attempt: Attempt, mu: float,
            rate_floor: float, search: Search | None, *, jointly: bool) -> ModeChoice:
    """The search of :func:`decide_modes` over every combination (``jointly``) or node by
    node, compiled where ``search`` takes it.
    """
    chosen = None if search is None else search(
        contacts, idx, np.array(_options(mu), np.int64), _zero_flags(idx, zero_at), mu=mu,
        rate_floor=rate_floor, by_node=not jointly)
    if chosen is not None:
        return ModeChoice(*chosen)
    if jointly:
        candidates = itertools.product(_options(mu), repeat=len(idx))
    else:
        candidates = [_node_by_node(contacts, idx, zero_at, attempt, mu, rate_floor)]
    best, failures = None, []
    for combo in candidates:
        stick, slip = contacts.stick.copy(), contacts.slip.copy()
        for k, (st, sl) in zip(idx, combo):
            stick[k], slip[k] = st, sl
        sol = attempt(contacts.with_modes(stick, slip))
        if isinstance(sol, SolveFailure):
            failures.append(sol)
            continue
        bad = _violations(sol, idx, zero_at, mu, stick, slip, rate_floor)
        if best is None or bad < best.violations:
            best = ModeChoice(stick, slip, sol.theta, bad)
        if bad == 0:
            break
    if best is None:
        raise _no_mode(nodes, failures)
    return best
