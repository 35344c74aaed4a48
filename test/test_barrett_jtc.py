# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The Barrett hand under a JointTrajectoryController of its joints on real rclpy
(docs/grippers.md, "The Barrett hand's joints"): the paper's foam square pinched by fingers 1
and 2 through the hand's trajectory equals the same scene on the fingers' Cartesian setpoint
topics, the recording replays, the joint states give the tips back through the forward
kinematics, and the scene section's errors name the field.
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader
from pipeline_support import run_observed, write_scene
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from squeeze_grasp_ros.control.barrett import JOINTS
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.recording.replay import replay
from squeeze_grasp_ros.scene import SceneError, load_scene, parse_scene
from squeeze_grasp_ros.scene.controller import HandController, scene_controller

SCENE = Path(__file__).resolve().parents[1] / "config" / "scenes" / "foam_square_barrett_jtc.yaml"
POSE = pipeline.message_type("geometry_msgs/msg/PoseStamped")


def scene_data(**changes) -> dict:
    data = yaml.safe_load(SCENE.read_text())
    data["object"]["mesh"]["nodes"] = 600
    data.update(changes)
    return {k: v for k, v in data.items() if v is not None}


def run(path: str, record: str | None = None) -> dict:
    out = run_observed(path, [
        ("trajectories", "hand_controller/joint_trajectory", JointTrajectory),
        ("joint_states", "joint_states", JointState),
        ("setpoints", pipeline.device_topic("barrett_f1", "setpoint"), POSE),
        ("poses", pipeline.device_topic("barrett_f1", "pose"), POSE)], record=record)
    assert out["result"].termination == "depth_reached"
    return out


def test_the_foam_square_through_the_hand_jtc_equals_the_setpoint_route(tmp_path):
    bag = tmp_path / "bag"
    jtc = run(write_scene(tmp_path, scene_data()), record=str(bag))
    cartesian = run(write_scene(tmp_path, scene_data(name="foam_cartesian", controller=None)))
    print(f"hand JTC: {len(jtc['trajectories'])} trajectories, {len(jtc['joint_states'])} joint "
          f"states, {len(jtc['events'])} events, forces {jtc['forces'].tolist()} N")
    # the routes differ: the fingers' setpoints go to the hand's controller as joints
    assert jtc["trajectories"] and not jtc["setpoints"] and not cartesian["trajectories"]
    for msg in jtc["trajectories"]:
        assert list(msg.joint_names) == list(JOINTS) and len(msg.points) == 1
        q = dict(zip(JOINTS, msg.points[0].positions))
        assert q["bh_j11_joint"] == q["bh_j21_joint"]                   # one spread motor
        for k in "123":
            assert q[f"bh_j{k}3_joint"] == pytest.approx(q[f"bh_j{k}2_joint"] / 3, rel=1e-15)
    # the same events, tick for tick and node for node; forces to 1e-9 relative
    assert jtc["events"] and jtc["events"] == cartesian["events"]
    scale = np.abs(cartesian["forces"]).max()
    difference = np.abs(jtc["forces"] - cartesian["forces"]).max() / scale
    print(f"largest force difference hand JTC - Cartesian: {difference:.1e} relative")
    assert difference < 1e-9
    assert jtc["depth"] == pytest.approx(cartesian["depth"], rel=1e-9)
    # the monitor positions the fingers from joint_states there, from their poses here
    assert jtc["result"].depth == pytest.approx(cartesian["result"].depth, rel=1e-9)
    # feedback: the last joint state through the forward kinematics is finger 1's measured tip
    hand = scene_controller(load_scene(SCENE), SCENE).hand
    last = jtc["joint_states"][-1]
    tip = hand.forward(dict(zip(last.name, last.position)))["barrett_f1"]
    pose = jtc["poses"][-1].pose.position
    np.testing.assert_allclose(tip, [pose.x, pose.y], atol=1e-12)
    # recorded message for message, and replayable
    with open(next(bag.glob("*.mcap")), "rb") as stream:
        recorded = Counter(channel.topic for _, channel, _ in
                           make_reader(stream).iter_messages())
    assert recorded["/hand_controller/joint_trajectory"] == len(jtc["trajectories"])
    assert recorded["/joint_states"] == len(jtc["joint_states"])
    replayed = replay(str(bag))
    assert replayed["reproduced"] is True and replayed["events"]


@pytest.mark.parametrize(("change", "message"), [
    ({"palm": None}, "controller.palm: the bh8 hand needs its palm's pose"),
    ({"type": "parallel_gripper"}, "controller.type: the bh8 hand is driven by a "
                                   "joint_trajectory controller"),
])
def test_hand_section_errors_name_the_field(change, message):
    data = scene_data()
    data["controller"] = {k: v for k, v in {**data["controller"], **change}.items()
                          if v is not None}
    with pytest.raises(SceneError, match=message):
        scene_controller(parse_scene(data), SCENE)


def test_a_hand_finger_must_be_on_a_hand_device():
    data = scene_data()
    data["fingers"]["F2"]["device"] = "cobra"
    with pytest.raises(SceneError, match=r"controller.jaws: F2's device cobra is not a finger "
                                         r"of the bh8 hand"):
        scene_controller(parse_scene(data), SCENE)
    data["fingers"]["F2"]["device"] = "barrett_f2"
    data["effects"] = ["friction"]
    with pytest.raises(SceneError, match="joint feedback alone is not built"):
        scene_controller(parse_scene(data), SCENE)


def test_the_shipped_scene_maps_fingers_1_and_2():
    controller = scene_controller(load_scene(SCENE), SCENE)
    assert isinstance(controller, HandController)
    assert {f.value: h.value for f, h in controller.fingers.items()} == {
        "F1": "barrett_f1", "F2": "barrett_f2"}
    assert controller.topic == "hand_controller/joint_trajectory"


def test_a_hostile_hand_trajectory_is_refused_and_a_valid_one_followed(tmp_path, capfd):
    """Wrong joint names, a NaN, a proximal joint beyond its 2.44 rad are refused with a log
    line (the hand holds); a valid trajectory moves finger 1's tip to the forward kinematics of
    the commanded joints.
    """
    import time

    from builtin_interfaces.msg import Duration
    from pipeline_support import sim_and_client
    from trajectory_msgs.msg import JointTrajectoryPoint

    def trajectory(names, positions) -> JointTrajectory:
        return JointTrajectory(joint_names=list(names), points=[JointTrajectoryPoint(
            positions=[float(p) for p in positions], time_from_start=Duration(nanosec=1_000_000))])

    path = write_scene(tmp_path, scene_data())
    with sim_and_client(path) as (executor, sim, client):
        publisher = client.create_publisher(JointTrajectory, "hand_controller/joint_trajectory",
                                            pipeline.loop_qos(10))
        pipeline.Participant(client, "hostile", [], [publisher])

        def spin_until(condition, timeout=10.0):
            deadline = time.monotonic() + timeout
            while not condition() and time.monotonic() < deadline:
                executor.spin_once(timeout_sec=0.05)

        spin_until(lambda: sim.now_ns >= 0)
        hand = sim.controller
        start = [hand.joints[j] for j in JOINTS]
        bad = dict(zip(JOINTS, start), bh_j12_joint=2.6)
        for msg in (trajectory(["bh_j11_joint"], [0.1]),
                    trajectory(JOINTS, [float("nan")] + start[1:]),
                    trajectory(JOINTS, [bad[j] for j in JOINTS])):
            publisher.publish(msg)
        spin_until(lambda: len(hand.refusals) >= 3)
        assert sim.now_ns == 0 and len(hand.refusals) == 3
        for reason, text in zip(hand.refusals, ("not the controller's joints", "non-finite",
                                                "bh_j12_joint 2.6 (range [0, 2.44])")):
            assert text in reason
        goal = dict(zip(JOINTS, start), bh_j12_joint=start[1] + 5e-4,
                    bh_j13_joint=(start[1] + 5e-4) / 3)   # ~0.06 mm: within a tick
        publisher.publish(trajectory(JOINTS, [goal[j] for j in JOINTS]))
        spin_until(lambda: sim.now_ns >= 1_000_000)
        assert sim.now_ns == 1_000_000
        expected = hand.hand.forward(goal)["barrett_f1"]
        np.testing.assert_allclose(sim.world.positions["F1"], expected, atol=1e-12)
    assert capfd.readouterr().err.count(
        "refused the trajectory on /hand_controller/joint_trajectory") == 3


def test_a_palm_out_of_reach_of_the_placements_is_one_error_line(tmp_path):
    """The palm 0.5 m from the square: the simulated hardware refuses to start, naming the
    palm, the finger, its target and its reach.
    """
    from squeeze_grasp_ros.ros.nodes import ParameterError
    from squeeze_grasp_ros.ros.nodes.sim_hardware import SimHardwareNode

    data = scene_data()
    data["controller"]["palm"] = [0.0, 0.5, 0.0]
    path = write_scene(tmp_path, data)
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context)
    try:
        with pytest.raises(ParameterError, match=r"controller.palm \[0.0, 0.5, 0.0\]: the "
                                                 r"fingers' initial tips are out of the hand's "
                                                 r"reach: barrett_f1: target \(-0.07, 0\) m lies "
                                                 r".* beyond its reach"):
            SimHardwareNode(context=context, parameter_overrides=[
                rclpy.parameter.Parameter("scene", value=path)])
    finally:
        rclpy.shutdown(context=context)


def test_the_monitor_positions_the_hand_fingers_from_joint_states():
    """The monitor's hand feedback: the carried fingers' positions are the forward kinematics
    of the joint state (the poses are replaced); a state missing a joint or with a NaN is
    ignored with one warning per stamp.
    """
    from builtin_interfaces.msg import Time

    from squeeze_grasp_ros.ros.nodes.monitor import HandFeedback

    feedback = HandFeedback.of({"controller_scene": str(SCENE)})
    joints = dict(zip(JOINTS, (0.9, 1.2, 0.4, 0.9, 1.1, 1.1 / 3, 0.0, 0.0)))
    msg = JointState(name=list(JOINTS), position=list(joints.values()))
    msg.header.stamp = Time(sec=1)
    fields = {"F1": {"position": np.zeros(2)}, "F2": {"position": np.zeros(2)}}
    feedback.replace(fields, msg, None)
    tips = feedback.controller.hand.forward(joints)
    np.testing.assert_array_equal(fields["F1"]["position"], tips["barrett_f1"])
    np.testing.assert_array_equal(fields["F2"]["position"], tips["barrett_f2"])
    warnings = []

    class Log:
        warning = warnings.append

    for bad in (JointState(name=list(JOINTS[:-1]), position=[0.0] * 7),
                JointState(name=list(JOINTS), position=[float("nan")] + [0.0] * 7)):
        bad.header.stamp = Time(sec=len(warnings) + 2)
        before = {f: v["position"].copy() for f, v in fields.items()}
        feedback.replace(fields, bad, Log())
        assert all(np.array_equal(fields[f]["position"], before[f]) for f in fields)
    assert len(warnings) == 2 and "bh_j33_joint" in warnings[0] and "nan" in warnings[1]
    assert HandFeedback.of({"controller_scene": ""}) is None
