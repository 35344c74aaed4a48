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
    print(f"foam square: {quiet.stepper.calls}; stepper s quiet {quiet.stepper_seconds:.3f}, "
          f"advance {full.stepper_seconds:.3f}")
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


def test_area_watch_answers_as_the_full_area_check():
    """AreaWatch's answer equals ``area_ratio(...)[0] > level`` along a squeeze, at levels
    around the smallest area ratio (so both answers occur), while it renews its reference.
    """
    world = SimWorld(GraspSetup.build(load_scene(scene_file("foam_square"))), quiet=False)
    watch, model = AreaWatch(world.model), world.model
    answers = set()
    for tick in squeeze_world(world, 200)[1:]:
        contacts = tick.state.contacts
        sd = model.set_data(tuple(c.node for c in contacts))
        delta = np.array([c.displacement for c in contacts]) / model.length
        F = np.array([c.force for c in contacts]) / model.force_unit
        ratio = model.area_ratio(sd, delta, F)[0]
        for level in (INVERSION_AREA_RATIO + 1e-12, ratio - 1e-9, ratio + 1e-9):
            expected = ratio > level
            assert watch.above(sd, delta, F, level) == expected, (tick.index, level)
            answers.add(expected)
    assert answers == {True, False} and watch.renewals >= 2


def test_area_watch_skips_only_where_the_full_check_agrees():
    """At one level, called tick after tick: AreaWatch answers most ticks from its bound on
    the motion since its last True answer, and still answers as ``area_ratio`` at every tick,
    also across the tick where the smallest area ratio passes the level (chosen in the middle
    of the squeeze's range, so both answers occur).
    """
    world = SimWorld(GraspSetup.build(load_scene(scene_file("foam_square"))), quiet=False)
    model, ticks = world.model, squeeze_world(world, 300)[1:]
    configurations, ratios = [], []
    for tick in ticks:
        contacts = tick.state.contacts
        sd = model.set_data(tuple(c.node for c in contacts))
        delta = np.array([c.displacement for c in contacts]) / model.length
        F = np.array([c.force for c in contacts]) / model.force_unit
        configurations.append((sd, delta, F))
        ratios.append(model.area_ratio(sd, delta, F)[0])
    skips = {}
    for level in (INVERSION_AREA_RATIO + 1e-12, 0.5 * (max(ratios) + min(ratios))):
        watch = AreaWatch(model)
        answers = [watch.above(*c, level) for c in configurations]
        assert answers == [r > level for r in ratios], level
        skips[level] = watch.skips
    print(f"AreaWatch skips of {len(ticks)} ticks per level: {skips}")
    assert answers.count(False) > 0 and answers.count(True) > 0
    assert min(skips.values()) > 0 and max(skips.values()) > len(ticks) // 2


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
        theirs = advance(world.model, state, translations, stepper.step, stepper.event_tol,
                         terminate_on=stepper.terminate_on)
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
