# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The stepper's units, each alone: event keys and the processing order, the finger motion and
tip geometry, the contact set, the event functions' slopes against finite differences, the
mode decision (against the paper's rule on synthetic solvers, and on a real contact set one
step further along the motion), root location on known functions, substep control and the
chattering bound.
"""
from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel, Solution, SolveFailure
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, initial_state
from squeeze_grasp_ros.mechanics.squeeze.event_key import (
    PROCESSING_ORDER,
    EventFunction,
    EventKey,
    processing_rank,
)
from squeeze_grasp_ros.mechanics.squeeze.fingertips import place_fingertip
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import Kernel
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze
from squeeze_grasp_ros.mechanics.squeeze.stepper import advance
from squeeze_grasp_ros.mechanics.squeeze.stepper.chatter import ChatterBound
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import (
    EventFunctions,
    KeyOrder,
    WatchedValues,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.location import (
    crossings,
    dips_inside,
    earliest_crossing,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.modes import (
    decide_modes,
    mode_violations,
    zero_functions,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.motion import FingerMotion
from squeeze_grasp_ros.mechanics.squeeze.stepper.solving import Counters, SetSolver
from squeeze_grasp_ros.mechanics.squeeze.stepper.substeps import ADAPTIVE_MAX_STEPS, SubstepControl
from squeeze_grasp_ros.mechanics.vocabulary import EventType, Termination

GAP, B, CP, CM, D = (EventFunction.GAP, EventFunction.NORMAL_FORCE, EventFunction.CONE_PLUS,
                     EventFunction.CONE_MINUS, EventFunction.SLIP_RATE)


# ---------------------------------------------------------------------------- keys and order
def test_every_function_is_one_event_type_or_one_termination():
    types = {f.event_type for f in EventFunction if f.event_type is not None}
    assert types == set(EventType)
    for f in EventFunction:
        assert (f.event_type is None) != (f.termination is None), f
    assert {f.termination for f in EventFunction} - {None} <= set(Termination)
    assert {f for f in EventFunction if f.has_slope} == {GAP, B, CP, CM}


def test_the_processing_order_is_one_table_for_the_stepper_and_the_monitor():
    """B < D < C < A (paper order of Sec. 5.3 processing), every type once; terminations after
    them; the tracker sorts the events of one tick by the same ranks.
    """
    assert PROCESSING_ORDER == (EventType.B, EventType.D, EventType.C, EventType.A)
    assert [processing_rank(t) for t in PROCESSING_ORDER] == [0, 1, 2, 3]
    assert processing_rank(None) == 4 == EventKey(EventFunction.STRAIN).rank
    assert EventKey(CP, 3).rank == EventKey(CM, 3).rank == processing_rank("C")
    found = [("A", 0.1), ("C", 0.3), ("B", 0.2), ("D", 0.0), ("A", -0.1)]
    found.sort(key=lambda e: (processing_rank(e[0]), e[1]))
    assert [k for k, _ in found] == ["B", "D", "C", "A", "A"]


def test_keys_are_values_and_the_fresh_form_drops_the_finger():
    gap = EventKey.gap(12, 1)
    assert gap == EventKey(GAP, 12, 1) and hash(gap) == hash(EventKey(GAP, 12, 1))
    assert gap.at_node == EventKey(GAP, 12) != gap
    assert EventKey(B, 12).at_node == EventKey(B, 12)
    assert sorted([EventKey(CM, 2), EventKey(B, 7), EventKey(CP, 2)]) == [
        EventKey(B, 7), EventKey(CP, 2), EventKey(CM, 2)]
    assert CP.slip == 1 and CM.slip == -1 and B.slip == 0
    assert EventFunction.cone_edge(1) == CP and EventFunction.cone_edge(-1) == CM


def test_an_initial_state_names_its_fresh_functions_by_key():
    tips = [place_fingertip(square()[0].mesh, n, c, 0.02) for n, c in zip(("F1", "F2"),
                                                                         square()[1])]
    state = initial_state(tips)
    assert {k.function for k in state.fresh} == {B, CP, CM}
    assert {k.node for k in state.fresh} == set(square()[1])
    assert all(k == k.at_node for k in state.fresh)


# ---------------------------------------------------------------------------- real contact sets
@functools.lru_cache(maxsize=None)
def square(nodes: int = 400) -> tuple[ElasticObject, tuple[int, int]]:
    outline = shapes.rectangle(0.1, 0.1)
    obj = ElasticObject(generate_mesh(outline, target_max_area(outline, nodes)),
                        Material(5e4, 0.3, 0.0254)).precompute()
    b, pts = obj.mesh.boundary, obj.mesh.nodes[obj.mesh.boundary]
    return obj, tuple(int(b[np.argmin(np.linalg.norm(pts - p, axis=1))])
                      for p in ([-0.05, 0.0], [0.05, 0.0]))


def squeezed(mu: float, relative: float = 0.04) -> tuple[ContactModel, ContactState, dict]:
    """The 400-node square squeezed stably to ``relative`` (several contacts per finger)."""
    obj, contacts = square()
    model = ContactModel(obj, mu)
    u = plan_squeeze(obj, list(contacts)).displacement.reshape(2, 2)
    tips = [place_fingertip(obj.mesh, n, c, 0.02) for n, c in zip(("F1", "F2"), contacts)]
    depth = relative * 0.1 / np.sqrt(2)
    r = advance(model, initial_state(tips), {"F1": depth * u[0], "F2": depth * u[1]})
    return model, r.state, {"F1": u[0], "F2": u[1]}


def units(model: ContactModel, state: ContactState, translations: dict):
    motion = FingerMotion.of(state, translations, model.length)
    solver = SetSolver(model, motion, Counters())
    return motion, ContactSet.of_state(model, state), solver, EventFunctions(
        model, motion, (Termination.FINGER_SLIP,))


def test_a_contact_set_is_sorted_and_changes_by_new_values():
    model, state, _ = squeezed(0.4)
    c = ContactSet.of_state(model, state)
    assert list(c.nodes) == sorted(c.nodes) and len(c) == len(state.contacts) >= 4
    for x in state.contacts:
        k = c.index(x.node)
        assert c.nodes[k] == x.node and c.finger_of(x.node) == ("F1", "F2").index(x.finger)
        assert c.theta[k] == x.theta
    slid = c.with_mode(1, False, -1)
    assert not slid.stick[1] and slid.slip[1] == -1 and c.stick[1] and c.slip[1] == 0
    assert slid.data is c.data
    smaller = c.without(model, 0)
    assert list(smaller.nodes) == list(c.nodes[1:]) and list(smaller.theta) == list(c.theta[1:])
    free = next(int(n) for n in model.boundary_nodes if n not in set(c.nodes.tolist()))
    grown = smaller.added(model, [free], [1], [0.5])
    k = grown.index(free)
    assert grown.stick[k] and grown.slip[k] == 0 and grown.finger[k] == 1
    assert grown.theta[k] == 0.5 and list(grown.nodes) == sorted(grown.nodes)
    assert np.array_equal(grown.rows, model.obj.boundary_positions(grown.nodes))


def test_a_finger_slips_when_all_its_contacts_slide_one_way():
    c = synthetic_set([(True, 0), (False, 1), (False, 1), (False, -1)], fingers=[0, 0, 1, 1])
    masks = tuple(c.finger == f for f in range(3))  # a third finger without contacts
    assert c.sliding_finger(c.slip, masks) is None
    both = c.with_mode(0, False, 1)
    assert both.sliding_finger(both.slip, masks) == 0
    assert c.with_mode(3, False, 1).sliding_finger(np.array([0, 1, 1, 1]), masks) == 1
    assert c.with_mode(1, True, 0).sliding_finger(c.slip * 0, masks) is None
    dtheta = np.array([1e-12, 2.0, 3.0, -1.0])
    assert list(c.slip_signs(dtheta, frictionless=True)) == [0, 1, 1, -1]


def test_gap_slopes_are_the_derivative_of_the_gaps():
    """Moving points against moving round tips: the slopes equal central differences."""
    rng = np.random.default_rng(3)
    motion = FingerMotion(("F1", "F2", "A"), rng.normal(size=(3, 2)), rng.normal(size=(3, 2)),
                          np.array([0.2, 0.3, 0.1]), 1.0, 0.0, 1.0)
    p0, v = rng.normal(size=(5, 2)), rng.normal(size=(5, 2))
    s, h = 0.37, 1e-6
    fd = (motion.gaps(p0 + (s + h) * v, s + h) - motion.gaps(p0 + (s - h) * v, s - h)) / (2 * h)
    assert np.allclose(motion.gap_slopes(p0 + s * v, v, s), fd, rtol=1e-7, atol=1e-8)


def test_a_new_contact_angle_is_taken_next_to_its_segment():
    motion = FingerMotion(("F1",), np.zeros((1, 2)), np.zeros((1, 2)), np.ones(1), 0.0, 0.0, 1.0)
    behind = np.array([np.cos(3.2), np.sin(3.2)])  # atan2 gives 3.2 - 2 pi
    assert motion.touch_angle(behind, 0, 0.0, None) == pytest.approx(3.2 - 2 * np.pi)
    assert motion.touch_angle(behind, 0, 0.0, 3.0) == pytest.approx(3.2)


@pytest.mark.parametrize("mu", [0.05, 0.4])
def test_event_function_slopes_are_their_derivatives_along_the_motion(mu):
    """Within a fixed set the gaps, normal forces and cone margins change along s at the rate
    EventFunctions.slopes gives: central differences of solutions at s +- h agree. The single
    key evaluation used by root location agrees with the table used for detection.
    """
    model, state, dirs = squeezed(mu)
    motion, contacts, solver, functions = units(
        model, state, {k: 1e-3 * v for k, v in dirs.items()})
    rows = functions.free_rows(contacts, [])
    s, h = 0.5, 1e-5
    sol = solver.solve(contacts, s)
    lo, hi = (solver.continue_to(contacts, sol, s, s + d) for d in (-h, h))
    table = [dict(functions.entries(contacts, functions.values(contacts, x, s + d, rows), rows,
                                    np.zeros(len(contacts), bool)))
             for x, d in ((sol, 0.0), (lo, -h), (hi, h))]
    slopes = functions.slopes(contacts, sol, s, rows)
    sloped = [k for k in table[0] if k in slopes]
    present = {k.function for k in sloped}
    assert {GAP, B} <= present and (CP in present) == bool(contacts.stick.any())
    scale = max(abs(slopes[k]) for k in sloped)
    for key in sloped:
        fd = (table[2][key] - table[1][key]) / (2 * h)
        assert abs(fd - slopes[key]) < 1e-5 * scale, key
    for key in sloped[:: max(1, len(sloped) // 40)] + [k for k in table[0] if k not in slopes]:
        assert functions.value(key, contacts, sol, s) == pytest.approx(table[0][key], abs=1e-14)
        if key in slopes:
            assert functions.slope(key, contacts, sol, s) == pytest.approx(slopes[key],
                                                                           rel=1e-12, abs=1e-14)


# ---------------------------------------------------------------------------- mode decision
def synthetic_set(modes, fingers=None) -> ContactSet:
    """A contact set of len(modes) nodes (2, 4, ...) without model data."""
    m = len(modes)
    return ContactSet(np.arange(2, 2 * m + 2, 2), np.asarray(fingers or [0] * m),
                      np.array([st for st, _ in modes], bool), np.array([sl for _, sl in modes]),
                      np.zeros(m), None, None, None)


def toy_solution(contacts: ContactSet, rates, mu: float) -> Solution:
    """Zero forces at polar angle 0 (so f_n = F_x, f_t = F_y) with force rates that depend on
    each node's hypothesis: sticking, the rate (a, b) of its finger's push; sliding with
    direction s, a normal rate a, a tangential rate on the cone edge, and a slip rate of the
    sign of -b (the tangential push drives the node the other way round the tip).
    """
    m = len(contacts)
    dF, dtheta = np.zeros((m, 2)), np.zeros(m)
    for k, (a, b) in enumerate(rates(contacts)):
        if contacts.stick[k]:
            dF[k] = (a, b)
        else:
            dF[k] = (a, -contacts.slip[k] * mu * a)
            dtheta[k] = -np.sign(b)
    z = np.zeros((m, 2))
    return Solution(np.zeros(m), z, z, dtheta, dF, z, 1, 0.0, 1.0)


def fresh_zero(contacts: ContactSet) -> set:
    return {EventKey(f, int(n)) for n in contacts.nodes for f in (B, CP, CM)}


def expected_mode(a: float, b: float, mu: float) -> tuple[bool, int]:
    """The paper's rule (Algorithm 1 line 13) for a force rate (a, b) at a fresh contact:
    stick inside the cone, else slide the way the tangential push drives the node.
    """
    if abs(b) < mu * a:
        return True, 0
    return False, int(-np.sign(b))


@given(st.lists(st.tuples(st.floats(0.05, 5.0), st.floats(-5.0, 5.0)), min_size=1, max_size=5),
       st.floats(0.0, 1.5))
def test_the_mode_decision_follows_the_cone_rule(rates, mu):
    """Fresh contacts pushed with force rates (a > 0, b): each sticks if |b| < mu a, else
    slides against its tangential push; jointly for up to three, node by node beyond, with
    no violated condition.
    """
    assume(all(abs(abs(b) - mu * a) > 1e-9 for a, b in rates))  # the edge: see the next test
    contacts = synthetic_set([(True, 0)] * len(rates))
    calls = []

    def attempt(c):
        calls.append(1)
        return toy_solution(c, lambda _: rates, mu)

    choice = decide_modes(contacts, list(contacts.nodes), fresh_zero(contacts), attempt, mu=mu)
    want = [expected_mode(a, b, mu) if mu > 0 else (False, 0) for a, b in rates]
    assert [(bool(x), int(y)) for x, y in zip(choice.stick, choice.slip)] == want
    assert choice.violations == 0
    if len(rates) > 3 and mu > 0:
        assert len(calls) <= 2 * 3 * len(rates) + 1 < 3 ** len(rates)


def test_stick_wins_when_several_hypotheses_are_consistent():
    """A push inside the cone for which the toy solver makes slip +1 consistent as well: the
    first consistent hypothesis in the order stick, slip +1, slip -1 is taken.
    """
    contacts = synthetic_set([(True, 0)])
    rates = [(1.0, -0.1)]
    slide = toy_solution(contacts.with_mode(0, False, 1), lambda _: rates, 0.5)
    assert slide.dtheta[0] > 0 and slide.dF[0, 0] > 0  # consistent too
    choice = decide_modes(contacts, [2], fresh_zero(contacts),
                          lambda c: toy_solution(c, lambda _: rates, 0.5), mu=0.5)
    assert choice.stick[0] and choice.violations == 0


def test_nodes_that_constrain_each_other_are_decided_jointly():
    """Node 2 can stick only while node 4 slides +1, and node 4 slides +1 only while node 2
    sticks; node 4 sticking is never consistent. Trying node 2 first on its own would keep it
    sticking with node 4 sticking; the joint search finds (stick, slip +1).
    """
    def rates(c):
        node4_slides = not c.stick[1] and c.slip[1] == 1
        return [(1.0, 0.0 if node4_slides else 5.0), (1.0, -5.0 if c.stick[0] else 5.0)]

    contacts = synthetic_set([(True, 0), (True, 0)])
    choice = decide_modes(contacts, [2, 4], fresh_zero(contacts),
                          lambda c: toy_solution(c, rates, 0.5), mu=0.5)
    assert list(choice.stick) == [True, False] and list(choice.slip) == [0, 1]
    assert choice.violations == 0


def test_without_a_consistent_hypothesis_the_fewest_violations_win():
    """A contact pulled away (a < 0): every hypothesis violates the normal force; sliding
    against the tangential push violates nothing else, sticking also a cone margin.
    """
    contacts = synthetic_set([(True, 0)])
    choice = decide_modes(contacts, [2], fresh_zero(contacts),
                          lambda c: toy_solution(c, lambda _: [(-1.0, 0.3)], 0.5), mu=0.5)
    assert (bool(choice.stick[0]), int(choice.slip[0])) == (False, -1)
    assert choice.violations == 1


def test_only_the_undecided_nodes_change_mode():
    contacts = synthetic_set([(False, -1), (True, 0), (False, 1)])
    choice = decide_modes(contacts, [4], fresh_zero(contacts),
                          lambda c: toy_solution(c, lambda _: [(1.0, 0.0)] * 3, 0.5), mu=0.5)
    assert list(choice.stick) == [False, True, False] and list(choice.slip) == [-1, 0, 1]


def test_no_solvable_hypothesis_is_an_error_of_the_right_kind():
    contacts = synthetic_set([(True, 0)])
    with pytest.raises(NumericalError, match="no contact mode of nodes"):
        decide_modes(contacts, [2], set(), lambda c: SolveFailure("x", 0.5), mu=0.5)
    with pytest.raises(InvalidInputError, match="fix the object"):
        decide_modes(contacts, [2], set(),
                     lambda c: SolveFailure("does not fix the object", indeterminate=True),
                     mu=0.5)


def test_zero_functions_are_the_fresh_ones_and_the_slip_side_cone():
    contacts = synthetic_set([(False, 1), (True, 0), (False, -1)])
    fresh = {EventKey(B, 4)}
    assert zero_functions(contacts, fresh) == {EventKey(B, 4), EventKey(CP, 2), EventKey(CM, 6)}
    assert mode_violations(mu=0.5, fn=0.0, ft=0.0, fn_rate=1.0, ft_rate=0.2, dtheta=0.0,
                           stick=True, slip=0, frictionless=False, zero={B, CP, CM}) == 0



def test_a_zero_function_must_grow_faster_than_the_noise_floor():
    """A rate of round-off size (the slide of a rigidly sliding object leaves the normal-force
    rate an exact zero) is not growth; above the floor it is.
    """
    args = dict(mu=0.5, fn=0.0, ft=0.0, ft_rate=0.0, dtheta=-0.5, stick=False, slip=-1,
                frictionless=False, zero={B})
    assert mode_violations(fn_rate=1e-15, **args) == 0
    assert mode_violations(fn_rate=1e-15, rate_floor=1e-12, **args) == 1
    assert mode_violations(fn_rate=-1e-15, rate_floor=1e-12, **args) == 1
    assert mode_violations(fn_rate=1e-6, rate_floor=1e-12, **args) == 0

def test_decided_modes_hold_one_step_further_along_the_motion():
    """Decide the modes of every contact for fingers that push at an angle to the squeeze
    line (the initial contacts of the square, zero force: a two-force body, so they stick; and
    the square squeezed at mu = 0.05, where some slide), then solve those modes a little
    further along the motion: the sticking contacts press with forces inside the cone, the
    sliding ones press on the cone edge and move the way they were assumed to.
    """
    obj, nodes = square()
    tips = [place_fingertip(obj.mesh, n, c, 0.02) for n, c in zip(("F1", "F2"), nodes)]
    cases = [(ContactModel(obj, mu), initial_state(tips)) for mu in (0.05, 0.4, 1.0)]
    cases.append(squeezed(0.05)[:2])
    seen = set()
    for model, state in cases:
        for tilt in (0.0, 0.5, 1.0):
            d = 1e-3 * np.array([np.cos(tilt), np.sin(tilt)])
            _, contacts, solver, _ = units(model, state, {"F1": d, "F2": -d})
            choice = decide_modes(contacts, list(contacts.nodes),
                                  zero_functions(contacts, set(state.fresh)),
                                  lambda c: solver.attempt(c, 0.0), mu=model.mu)
            assert choice.violations == 0
            decided = contacts.with_modes(choice.stick, choice.slip).with_theta(choice.theta)
            later = solver.solve(decided, 0.05)
            fn, ft = later.normal, later.tangential
            for k in range(len(decided)):
                assert fn[k] > 0
                if decided.stick[k]:
                    assert abs(ft[k]) < model.mu * fn[k]
                else:
                    assert decided.slip[k] * later.dtheta[k] > 0
                    assert abs(ft[k]) == pytest.approx(model.mu * fn[k], rel=1e-8)
            seen |= {bool(x) for x in decided.stick}
    assert seen == {True, False}


def counted(solver: SetSolver, taken: list):
    """The compiled mode search of ``solver`` at s = 0, noting in ``taken`` whether it chose."""
    def search(*args, **options):
        chosen = solver.decide(*args, s=0.0, **options)
        taken.append(chosen is not None)
        return chosen
    return search


def test_the_compiled_mode_search_is_the_python_one():
    """On the numba route the linear model's mode search is one compiled call
    (:meth:`SetSolver.decide`): for the square's contacts, with friction and without, pushed
    at an angle, jointly (up to three nodes, every pair of the first four) and node by node
    (all of them), it chooses the modes, angles and violations the search in Python does
    from the same solves, and counts those solves the same way.
    """
    pytest.importorskip("numba")
    obj, nodes = square()
    tips = [place_fingertip(obj.mesh, n, c, 0.02) for n, c in zip(("F1", "F2"), nodes)]
    cases = [(ContactModel(obj, mu), initial_state(tips)) for mu in (0.0, 0.4)]
    cases += [squeezed(0.05)[:2], squeezed(0.4)[:2]]
    by_node, taken = 0, []
    for model, state in cases:
        for tilt in (0.0, 0.5, 1.0):
            d = 1e-3 * np.array([np.cos(tilt), np.sin(tilt)])
            motion, contacts, _, _ = units(model, state, {"F1": d, "F2": -d})
            zero = zero_functions(contacts, set(state.fresh))
            first = range(min(4, len(contacts)))
            picks = [list(contacts.nodes)] + [
                list(contacts.nodes[[i, j]]) for i in first for j in first if i < j]
            for pick in picks:
                results = []
                for compiled in (False, True):
                    solver = SetSolver(model, motion, Counters(), Kernel.NUMBA)
                    choice = decide_modes(contacts, pick, zero, lambda c: solver.attempt(c, 0.0),
                                          mu=model.mu, rate_floor=1e-12,
                                          search=counted(solver, taken) if compiled else None)
                    results.append((choice.stick.tolist(), choice.slip.tolist(),
                                    choice.theta.tobytes(), choice.violations,
                                    solver.counters.as_dict()))
                assert results[0] == results[1]
                by_node += len(pick) > 3
    assert by_node > 0 and all(taken)


# ---------------------------------------------------------------------------- root location
def analytic(roots: dict, curvature: dict):
    """g_k(s) = (r_k - s)(1 + c_k s) (one root r_k in [0, 1] for c_k > -1) and its slope,
    as callables of (key, s) that count their calls per key.
    """
    calls: dict = {}

    def value(key, s):
        calls[key] = calls.get(key, 0) + 1
        return (roots[key] - s) * (1 + curvature[key] * s)

    def slope(key, s):
        return -(1 + curvature[key] * s) + (roots[key] - s) * curvature[key]

    return value, slope, calls


def order(key):
    return key.rank, key.finger, key.node


@given(st.lists(st.tuples(st.floats(0.01, 0.99), st.floats(-0.9, 3.0), st.booleans()),
                min_size=1, max_size=6),
       st.sampled_from([1e-9, 1e-6, 1e-3]))
def test_the_earliest_bracket_ends_within_the_tolerance_past_the_first_root(spec, tol):
    """Crossed functions with known roots in [0, 1], with or without slopes: the event point
    lies in [first root, first root + tol]. With slopes the estimates are exact (a quadratic
    is its own Hermite interpolant), so the functions are taken in the order of their roots and
    every one whose root is more than tol later costs one evaluation (at the start of the
    earliest bracket), not a location of its own.
    """
    keys = [EventKey.gap(10 + k, 0) if sloped else EventKey(D, 10 + k)
            for k, (_, _, sloped) in enumerate(spec)]
    roots = {key: r for key, (r, _, _) in zip(keys, spec)}
    curv = {key: c for key, (_, c, _) in zip(keys, spec)}
    value, slope, calls = analytic(roots, curv)
    start = {k: value(k, 0.0) for k in keys}
    end = {k: value(k, 1.0) for k in keys}
    calls.clear()
    slopes_a = {k: slope(k, 0.0) for k in keys if k.function.has_slope}
    slopes_b = {k: slope(k, 1.0) for k in keys if k.function.has_slope}
    s_e, evaluations = earliest_crossing(
        keys, 0.0, 1.0, tol, start=start, end=end, start_slopes=slopes_a, end_slopes=slopes_b,
        fresh=set(), value=value, slope=slope, order=order)
    first = min(roots.values())
    assert first <= s_e <= first + tol * (1 + 1e-9)
    if all(sloped for _, _, sloped in spec):
        late = [k for k in keys if roots[k] > first + 2 * tol]
        assert all(calls.get(k, 0) <= 1 for k in late)
    assert evaluations <= sum(calls.values())


def test_slopes_save_evaluations_over_regula_falsi():
    roots = {EventKey.gap(1, 0): 0.3, EventKey(D, 1): 0.3}
    curv = dict.fromkeys(roots, 2.0)
    counts = []
    for key in roots:
        value, slope, _ = analytic(roots, curv)
        sloped = key.function.has_slope
        _, n = earliest_crossing(
            [key], 0.0, 1.0, 1e-9, start={key: value(key, 0.0)}, end={key: value(key, 1.0)},
            start_slopes={key: slope(key, 0.0)} if sloped else {},
            end_slopes={key: slope(key, 1.0)} if sloped else {}, fresh=set(), value=value,
            slope=slope, order=order)
        counts.append(n)
    assert counts[0] < counts[1]


def test_a_fresh_function_falling_at_the_start_is_an_event_one_tolerance_in():
    """A function zero by construction at a (a new contact's cone margin) whose slope is
    negative crosses at once: located at a + tol with one evaluation.
    """
    key = EventKey(CP, 5)
    value, slope, _ = analytic({key: 0.0}, {key: 0.0})
    s_e, n = earliest_crossing(
        [key], 0.2, 0.6, 1e-6, start={key: 0.0}, end={key: value(key, 0.6)},
        start_slopes={key: -1.0}, end_slopes={key: -1.0}, fresh={key}, value=value,
        slope=slope, order=order)
    assert s_e == pytest.approx(0.2 + 1e-6, abs=1e-15) and n == 1


def test_crossings_and_dips():
    a, b = 0.0, 1.0
    down, fresh, stays, graze = (EventKey(B, 1), EventKey(CP, 2), EventKey(B, 3),
                                 EventKey.gap(4, 0))
    start = {down: 1.0, fresh: 0.0, stays: 1.0, graze: 1.0}
    end = {down: -1.0, fresh: -1.0, stays: 2.0, graze: 1.0}
    assert crossings(start, end, set()) == [down]
    assert crossings(start, end, {fresh}) == [down, fresh]
    assert crossings(start, {**end, EventKey(B, 9): -1.0}, set()) == [down]
    slopes_a, slopes_b = {graze: -6.0, stays: 1.0}, {graze: 6.0, stays: 1.0}
    assert dips_inside(a, b, start, end, slopes_a, slopes_b, set())
    assert not dips_inside(a, b, start, end, slopes_a, slopes_b, {graze.at_node})
    assert not dips_inside(a, b, start, end, {stays: 1.0}, {stays: 1.0}, set())


def test_crossings_of_watched_arrays_are_those_of_their_mappings():
    """A substep's two WatchedValues (one key order) are compared as arrays; the result is that
    of the same values as dicts, fresh keys, terminations and a NaN at the end included, and
    values of another key order are compared by key.
    """
    keys = (EventKey(B, 1), EventKey(CP, 2), EventKey(B, 3), EventKey.gap(4, 0),
            EventKey.gap(4, 1), EventKey(B, 5))
    order = KeyOrder(keys)
    area, pickup = (EventKey(function) for function in (EventFunction.AREA,
                                                        EventFunction.PICKUP))
    start = WatchedValues(order, np.array([1.0, 0.0, 1.0, 1.0, 0.0, 2.0]),
                          {area: 0.5, pickup: 1.0})
    end = WatchedValues(order, np.array([-1.0, -1.0, 2.0, 0.0, -3.0, np.nan]),
                        {area: -0.1, pickup: 2.0})
    assert dict(start) == dict(zip(keys, start.values)) | start.ends and len(end) == 8
    for fresh in (set(), {keys[1]}, {keys[4].at_node}):
        expected = crossings(dict(start), dict(end), fresh)
        assert crossings(start, end, fresh) == expected
    assert crossings(start, end, set()) == [keys[0], keys[3], keys[5], area]
    other = WatchedValues(KeyOrder(keys[::-1]), end.values[::-1].copy(), end.ends)
    assert crossings(start, other, set()) == crossings(dict(start), dict(other), set())


def test_dips_of_watched_arrays_are_those_of_their_mappings():
    """A substep's two WatchedValues are read as arrays at the sloped keys: whether a Hermite
    interpolant dips inside is that of the same values as dicts, for grazing and steady
    functions, a function not positive at an end, fresh nodes, and a sloped key of another order.
    """
    keys = (EventKey(B, 1), EventKey(CP, 1), EventKey.gap(4, 0), EventKey.gap(4, 1),
            EventKey.gap(6, 0), EventKey(B, 7))
    order = KeyOrder(keys)
    start = WatchedValues(order, np.array([1.0, 1.0, 1.0, 1.0, -0.5, 1.0]), {})
    end = WatchedValues(order, np.array([1.0, 2.0, 1.0, 1.0, 1.0, 1.0]), {})
    a, b = 0.0, 1.0
    cases = [({keys[0]: 1.0, keys[2]: -6.0, keys[4]: -9.0}, {keys[0]: 1.0, keys[2]: 6.0,
                                                              keys[4]: 9.0}),
             ({keys[1]: 0.1, keys[3]: -1.0}, {keys[1]: 0.1, keys[3]: 1.0}),
             ({keys[5]: -7.0, keys[3]: -6.0}, {keys[5]: 7.0})]
    seen = set()
    for slopes_a, slopes_b in cases:
        for fresh in (set(), {4}, {7}):
            expected = dips_inside(a, b, dict(start), dict(end), slopes_a, slopes_b, fresh)
            assert dips_inside(a, b, start, end, slopes_a, slopes_b, fresh) == expected
            seen.add(expected)
    assert seen == {True, False}
    stray = EventKey.gap(9, 0)
    assert dips_inside(a, b, start, end, {stray: -6.0}, {stray: 6.0}, set()) is False


# ---------------------------------------------------------------------------- substeps
def linear_path(F0, dF, s):
    z = np.zeros((len(F0), 2))
    return Solution(np.zeros(len(F0)), z, F0 + s * dF, np.zeros(len(F0)), dF, z, 1, 0.0, 1.0)


def test_adaptive_substeps_grow_on_a_straight_force_path_up_to_the_cap():
    grid = 0.01
    control = SubstepControl(grid, True, grid)
    F0, dF = np.ones((2, 2)), np.full((2, 2), 0.5)
    a, lengths = 0.0, []
    for _ in range(6):
        b = control.end(a)
        control.accept(linear_path(F0, dF, a), linear_path(F0, dF, b), a, b, {}, {}, True)
        lengths.append(b - a)
        a = b
    assert lengths == pytest.approx([grid, 2 * grid, 4 * grid, 4 * grid, 4 * grid, 4 * grid])
    assert control.h == pytest.approx(ADAPTIVE_MAX_STEPS * grid)


def test_adaptive_substeps_shrink_for_curvature_sliding_and_a_near_termination():
    grid = 0.01
    control = SubstepControl(grid, True, 4 * grid)
    assert control.h == pytest.approx(4 * grid)
    bent = linear_path(np.ones((1, 2)), np.full((1, 2), 5.0), 0.04)
    control.accept(linear_path(np.ones((1, 2)), np.zeros((1, 2)), 0.0), bent, 0.0, 0.04, {}, {},
                   True)
    assert control.h == pytest.approx(2 * grid)  # halved: the slope changed as much as F
    control.accept(bent, bent, 0.0, 0.02, {}, {}, False)
    assert control.h == grid  # a contact slides
    area = EventKey(EventFunction.AREA)
    control = SubstepControl(grid, True, 4 * grid)
    flat = linear_path(np.ones((1, 2)), np.zeros((1, 2)), 0.0)
    control.accept(flat, flat, 0.0, 0.04, {area: 1.0}, {area: 0.5}, True)
    assert control.h == pytest.approx(0.02)  # half the distance to zero at the last rate
    control.reject(0.0, 0.012)
    assert control.h == grid


def test_the_grid_does_not_adapt():
    control = SubstepControl(0.01, False, 0.04)
    flat = linear_path(np.ones((1, 2)), np.zeros((1, 2)), 0.0)
    control.accept(flat, flat, 0.0, 0.01, {}, {}, True)
    assert control.h == 0.01 and control.end(0.995) == 1.0
    assert not control.may_reject(0.0, 0.01)


# ---------------------------------------------------------------------------- chattering bound
def test_the_chattering_bound_freezes_a_node_for_one_window():
    bound = ChatterBound(ContactState((), ()), window=1.0, max_events=2)
    assert bound.admit(5, "F1", 0.0) and bound.admit(5, "F1", 0.1) and bound.admit(6, "F2", 0.1)
    assert not bound.admit(5, "F1", 0.2)
    assert [(c.node, c.finger, c.depth, c.until) for c in bound.chatter] == [(5, "F1", 0.2, 1.2)]
    assert list(bound.held(np.array([5, 6]), 1.1)) == [True, False]
    assert bound.held_nodes(1.1) == [5] and bound.held_nodes(1.3) == []
    assert bound.state_holds(0.5) == ((5, 1.2),) and bound.state_holds(1.2) == ()
    assert bound.admit(5, "F1", 1.15)  # its events at 0 and 0.1 left the window
    carried = ChatterBound(ContactState((), (), history=((7, 0.0),), holds=((7, 0.5),)), 1.0, 1)
    assert carried.held_nodes(0.2) == [7] and not carried.admit(7, "A", 0.2)


@given(st.lists(st.tuples(st.floats(0.01, 0.99), st.floats(-0.9, 3.0), st.booleans()),
                min_size=1, max_size=6),
       st.sampled_from([1e-9, 1e-6]))
def test_skipping_the_sure_evaluations_gives_the_same_event_point(spec, tol):
    """With ``skip_sure`` (a model whose evaluations are dear) the event point is the one
    the evaluating route finds, bit for bit, with no more location evaluations; a crossing
    with slopes located alone costs one fewer (a quadratic is its own Hermite interpolant, so
    the first point lands a quarter tolerance past the root and the evaluating route closes
    the bracket from below, at a point whose sign is sure).
    """
    keys = [EventKey.gap(10 + k, 0) if sloped else EventKey(D, 10 + k)
            for k, (_, _, sloped) in enumerate(spec)]
    roots = {key: r for key, (r, _, _) in zip(keys, spec)}
    curv = {key: c for key, (_, c, _) in zip(keys, spec)}
    runs = []
    for skip_sure in (False, True):
        value, slope, _ = analytic(roots, curv)
        s_e, evaluations = earliest_crossing(
            keys, 0.0, 1.0, tol, start={k: value(k, 0.0) for k in keys},
            end={k: value(k, 1.0) for k in keys},
            start_slopes={k: slope(k, 0.0) for k in keys if k.function.has_slope},
            end_slopes={k: slope(k, 1.0) for k in keys if k.function.has_slope},
            fresh=set(), value=value, slope=slope, order=order, skip_sure=skip_sure)
        runs.append((s_e, evaluations))
    (s_every, n_every), (s_sure, n_sure) = runs
    assert s_sure == s_every
    assert n_sure <= n_every
    if len(keys) == 1 and keys[0].function.has_slope:
        assert n_sure == n_every - 1
