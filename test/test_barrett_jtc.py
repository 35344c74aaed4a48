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
from pipeline_support import LogLines, run_observed, write_scene
from scipy.optimize import brentq
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from squeeze_grasp_interfaces.msg import MonitorStatus
from squeeze_grasp_ros.control.barrett import (
    JOINTS,
    BarrettFinger,
    BarrettHand,
    HandPose,
    SingularPosture,
)
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline
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


def _answers(messages: list) -> int:
    """The messages less the copies of a re-sent tick: a loop that stalls for
    ``resend_timeout`` (a loaded machine) publishes its tick again, message for message, and
    the recorder keeps one message per stamp (seen: 702 joint states received, 701 recorded).
    """
    return len({(m.header.stamp.sec, m.header.stamp.nanosec) for m in messages})


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
    assert recorded["/hand_controller/joint_trajectory"] == _answers(jtc["trajectories"])
    assert recorded["/joint_states"] == _answers(jtc["joint_states"])
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
    # without sensors the thumb cannot be read from its efforts
    data["fingers"]["F2"]["device"] = "barrett_f3"
    data["effects"] = ["friction"]
    with pytest.raises(SceneError, match=r"controller.jaws: without force_sensing or "
                                         r"tactile_sensing .* carry two fingers on barrett_f1 "
                                         r"and barrett_f2, got \{'F1': 'barrett_f1', 'F2': "
                                         r"'barrett_f3'\}"):
        scene_controller(parse_scene(data), SCENE)
    data["fingers"]["F2"]["device"] = "barrett_f2"
    assert isinstance(scene_controller(parse_scene(data), SCENE), HandController)


def run_with_status(path: str) -> dict:
    return run_observed(path, [("joint_states", "joint_states", JointState),
                               ("status", pipeline.STATUS, MonitorStatus)])


def test_the_hand_on_joint_efforts_equals_the_hand_with_force_sensors(tmp_path):
    # the same scene without force and tactile sensing: the monitor reads each finger's force
    # from the joint efforts (J^T F = tau per finger) where the other run reads the wrench
    sensed = run_with_status(write_scene(tmp_path, scene_data(
        name="foam_sensed", effects=["friction", "force_sensing"])))
    efforts = run_with_status(write_scene(tmp_path, scene_data(
        name="foam_efforts", effects=["friction"])))
    for out in (sensed, efforts):
        assert out["result"].termination == "depth_reached", out["result"].message
    # the world: the same events, tick for tick and node for node, and forces (1e-9 relative)
    assert efforts["events"] and efforts["events"] == sensed["events"]
    scale = np.abs(sensed["forces"]).max()
    assert np.abs(efforts["forces"] - sensed["forces"]).max() < 1e-9 * scale
    assert efforts["result"].depth == pytest.approx(sensed["result"].depth, rel=1e-9)
    # the monitor: the forces it measured at every tick, from the efforts here and the wrench
    # sensors there, agree to 1e-9 of the largest force (the round trip tau = J^T F -> F
    # loses only rounding)
    def forces(out):
        return {m.header.stamp.sec * 10**9 + m.header.stamp.nanosec:
                np.array([[v.x, v.y] for v in m.forces]) for m in out["status"]}
    a, b = forces(sensed), forces(efforts)
    common = sorted(set(a) & set(b))
    assert len(common) >= 0.99 * len(a)
    worst = max(np.abs(a[t] - b[t]).max() for t in common)
    print(f"{len(common)} ticks; largest monitor force difference {worst:.2e} N "
          f"({worst / scale:.1e} of {scale:.3f} N)")
    assert worst < 1e-9 * scale
    # the efforts are the statics of the model: J^T F of the ground truth at the last tick
    hand = scene_controller(load_scene(SCENE), SCENE).hand
    last = efforts["joint_states"][-1]
    joints, tau = dict(zip(last.name, last.position)), dict(zip(last.name, last.effort))
    for finger, force in zip(("barrett_f1", "barrett_f2"), efforts["forces"]):
        np.testing.assert_allclose(hand.tip_force(finger, joints, tau).force, force,
                                   rtol=1e-6, atol=1e-9 * scale)
    assert tau["bh_j32_joint"] == tau["bh_j33_joint"] == 0.0       # the thumb is not carried


def test_the_jacobian_is_the_derivative_of_the_forward_kinematics():
    # an independent check of J: central differences of the forward kinematics, each joint
    # moved alone (the two spread joints are one in forward(): both moved together, each
    # finger's own spread column is its share)
    hand = BarrettHand(pose=HandPose((0.01, 0.03), 0.4))
    joints = dict(zip(JOINTS, (0.9, 1.0, 0.2, 0.9, 0.5, 0.3, 1.2, 0.4)))
    h = 1e-6
    for finger in BarrettFinger:
        names = (finger.spread, finger.proximal, finger.distal)
        numeric = []
        for name in names:
            if name is None:
                numeric.append(np.zeros(2))
                continue
            moved = [n for n in JOINTS if n == name or name.endswith("1_joint")
                     and n.endswith("1_joint")]
            up = {**joints, **{n: joints[n] + h for n in moved}}
            down = {**joints, **{n: joints[n] - h for n in moved}}
            numeric.append((hand.forward(up)[finger] - hand.forward(down)[finger]) / (2 * h))
        np.testing.assert_allclose(hand.jacobian(finger, joints), np.column_stack(numeric),
                                   atol=1e-9)
    # the statics round trip, and virtual work: tau . dq = F . dp for a small joint motion
    forces = {BarrettFinger.F1: np.array([1.5, -2.0]), BarrettFinger.F2: np.array([-0.7, 3.1])}
    tau = hand.efforts(joints, forces)
    for finger, force in forces.items():
        recovered = hand.tip_force(finger, joints, tau)
        np.testing.assert_allclose(recovered.force, force, rtol=1e-12)
        assert recovered.residual < 1e-15 and recovered.condition < 10
        dq = np.array([1e-7, -2e-7, 0.5e-7])
        dp = hand.jacobian(finger, joints) @ dq
        own = [tau[n] for n in (finger.spread, finger.proximal, finger.distal)]
        assert np.dot(own, dq) == pytest.approx(np.dot(force, dp), rel=1e-12)


def test_a_singular_posture_is_refused_with_a_clear_error():
    hand = BarrettHand()
    # finger 1's tip on its spread axis (rho = 0): the spread cannot move it, so its efforts
    # say nothing of the force across its line
    q = brentq(lambda x: hand.rho(x), 0.0, hand.turning)
    joints = {**{n: 0.0 for n in JOINTS}, "bh_j12_joint": q, "bh_j13_joint": q / 3}
    tau = hand.efforts(joints, {BarrettFinger.F1: np.array([0.0, 1.0])})
    with pytest.raises(SingularPosture, match=r"barrett_f1: its joint efforts do not determine "
                                              r"its tip force at spread 0, proximal 1.598, "
                                              r"distal 0.5327 rad: J\^T has condition number "
                                              r".* > 100 \(the tip .* mm from its spread axis"):
        hand.tip_force(BarrettFinger.F1, joints, tau)
    # 5 mm from the axis it is read (condition about 15), 0.5 mm from it refused
    for rho, readable in ((0.005, True), (0.0005, False)):
        q = brentq(lambda x, r=rho: hand.rho(x) - r, 0.0, hand.turning)
        joints.update(bh_j12_joint=q, bh_j13_joint=q / 3)
        if readable:
            assert hand.tip_force(BarrettFinger.F1, joints, tau).condition < 100
        else:
            with pytest.raises(SingularPosture):
                hand.tip_force(BarrettFinger.F1, joints, tau)
    with pytest.raises(SingularPosture, match="barrett_f3: the thumb has no spread joint"):
        hand.tip_force(BarrettFinger.F3, joints, tau)


def test_efforts_out_of_the_models_proportions_show_in_the_residual():
    # a driver that copies one strain-gauge torque into a finger's proximal and distal efforts
    # and reports no spread torque (RobotnikAutomation's bhand_controller): the least squares
    # cannot fit both joints, and the residual says so; the model's own efforts leave none
    hand = BarrettHand()
    joints = dict(zip(JOINTS, (0.9, 1.1, 1.1 / 3, 0.9, 1.1, 1.1 / 3, 0.0, 0.0)))
    tau = hand.efforts(joints, {BarrettFinger.F1: np.array([1.0, -0.5])})
    assert hand.tip_force(BarrettFinger.F1, joints, tau).residual < 1e-15
    driver = {**tau, "bh_j11_joint": 0.0, "bh_j12_joint": tau["bh_j13_joint"]}
    assert hand.tip_force(BarrettFinger.F1, joints, driver).residual > 0.1 * abs(
        tau["bh_j13_joint"])


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


def test_the_simulated_hand_controller_starts_a_trajectory_from_the_measured_joints(tmp_path):
    """As Jazzy's JointTrajectoryController by default (interpolate_from_desired_state false):
    the segment to a first point ahead starts at the joints' measured state at receipt. Before,
    the simulated hand's started at its last command (the gripper's was fixed before).
    """
    import time

    from builtin_interfaces.msg import Duration
    from pipeline_support import sim_and_client
    from trajectory_msgs.msg import JointTrajectoryPoint

    path = write_scene(tmp_path, scene_data())
    with sim_and_client(path) as (executor, sim, client):
        publisher = client.create_publisher(JointTrajectory, "hand_controller/joint_trajectory",
                                            pipeline.loop_qos(10))
        pipeline.Participant(client, "hostile", [], [publisher])
        deadline = time.monotonic() + 10.0
        while sim.now_ns < 0 and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
        hand = sim.controller
        command = hand.follower.sample(0)
        # the joints as measured at receipt, 1 mrad off the command (a lagging hand; the
        # simulated tips follow their setpoints within a tick)
        hand.joints = {j: hand.joints[j] + 1e-3 for j in JOINTS}
        measured = [hand.joints[j] for j in JOINTS]
        goal = [hand.joints[j] + 5e-3 for j in JOINTS]
        publisher.publish(JointTrajectory(joint_names=list(JOINTS), points=[JointTrajectoryPoint(
            positions=goal, time_from_start=Duration(nanosec=5_000_000))]))
        deadline = time.monotonic() + 10.0
        while sim.now_ns < 1_000_000 and time.monotonic() < deadline:  # taken, then a step
            executor.spin_once(timeout_sec=0.05)
        assert sim.now_ns == 1_000_000 and hand.refusals == []
        (t0, start), (t1, end) = hand.follower.knots
        assert (t0, t1) == (0, 5_000_000)
        np.testing.assert_array_equal(start, measured)
        np.testing.assert_array_equal(end, goal)
        assert np.max(np.abs(start - command)) == pytest.approx(1e-3)


def test_a_palm_out_of_reach_of_the_placements_is_one_error_line(tmp_path):
    """The palm 0.5 m from the square: the simulated hardware refuses to start, naming the
    palm, the finger, its target and its reach.
    """
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

    feedback = HandFeedback.of({"controller_scene": str(SCENE)}, ["wrench", "tactile"])
    assert feedback.watch is None                 # the sensors give the forces
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
    assert HandFeedback.of({"controller_scene": ""}, []) is None


def test_the_monitor_reads_the_hand_efforts_and_refuses_a_singular_posture(tmp_path):
    """Without sensors the monitor's hand feedback reads the forces from the efforts; a NaN
    effort is ignored with a warning, and a singular posture is refused with one warning line
    per episode (the readings go stale), naming the finger and the conditioning.
    """
    from builtin_interfaces.msg import Time

    from squeeze_grasp_ros.ros.nodes.monitor import HandFeedback

    path = write_scene(tmp_path, scene_data(effects=["friction"]))
    feedback = HandFeedback.of({"controller_scene": path, "load_threshold": 0.002,
                                "joint_slip_window": 1e-4, "joint_slip_ratio": 0.5}, [""])
    hand = feedback.controller.hand
    with pytest.raises(ParameterError, match="hand_max_condition must be >= 1"):
        HandFeedback.of({"controller_scene": path, "hand_max_condition": 0.5}, [""])
    joints = dict(zip(JOINTS, (0.9, 1.2, 0.4, 0.9, 1.1, 1.1 / 3, 0.0, 0.0)))
    pushes = {BarrettFinger.F1: np.array([2.0, 0.5]), BarrettFinger.F2: np.array([-2.0, -0.5])}
    tau = hand.efforts(joints, pushes)
    log = LogLines()
    warnings = log.lines

    def state(sec, positions, efforts):
        msg = JointState(name=list(JOINTS), position=list(positions), effort=list(efforts))
        msg.header.stamp = Time(sec=sec)
        fields = {"F1": {}, "F2": {}}
        feedback.replace(fields, msg, log)
        return fields

    fields = state(1, joints.values(), [tau[j] for j in JOINTS])
    # the wrench of the object on each finger: minus its push
    np.testing.assert_allclose(fields["F1"]["force"][:2], -pushes[BarrettFinger.F1], rtol=1e-12)
    np.testing.assert_allclose(fields["F2"]["force"][:2], -pushes[BarrettFinger.F2], rtol=1e-12)
    assert fields["F1"]["force_stamp_ns"] == 10**9
    assert "force" not in state(2, joints.values(), [float("nan")] * 8)["F1"]
    assert len(warnings) == 2 and "efforts [nan" in warnings[1]   # warnings[0]: first touch
    # finger 1's tip on its spread axis: refused, one warning for two states
    q = brentq(lambda x: hand.rho(x), 0.0, hand.turning)
    singular = {**joints, "bh_j12_joint": q, "bh_j13_joint": q / 3}
    for sec in (3, 4):
        assert state(sec, singular.values(), [tau[j] for j in JOINTS]) == {"F1": {}, "F2": {}}
    assert len(warnings) == 3 and "barrett_f1: its joint efforts do not determine" in warnings[2]


def test_the_hand_slip_watch_on_efforts_fires_when_the_force_stops_rising(tmp_path):
    """Fingers 1 and 2 close on a spring along the line between them (the foam square's
    placement); the efforts are the statics of the spring's force. While it rises no alarm;
    once it stops rising (a slip) the slip watch raises ``slip_imminent`` for both fingers
    within a window of closing.
    """
    from builtin_interfaces.msg import Time

    from squeeze_grasp_ros.ros.nodes.monitor import HandFeedback

    path = write_scene(tmp_path, scene_data(effects=["friction"]))
    feedback = HandFeedback.of({"controller_scene": path, "load_threshold": 0.002,
                                "joint_slip_window": 1e-4, "joint_slip_ratio": 0.5}, [""])
    hand = feedback.controller.hand
    log = LogLines()
    alarms = []
    for k in range(200):
        closing = 2e-5 * k                  # of the tip distance: each tip moves 10 um a tick
        tips = {BarrettFinger.F1: np.array([-0.07 + closing / 2, 0.0]),
                BarrettFinger.F2: np.array([0.07 - closing / 2, 0.0])}
        joints = hand.inverse(tips).joints
        # touch at 0.1 mm of closing, a 500 N/m spring, the force flat at 1 N from 2.1 mm on
        force = 500.0 * min(max(closing - 1e-4, 0.0), 2e-3)
        tau = hand.efforts(joints, {BarrettFinger.F1: np.array([force, 0.0]),
                                    BarrettFinger.F2: np.array([-force, 0.0])})
        msg = JointState(name=list(JOINTS), position=[joints[j] for j in JOINTS],
                         effort=[tau[j] for j in JOINTS])
        msg.header.stamp = Time(nanosec=10**6 * k)
        feedback.replace({"F1": {}, "F2": {}}, msg, log)
        alarms.append((closing, [(a.type, a.finger) for a in feedback.alarms]))
    plateau = 2.1e-3
    assert not [a for c, a in alarms if c <= plateau and a]
    late = [a for c, a in alarms if c > plateau + 1e-4 + 1e-9]
    assert late and all(a == [("slip_imminent", "F1"), ("slip_imminent", "F2")] for a in late)
    # first touch: the tip distance of the last reading without force, 0.14 m less 0.1 mm
    assert 0.14 - 1.2e-4 <= feedback.watch.first_touch <= 0.14 - 1e-4
    assert log.lines == [f"first touch of the hand's fingers at tip distance "
                         f"{feedback.watch.first_touch * 1e3:.4f} mm (force 0.01 N)"]


def test_setpoints_off_a_fingers_line_are_commanded_as_the_closest_reachable_joints(ros_context):
    """A setpoint the hand cannot reach exactly (a tilted squeeze's round-off, or a redirect off
    the fingers' lines) moves the fingers to the closest reachable joints instead of holding the
    last ones (which left a run waiting for a depth it could never reach); beyond
    REACH_TOLERANCE the executor warns once, naming the finger.
    """
    from rclpy.node import Node

    from squeeze_grasp_ros.control.motion import Observation
    from squeeze_grasp_ros.ros.nodes.jaw_commands import REACH_TOLERANCE, HandCommands

    controller = scene_controller(load_scene(SCENE), SCENE)
    hand = controller.hand
    node = Node("hand_commands_test", context=ros_context)
    try:
        log = LogLines()
        node.get_logger = lambda: log
        commands = HandCommands(node, controller, 0.001, pipeline.loop_qos(4))
        tips = {"F1": np.array([-0.07, 0.0]), "F2": np.array([0.07, 0.0])}
        zeros = {f: np.zeros(2) for f in tips}
        commands.start(Observation(0, tips, zeros, zeros))
        inward = np.array([1e-3, 0.0])
        # the spread follows finger 1's target, so finger 2's line is fixed by it: push finger
        # 2's setpoint across that line by round-off, then by a millimetre
        for step, (off, warned) in enumerate(((1e-8, False), (1e-3, True)), start=1):
            targets = {"F1": tips["F1"] + step * inward,
                       "F2": tips["F2"] - step * inward + np.array([0.0, off])}
            before = dict(commands.solution.joints)
            _, msg = commands.trajectory(targets, 0)
            after = commands.solution.joints
            assert after[BarrettFinger.F2.proximal] != before[BarrettFinger.F2.proximal]
            reached = hand.forward(after)
            assert np.hypot(*(reached[BarrettFinger.F1] - targets["F1"])) < 1e-12
            assert 0.5 * off < np.hypot(*(reached[BarrettFinger.F2] - targets["F2"])) <= off
            assert list(msg.points[0].positions) == [after[j] for j in JOINTS]
            assert bool(log.lines) is warned, (off, log.lines)
        assert len(log.lines) == 1 and "barrett_f2" in log.lines[0], log.lines
        assert "closest reachable" in log.lines[0]
        assert 1e-8 < REACH_TOLERANCE < 1e-3
    finally:
        node.destroy_node()
