# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The stock JointTrajectoryController route of a gripper scene (docs/grippers.md): the
follower's semantics, the scene section's checks, the sponge gripper through the JTC against
the Cartesian setpoint route on real rclpy, and a hostile trajectory client.
"""

from __future__ import annotations

import re
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import rclpy
import yaml
from builtin_interfaces.msg import Duration
from doc_transcripts import REPO, blocks
from mcap.reader import make_reader
from pipeline_support import run_observed, write_scene
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from squeeze_grasp_ros.control.joint_trajectory import (
    JawLine,
    JointFollower,
    TrajectoryFollower,
    TrajectoryRefused,
)
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.sim_hardware import SimHardwareNode
from squeeze_grasp_ros.scene import SceneError, load_scene, parse_scene
from squeeze_grasp_ros.scene.controller import scene_controller

SPONGE = Path(__file__).resolve().parents[1] / "config" / "scenes" / "sponge_gripper.yaml"
MS = 1_000_000


def sponge_data(**changes) -> dict:
    data = yaml.safe_load(SPONGE.read_text())
    data.update(changes)
    return {k: v for k, v in data.items() if v is not None}


# --------------------------------------------------------------------------- the follower
def follower() -> TrajectoryFollower:
    return TrajectoryFollower(0.05, opening=(0.0, 0.085))


def test_follower_interpolates_linearly_and_holds_the_last_point():
    f = follower()
    f.accept([(10 * MS, (0.04,)), (30 * MS, (0.02,))], now_ns=0, to_aperture=lambda p: p)
    # anchor (0, 0.05) -> (10 ms, 0.04) -> (30 ms, 0.02), held after
    for t, expected in ((0, 0.05), (5 * MS, 0.045), (10 * MS, 0.04), (20 * MS, 0.03),
                        (30 * MS, 0.02), (99 * MS, 0.02)):
        assert f.sample(t) == pytest.approx(expected, abs=1e-15)


def test_a_new_trajectory_replaces_the_old_from_the_command_to_its_first_point():
    f = follower()
    f.accept([(10 * MS, (0.04,))], now_ns=0, to_aperture=lambda p: p)
    # at 5 ms the command is 0.045; the new trajectory's first point lies ahead
    f.accept([(15 * MS, (0.065,))], now_ns=5 * MS, to_aperture=lambda p: p)
    assert f.sample(5 * MS) == pytest.approx(0.045)
    assert f.sample(10 * MS) == pytest.approx(0.055)
    assert f.sample(15 * MS) == pytest.approx(0.065)


def test_a_trajectory_begun_in_the_past_is_followed_on_its_own_segments():
    # Jazzy's JointTrajectoryController (trajectory.cpp, Trajectory::sample) interpolates from
    # the state before the message only up to a first point still ahead; past it, it samples the
    # message's own segment: at 5 ms the new command is 3/13 of the way from the 2 ms point
    # (0.0) to the 15 ms point (0.065), not the old command 0.045
    f = follower()
    f.accept([(10 * MS, (0.04,))], now_ns=0, to_aperture=lambda p: p)
    f.accept([(2 * MS, (0.0,)), (15 * MS, (0.065,))], now_ns=5 * MS, to_aperture=lambda p: p)
    assert f.sample(5 * MS) == pytest.approx(0.065 * 3 / 13)
    assert f.sample(10 * MS) == pytest.approx(0.065 * 8 / 13)
    assert f.sample(15 * MS) == pytest.approx(0.065)


def test_a_point_at_the_time_of_receipt_is_taken_at_once():
    # a zero stamp with time_from_start 0 ("go there now"): the stock controller starts the
    # trajectory at its first sample and holds the point from then on; it refuses a
    # trajectory only when it ends before now (validate_trajectory_msg)
    f = follower()
    f.accept([(5 * MS, (0.03,))], now_ns=5 * MS, to_aperture=lambda p: p)
    assert f.sample(5 * MS) == f.sample(6 * MS) == pytest.approx(0.03)



def test_a_new_trajectory_starts_from_the_measured_position():
    # Jazzy's default (interpolate_from_desired_state false): the segment to a first point ahead
    # starts at the joint's measured state when the controller takes the message, not at its
    # last command
    f = follower()
    f.accept([(10 * MS, (0.04,))], now_ns=0, to_aperture=lambda p: p)
    f.accept([(15 * MS, (0.065,))], now_ns=5 * MS, to_aperture=lambda p: p, measured=0.047)
    assert f.sample(5 * MS) == pytest.approx(0.047)
    assert f.sample(10 * MS) == pytest.approx(0.056)


def test_the_hand_follower_replaces_a_trajectory_as_the_stock_controller_does():
    f = JointFollower([0.5, 0.5], limits=[(0.0, 2.0), (0.0, 2.0)], names=["a", "b"])
    f.accept([(10 * MS, (1.0, 0.0))], now_ns=0)
    # begun in the past: sampled on its own segment (2 ms -> 15 ms), not from the command
    f.accept([(2 * MS, (0.0, 1.3)), (15 * MS, (1.3, 0.0))], now_ns=5 * MS)
    assert f.sample(5 * MS) == pytest.approx([0.3, 1.0])
    # a point at the time of receipt is taken at once
    f.accept([(6 * MS, (1.5, 1.5))], now_ns=6 * MS)
    assert f.sample(6 * MS) == pytest.approx([1.5, 1.5])


def test_a_new_hand_trajectory_starts_from_the_measured_joints():
    # as the jaws' follower: the segment to a first point ahead starts at the joints' measured
    # state when the controller takes the message, not at their last command
    f = JointFollower([0.5, 0.5], limits=[(0.0, 2.0), (0.0, 2.0)], names=["a", "b"])
    f.accept([(10 * MS, (1.0, 0.0))], now_ns=0)
    f.accept([(15 * MS, (1.5, 1.0))], now_ns=5 * MS, measured=(0.6, 0.4))
    assert f.sample(5 * MS) == pytest.approx([0.6, 0.4])
    assert f.sample(10 * MS) == pytest.approx([1.05, 0.7])


@pytest.mark.parametrize("points, why", [
    ([], "no points"),
    ([(10 * MS, (float("nan"),))], "non-finite"),
    ([(10 * MS, (0.09,))], "outside the opening range"),
    ([(10 * MS, (-0.001,))], "outside the opening range"),
    ([(10 * MS, (0.04,)), (10 * MS, (0.03,))], "strictly increasing"),
    ([(10 * MS, (0.04, 0.03))], "different apertures"),
    ([(1 * MS, (0.04,))], "in the past"),
])
def test_a_refused_trajectory_keeps_the_active_one(points, why):
    f = follower()
    f.accept([(20 * MS, (0.03,))], now_ns=0, to_aperture=lambda p: p)
    before = list(f.knots)
    with pytest.raises(TrajectoryRefused, match=why):
        f.accept(points, now_ns=2 * MS, to_aperture=lambda p: p)
    assert f.knots == before


def test_jaw_line_round_trip_and_symmetry():
    line = JawLine.between(np.array([0.01, -0.027]), np.array([0.03, 0.027]), reach=0.002)
    first, second = line.positions(0.031)
    assert line.aperture(first, second) == pytest.approx(0.031, abs=1e-15)
    np.testing.assert_allclose(0.5 * (first + second), line.centre, atol=1e-15)
    with pytest.raises(ValueError, match="overlap"):
        JawLine.between(np.zeros(2), np.array([0.0, 0.003]), reach=0.002)


# --------------------------------------------------------------------------- the scene section
def test_the_shipped_sponge_maps_its_jaws_to_the_generic_gripper():
    jaws = scene_controller(load_scene(SPONGE), SPONGE)
    assert jaws.topic == "gripper_controller/joint_trajectory"
    assert jaws.joints == ("finger_joint",) and jaws.jaws == ("F1", "F2")
    # transmission of generic_85mm: 0.8 rad closed, 0 rad open at 85 mm
    assert jaws.joint_positions(0.085)[0] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("controller, message", [
    ({"jaws": ["F1", "F1"]}, "controller.jaws must be two distinct"),
    ({"joints": ["a", "b"]}, "controller.joints must be 1 distinct"),
    ({"device": "no_such_gripper"}, "controller.device: no shipped device 'no_such_gripper'"),
    ({"device": "nope.yaml"}, "controller.device: gripper device file not found"),
    ({"type": "effort_gripper"}, "controller.type"),
    ({"type": "gripper_action", "joints": ["a", "b"]}, "controller.joints must be 1 distinct"),
])
def test_controller_section_errors_name_the_field(controller, message):
    section = {"type": "joint_trajectory", "name": "gripper_controller",
               "device": "generic_85mm", **controller}
    with pytest.raises(SceneError, match=message):
        scene_controller(parse_scene(sponge_data(controller=section)), SPONGE)


def test_loading_a_scene_checks_its_controller_section(tmp_path):
    data = sponge_data()
    data["controller"]["jaws"] = ["F2", "F1", "F1"]
    with pytest.raises(SceneError, match="controller.jaws must be two distinct"):
        load_scene(write_scene(tmp_path, data))


def test_a_jaw_whose_tip_is_not_the_device_pad_is_refused():
    data = sponge_data()
    data["fingers"]["F2"]["tip"] = {"shape": "pad", "width": 0.03, "edge_radius": 0.002}
    with pytest.raises(SceneError, match="fingers.F2.tip must be the device's pad"):
        scene_controller(parse_scene(data), SPONGE)


# --------------------------------------------------------------------------- end to end
def run_sponge(path: str, record: str | None = None) -> dict:
    """Run a sponge scene on real rclpy; the ground truth and what went on the JTC topics."""
    out = run_observed(path, [
        ("trajectories", "gripper_controller/joint_trajectory", JointTrajectory),
        ("joint_states", "joint_states", JointState),
        ("setpoints", pipeline.device_topic("barrett_f1", "setpoint"),
         pipeline.message_type("geometry_msgs/msg/PoseStamped"))], record=record)
    assert out["result"].termination == "depth_reached"
    return out


def test_sponge_through_the_jtc_equals_the_cartesian_route(tmp_path):
    jtc = run_sponge(str(SPONGE), record=str(tmp_path / "bag"))
    cartesian = run_sponge(write_scene(tmp_path, sponge_data(controller=None)))
    print(f"JTC route: {len(jtc['trajectories'])} trajectories, {len(jtc['joint_states'])} "
          f"joint states, {len(jtc['events'])} events, forces {jtc['forces'].tolist()} N")
    # the routes really differ: the jaw setpoints go to the controller, not to the device topic
    assert jtc["trajectories"] and not jtc["setpoints"] and not cartesian["trajectories"]
    assert cartesian["setpoints"] and not cartesian["joint_states"]
    assert all(len(t.points) == 1 and t.joint_names == ["finger_joint"]
               for t in jtc["trajectories"])
    assert len(jtc["events"]) == 20 and jtc["events"] == cartesian["events"]
    scale = np.abs(cartesian["forces"]).max()
    print(f"largest force difference JTC - Cartesian: "
          f"{np.abs(jtc['forces'] - cartesian['forces']).max() / scale:.1e} relative")
    np.testing.assert_allclose(jtc["forces"], cartesian["forces"], rtol=0, atol=1e-6 * scale)
    assert jtc["depth"] == pytest.approx(cartesian["depth"], rel=1e-6)
    # the recording holds both controller topics, message for message (independent reader)
    with open(next((tmp_path / "bag").glob("*.mcap")), "rb") as stream:
        recorded = Counter(channel.topic for _, channel, _ in
                           make_reader(stream).iter_messages())
    assert recorded["/gripper_controller/joint_trajectory"] == len(jtc["trajectories"])
    assert recorded["/joint_states"] == len(jtc["joint_states"])
    # the joint state's effort is the jaw force through the transmission (effort_per_force 1)
    last = jtc["joint_states"][-1]
    assert last.effort[0] == pytest.approx(abs(jtc["forces"][0, 1]), rel=1e-3)


# --------------------------------------------------------------------------- hostile client
def hostile(names: list[str], positions: list[float], ms: int = 5) -> JointTrajectory:
    return JointTrajectory(joint_names=names, points=[JointTrajectoryPoint(
        positions=positions, time_from_start=Duration(nanosec=ms * MS))])


class SimWithClient:
    """The simulated hardware of a scene and a client node that answers its hello (tick 0)."""

    def __init__(self, scene: Path) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.sim = SimHardwareNode(context=self.context, parameter_overrides=[
            rclpy.parameter.Parameter("scene", value=str(scene)),
            rclpy.parameter.Parameter("participants", value=["hostile"])])
        self.client = Node("hostile", context=self.context)
        self.executor.add_node(self.sim)
        self.executor.add_node(self.client)
        self.pub = self.client.create_publisher(
            JointTrajectory, "gripper_controller/joint_trajectory", pipeline.loop_qos(10))
        pipeline.Participant(self.client, "hostile", [], [self.pub])
        self.spin_until(lambda: self.pub.get_subscription_count() > 0)
        self.spin_until(lambda: self.sim.now_ns >= 0)

    def spin_until(self, condition, timeout: float = 10.0) -> None:
        deadline = time.monotonic() + timeout
        while not condition() and time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.05)

    def close(self) -> None:
        self.executor.shutdown()
        self.sim.destroy_node()
        self.client.destroy_node()
        rclpy.shutdown(context=self.context)


def test_a_hostile_trajectory_is_refused_with_a_log_line_not_followed(capfd):
    rig = SimWithClient(SPONGE)
    sim, pub = rig.sim, rig.pub
    try:
        assert sim.now_ns == 0
        jtc = sim.controller
        before = list(jtc.follower.knots)
        gripper = jtc.controller.gripper
        for msg in (hostile(["wrong_joint"], [0.4]),
                    hostile(["finger_joint"], [float("nan")]),
                    hostile(["finger_joint"], list(gripper.joint_positions(0.1))),
                    hostile(["finger_joint", "finger_joint"], [0.4, 0.4]),
                    hostile(["finger_joint"], [0.4, 0.5])):
            pub.publish(msg)
        rig.spin_until(lambda: len(jtc.refusals) >= 5)
        assert jtc.follower.knots == before and sim.now_ns == 0
        assert len(jtc.refusals) == 5
        for reason, text in zip(jtc.refusals, ("not the controller's joints", "non-finite",
                                               "outside the opening range",
                                               "not the controller's joints", "2 positions")):
            assert text in reason
        # a valid one is followed: 0.05 m -> 0.04 m in 5 ms is 0.048 m at tick 1 (1 ms), of
        # which the joint's speed limit (max_speed 0.15 m/s of aperture) lets 0.15 mm through
        pub.publish(hostile(["finger_joint"], list(gripper.joint_positions(0.04))))
        rig.spin_until(lambda: sim.now_ns >= MS)
        assert sim.now_ns == MS and jtc.follower.sample(MS) == pytest.approx(0.048)
        world = sim.world.positions
        assert jtc.line.aperture(world["F1"], world["F2"]) == pytest.approx(0.04985, abs=1e-12)
    finally:
        rig.close()
    err = capfd.readouterr().err
    assert err.count("refused the trajectory on /gripper_controller/joint_trajectory") == 5
    # docs/grippers.md quotes the first refusal's log line, its stamp as [...]
    logged = [re.sub(r"^(\[\w+\]) \[[\d.]+\]", r"\1 [...]", line) for line in err.splitlines()]
    assert grippers_md_text("refused the trajectory") in logged, err


def grippers_md_text(containing: str) -> str:
    """The one-line ``text`` block of docs/grippers.md that contains ``containing``."""
    found = [b.lines for b in blocks(REPO / "docs" / "grippers.md")
             if b.language == "text" and containing in "\n".join(b.lines)]
    assert len(found) == 1 and len(found[0]) == 1, found
    return found[0][0]


def test_a_zero_stamp_point_at_time_zero_is_followed_not_refused():
    # "go there now" (header.stamp 0, time_from_start 0): Jazzy's controller accepts it (it
    # refuses only a trajectory with a non-zero stamp that ends in the past) and commands the
    # point from its first update on
    rig = SimWithClient(SPONGE)
    sim, pub = rig.sim, rig.pub
    try:
        jtc = sim.controller
        gripper = jtc.controller.gripper
        pub.publish(hostile(["finger_joint"], list(gripper.joint_positions(0.04)), ms=0))
        rig.spin_until(lambda: sim.now_ns >= MS or jtc.refusals)
        assert jtc.refusals == []
        assert sim.now_ns == MS and jtc.follower.sample(MS) == pytest.approx(0.04)
        # the joint's speed limit lets 0.15 mm of aperture through in the 1 ms tick
        world = sim.world.positions
        assert jtc.line.aperture(world["F1"], world["F2"]) == pytest.approx(0.04985, abs=1e-12)
    finally:
        rig.close()



def test_the_simulated_controller_starts_a_trajectory_from_the_measured_aperture():
    rig = SimWithClient(SPONGE)
    sim, pub = rig.sim, rig.pub
    try:
        jtc = sim.controller
        target = list(jtc.controller.gripper.joint_positions(0.04))
        pub.publish(hostile(["finger_joint"], target))
        rig.spin_until(lambda: sim.now_ns >= MS)
        # tick 1: commanded 0.048 m, measured 0.04985 m (the joint's speed limit)
        measured = jtc.aperture
        assert jtc.follower.sample(MS) == pytest.approx(0.048)
        assert measured == pytest.approx(0.04985, abs=1e-12)
        pub.publish(hostile(["finger_joint"], target))
        rig.spin_until(lambda: sim.now_ns >= 2 * MS)
        assert jtc.refusals == []
        # from the measured 0.04985 m at 1 ms to 0.04 m at 6 ms (the old command 0.048 m
        # would give 0.0464 m at 2 ms)
        assert jtc.follower.sample(2 * MS) == pytest.approx(measured + (0.04 - measured) / 5)
    finally:
        rig.close()


def test_the_simulated_controller_keeps_the_device_speed_limit(tmp_path):
    """A slow gripper (max_speed 0.04 m/s of aperture, below its jaws' devices' 0.1 m/s each):
    commanded to close 10 mm at once, the jaws close 0.04 mm per 1 ms tick, not faster.
    """
    device = yaml.safe_load((SPONGE.parents[1] / "devices" / "generic_85mm.yaml").read_text())
    device.update(name="slow_85mm", max_speed=0.04)
    (tmp_path / "slow_85mm.yaml").write_text(yaml.safe_dump(device))
    data = sponge_data()
    data["controller"]["device"] = "slow_85mm.yaml"
    rig = SimWithClient(Path(write_scene(tmp_path, data)))
    try:
        jtc = rig.sim.controller
        gripper = jtc.controller.gripper
        world = rig.sim.world.positions
        apertures = [jtc.line.aperture(world["F1"], world["F2"])]
        for tick in range(1, 6):
            rig.pub.publish(hostile(["finger_joint"],
                                    list(gripper.joint_positions(apertures[0] - 0.01)), ms=1))
            rig.spin_until(lambda t=tick: rig.sim.now_ns >= t * MS)
            apertures.append(jtc.line.aperture(world["F1"], world["F2"]))
    finally:
        rig.close()
    steps = -np.diff(apertures)
    print(f"aperture per tick [mm]: {(steps * 1e3).tolist()}")
    np.testing.assert_allclose(steps, 0.04 * 1e-3, rtol=1e-9)


# --------------------------------------------------------------------------- recording
def test_a_processes_run_records_the_controller_topics_from_their_first_message(tmp_path):
    """Across processes the recorder can see a publisher before that writer matched its reader;
    the controller's per-tick topics (the executor's trajectory and the joint_state_broadcaster's
    joint_states) are transient-local and awaited by the recorder, so the bag has them from
    their first message: a joint state per tick from tick 0, a trajectory per executor cycle.
    """
    from squeeze_grasp_ros.ros.run.options import RunOptions, node_parameters
    from squeeze_grasp_ros.ros.run.runner import PipelineRunner

    data = sponge_data(squeeze={"type": "stable", "relative_depth": 0.04})
    data["object"]["mesh"]["nodes"] = 300
    path = write_scene(tmp_path, data)
    params = node_parameters(load_scene(path), path, RunOptions(path, record="x"), 1.0)
    assert params["recorder"]["lockstep_topics"] == ["gripper_controller/joint_trajectory",
                                                     "joint_states"]
    result = PipelineRunner(RunOptions(path, record=str(tmp_path / "bag"),
                                       processes=True)).run()
    assert result["mode"] == "processes" and result["termination"] == "depth_reached"
    stamps: dict[str, list[int]] = {}
    qos: dict[str, str] = {}
    with open(next((tmp_path / "bag").glob("*.mcap")), "rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages():
            stamps.setdefault(channel.topic, []).append(message.log_time)
            qos[channel.topic] = channel.metadata.get("offered_qos_profiles", "")
    ticks, states = stamps["/sim/tick"], stamps["/joint_states"]
    trajectories = stamps["/gripper_controller/joint_trajectory"]
    print(f"{len(ticks)} ticks, {len(states)} joint states, {len(trajectories)} trajectories")
    assert states == ticks and states[0] == 0
    dt = int(round(float(data.get("sim", {}).get("dt", 1e-3)) * 1e9))
    assert np.all(np.diff(trajectories) == dt) and len(trajectories) == result["ticks"]
    for topic in ("/joint_states", "/gripper_controller/joint_trajectory"):
        assert "durability: transient_local" in qos[topic], (topic, qos[topic])


# --------------------------------------------------------------------------- effort limit
def weak_gripper_scene(tmp_path: Path, max_force: float) -> Path:
    """The sponge scene on the generic gripper with its ``max_force`` lowered (N)."""
    device = yaml.safe_load((SPONGE.parents[1] / "devices" / "generic_85mm.yaml").read_text())
    device.update(name="weak_85mm", max_force=max_force)
    (tmp_path / "weak_85mm.yaml").write_text(yaml.safe_dump(device))
    data = sponge_data()
    data["controller"]["device"] = "weak_85mm.yaml"
    return Path(write_scene(tmp_path, data))


def squeeze_by_hand(scene: Path, ticks: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Command the scene's JTC to close 10 mm below the initial aperture, one message per tick;
    the measured (aperture m, jaw force N) of each tick, and the commanded aperture.
    """
    rig = SimWithClient(scene)
    try:
        jtc = rig.sim.controller
        target = jtc.aperture - 0.01
        apertures, forces = [], []
        for tick in range(1, ticks + 1):
            rig.pub.publish(hostile(["finger_joint"],
                                    list(jtc.controller.gripper.joint_positions(target)), ms=1))
            rig.spin_until(lambda t=tick: rig.sim.now_ns >= t * MS)
            apertures.append(jtc.aperture)
            forces.append(jtc.force)
    finally:
        rig.close()
    return np.array(apertures), np.array(forces), target


def test_the_simulated_controller_stops_the_jaws_at_the_device_effort_limit(tmp_path):
    """A position JTC limits no effort; the gripper's drive does: commanded 10 mm into the
    sponge, a gripper of 1.5 N closes until its jaw force reaches 1.5 N and holds there, short
    of the command, while the stock 235 N gripper goes on loading the sponge.
    """
    ticks = 120
    weak_a, weak_f, target = squeeze_by_hand(weak_gripper_scene(tmp_path, 1.5), ticks)
    strong_a, strong_f, _ = squeeze_by_hand(SPONGE, ticks)
    stop = int(np.argmax(weak_f >= 1.5))
    print(f"weak gripper: {weak_f[stop]:.4g} N at tick {stop + 1}, held at "
          f"{weak_a[-1] * 1e3:.4f} mm (commanded {target * 1e3:.4f} mm); stock gripper "
          f"{strong_f[-1]:.4g} N at {strong_a[-1] * 1e3:.4f} mm")
    assert weak_f[stop] >= 1.5 and 0 < stop < ticks - 20
    # up to the stop both grippers close alike; after it the weak one holds
    np.testing.assert_allclose(weak_a[:stop + 1], strong_a[:stop + 1], rtol=0, atol=1e-12)
    assert np.ptp(weak_a[stop + 1:]) < 1e-6 and weak_a[-1] > target + 5e-3
    assert weak_f.max() < 1.5 * 1.2 and strong_f[-1] > 2 * 1.5


def test_the_executor_refuses_a_plan_beyond_the_device_effort(tmp_path):
    """The sponge's plan needs 5.97 N per jaw; on a 3 N gripper the executor refuses the goal
    (invalid_goal, naming the force and the limit) and sends no trajectory.
    """
    out = run_observed(str(weak_gripper_scene(tmp_path, 3.0)), [
        ("trajectories", "gripper_controller/joint_trajectory", JointTrajectory)])
    result = out["result"]
    print(result.message)
    assert result.termination == "invalid_goal" and not result.success
    assert "max_force 3 N" in result.message and "jaw force of 5.97 N" in result.message
    assert result.message == grippers_md_text("beyond weak_85mm's max_force")  # as quoted
    assert out["trajectories"] == []


def test_the_executor_refuses_a_squeeze_below_the_device_opening(tmp_path):
    """A lab's device closing no further than 45 mm: the sponge's plan takes the jaws from 50
    to 42.5 mm. Before, the executor sent the trajectories, the controller refused each one
    ("point 0's aperture ... is outside the opening range") and the goal waited for the stall
    watch (30 s of sim time); now it ends invalid_goal at its first cycle, naming the range,
    and sends no trajectory.
    """
    device = yaml.safe_load((SPONGE.parents[1] / "devices" / "generic_85mm.yaml").read_text())
    device["name"], device["opening"]["min"] = "narrow_85mm", 0.045
    device["transmission"]["position_limits"] = [0.0, 0.8 - 0.045 * 0.8 / 0.085]
    (tmp_path / "narrow_85mm.yaml").write_text(yaml.safe_dump(device))
    data = sponge_data()
    data["controller"]["device"] = "narrow_85mm.yaml"
    out = run_observed(write_scene(tmp_path, data), [
        ("trajectories", "gripper_controller/joint_trajectory", JointTrajectory)])
    result = out["result"]
    print(result.message)
    assert result.termination == "invalid_goal" and not result.success
    assert result.message == grippers_md_text("outside narrow_85mm's opening")  # as quoted
    assert "from 50 mm to 42.5 mm" in result.message
    assert out["trajectories"] == [] and out["depth"] == 0.0
