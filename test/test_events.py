# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event-driven squeeze (Sec. 5): physical invariants at every event, the one-shot invariant by
an independent sparse solve, convergence in the tolerance, symmetry and path independence.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from contact_support import check_state

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import (
    generate_mesh,
    mesh_from_triangles,
    target_max_area,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, Event, initial_state
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.fingertips import place_fingertip
from squeeze_grasp_ros.mechanics.squeeze.oneshot import one_shot_solve
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze
from squeeze_grasp_ros.mechanics.squeeze.stepper import advance
from squeeze_grasp_ros.mechanics.vocabulary import EventType, Finger

FOAM = Material(5e4, 0.3, 0.0254)
RADIUS = 0.02


@functools.lru_cache(maxsize=None)
def foam_square(nodes: int = 2000) -> tuple[ElasticObject, tuple[int, int]]:
    """The Sec. 5.5 square and the boundary nodes nearest (-0.05, 0) and (0.05, 0)."""
    outline = shapes.rectangle(0.1, 0.1)
    obj = ElasticObject(generate_mesh(outline, target_max_area(outline, nodes)), FOAM).precompute()
    b = obj.mesh.boundary
    pts = obj.mesh.nodes[b]
    ends = tuple(
        int(b[np.argmin(np.linalg.norm(pts - p, axis=1))]) for p in ([-0.05, 0], [0.05, 0])
    )
    return obj, ends


@functools.lru_cache(maxsize=None)
def symmetric_square(cells: int = 16) -> tuple[ElasticObject, tuple[int, int]]:
    """A structured square mesh symmetric about both axes (each cell split at its centre)."""
    h = 0.1 / cells
    g = np.linspace(-0.05, 0.05, cells + 1)
    X, Y = np.meshgrid(g, g, indexing="ij")
    corners = np.column_stack([X.ravel(), Y.ravel()])
    cx, cy = np.meshgrid(g[:-1] + h / 2, g[:-1] + h / 2, indexing="ij")
    centres = np.column_stack([cx.ravel(), cy.ravel()])
    nodes = np.vstack([corners, centres])
    tris = []
    for i in range(cells):
        for j in range(cells):
            a, b = i * (cells + 1) + j, (i + 1) * (cells + 1) + j
            c = len(corners) + i * cells + j
            for p, q in ((a, b), (b, b + 1), (b + 1, a + 1), (a + 1, a)):
                tris.append((p, q, c))
    mesh = mesh_from_triangles(nodes, np.array(tris))
    obj = ElasticObject(mesh, FOAM).precompute()
    mid = cells // 2
    return obj, (mid, cells * (cells + 1) + mid)


def squeeze_directions(obj, contacts) -> dict:
    u = plan_squeeze(obj, list(contacts)).displacement.reshape(2, 2)
    return {"F1": u[0], "F2": u[1]}


def start(obj, contacts, rel_per_depth: float = 0.0) -> ContactState:
    tips = [place_fingertip(obj.mesh, n, c, RADIUS) for n, c in zip(("F1", "F2"), contacts)]
    return initial_state(tips, rel_per_depth)


def walk(model: ContactModel, state: ContactState, dirs: dict, depth: float, **kw):
    """States after every event point of a squeeze to ``depth`` (Algorithm 1, one call per
    event).
    """
    out, done = [], 0.0
    while done < depth * (1 - 1e-12):
        r = advance(
            model,
            state,
            {k: (depth - done) * v for k, v in dirs.items()},
            stop_on_event=True,
            **kw,
        )
        done += r.state.depth - state.depth
        state = r.state
        out.append((r, state))
        if r.termination:
            break
    return out


@pytest.mark.parametrize("mu", [0.4, 0.05])
def test_invariants_hold_at_every_event(mu):
    obj, contacts = foam_square()
    model = ContactModel(obj, mu)
    dirs = squeeze_directions(obj, contacts)
    states = walk(model, start(obj, contacts), dirs, 0.0085)
    events = [e for r, _ in states for e in r.events]
    assert len(events) >= 12 and {e.type for e in events} >= {EventType.A}
    if mu < 0.1:
        assert {EventType.C, EventType.D} <= {e.type for e in events}
    for _, state in states:
        check_state(model, state)
    sizes = {f: len(states[-1][1].segment(f)) for f in ("F1", "F2")}
    assert min(sizes.values()) >= 4


@pytest.mark.parametrize("mu", [0.4, 0.05])
def test_one_shot_invariant_by_independent_sparse_solve(mu):
    obj, contacts = foam_square()
    res = event_squeeze(obj, contacts, RADIUS, mu, relative_depth=0.12)
    assert any(c.mode == "slip" for c in res.state.contacts) == (mu < 0.1)
    shot = one_shot_solve(obj, res.state, mu)
    F = np.array([c.force for c in res.state.contacts])
    theta = np.array([c.theta for c in res.state.contacts])
    sliding = any(c.mode == "slip" for c in res.state.contacts)
    assert shot.iterations >= (2 if sliding else 1)  # sliding angles start perturbed
    assert np.abs(shot.forces - F).max() < 1e-9 * np.abs(F).max()
    assert np.abs(shot.theta - theta).max() < 1e-10
    assert (
        np.abs(shot.displacement - res.displacement).max() < 1e-9 * np.abs(res.displacement).max()
    )


def test_events_converge_as_the_tolerance_shrinks():
    obj, contacts = foam_square()
    runs = {
        tol: event_squeeze(obj, contacts, RADIUS, 0.05, relative_depth=0.12, event_tol=tol)
        for tol in (1e-3, 1e-5, 1e-7, 1e-9)
    }
    fine = runs[1e-9]
    fine_events = [(e.type, e.node) for e in fine.events]
    F_fine = np.array([c.force for c in fine.state.contacts])
    errors = {}
    for tol in (1e-5, 1e-7):
        r = runs[tol]
        assert [(e.type, e.node) for e in r.events] == fine_events
        depth_err = max(abs(a.depth - b.depth) for a, b in zip(r.events, fine.events))
        assert depth_err <= 2 * tol * obj.scale
        F = np.array([c.force for c in r.state.contacts])
        errors[tol] = np.abs(F - F_fine).max()
    assert errors[1e-7] < errors[1e-5] or errors[1e-5] < 1e-12 * np.abs(F_fine).max()
    assert errors[1e-7] < 1e-4 * np.abs(F_fine).max()


def test_results_do_not_depend_on_the_step_beyond_the_tolerance():
    obj, contacts = foam_square()
    a = event_squeeze(obj, contacts, RADIUS, 0.05, relative_depth=0.12, step=1e-3)
    b = event_squeeze(obj, contacts, RADIUS, 0.05, relative_depth=0.12, step=2.7e-4)
    assert [(e.type, e.node) for e in a.events] == [(e.type, e.node) for e in b.events]
    assert max(abs(x.depth - y.depth) for x, y in zip(a.events, b.events)) < 3e-9 * obj.scale
    Fa = np.array([c.force for c in a.state.contacts])
    Fb = np.array([c.force for c in b.state.contacts])
    assert np.abs(Fa - Fb).max() < 1e-6 * np.abs(Fa).max()


@pytest.mark.parametrize("mu", [0.4, 0.05])
def test_symmetric_scene_gives_symmetric_results(mu):
    obj, contacts = symmetric_square()
    mesh = obj.mesh
    res = event_squeeze(obj, contacts, RADIUS, mu, relative_depth=0.12)
    assert res.event_counts["A"] >= 4

    def mirror(node, axis):
        p = mesh.nodes[node] * (np.array([-1, 1]) if axis == 0 else np.array([1, -1]))
        return int(np.argmin(np.linalg.norm(mesh.nodes - p, axis=1)))

    forces = {c.node: c for c in res.state.contacts}
    scale = max(np.abs(c.force).max() for c in res.state.contacts)
    for c in res.state.contacts:
        lr = forces[mirror(c.node, 0)]  # F1 <-> F2: x -> -x
        ud = forces[mirror(c.node, 1)]  # within a segment: y -> -y
        assert lr.mode == c.mode and ud.mode == c.mode
        assert np.allclose(lr.force, c.force * [-1, 1], atol=1e-8 * scale)
        assert np.allclose(ud.force, c.force * [1, -1], atol=1e-8 * scale)
        assert ud.slip == -c.slip and lr.slip == -c.slip
    by_node = {}
    for e in res.events:
        by_node.setdefault((e.type, e.node), e.depth)
    for (kind, node), depth in by_node.items():
        for axis in (0, 1):
            assert abs(by_node[(kind, mirror(node, axis))] - depth) < 1e-8 * obj.scale
    assert res.work["F1"] == pytest.approx(res.work["F2"], rel=1e-8)


def test_path_with_direction_changes_equals_one_step_when_no_event_occurs():
    obj, contacts = foam_square()
    model = ContactModel(obj, 0.05)
    dirs = squeeze_directions(obj, contacts)
    state = walk(model, start(obj, contacts), dirs, 0.004)[-1][1]
    sliding = [c for c in state.contacts if c.mode == "slip"]
    assert sliding, "the test needs sliding nodes to be meaningful"
    total = {k: 2e-5 * v for k, v in dirs.items()}
    one = advance(model, state, total)
    kink = np.array([0.0, 4e-6])
    pieces = [
        {"F1": 0.3 * total["F1"] + kink, "F2": 0.5 * total["F2"]},
        {"F1": 0.2 * total["F1"] - 2 * kink, "F2": 0.5 * total["F2"] + kink},
        {"F1": 0.5 * total["F1"] + kink, "F2": -kink},
    ]
    s = state
    for piece in pieces:
        r = advance(model, s, piece)
        assert not r.events
        s = r.state
    assert not one.events
    for a, b in zip(one.state.contacts, s.contacts):
        assert a.node == b.node and a.mode == b.mode
        assert np.allclose(a.force, b.force, rtol=0, atol=1e-12 * np.abs(a.force).max())
        assert a.theta == pytest.approx(b.theta, abs=1e-13)


def test_reference_mode_reproduces_the_located_events():
    obj, contacts = foam_square(800)
    fast = event_squeeze(obj, contacts, RADIUS, 0.05, relative_depth=0.12)
    ref = event_squeeze(
        obj, contacts, RADIUS, 0.05, relative_depth=0.12, step=1e-4, reference=True
    )
    assert [(e.type, e.node) for e in ref.events] == [(e.type, e.node) for e in fast.events]
    for e_ref, e_fast in zip(ref.events, fast.events):
        assert 0 <= e_ref.depth - e_fast.depth <= 2e-4 * obj.scale
    Ff = np.array([c.force for c in fast.state.contacts])
    Fr = np.array([c.force for c in ref.state.contacts])
    assert np.abs(Ff - Fr).max() < 1e-2 * np.abs(Ff).max()


def test_all_stick_work_equals_strain_energy_and_slip_dissipates():
    obj, contacts = foam_square()
    stuck = event_squeeze(obj, contacts, RADIUS, 1.0, relative_depth=0.12)
    assert all(c.mode == "stick" for c in stuck.state.contacts)
    assert sum(stuck.work.values()) == pytest.approx(stuck.energy, rel=1e-6)
    slippery = event_squeeze(obj, contacts, RADIUS, 0.05, relative_depth=0.12)
    lost = sum(slippery.dissipation.values())
    assert lost > 0.0
    assert sum(slippery.work.values()) == pytest.approx(slippery.energy + lost, rel=1e-6)
    assert sum(stuck.dissipation.values()) == 0.0


def test_non_force_closure_placement_slips_at_once():
    obj, contacts = foam_square()
    tilt = abs(np.diff(obj.mesh.nodes[list(contacts), 1])[0]) / 0.1
    res = event_squeeze(obj, contacts, RADIUS, 0.5 * tilt, relative_depth=0.12)
    assert res.termination == "finger_slip" and res.depth == 0.0


def test_chattering_bound_freezes_modes_and_terminates(kernel):
    """On both routes: a hold expiring while the free rows stay the same once made the
    compiled substeps write past their values (an abort) on the numba route. The bound counts
    every event but the C of a frozen node that sticks and reaches its cone.
    """
    obj, contacts = foam_square()
    free = event_squeeze(obj, contacts, RADIUS, 0.05, relative_depth=0.12)
    capped = event_squeeze(
        obj, contacts, RADIUS, 0.05, relative_depth=0.12, max_events_per_depth=1, step=0.02
    )
    assert capped.termination == "depth_reached"
    assert capped.chatter and len(capped.events) <= len(free.events)
    window = 0.02 * obj.scale
    def frozen(x) -> bool:
        return x.type == EventType.C and any(c.node == x.node and c.depth <= x.depth < c.until
                                     for c in capped.chatter)

    for e in capped.events:
        same = [x for x in capped.events if x.node == e.node and 0 <= e.depth - x.depth < window
                and not frozen(x)]
        assert len(same) <= 1


def test_three_fingers_and_arbitrary_translations():
    obj, contacts = foam_square(800)
    mesh = obj.mesh
    b = mesh.boundary
    top = int(b[np.argmin(np.linalg.norm(mesh.nodes[b] - [0.0, 0.05], axis=1))])
    tips = [
        place_fingertip(mesh, n, c, RADIUS) for n, c in zip(("F1", "F2", "A"), (*contacts, top))
    ]
    model = ContactModel(obj, 0.8)
    state = initial_state(tips)
    r = advance(model, state, {"F1": (0.002, 0.0), "F2": (-0.002, 0.0), "A": (0.0, -0.0016)})
    assert r.termination is None and r.fraction == 1.0
    assert {e.finger for e in r.events} == {"F1", "F2", "A"}
    check_state(model, r.state)
    r2 = advance(model, r.state, {"A": (0.0003, -0.0002)})
    assert r2.fraction == 1.0
    assert r2.state.finger("F1").translation == pytest.approx([0.002, 0.0])
    assert r2.state.finger("A").translation == pytest.approx([0.0003, -0.0018])
    check_state(model, r2.state)


# ---------------------------------------------------------------- substeps and event location
def test_a_linear_call_stays_on_the_grid_and_the_first_substep_is_checked():
    from squeeze_grasp_ros.mechanics.errors import InvalidInputError

    obj, contacts = symmetric_square()
    model = ContactModel(obj, 0.4)
    dirs = {k: 0.002 * v for k, v in squeeze_directions(obj, contacts).items()}
    result = advance(model, start(obj, contacts), dirs, step=2e-3)
    assert result.next_substep == 2e-3 and result.diagnostics["substep_rejections"] == 0
    for bad in (0.0, -1e-3, float("nan")):
        with pytest.raises(InvalidInputError, match="first_substep must be finite and > 0"):
            advance(model, start(obj, contacts), dirs, first_substep=bad)


def test_an_events_fields_have_one_type_whatever_the_route_computed_them_with():
    """NumPy scalars given to an Event become the Python types its fields declare, so that the
    numpy and the numba routes' events repr and compare alike (a D event's depth was a
    numpy.float64 on the numpy route).
    """
    given = Event("D", np.int64(7), "F2", np.float64(0.0125), np.float64(0.125), "stick",
                  np.int64(-1))
    plain = Event("D", 7, "F2", 0.0125, 0.125, "stick", -1)
    assert [type(getattr(given, f)) for f in ("node", "depth", "relative_depth", "slip")] == [
        int, float, float, int]
    assert repr(given) == repr(plain) and given == plain
    assert (given.type, given.finger) == (EventType.D, Finger.F2)


@pytest.mark.parametrize("args, overrides, message", [
    ((0.02, 0.4), {"material_model": "rubber"},
     r"material_model must be one of linear, corotational, neo_hookean, got 'rubber'"),
    (({"F1": 0.02}, 0.4), {}, r"tip gives no fingertip for F2"),
    ((0.02, 0.4), {"relative_depth": -0.1}, r"relative depth must be in \[0, 1\).*got -0.1"),
], ids=["material_model", "tip_mapping", "relative_depth"])
def test_bad_arguments_of_event_squeeze_name_the_argument(args, overrides, message):
    """Each used to escape as ValueError, KeyError, or an error about ``depth`` in metres."""
    from squeeze_grasp_ros.mechanics.errors import InvalidInputError

    obj, contacts = symmetric_square()
    kwargs = {"relative_depth": 0.02, **overrides}
    with pytest.raises(InvalidInputError, match=message):
        event_squeeze(obj, contacts, *args, **kwargs)


@pytest.mark.parametrize("count", [1, 3])
def test_event_squeeze_takes_exactly_two_contacts(count):
    """A third node used to be dropped silently (and one node squeezed F1 alone)."""
    from squeeze_grasp_ros.mechanics.errors import InvalidInputError

    obj, contacts = symmetric_square()
    nodes = (tuple(contacts) + (int(obj.mesh.boundary[3]),))[:count]
    with pytest.raises(InvalidInputError, match=f"contacts must be 2 nodes .F1, F2., got {count}"):
        event_squeeze(obj, nodes, 0.02, 0.4, relative_depth=0.02)


def test_a_node_index_that_is_no_whole_number_is_refused():
    """``j + 0.5`` used to be truncated to node j (another placement, silently); NaN escaped
    as ValueError.
    """
    from squeeze_grasp_ros.mechanics.errors import InvalidInputError

    obj, (i, j) = symmetric_square()
    for bad in (j + 0.5, float("nan")):
        with pytest.raises(InvalidInputError, match="contacts must be whole node indices"):
            plan_squeeze(obj, [i, bad])
        with pytest.raises(InvalidInputError, match="contacts must be whole node indices"):
            event_squeeze(obj, (i, bad), 0.02, 0.4, relative_depth=0.02)
    assert plan_squeeze(obj, [float(i), float(j)]).contacts.tolist() == [i, j]


@pytest.mark.parametrize("directions, message", [
    ({"F1": (float("nan"), 0.0), "F2": (1.0, 0.0)}, "squeeze directions must be finite"),
    ({"F1": (1.0, 0.0)}, "squeeze directions give none for F2"),
    ({"F1": (1.0, 0.0, 0.0), "F2": (-1.0, 0.0, 0.0)}, r"one \[x, y\] per finger, got shape"),
], ids=["nan", "missing", "three_components"])
def test_bad_squeeze_directions_are_refused_by_name(directions, message):
    """NaN was reported as 'must not all be zero', a missing finger escaped as KeyError."""
    from squeeze_grasp_ros.mechanics.errors import InvalidInputError

    obj, contacts = symmetric_square()
    with pytest.raises(InvalidInputError, match=message):
        event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.02, directions=directions)
