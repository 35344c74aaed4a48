# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated world's quiet ticks (stepper/quiet.py) against every tick through advance().

A quiet tick must give the state advance() gives: the same events at the same ticks, and the
same forces, displacements, angles, work and sensor readings bit for bit (the same functions on
the same arrays). Each case drives one world with quiet ticks and one without along the same
squeeze, tick by tick.
"""
from __future__ import annotations

import numpy as np
import pytest
import yaml

from squeeze_grasp_ros.bench.pipeline import squeeze_world
from squeeze_grasp_ros.mechanics.squeeze.contact_model import INVERSION_AREA_RATIO
from squeeze_grasp_ros.mechanics.squeeze.stepper import area_watch
from squeeze_grasp_ros.mechanics.squeeze.stepper.area_watch import AreaWatch
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.scene import GraspSetup, load_scene, parse_scene
from squeeze_grasp_ros.sim.world import SimWorld


def _worlds(scene, ticks: int):
    """(quiet world, its outputs, reference world, its outputs) of one scene."""
    out = []
    for quiet in (True, False):
        world = SimWorld(GraspSetup.build(scene), quiet=quiet)
        out += [world, squeeze_world(world, ticks)]
    return out


def _assert_same_ticks(quiet_out, full_out) -> None:
    """Events (kind, node, finger) at the same ticks, terminations, and every number of the
    state and the readings equal.
    """
    assert len(quiet_out) == len(full_out)
    for a, b in zip(quiet_out, full_out):
        assert [(e.type, e.node, e.finger) for e in a.events] == [
            (e.type, e.node, e.finger) for e in b.events], a.index
        assert [e.depth for e in a.events] == [e.depth for e in b.events], a.index
        assert a.termination == b.termination, a.index
        sa, sb = a.state, b.state
        assert (sa.depth, sa.fresh, sa.undetermined, sa.history, sa.holds) == (
            sb.depth, sb.fresh, sb.undetermined, sb.history, sb.holds), a.index
        for ca, cb in zip(sa.contacts, sb.contacts, strict=True):
            assert (ca.node, ca.finger, ca.mode, ca.slip, ca.theta) == (
                cb.node, cb.finger, cb.mode, cb.slip, cb.theta), a.index
            assert np.array_equal(ca.force, cb.force) and np.array_equal(
                ca.displacement, cb.displacement), (a.index, ca.node)
        for fa, fb in zip(sa.fingers, sb.fingers, strict=True):
            assert (fa.work, fa.dissipation) == (fb.work, fb.dissipation), a.index
            assert np.array_equal(fa.center, fb.center), a.index
        for ra, rb in zip(a.readings, b.readings, strict=True):
            for name in ("position", "force", "torque", "normal", "tangential"):
                x, y = getattr(ra, name), getattr(rb, name)
                assert (x is None) == (y is None) and (x is None or np.array_equal(x, y))


def test_foam_square_quiet_ticks_are_advance_bit_for_bit():
    """Sec. 5.5's foam square, mu = 0.4: all but the event ticks are quiet, nothing differs."""
    quiet, q, full, f = _worlds(load_scene(scene_file("foam_square")), 700)
    assert sum(len(t.events) for t in q) == 12
    assert quiet.stepper.calls["quiet"] >= 600 and full.stepper.calls["quiet"] == 0
    # most quiet ticks end within the reach of the last evaluation of the watched functions
    assert quiet.stepper.evaluations < quiet.stepper.calls["quiet"] // 4
    print(f"foam square: {quiet.stepper.calls}, {quiet.stepper.evaluations} evaluations; "
          f"stepper s quiet {quiet.stepper_seconds:.3f}, advance {full.stepper_seconds:.3f}")
    _assert_same_ticks(q, f)


@pytest.mark.parametrize("name, ticks", [
    ("foam_square_low_friction", 400),  # mu = 0.05: slides, C/D events; full calls
    ("foam_square_strain_limit", 400),  # a strain limit checked at every quiet tick
    ("foam_square_pickup", 400),        # a pickup margin checked at every quiet tick
    ("disk", 300),
])
def test_shipped_scenes_quiet_ticks_are_advance_bit_for_bit(name, ticks):
    quiet, q, _, f = _worlds(load_scene(scene_file(name)), ticks)
    print(f"{name}: {quiet.stepper.calls}, events {sum(len(t.events) for t in q)}, "
          f"termination {q[-1].termination}")
    _assert_same_ticks(q, f)


@pytest.mark.slow
@pytest.mark.parametrize("name, ticks", [("disk_finger_slip", 500), ("nonconvex_blob", 300)])
def test_more_shipped_scenes_quiet_ticks_are_advance_bit_for_bit(name, ticks):
    quiet, q, _, f = _worlds(load_scene(scene_file(name)), ticks)
    print(f"{name}: {quiet.stepper.calls}, termination {q[-1].termination}")
    _assert_same_ticks(q, f)


@pytest.mark.slow
@pytest.mark.parametrize("model", ["corotational", "neo_hookean"])
def test_nonlinear_worlds_take_every_tick_through_advance(model):
    """A finite-deformation material is not quiet (its forces are not a product with a fixed
    stiffness): every tick goes through advance(), as before.
    """
    data = yaml.safe_load(scene_file("foam_square").read_text())
    data["object"]["material"]["model"] = model
    data["object"]["mesh"]["nodes"] = 300
    scene = parse_scene(data)
    quiet, q, _, f = _worlds(scene, 150)
    assert quiet.stepper.calls["quiet"] == 0
    _assert_same_ticks(q, f)


def _configurations(ticks: int):
    """(model, [(set data, delta, F) per tick]) of the foam square's squeeze through advance()."""
    world = SimWorld(GraspSetup.build(load_scene(scene_file("foam_square"))), quiet=False)
    model, out = world.model, []
    for tick in squeeze_world(world, ticks)[1:]:
        contacts = tick.state.contacts
        sd = model.set_data(tuple(c.node for c in contacts))
        delta = np.array([c.displacement for c in contacts]) / model.length
        F = np.array([c.force for c in contacts]) / model.force_unit
        out.append((sd, delta, F))
    return model, out


def _smallest_det(model, sd, delta, F) -> float:
    """Every element's det(I + grad u) from the full displacement field (one sparse solve,
    not the bounds or the kept gradients AreaWatch uses): the smallest.
    """
    H = (model.obj.gradient @ model.full_displacement(sd, delta, F)).reshape(-1, 4)
    return float(((1.0 + H[:, 0]) * (1.0 + H[:, 3]) - H[:, 1] * H[:, 2]).min())


def _moved(model, a, b) -> float:
    """The bound on every element's gradient change from configuration a to b: sum_k
    max_e b_ek ||dF_k|| + max_e ||R_e|| ||dg|| (from the object's gradient bounds).
    """
    (sd, delta_a, F_a), (_, delta_b, F_b) = a, b
    column_max = model.obj.gradient_bounds(tuple(sd.nodes.tolist())).max(axis=0)
    R = model.obj.rigid_gradients.reshape(-1, 4, 3)
    dg = sd.E.T @ (delta_b - delta_a).reshape(-1)
    return float(column_max @ np.linalg.norm(F_b - F_a, axis=1)
                 + np.sqrt((R * R).sum(axis=(1, 2))).max() * np.linalg.norm(dg))


def test_area_reserve_holds_every_element_above_the_level_within_it(monkeypatch):
    """AreaWatch.reserve against the full field: at a level just under the configuration's
    smallest det F, every later configuration of the same set whose gradients moved by less
    than the reserve has every element above the level, the reach covers later ticks, and
    the squeeze passes the level beyond it (so the check can fail). At a level above the
    smallest det F the reserve is 0. Every element is kept (levels this high leave none to a
    bound: the foam square stays far from inversion); at the stepper's level the default
    candidates give a reserve at every tick.
    """
    model, configurations = _configurations(300)
    dets = [_smallest_det(model, *c) for c in configurations]
    monkeypatch.setattr(area_watch, "AREA_CANDIDATES", 10 ** 9)
    watch, covered, beyond = AreaWatch(model), 0, 0
    for i in range(0, len(configurations), 10):
        assert watch.reserve(*configurations[i], dets[i] + 1e-9) == 0.0, i
        for level in (dets[i] - 0.02, dets[i] - 0.1):
            reserve = watch.reserve(*configurations[i], level)
            assert reserve > 0.0, i
            for j in range(i + 1, len(configurations)):
                if configurations[j][0] is not configurations[i][0]:
                    break
                if _moved(model, configurations[i], configurations[j]) < reserve:
                    assert dets[j] > level, (i, j)
                    covered += 1
                elif dets[j] <= level:
                    beyond += 1
    print(f"area reserve: {covered} later ticks within a reach, {beyond} below its level "
          f"beyond it, {watch.renewals} renewals")
    assert covered > 20 and beyond > 0
    monkeypatch.undo()
    watch = AreaWatch(model)
    assert all(watch.reserve(*c, INVERSION_AREA_RATIO + 1e-12) > 0.0 for c in configurations)


def test_travel_rates_bound_the_gaps_change_and_margins_are_the_contact_functions():
    """Within one sticking mode of the quiet world, the free rows' gaps from the full
    displacement field (not the boundary compliance the rates are made from) move by at most
    their rate (stepper/travel.py) times the fingers' stacked translation; the mode's margins
    are the watched contacts' normal forces and cone margins (the contact functions a quiet
    tick checks at its end).
    """
    world = SimWorld(GraspSetup.build(load_scene(scene_file("foam_square"))))
    stepper, seen = world.stepper, []
    result = stepper._result

    def keep(mode, state, motion, ends):
        out = result(mode, state, motion, ends)
        seen.append((mode, ends[0][1], ends[1][1], ends[2][1]))
        return out

    stepper._result = keep
    squeeze_world(world, 300)
    model, checked = world.model, 0
    boundary = model.positions(model.boundary_nodes)
    for (mode, c0, d0, F0), (other, c1, d1, F1) in zip(seen, seen[1:]):
        if other is not mode:
            continue
        sd, rates, mu = mode.sticking.contacts.data, mode.rates, model.mu
        travel = np.linalg.norm(c1 - c0)
        gaps = []
        for c, delta, F in ((c0, d0, F0), (c1, d1, F1)):
            u = model.full_displacement(sd, delta, F).reshape(-1, 2)
            points = boundary[mode.rows] + u[model.boundary_nodes[mode.rows]]
            gaps.append(mode.tip.gaps(points, c))
        assert np.all(np.abs(gaps[1] - gaps[0]) <= rates.gaps * travel * (1 + 1e-9) + 1e-13)
        # no chattering hold on the foam square: every contact is watched
        fn, ft = (F1 * mode.sticking.unit).sum(axis=1), (F1 * mode.sticking.tangent).sum(axis=1)
        expected = np.concatenate([fn, mu * fn - ft, mu * fn + ft])
        assert np.allclose(mode.margins @ F1.reshape(-1), expected, rtol=1e-12, atol=1e-15)
        checked += 1
    assert checked > 200


def test_quiet_results_are_advance_results_field_by_field():
    """Beyond the state: a quiet call's samples (depths, nodes, angles, finger forces),
    diagnostics, fraction and next substep are those advance() returns for the same call.
    """
    from squeeze_grasp_ros.mechanics.squeeze.stepper import advance

    world = SimWorld(GraspSetup.build(load_scene(scene_file("foam_square"))), quiet=True)
    stepper, calls = world.stepper, []
    quiet = stepper._quiet

    def keep(state, translations):
        result = quiet(state, translations)
        if result is not None:
            calls.append((state, dict(translations), result))
        return result

    stepper._quiet = keep
    squeeze_world(world, 300)
    assert len(calls) > 250
    for state, translations, ours in calls[::10]:
        theirs = advance(world.model, state, translations, step=stepper.step,
                         event_tol=stepper.event_tol, terminate_on=stepper.terminate_on)
        assert (ours.events, ours.fraction, ours.termination, ours.chatter,
                ours.next_substep) == (theirs.events, theirs.fraction, theirs.termination,
                                       theirs.chatter, theirs.next_substep)
        # sets_factored and reduced_max_condition are the model's running totals (advance()
        # is called here after the whole run): the rest are the call's own counters
        model_totals = ("sets_factored", "reduced_max_condition")
        assert list(ours.diagnostics) == list(theirs.diagnostics)
        assert {k: v for k, v in ours.diagnostics.items() if k not in model_totals} == {
            k: v for k, v in theirs.diagnostics.items() if k not in model_totals}
        assert ours.samples == theirs.samples
