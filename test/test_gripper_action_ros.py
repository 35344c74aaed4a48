# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The gripper action routes on real rclpy (docs/grippers.md): the sponge gripper through a
simulated ParallelGripperController and GripperActionController against the
JointTrajectoryController route, a stall at a low effort, and a hostile action client.

They need control_msgs, which has no wheel: without it they skip, saying how to build it.
"""
from __future__ import annotations

import importlib.util
import math
import re
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from doc_transcripts import REPO, blocks
from mcap.reader import make_reader
from pipeline_support import run_observed, sim_and_client, write_scene

if importlib.util.find_spec("control_msgs") is None:
    pytest.skip("control_msgs is not built: squeeze-grasp ros-setup --control-msgs DIR (DIR a "
                "jazzy checkout of github.com/ros-controls/control_msgs)",
                allow_module_level=True)

from control_msgs.action import GripperCommand, ParallelGripperCommand  # noqa: E402
from rclpy.action import ActionClient  # noqa: E402
from rclpy.serialization import deserialize_message  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Header  # noqa: E402

from squeeze_grasp_ros.ros.nodes import pipeline  # noqa: E402
from squeeze_grasp_ros.scene import GraspSetup, load_scene  # noqa: E402

SPONGE = Path(__file__).resolve().parents[1] / "config" / "scenes" / "sponge_gripper.yaml"
TIGHT = {"goal_tolerance": 1e-7, "stall_timeout": 0.02}


def sponge(kind: str | None, **controller) -> dict:
    data = yaml.safe_load(SPONGE.read_text())
    if kind is not None:
        data["controller"] = {"type": kind, "name": "gripper_controller",
                              "device": "generic_85mm", **controller}
    data["name"] = f"sponge_{kind}"
    return data


def run(path: str, record: str | None = None) -> dict:
    """Run a sponge scene on real rclpy: result, ground-truth events (without their ticks: the
    routes close at different speeds) and forces, joint states.
    """
    out = run_observed(path, [("states", "joint_states", JointState)], record=record)
    out["events"] = [(kind, finger, node) for _, _, kind, finger, node in out["events"]]
    return out


@pytest.fixture(scope="module")
def jtc_route(tmp_path_factory):
    return run(str(SPONGE))


@pytest.mark.parametrize("kind", ["parallel_gripper", "gripper_action"])
def test_sponge_through_the_action_controller_equals_the_jtc_route(kind, jtc_route, tmp_path):
    """One goal (planned aperture, planned force x 1.25) reaches the planned depth: the same
    20 events in the same order as the JointTrajectory route and forces within 0.1 % (the
    issue's target for the world against the mechanics API, which test_sim_world checks for
    this world); the action's status and joint_states are in the bag.
    """
    action = run(write_scene(tmp_path, sponge(kind, **TIGHT)), record=str(tmp_path / "bag"))
    result = action["result"]
    print(f"{kind}: {result.termination} after {result.ticks} ticks: {result.message}")
    assert result.success and result.termination == "depth_reached"
    assert "reached_goal True, stalled False" in result.message
    assert action["events"] == jtc_route["events"] and len(action["events"]) == 20
    scale = np.abs(jtc_route["forces"]).max()
    error = np.abs(action["forces"] - jtc_route["forces"]).max() / scale
    print(f"largest force difference {kind} - JTC: {error:.1e} relative")
    assert error < 1e-3
    assert action["depth"] == pytest.approx(jtc_route["depth"], rel=1e-3)
    # and the mechanics API's event squeeze with the same pads, called directly
    direct = GraspSetup.build(load_scene(SPONGE)).event_squeeze(depth=action["depth"])
    assert action["events"] == [(str(e.type), str(e.finger), e.node) for e in direct.events]
    want = np.array([direct.state.finger_force(f)[:2] for f in ("F1", "F2")])
    print(f"largest force difference {kind} - mechanics API: "
          f"{np.abs(action['forces'] - want).max() / scale:.1e} relative")
    np.testing.assert_allclose(action["forces"], want, rtol=0, atol=1e-3 * scale)
    # the bag, read with mcap's own reader: one message per tick on each stamped topic (a tick
    # re-sent under load repeats its messages: count stamps), the action's status changes
    stamps: dict[str, set] = {"joint_states": set(), pipeline.EXECUTOR_CYCLE: set()}
    statuses = 0
    with open(next((tmp_path / "bag").glob("*.mcap")), "rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages():
            topic = channel.topic.lstrip("/")          # recorded under the run's namespace
            if topic in stamps:
                cls = JointState if topic == "joint_states" else Header
                msg = deserialize_message(message.data, cls)
                stamp = (msg.header if cls is JointState else msg).stamp
                stamps[topic].add((stamp.sec, stamp.nanosec))
            statuses += topic == "gripper_controller/gripper_cmd/_action/status"
    assert len(stamps["joint_states"]) == len({(m.header.stamp.sec, m.header.stamp.nanosec)
                                               for m in action["states"]}) > result.ticks
    assert len(stamps[pipeline.EXECUTOR_CYCLE]) == result.ticks
    assert statuses >= 2                          # executing, succeeded
    # the jaw force on joint_states is the ground truth's through the transmission (1 N/N)
    assert action["states"][-1].effort[0] == pytest.approx(abs(action["forces"][0, 1]),
                                                           rel=1e-3)


def test_an_effort_below_the_planned_force_stalls(tmp_path):
    """With effort_margin 0.5 the jaws stop at half the planned force and the goal aborts
    stalled after stall_timeout: the run says gripper_stalled, not success.
    """
    out = run(write_scene(tmp_path, sponge("parallel_gripper", effort_margin=0.5, **TIGHT)))
    result = out["result"]
    print(f"{result.termination}: {result.message}; depth {result.depth:.6g} m")
    assert not result.success and result.termination == "gripper_stalled"
    assert "reached_goal False, stalled True" in result.message
    limit = float(result.message.split("max_effort ")[1].rstrip(")"))  # N (1 N per N)
    planned_force = 5.9703                       # docs/grippers.md's run (F1 along y, N)
    assert limit == pytest.approx(0.5 * planned_force, rel=1e-4)
    force = abs(out["forces"][0, 1])             # stopped at the first tick at the limit
    assert limit <= force <= 1.05 * limit


def test_a_joint_in_metres_gets_its_goal_in_metres_and_a_wide_tolerance_is_refused(tmp_path):
    """A lab's own device, a joint at half the aperture in m (as a Franka Hand's finger): the
    gripper goal's position is half the planned aperture, 0.5 x (50 - 7.5) mm. With the stock
    goal_tolerance 0.01 (20 mm of aperture, beyond the 7.5 mm closing) the run said "grasp
    held" at a depth of 0.04 mm, the controller having reported the goal reached at once; now
    the executor refuses the goal (invalid_goal), naming the field, and sends none.
    """
    device = yaml.safe_load((REPO / "config" / "devices" / "generic_85mm.yaml").read_text())
    device.update(name="half_85mm", transmission={
        "joints": ["finger_joint"], "position_per_aperture": 0.5, "position_limits": [0, 0.0425]})
    (tmp_path / "half_85mm.yaml").write_text(yaml.safe_dump(device))
    tight = run(write_scene(tmp_path, sponge("gripper_action", device="half_85mm.yaml",
                                             **TIGHT)))["result"]
    print(tight.message)
    assert tight.termination == "depth_reached" and tight.success
    sent = re.search(r"goal: position ([-\d.e]+), max_effort ([-\d.e]+)", tight.message)
    assert float(sent[1]) == pytest.approx(0.5 * (0.05 - 0.0075), abs=1e-6)
    assert float(sent[2]) == pytest.approx(1.25 * 5.9703, rel=1e-3)   # 1 N per N
    wide = run(write_scene(tmp_path, sponge("gripper_action", device="half_85mm.yaml")))
    result = wide["result"]
    print(result.message)
    assert result.termination == "invalid_goal" and not result.success
    assert result.message.startswith("controller.goal_tolerance 0.01 (joint units) is 20 mm of "
                                     "aperture on half_85mm")
    assert "closing of 7.5 mm" in result.message and result.ticks == 0
    assert wide["depth"] == 0.0


@pytest.mark.parametrize("kind", ["parallel_gripper", "gripper_action"])
def test_a_squeeze_below_the_device_opening_is_refused_before_any_goal(kind, tmp_path, capfd):
    """A device closing no further than 45 mm, the sponge planned from 50 to 42.5 mm: before,
    the gripper goal went out and the grasp goal ended "gripper_rejected (... rejected the goal
    (position ..., max_effort ...): its log says why)"; now it ends invalid_goal at its first
    cycle, naming the range, as on the JointTrajectory route, and no gripper goal is sent.
    """
    device = yaml.safe_load((REPO / "config" / "devices" / "generic_85mm.yaml").read_text())
    device["name"], device["opening"]["min"] = "narrow_85mm", 0.045
    device["transmission"]["position_limits"] = [0.0, 0.8 - 0.045 * 0.8 / 0.085]
    (tmp_path / "narrow_85mm.yaml").write_text(yaml.safe_dump(device))
    out = run_observed(write_scene(tmp_path, sponge(kind, device="narrow_85mm.yaml", **TIGHT)))
    result = out["result"]
    print(result.message)
    assert result.termination == "invalid_goal" and not result.success
    assert result.message.startswith("the goal's squeeze takes the aperture from 50 mm to "
                                     "42.5 mm, outside narrow_85mm's opening [45, 85] mm")
    # the simulated server logs each goal it rejects (this one would be, outside its range)
    assert out["depth"] == 0.0 and "rejected the goal on" not in capfd.readouterr().err


def test_a_canceled_grasp_cancels_the_gripper_goal(tmp_path):
    """A cancel of the grasp goal mid-squeeze cancels the gripper goal: the controller holds the
    measured position and the goal ends canceled, short of the planned depth.
    """
    out = run_observed(write_scene(tmp_path, sponge("parallel_gripper", **TIGHT)),
                       cancel_after=0.2)
    result = out["result"]
    print(f"{result.termination} after {result.ticks} ticks, depth {result.depth:.6g} m")
    assert result.termination == "canceled" and not result.success
    assert 150 < result.ticks < 400 and 0.0 < out["depth"] < 0.7 * 5.3033e-3


@pytest.mark.parametrize("kind", ["parallel_gripper", "gripper_action"])
def test_the_jaws_slip_under_an_action_controller_the_alarm_cancels_the_goal(kind, tmp_path):
    """The slip scene (a jaw slips at 1.99 mm in the world) through a gripper action
    controller, watched on joint_states alone: the monitor's slip watch raises slip_imminent,
    the executor cancels the gripper goal (its status goes to CANCELED: the controller holds)
    and ends the grasp goal slip_alarm, after the world's slip and short of the planned depth.
    """
    from action_msgs.msg import GoalStatus, GoalStatusArray

    data = yaml.safe_load((SPONGE.parent / "sponge_gripper_slip.yaml").read_text())
    data["controller"] = {"type": kind, "name": "gripper_controller", "device": "generic_85mm",
                          **TIGHT}
    data["name"] = f"slip_{kind}"
    out = run_observed(write_scene(tmp_path, data), [
        ("status", "gripper_controller/gripper_cmd/_action/status", GoalStatusArray),
        ("alarms", pipeline.ALARMS, pipeline.message_type("squeeze_grasp_interfaces/msg/Alarm"))])
    result = out["result"]
    statuses = [s.status for msg in out["status"] for s in msg.status_list]
    print(f"{kind}: {result.termination} after {result.ticks} ticks at depth "
          f"{result.depth * 1e3:.4f} mm; gripper goal statuses {statuses}; first alarm "
          f"{out['alarms'][0].message if out['alarms'] else None}")
    assert result.termination == "slip_alarm" and not result.success
    assert {(a.type, a.finger) for a in out["alarms"]} >= {("slip_imminent", "F1"),
                                                           ("slip_imminent", "F2")}
    assert GoalStatus.STATUS_CANCELED in statuses and GoalStatus.STATUS_SUCCEEDED not in statuses
    assert 1.99e-3 < result.depth < 0.5 * 5.3033e-3


@pytest.mark.parametrize("kind", ["parallel_gripper", "gripper_action"])
def test_the_jaws_slip_under_an_action_controller_and_are_squeezed_again(kind, tmp_path):
    """The slip scene through a gripper action controller with ``on_slip_alarm: resqueeze``:
    three gripper goals (the squeeze, canceled at the alarm; the release to first contact + 2 x
    2 mm, succeeded; the re-squeeze, succeeded at 0.75 of the alarm's depth), the world
    releases the object once, and the grasp is held: the mechanics API's squeeze to that
    depth, as on the JointTrajectory route (test_resqueeze.py).
    """
    from action_msgs.msg import GoalStatus, GoalStatusArray

    from squeeze_grasp_ros.ros.run.options import RunOptions
    from squeeze_grasp_ros.ros.run.runner import PipelineRunner

    data = yaml.safe_load((SPONGE.parent / "sponge_gripper_slip.yaml").read_text())
    data["controller"] = {"type": kind, "name": "gripper_controller", "device": "generic_85mm",
                          **TIGHT}
    data["name"] = f"slip_{kind}"
    path = write_scene(tmp_path, data)
    runner = PipelineRunner(RunOptions(path, planner=False, on_slip_alarm="resqueeze"))
    statuses: dict = {}

    def status(msg: GoalStatusArray) -> None:
        for s in msg.status_list:
            statuses.setdefault(bytes(s.goal_info.goal_id.uuid), []).append(s.status)

    runner.client.create_subscription(GoalStatusArray,
                                      "gripper_controller/gripper_cmd/_action/status", status,
                                      pipeline.loop_qos(1000))
    try:
        runner.start()
        runner.send_goal()
        result = runner.wait_result()
        releases = list(runner.observer.world_releases)
        state = runner.observer.sim_states[-1]
    finally:
        runner.shutdown()
    ends = [seen[-1] for seen in statuses.values()]
    print(f"{kind}: {result.termination} after {result.ticks} ticks, {result.attempts} squeezes "
          f"to {result.planned_depth * 1e3:.4f} mm; gripper goals end {ends}")
    assert result.termination == "depth_reached" and result.success
    assert result.attempts == 2 and result.resqueezed and len(releases) == 1
    assert ends == [GoalStatus.STATUS_CANCELED, GoalStatus.STATUS_SUCCEEDED,
                    GoalStatus.STATUS_SUCCEEDED]
    assert state.termination == "" and state.contacts.depth == pytest.approx(
        result.planned_depth, rel=1e-9)
    direct = GraspSetup.build(load_scene(path)).event_squeeze(depth=state.contacts.depth)
    for k, name in enumerate(("F1", "F2")):
        got = np.array([state.forces[k].x, state.forces[k].y])
        want = direct.state.finger_force(name)
        assert np.linalg.norm(got - want) <= 1e-3 * np.linalg.norm(want)


# --------------------------------------------------------------------------- hostile client
def wait(executor, condition, seconds=10.0):
    deadline = time.monotonic() + seconds
    while not condition() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    return condition()


@pytest.mark.parametrize("kind", ["parallel_gripper", "gripper_action"])
def test_a_hostile_action_client_is_rejected(kind, tmp_path, capfd):
    """NaN position, a position outside the opening range, an effort beyond the device's 235 N
    and (parallel) a wrong joint name or two positions: each goal rejected with one log line,
    the jaws unmoved; a valid goal is accepted.
    """
    path = write_scene(tmp_path, sponge(kind, **TIGHT))
    action = ParallelGripperCommand if kind == "parallel_gripper" else GripperCommand
    with sim_and_client(path) as (executor, sim, client):
        cycle = client.create_publisher(pipeline.message_type("std_msgs/msg/Header"),
                                        pipeline.EXECUTOR_CYCLE, pipeline.loop_qos(10))
        pipeline.Participant(client, "hostile", [], [cycle])
        ac = ActionClient(client, action, "gripper_controller/gripper_cmd")
        assert wait(executor, lambda: sim.now_ns == 0 and ac.server_is_ready())
        before = dict(sim.world.positions)

        def goal(position, effort=0.0, name=("finger_joint",), positions=None):
            g = action.Goal()
            if kind == "parallel_gripper":
                g.command.name = list(name)
                g.command.position = positions or [position]
                g.command.effort = [effort] if effort else []
            else:
                g.command.position, g.command.max_effort = position, effort
            future = ac.send_goal_async(g)
            assert wait(executor, future.done)
            return future.result()

        hostile = [goal(math.nan), goal(0.9), goal(-0.1), goal(0.4, effort=300.0)]
        if kind == "parallel_gripper":
            hostile += [goal(0.4, name=("wrong_joint",)), goal(0.4, positions=[0.4, 0.4])]
        assert not any(h.accepted for h in hostile)
        reasons = sim.controller.refusals
        for reason, text in zip(reasons, ("position nan is not finite", "outside the joint range",
                                          "outside the joint range", "effort 300 is outside",
                                          "not the controller's joint", "has 2 values")):
            assert text in reason
        assert len(reasons) == len(hostile)
        assert sim.now_ns == 0 and all(np.array_equal(sim.world.positions[f], p)
                                       for f, p in before.items())
        assert goal(0.4, effort=3.0).accepted
    err = capfd.readouterr().err
    assert err.count("rejected the goal on /gripper_controller/gripper_cmd") == len(hostile)
    # the log lines docs/grippers.md quotes (the second a parallel gripper's), stamps as [...]
    logged = [re.sub(r"^(\[\w+\]) \[[\d.]+\]", r"\1 [...]", line) for line in err.splitlines()]
    quoted = [b.lines for b in blocks(REPO / "docs" / "grippers.md")
              if b.language == "text" and "rejected the goal on" in "\n".join(b.lines)]
    assert len(quoted) == 1 and len(quoted[0]) == 2, quoted
    shown = quoted[0] if kind == "parallel_gripper" else quoted[0][:1]
    assert [line for line in shown if line not in logged] == [], err


def test_a_stopping_executor_cancels_the_gripper_goal(tmp_path):
    """An executor node stopped mid-squeeze (SIGINT, SIGTERM: its ``drain``) cancels its
    gripper goal before it ends the grasp goal: the controller holds the measured position, and
    the goal's result says so. Before, the controller went on to the goal's aperture after the
    executor had gone.
    """
    from squeeze_grasp_ros.ros.run.options import RunOptions
    from squeeze_grasp_ros.ros.run.runner import PipelineRunner

    path = write_scene(tmp_path, sponge("parallel_gripper", **TIGHT))
    runner = PipelineRunner(RunOptions(path, planner=False))
    try:
        runner.start()
        runner.send_goal()

        def sim_time() -> float:
            return (runner.observer.sim_state_ns - runner.start_ns) * 1e-9

        runner.spin_until(lambda: sim_time() > 0.2, 60.0, "0.2 s of the squeeze")
        controller = runner.nodes["sim_hardware"].controller
        assert controller.active is not None  # the gripper goal runs
        runner.nodes["executor"].drain(runner.executor)
        assert controller.active is None  # canceled: the servo holds the measured position
        runner.spin_until(runner.goal.result_future.done, 10.0, "the goal's result")
        result = runner.goal.result_future.result().result
        assert result.termination == "canceled" and not result.success
        assert "it canceled the gripper goal" in result.message, result.message
    finally:
        runner.shutdown()
