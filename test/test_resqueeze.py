# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The re-squeeze after a slip (docs/grippers.md, "Release and re-squeeze"): the simulated
world's release of an ended squeeze and its fresh squeeze from rest, the executor's program
closed around the world and the monitor's joint slip watch, and the slip scene through the
JointTrajectory route on real rclpy, recorded and replayed.
"""
from __future__ import annotations

import re

import numpy as np
import pytest
import yaml
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from squeeze_grasp_interfaces.msg import ContactEventArray, ExecutorStatus, MonitorStatus
from squeeze_grasp_ros.control.joint_feedback import JointSlipWatch
from squeeze_grasp_ros.control.motion import (
    GraspGoal,
    GraspProgram,
    MotionLimits,
    Observation,
    goal_problem,
)
from squeeze_grasp_ros.control.tracker import ContactTracker, FingerSample, TrackerConfig
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.ros.recording.bag import read_bag
from squeeze_grasp_ros.ros.recording.replay import replay
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner
from squeeze_grasp_ros.scene import GraspSetup, load_scene, parse_scene
from squeeze_grasp_ros.sim.world import RELEASED, SimWorld

SLIP = scene_file("sponge_gripper_slip")
WINDOW, RATIO, CONTACT_FORCE = 1e-4, 0.5, 0.002
"""The monitor's joint slip watch defaults (config/monitor.yaml)."""


@pytest.fixture(scope="module")
def setup():
    return GraspSetup.build(load_scene(SLIP))


# --------------------------------------------------------------------------- release


def jaw_setpoints(world, s: float) -> dict:
    """Both jaws of ``world`` at squeeze parameter ``s`` (m) from their placements."""
    return {t.name: np.asarray(t.center, float) + s * np.asarray(world.directions[t.name])
            for t in world.placements}


def test_an_ended_world_releases_the_object_and_squeezes_it_again_from_rest():
    """The slip scene's jaws close until a jaw slips (the world ends and freezes), open back
    past their first-contact positions (the object relaxes to rest: no contacts, zero forces
    and wrench, zero displacement, the rest outline), then close again: the second squeeze
    from rest equals a fresh world's squeeze tick by tick (forces, events, depth).
    """
    data = yaml.safe_load(scene_file("sponge_gripper_slip").read_text())
    data["effects"] = ["friction", "force_sensing"]
    setup = GraspSetup.build(parse_scene(data))
    world = SimWorld(setup)
    step = 1e-5
    out, k = world.start(), 0
    while out.termination is None:
        k += 1
        out = world.step(jaw_setpoints(world, k * step))
    assert out.termination == "finger_slip" and k < 400
    slipped = k
    frozen = out.state
    releases = []
    while k > -200:  # 2 mm behind the placements
        k -= 1
        out = world.step(jaw_setpoints(world, k * step))
        if k >= 0:  # a jaw still reaches the object at rest: frozen, as before a release
            assert out.state is frozen and out.termination == "finger_slip"
            assert not out.released
        releases += [k] if out.released else []
        if k < 0:
            assert out.termination is None and out.state.contacts == ()
            for reading in out.readings:
                assert np.array_equal(reading.force, np.zeros(3))
                assert np.array_equal(reading.torque, np.zeros(3))
    assert releases == [-1]  # the first tick behind the first-contact positions
    assert world.work["releases"] == 1
    assert np.array_equal(world.displacement_field(), np.zeros_like(setup.solid.mesh.nodes))
    view = world.view()
    assert view.contacts == () and np.array_equal(view.outline, world.rest_outline)
    for name, center, _ in view.tips:
        assert np.array_equal(center, jaw_setpoints(world, k * step)[name])
    # close again through the placements and on, beside a fresh world given the same setpoints
    while k < 0:
        k += 1
        out = world.step(jaw_setpoints(world, k * step))
    assert not world.released and world.work["fresh_squeezes"] == 1
    fresh = SimWorld(setup)
    fresh.start()
    events, fresh_events = [], []
    for k in range(1, int(0.75 * slipped) + 1):
        out, want = world.step(jaw_setpoints(world, k * step)), fresh.step(
            jaw_setpoints(fresh, k * step))
        events += out.events
        fresh_events += want.events
        for name in ("F1", "F2"):
            assert np.array_equal(out.state.finger_force(name), want.state.finger_force(name))
        assert out.state.depth == want.state.depth and out.termination is None
    assert [(e.type, e.node, e.finger) for e in events] == [
        (e.type, e.node, e.finger) for e in fresh_events]
    assert np.linalg.norm(out.state.finger_force("F1")) > 0.5  # N: squeezed, not touching


# --------------------------------------------------------------------------- the program


def jaw_loop(world: SimWorld, goal: GraspGoal, limits: MotionLimits = MotionLimits()) -> dict:
    """The program closed around ``world`` and a joint slip watch fed as the monitor feeds it
    (the aperture between the jaws, the jaw force along the closing line; here from the ground
    truth), ROS-free, until the goal ends.
    """
    program = GraspProgram(goal, limits, world.fingers)
    depth = ContactTracker(TrackerConfig(mu=world.scene.mu), world.fingers, streams=())
    watch = JointSlipWatch(("F1", "F2"), contact_force=CONTACT_FORCE, window=WINDOW,
                           ratio=RATIO)
    closing = np.asarray(world.directions["F1"], float)
    closing /= np.linalg.norm(closing)
    out = world.start()
    trace, depths = [], []
    while True:
        positions = {r.finger: r.position for r in out.readings}
        tracked = depth.update(out.stamp_ns, {f: FingerSample(p) for f, p in positions.items()})
        force = float(out.state.finger_force("F1") @ closing)
        alarms = watch.update(float(np.linalg.norm(positions["F2"] - positions["F1"])), force)
        forces = {f: out.state.finger_force(f) for f in world.fingers}
        obs = Observation(
            out.stamp_ns, positions, forces, {f: np.zeros(2) for f in world.fingers},
            tuple((a.type, a.finger) for a in alarms), (), tracked.depth)
        command = program.step(obs, world.dt)
        trace.append((out, command, tracked.depth, alarms))
        depths.append(program.depth(obs))
        out = world.step(command.setpoints)
        if command.termination is not None:
            return {"program": program, "trace": trace, "last": out, "depths": depths}


def slip_goal(world: SimWorld, **reaction) -> GraspGoal:
    depth = world.scene.squeeze.relative_depth / world.relative_per_depth
    return GraspGoal(("F1", "F2"), np.array([world.directions["F1"], world.directions["F2"]]),
                     depth, world.relative_per_depth, **reaction)


def test_the_program_releases_and_squeezes_again_below_the_alarm_depth(setup):
    """After the slip alarm the jaws open to 2 mm past first contact at the speed limit, wait
    for the watch's contact_lost on both, and squeeze again from rest to 0.75 of the alarm's
    measured depth: held, and the world's second squeeze is a fresh squeeze to that depth.
    """
    world = SimWorld(setup)
    run = jaw_loop(world, slip_goal(world, on_slip_alarm="resqueeze"))
    program, trace, last = run["program"], run["trace"], run["last"]
    states = [command.state for _, command, _, _ in trace]
    first_alarm = next(k for k, (_, _, _, alarms) in enumerate(trace)
                       if any(a.type == "slip_imminent" for a in alarms))
    alarm_depth = trace[first_alarm][2]
    ended = next(k for k, (out, _, _, _) in enumerate(trace) if out.termination)
    released = [k for k, (out, _, _, _) in enumerate(trace) if out.released]
    print(f"world slip at tick {ended} ({trace[ended][0].state.depth * 1e3:.4f} mm), alarm at "
          f"tick {first_alarm} ({alarm_depth * 1e3:.4f} mm), released at tick {released}, "
          f"{program.attempts} squeezes, last planned {program.planned_depth * 1e3:.4f} mm, "
          f"{len(trace)} ticks")
    assert trace[ended][0].termination == "finger_slip" and ended < first_alarm
    assert states[first_alarm] == "releasing" and states[first_alarm - 1] == "squeezing"
    assert trace[-1][1].termination == "depth_reached" and program.attempts == 2
    assert len(released) == 1 and last.termination is None
    assert program.planned_depth == pytest.approx(0.75 * alarm_depth, rel=1e-12)
    # the release positions: first contact moved back 2 mm along each jaw's closing direction
    start = {r.finger: r.position for r in trace[0][0].readings}
    widest = {f: max(np.linalg.norm(command.setpoints[f] - start[f])
                     for out, command, _, _ in trace[first_alarm:]
                     if command.state == "releasing") for f in ("F1", "F2")}
    assert widest == pytest.approx({"F1": 0.002, "F2": 0.002}, rel=1e-12)
    # no setpoint step beyond the speed limit, across the reversals too
    steps = [np.linalg.norm(b[1].setpoints[f] - a[1].setpoints[f])
             for a, b in zip(trace, trace[1:]) for f in ("F1", "F2")]
    assert max(steps) <= MotionLimits().max_velocity * world.dt * (1 + 1e-9)
    # the depth the executor reports (feedback, status, result) is the squeeze under way's:
    # negative while the jaws stand open past first contact, the planned depth at the end
    opened = min(d for d, (_, command, _, _) in zip(run["depths"], trace)
                 if command.state == "releasing")
    assert opened == pytest.approx(-0.002 * np.sqrt(2), abs=2 * MotionLimits().position_tolerance)
    assert run["depths"][-1] == pytest.approx(program.planned_depth, rel=1e-6)
    # the last squeeze is a fresh one from rest: the mechanics API's squeeze to that depth
    assert last.state.depth == pytest.approx(program.planned_depth, rel=1e-9)
    direct = setup.event_squeeze(depth=last.state.depth)
    after = [e for out, _, _, _ in trace[released[0]:] for e in out.events] + list(last.events)
    assert [(e.type, e.node, e.finger) for e in after] == [
        (e.type, e.node, e.finger) for e in direct.events]
    for name in ("F1", "F2"):
        got, want = last.state.finger_force(name), direct.state.finger_force(name)
        assert np.linalg.norm(got - want) <= 1e-3 * np.linalg.norm(want)


def test_a_second_slip_ends_the_goal_and_one_attempt_is_hold(setup):
    """A margin too small to stay below the slip slips again: the goal ends slip_alarm after
    its two squeezes; max_attempts 1 holds at the first alarm, as "hold" does.
    """
    world = SimWorld(setup)
    run = jaw_loop(world, slip_goal(world, on_slip_alarm="resqueeze", resqueeze_margin=0.001))
    assert run["trace"][-1][1].termination == "slip_alarm" and run["program"].attempts == 2
    assert sum(out.released for out, _, _, _ in run["trace"]) == 1
    assert run["last"].termination == "finger_slip"
    once = jaw_loop(SimWorld(setup), slip_goal(world, on_slip_alarm="resqueeze", max_attempts=1))
    hold = jaw_loop(SimWorld(setup), slip_goal(world))
    assert once["program"].attempts == hold["program"].attempts == 1
    assert len(once["trace"]) == len(hold["trace"])
    for (_, a, _, _), (_, b, _, _) in zip(once["trace"], hold["trace"]):
        assert all(np.array_equal(a.setpoints[f], b.setpoints[f]) for f in ("F1", "F2"))
    assert once["trace"][-1][1].termination == "slip_alarm"


@pytest.mark.parametrize("field, value, why", [
    ("max_attempts", 0, "max_attempts must be >= 1"),
    ("resqueeze_margin", 1.0, r"resqueeze_margin must be in \(0, 1\)"),
    ("resqueeze_margin", float("nan"), r"resqueeze_margin must be in \(0, 1\)"),
    ("release_clearance", -1e-3, r"release_clearance must be in \(0, 10\] m"),
    ("release_clearance", float("inf"), r"release_clearance must be in \(0, 10\] m"),
    ("release_clearance", 1e308, r"release_clearance must be in \(0, 10\] m, got 1e\+308"),
])
def test_invalid_resqueeze_fields_are_named(field, value, why):
    goal = GraspGoal(("F1", "F2"), np.array([[0.0, 1.0], [0.0, -1.0]]) / np.sqrt(2), 1e-3,
                     on_slip_alarm="resqueeze", **{field: value})
    problem = goal_problem(goal, ["F1", "F2"])
    assert problem is not None and re.match(why, problem), problem


# --------------------------------------------------------------------------- on real rclpy


def test_the_slip_scene_resqueezes_to_a_held_grasp_on_the_joint_trajectory_route(tmp_path):
    """The slip scene through the JointTrajectoryController, watched on joint_states alone, with
    ``on_slip_alarm: resqueeze``: the alarm, the release (the trajectories open the jaws to
    first contact + 2 x 2 mm, joint_states follow, the world releases the object, the monitor
    reports contact_lost) and the second squeeze, to 0.75 of the alarm's depth, are in the
    recording and the summary; the grasp is held, the world's last squeeze is the mechanics
    API's fresh squeeze to that depth, and ``replay`` reproduces the monitor's alarms.
    """
    bag = tmp_path / "bag"
    run = PipelineRunner(RunOptions(str(SLIP), planner=False, on_slip_alarm="resqueeze",
                                    record=str(bag))).run()
    print(f"{run['outcome']}: {run['termination']} after {run['ticks']} ticks, "
          f"{run['attempts']} squeezes, last planned {run['planned_depth'] * 1e3:.4f} mm; "
          f"releases {run['world_releases']}; alarms {run['alarms']}")
    assert run["outcome"] == "grasp held" and run["success"]
    assert run["termination"] == "depth_reached" and run["world_termination"] == "none"
    assert run["attempts"] == 2 and run["resqueezed"] and not run["redirected"]
    [release] = run["world_releases"]
    assert release["after"]["termination"] == "finger_slip" and run["world_end"] is None
    assert run["alarms"]["contact_lost"] == 2 and run["alarms"]["slip_imminent"] >= 2
    assert run["planned_depth"] < release["after"]["depth"]
    assert run["measured_depth"] == pytest.approx(run["planned_depth"], rel=1e-9)
    assert run["depth"] == pytest.approx(run["planned_depth"], rel=1e-9)
    setup = GraspSetup.build(load_scene(SLIP))
    direct = setup.event_squeeze(depth=run["depth"])
    for name in ("F1", "F2"):
        got, want = np.array(run["forces"][name]), direct.state.finger_force(name)
        assert np.linalg.norm(got - want) <= 1e-3 * np.linalg.norm(want)
    after = [e for e in run["events"] if e["stamp_ns"] > release["stamp_ns"]]
    assert [(e["type"], e["node"], e["finger"]) for e in after] == [
        (str(e.type), e.node, e.finger) for e in direct.events]

    contents = read_bag(bag)

    def recorded(topic, kind):
        return [deserialize_message(m.data, kind) for m in contents.messages
                if m.topic.endswith(topic)]

    states = [s.state for s in recorded("/executor/status", ExecutorStatus)]
    assert states == ["squeezing", "releasing", "squeezing", "idle"]
    released = [m for m in recorded("/sim/events", ContactEventArray)
                if m.termination == RELEASED]
    assert len(released) == 1
    joints = recorded("/joint_states", JointState)
    commanded = recorded("/joint_trajectory", JointTrajectory)
    # in joint units, signed so that closing is positive: closes, opens past first contact,
    # closes again (three monotone legs), and the joint states follow
    target = np.array([sum(t.points[0].positions) for t in commanded])
    closing = np.sign(target[1] - target[0])
    target = closing * target
    measured = closing * np.array([sum(j.position) for j in joints])
    moves = np.diff(target)[np.diff(target) != 0]
    assert np.count_nonzero(np.diff(np.sign(moves))) == 2 and target.min() < measured[0]
    assert measured.min() == pytest.approx(target.min(), rel=1e-9)
    alarms = [a for s in recorded("/monitor/status", MonitorStatus) for a in s.alarms]
    replayed = replay(str(bag))
    assert replayed["ticks"] == run["ticks"] + 1
    assert replayed["alarms"] == len(alarms) >= 4
