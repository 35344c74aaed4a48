# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Hardware mode (``lockstep: false``) against an outside JointTrajectoryController, in wall time.

The controller here is not ours: a plain rclpy node that takes ``JointTrajectory`` on
``gripper_controller/joint_trajectory``, moves its one joint toward the last point at the
device's speed and publishes ``joint_states`` at 100 Hz, as joint_state_broadcaster would; and
a stand-in for the lab's forward kinematics that publishes the jaws' tips once, or none at all
(the joint_states-only route: the gripper's pose as the monitor's ``gripper_pose`` parameter or
one message on ``gripper_pose``, as tf2 gives it); and a plain
rclpy ``control_msgs/action/GripperCommand`` server closing on a spring whose force stops rising
(a slip). Our monitor and executor run in hardware mode on wall-clock timers. The tests read the
commands as a controller would: topic, joint names, positions in the device file's joint
convention (0 rad open, 0.8 rad closed), ``time_from_start`` and the "on receipt" stamp;
``max_effort`` and the cancel on the slip alarm.
"""
from __future__ import annotations

import gc
import importlib.util
import math
import re
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import rclpy
import yaml
from geometry_msgs.msg import PoseStamped
from rclpy.action import ActionClient, ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_ros.control.motion import GraspGoal
from squeeze_grasp_ros.ros import messages, nodes
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "config" / "scenes" / "sponge_gripper.yaml"
DEVICE = yaml.safe_load((ROOT / "config" / "devices" / "generic_85mm.yaml").read_text())
PERIOD = 0.01
"""The executor's control period here, s."""
OPEN = 0.06
"""The jaws' aperture at the start, m."""
DEPTH = 0.01
"""The squeeze depth, m: each jaw closes DEPTH / sqrt 2 (depth is the stacked translation)."""
PLANNED = OPEN - math.sqrt(2.0) * DEPTH
"""The planned aperture, m."""
NO_CONTROL_MSGS = importlib.util.find_spec("control_msgs") is None


def joint_of(aperture: float) -> float:
    """The device file's joint position of a jaw aperture, by its stated linear transmission."""
    t = DEVICE["transmission"]
    return t["position_per_aperture"] * aperture + t["position_offset"]


class Joint:
    """The gripper's one joint: moves toward ``target`` at ``speed`` (m/s of aperture, default the
    device's); its effort is
    a spring of ``stiffness`` (N/m of closing) from first touch at ``touch`` (aperture, m) that
    stops rising at ``plateau`` (N): the jaws slide over the object there.
    """

    def __init__(self, aperture: float, *, touch: float = 0.0, stiffness: float = 0.0,
                 plateau: float = 0.0, speed: float = DEVICE["max_speed"]) -> None:
        self.q = self.target = joint_of(aperture)
        self.speed = abs(DEVICE["transmission"]["position_per_aperture"]) * speed
        self.touch, self.stiffness, self.plateau = touch, stiffness, plateau
        self.lock = threading.Lock()

    def step(self, dt: float) -> tuple[float, float]:
        with self.lock:
            self.q += float(np.clip(self.target - self.q, -self.speed * dt, self.speed * dt))
            q = self.q
        t = DEVICE["transmission"]
        aperture = (q - t["position_offset"]) / t["position_per_aperture"]
        force = min(self.stiffness * max(self.touch - aperture, 0.0), self.plateau)
        return q, force * t["effort_per_force"]


class OutsideHardware(Node):
    """joint_state_broadcaster at 100 Hz for a :class:`Joint`, and a JTC-like trajectory
    subscriber that sets the joint's target to the last point.
    """

    def __init__(self, context: Context, joint: Joint) -> None:
        super().__init__("outside_gripper", context=context)
        self.joint = joint
        self.received: list[JointTrajectory] = []
        self.create_subscription(JointTrajectory, "gripper_controller/joint_trajectory",
                                 self._command, 10)
        self.states = self.create_publisher(JointState, "joint_states", 10)
        self.dt = 0.01
        self.create_timer(self.dt, self._step)

    def _command(self, msg: JointTrajectory) -> None:
        self.received.append(msg)
        with self.joint.lock:
            self.joint.target = float(msg.points[-1].positions[0])

    def _step(self) -> None:
        q, effort = self.joint.step(self.dt)
        msg = JointState(name=["finger_joint"], position=[q], effort=[effort])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.states.publish(msg)


class LabThread:
    """An executor spun in a thread of its own by ``spin_once``."""

    def __init__(self, executor, *spun: Node) -> None:
        self.executor, self.running = executor, True
        for node in spun:
            executor.add_node(node)
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self) -> None:
        while self.running:
            self.executor.spin_once(timeout_sec=0.02)

    def stop(self) -> None:
        self.running = False
        self.thread.join(timeout=5.0)
        self.executor.shutdown()


class Rig:
    """The outside hardware, our monitor and executor in hardware mode, the jaws' kinematics
    stand-in and a grasp client, in one context, on one ``EventsExecutor`` spun in the test's
    thread as ``run_node`` spins a node (:class:`~squeeze_grasp_ros.ros.nodes.Spinner`); a
    lab's gripper action server (:meth:`lab_node`), which blocks in its goals, on a
    multi-threaded executor in a thread of its own. Before, all of them shared one
    multi-threaded executor spun by ``spin_once`` in the test's thread: each call first re-ran
    the goal's suspended execute coroutine, the process ran at 100 % CPU, and the executor's
    100 Hz control timer ran 15 to 38 times a second, stretching every wall-clock budget (a
    0.5 s stall_timeout ended after 6.5 s).
    """

    def __init__(self, scene: Path, joint: Joint, *,
                 reach: float | None = DEVICE["pad"]["edge_radius"],
                 gripper_pose: list[float] | None = None,
                 executor: tuple[Parameter, ...] = ()) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.outside = OutsideHardware(self.context, joint)
        common = [Parameter("lockstep", value=False),
                  Parameter("finger_devices", value=["F1:jaw_f1", "F2:jaw_f2"]),
                  Parameter("controller_scene", value=str(scene))]
        posed = [] if gripper_pose is None else [Parameter("gripper_pose", value=gripper_pose)]
        self.monitor = MonitorNode(context=self.context, parameter_overrides=common + posed + [
            Parameter("streams", value=[""]), Parameter("rate", value=100.0),
            Parameter("stale_after", value=0.1), Parameter("force_watch", value=False)])
        self.executor = ExecutorNode(context=self.context, parameter_overrides=common + [
            Parameter("period", value=PERIOD), Parameter("stale_budget", value=1.0),
            *executor])
        self.kinematics = Node("jaw_kinematics", context=self.context)
        self.client_node = Node("grasp_client", context=self.context)
        self.client = ActionClient(self.client_node, ExecuteGrasp, pipeline.ACTION)
        self.nodes = [self.outside, self.monitor, self.executor, self.kinematics,
                      self.client_node]
        self.spin = EventsExecutor(context=self.context)
        for node in self.nodes:
            self.spin.add_node(node)
        self.slice = nodes.Spinner(self.spin, self.client_node, 0.02)
        self.lab: LabThread | None = None
        if reach is None:       # no pose topics
            return
        # the tips' centres: half the aperture between the pad faces plus the pad's edge radius
        tip = OPEN / 2 + reach
        now = self.kinematics.get_clock().now().nanoseconds
        for device, y in (("jaw_f1", -tip), ("jaw_f2", tip)):
            self.kinematics.create_publisher(
                PoseStamped, pipeline.device_topic(device, "pose"), pipeline.LATCHED).publish(
                messages.pose_msg((0.0, y), now, pipeline.FRAME))

    def spin_until(self, condition, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while not condition() and time.monotonic() < deadline:
            self.slice()

    def squeeze(self, *, seen: bool = True) -> ExecuteGrasp.Result:
        """Send the squeeze of DEPTH and return its result (``seen``: once the monitor has
        fixed the jaw line).
        """
        self.spin_until(lambda: self.client.server_is_ready()
                        and (self.monitor.jaws.line is not None or not seen))
        assert self.monitor.jaws.line is not None or not seen, "the monitor never fixed the line"
        s = 1.0 / math.sqrt(2.0)
        goal = GraspGoal(("F1", "F2"), np.array([[0.0, s], [0.0, -s]]), DEPTH)
        sent = self.client.send_goal_async(messages.grasp_goal_msg(goal))
        self.spin_until(sent.done)
        assert sent.result().accepted
        done = sent.result().get_result_async()
        self.spin_until(done.done, timeout=60.0)
        assert done.done(), "the grasp goal did not end within 60 s"
        return done.result().result

    def lab_node(self) -> Node:
        """A node for the lab's gripper action server, spun in a thread of its own (the server
        blocks in its goals).
        """
        node = Node("outside_gripper_action", context=self.context)
        self.nodes.append(node)
        self.lab = LabThread(MultiThreadedExecutor(num_threads=3, context=self.context), node)
        return node

    def close(self) -> None:
        self.client.destroy()
        if self.lab is not None:
            self.lab.stop()
        self.spin.shutdown()
        for node in self.nodes:
            node.destroy_node()
        rclpy.shutdown(context=self.context)
        # rclpy prints "The following exception was never retrieved" when a task of the stopped
        # executor is collected: drop the executors and their nodes and collect here, not in a
        # later test that reads stderr
        self.spin = self.lab = self.slice = self.nodes = self.outside = self.monitor = None
        self.executor = None
        gc.collect()


def test_the_executor_drives_an_outside_jtc_in_wall_time(capfd):
    rig = Rig(SCENE, Joint(OPEN))
    try:
        result = rig.squeeze()
        assert result.termination == ExecuteGrasp.Result.DEPTH_REACHED, result.message
        commands = list(rig.outside.received)
        assert commands, "the outside controller received no trajectory"
        for msg in commands:
            assert list(msg.joint_names) == ["finger_joint"]
            assert len(msg.points) == 1 and len(msg.points[0].positions) == 1
            tfs = msg.points[0].time_from_start
            assert tfs.sec * 10**9 + tfs.nanosec == round(PERIOD * 1e9)
            assert msg.header.stamp.sec == 0 and msg.header.stamp.nanosec == 0  # on receipt
        q = np.array([msg.points[0].positions[0] for msg in commands])
        lo, hi = sorted((joint_of(DEVICE["opening"]["min"]), joint_of(DEVICE["opening"]["max"])))
        assert np.all((q >= lo) & (q <= hi))
        assert np.all(np.diff(q) >= -1e-12), "a closing squeeze commanded an opening joint move"
        # the last command is the planned aperture in the device's joint convention (to 0.1 %
        # of the opening range)
        assert q[-1] == pytest.approx(joint_of(PLANNED), abs=1e-3 * (hi - lo))
        assert rig.outside.joint.q == pytest.approx(q[-1], abs=1e-3 * (hi - lo))
        assert result.depth == pytest.approx(DEPTH, rel=0.05)
    finally:
        rig.close()
    assert "pose readings put the pad faces" not in capfd.readouterr().err


def hold_the_gil(seconds: float) -> None:
    """Stall the whole process for ``seconds`` as a long garbage collection would: this thread
    keeps the GIL (no forced switch) while it spins.
    """
    interval = sys.getswitchinterval()
    sys.setswitchinterval(10.0 * seconds)
    try:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            pass
    finally:
        sys.setswitchinterval(interval)


def test_a_stall_of_the_whole_process_is_not_the_monitors_silence(capfd):
    """The process that runs the monitor and the executor stands still for 1.3 s mid-squeeze,
    more than the executor's stale_budget (1 s): nobody could publish or hear. The goal goes on
    to its depth. Before, it ended ``stale_data`` ("no /monitor/status message for 1.305 s ...
    (is the monitor running?)"): a loaded CI machine failed the test above so.
    """
    rig = Rig(SCENE, Joint(OPEN))
    stalled = threading.Event()

    def stall() -> None:
        while rig.executor.goal is None or rig.executor.goal.start_ns is None:
            time.sleep(0.005)
        hold_the_gil(1.3)
        stalled.set()

    thread = threading.Thread(target=stall, daemon=True)
    thread.start()
    try:
        result = rig.squeeze()
        thread.join(timeout=10.0)
        assert stalled.is_set(), "the stall never came: the goal ended before it started"
        assert result.termination == ExecuteGrasp.Result.DEPTH_REACHED, result.message
        assert result.depth == pytest.approx(DEPTH, rel=0.05)
    finally:
        rig.close()
    stall = re.search(r"the control timer did not run for ([0-9.]+) s \(period 0\.01 s\): this "
                      r"process stood still \(garbage collection, a starved CPU\); no setpoint "
                      r"went out meanwhile", capfd.readouterr().err)
    assert stall is not None and 1.3 <= float(stall.group(1)) < 3.0


def test_a_control_period_the_timer_cannot_keep_is_named(capfd):
    """Period 0.1 ms asks for 10,000 control cycles a second, more than an rclpy timer beside
    the rig's other nodes runs: the squeeze still ends at its depth (each cycle advances one
    period), and the executor says how slow its cycles ran against the asked rate.
    """
    rig = Rig(SCENE, Joint(OPEN), executor=(Parameter("period", value=1e-4),))
    try:
        result = rig.squeeze()
        assert result.termination == ExecuteGrasp.Result.DEPTH_REACHED, result.message
    finally:
        rig.close()
    rate = result.ticks / result.duration
    assert rate < 7500.0, f"{rate:.0f} cycles a second: this machine keeps 75 % of 10 kHz"
    warned = re.search(r"the goal ran (\d+) control cycles in ([0-9.]+) s(?: \(and [0-9.]+ s of "
                       r"stalls\))?: ([0-9.e+]+) a second "
                       r"against the 1e\+04 that period 0\.0001 s asks; the motion ran and its "
                       r"time budgets counted at (\d+) % of wall time: give a period this "
                       r"machine keeps", capfd.readouterr().err)
    assert warned is not None
    assert int(warned.group(1)) == result.ticks
    running = float(warned.group(2))   # the duration outside the executor's own stalls
    assert running <= result.duration + 1e-3
    assert float(warned.group(3)) == pytest.approx(result.ticks / running, rel=2e-3)


def test_a_reader_that_starts_late_gets_the_executors_current_state():
    """``ros2 topic echo --once /executor/status`` started after a goal (or before the first)
    never printed on hardware: the status was volatile, and only published on a change (with
    ``--qos-durability transient_local`` it matched no publisher). Now the executor publishes
    its state at start and keeps the current one for late readers.
    """
    from rclpy.qos import DurabilityPolicy, QoSProfile

    from squeeze_grasp_interfaces.msg import ExecutorStatus

    rig = Rig(SCENE, Joint(OPEN))
    readers: list[Node] = []

    def late_reader() -> list[ExecutorStatus]:
        got: list[ExecutorStatus] = []
        node = Node(f"late_reader_{len(readers)}", context=rig.context)
        node.create_subscription(ExecutorStatus, pipeline.EXECUTOR_STATUS, got.append,
                                 QoSProfile(depth=10,
                                            durability=DurabilityPolicy.TRANSIENT_LOCAL))
        readers.append(node)
        rig.spin.add_node(node)
        rig.spin_until(lambda: got)
        rig.spin_until(lambda: False, timeout=0.3)  # anything else kept would arrive meanwhile
        return got

    try:
        assert [(s.state, s.message) for s in late_reader()] == [(ExecutorStatus.IDLE, "")]
        result = rig.squeeze()
        assert result.termination == ExecuteGrasp.Result.DEPTH_REACHED, result.message
        late = late_reader()
        assert [(s.state, s.message) for s in late] == [(ExecutorStatus.IDLE, result.message)]
        # the status's depth is the measured one (ExecutorStatus.msg said "commanded")
        assert late[0].depth == result.depth
    finally:
        for node in readers:
            rig.spin.remove_node(node)
            node.destroy_node()
        rig.close()


def test_an_inactive_jtc_ends_the_grasp_gripper_stalled_after_stall_timeout():
    """A JointTrajectoryController loaded but not active drops every trajectory: the joint
    stays open. Before, the grasp goal went on "squeezing" at depth 0 for ever (70 s here
    before the test gave up); now it ends gripper_stalled once the jaws have stood still short
    of their setpoints for stall_timeout.
    """
    rig = Rig(SCENE, Joint(OPEN, speed=0.0), executor=(Parameter("stall_timeout", value=0.5),))
    try:
        result = rig.squeeze()
        assert result.termination == ExecuteGrasp.Result.GRIPPER_STALLED, result.message
        assert not result.success and result.depth == pytest.approx(0.0, abs=1e-6)
        assert result.message.startswith("F1, F2 stood still (within 0.1 mm) for "), \
            result.message
        # the setpoints run on along the planned path (7.071 mm each) while the jaws stand
        gaps = re.search(r"\(stall_timeout 0\.5 s\) short of the setpoints by F1 ([0-9.]+) "
                         r"mm, F2 ([0-9.]+) mm: a JointTrajectoryController that is loaded but "
                         r"not active drops every trajectory", result.message)
        assert gaps is not None, result.message
        assert all(0.0 < float(gap) <= 7.071 for gap in gaps.groups())
        assert 0.5 < result.duration < 5.0, result.duration
        assert rig.outside.joint.q == joint_of(OPEN)
    finally:
        rig.close()


def pose_topics(rig: Rig) -> dict[str, int]:
    """The publishers of the jaws' pose topics (none on the joint_states-only route)."""
    return {d: rig.monitor.count_publishers(pipeline.device_topic(d, "pose"))
            for d in ("jaw_f1", "jaw_f2")}


def test_joint_states_alone_with_the_gripper_pose_parameter_end_as_planned(capfd):
    # no pose topic at all: the gripper's centre (0, 0) and closing direction +y (yaw 90 deg,
    # F1's jaw closing toward F2's) fix the jaw line, joint_states move the jaws on it
    rig = Rig(SCENE, Joint(OPEN), reach=None, gripper_pose=[0.0, 0.0, 90.0])
    try:
        result = rig.squeeze()
        assert pose_topics(rig) == {"jaw_f1": 0, "jaw_f2": 0}
        assert result.termination == ExecuteGrasp.Result.DEPTH_REACHED, result.message
        assert result.success
        q = np.array([msg.points[0].positions[0] for msg in rig.outside.received])
        lo, hi = sorted((joint_of(DEVICE["opening"]["min"]), joint_of(DEVICE["opening"]["max"])))
        assert np.all(np.diff(q) >= -1e-12)
        assert q[-1] == pytest.approx(joint_of(PLANNED), abs=1e-3 * (hi - lo))
        assert result.depth == pytest.approx(DEPTH, rel=0.05)
        # the jaws' tips as the monitor puts them: on the line x = 0, symmetric about the
        # centre, the pad faces at the aperture of the joint's reading
        line = rig.monitor.jaws.line
        first, second = line.positions(OPEN)
        np.testing.assert_allclose(first, [0.0, -(OPEN / 2 + DEVICE["pad"]["edge_radius"])],
                                   atol=1e-15)
        np.testing.assert_allclose(second, -first, atol=1e-15)
        assert "jaw line at (0, 0) m, yaw 90 deg" in rig.monitor.ready_summary()
    finally:
        rig.close()
    assert "pose readings put the pad faces" not in capfd.readouterr().err


def test_joint_states_alone_with_a_gripper_pose_message_stop_on_the_slip(tmp_path):
    # the gripper's pose as a lab's tf2 lookup gives it (PoseStamped in the object frame, a
    # rotation about z), published once, latched; the jaws close on a spring whose force stops
    # rising at 10 N (50 mm), short of the planned 45.9 mm
    joint = Joint(OPEN, touch=0.055, stiffness=2000.0, plateau=10.0, speed=0.02)
    rig = Rig(SCENE, joint, reach=None)
    publisher = rig.kinematics.create_publisher(PoseStamped, pipeline.GRIPPER_POSE,
                                                pipeline.LATCHED)
    pose = PoseStamped()
    pose.header.frame_id = pipeline.FRAME
    pose.pose.orientation.z = pose.pose.orientation.w = math.sqrt(0.5)   # yaw 90 deg
    publisher.publish(pose)
    try:
        result = rig.squeeze()
        assert pose_topics(rig) == {"jaw_f1": 0, "jaw_f2": 0}
        assert result.termination == ExecuteGrasp.Result.SLIP_ALARM, result.message
        assert not result.success and "slip" in result.message
        np.testing.assert_allclose(rig.monitor.jaws.line.direction, [0.0, 1.0], atol=1e-15)
        # the jaws stopped past the plateau's start, short of the plan: the last command holds
        q = [msg.points[0].positions[0] for msg in rig.outside.received]
        assert joint_of(0.050) < q[-1] < joint_of(PLANNED)
    finally:
        rig.close()


def test_a_gripper_pose_out_of_the_plane_or_frame_is_refused():
    def stamped(frame: str, tilt: float) -> PoseStamped:
        msg = PoseStamped()
        msg.header.frame_id = frame
        # the closing direction (x axis) turned by ``tilt`` about the y axis: out of the plane
        msg.pose.orientation.y, msg.pose.orientation.w = -math.sin(tilt / 2), math.cos(tilt / 2)
        return msg

    centre, yaw = messages.gripper_line_pose(stamped("object", 0.005), "object")
    assert yaw == pytest.approx(0.0, abs=1e-12) and list(centre) == [0.0, 0.0]
    # sin 0.05 = 0.04998 > 0.01
    with pytest.raises(ValueError, match=r"leaves the object plane: its z component is 0.04998"):
        messages.gripper_line_pose(stamped("object", 0.05), "object")
    with pytest.raises(ValueError, match="in frame 'base_link', not the object frame 'object'"):
        messages.gripper_line_pose(stamped("base_link", 0.0), "object")


def test_jaw_poses_that_disagree_with_joint_states_are_named_once(capfd):
    # the lab's kinematics publishes the pad faces, not the tips' centres: 2 mm per jaw off
    rig = Rig(SCENE, Joint(OPEN), reach=0.0)
    try:
        result = rig.squeeze()
        # a failure names the goal's end: once under load 4-5 this test saw depth 0 and no cause
        assert result.termination == ExecuteGrasp.Result.DEPTH_REACHED, \
            (result.termination, result.message)
        # the jaws jump 2 mm each to the joint reading; whether the monitor's depth counts the
        # jump depends on whether its first tick had a joint state (wall time): either is named
        assert result.depth == pytest.approx(DEPTH, rel=0.05) or \
            result.depth == pytest.approx(DEPTH + math.sqrt(2.0) * 0.002, rel=0.05)
    finally:
        rig.close()
    err = capfd.readouterr().err
    assert err.count("pose readings put the pad faces 56.0000 mm apart, joint_states "
                     "60.0000 mm") == 1


def test_a_driver_repeating_an_unusable_joint_state_gets_one_warning_line_a_second(capfd):
    # a second driver on joint_states with a joint the device file does not know, at 200 Hz:
    # before, the monitor wrote a warning for every new one its 100 Hz ticks read (19 lines in
    # 2.5 s here); now one line a second, the next naming how many it did not write
    rig = Rig(SCENE, Joint(OPEN))
    try:
        # the gripper's own driver falls silent: were its valid state the newest at every tick
        # of the monitor (their 100 Hz timers in step on one executor), no refusal would come
        for timer in rig.outside.timers:
            timer.cancel()
        rogue = Node("rogue_driver", context=rig.context)
        rig.nodes.append(rogue)
        rig.spin.add_node(rogue)
        states = rogue.create_publisher(JointState, "joint_states", 10)

        def publish():
            msg = JointState(name=["wrong_joint"], position=[0.1], effort=[0.0])
            msg.header.stamp = rogue.get_clock().now().to_msg()
            states.publish(msg)

        rogue.create_timer(0.005, publish)
        start = time.monotonic()
        rig.spin_until(lambda: time.monotonic() - start > 2.5, timeout=10.0)
        elapsed = time.monotonic() - start
    finally:
        rig.close()
    lines = [line for line in capfd.readouterr().err.splitlines()
             if "ignored the joint state" in line]
    assert lines and all("wrong_joint" in line or "finger_joint" in line for line in lines)
    assert len(lines) <= elapsed / 1.0 + 1, lines
    assert len(lines) >= 2 and all(
        re.search(r"\(and \d+ more joint_states refusals in the \d\.\d s before, not "
                  r"logged\)", line) for line in lines[1:]), lines


class OutsideGripperAction:
    """A plain rclpy GripperCommand server on ``gripper_controller/gripper_cmd``: moves the joint
    to the goal's position, succeeds with ``reached_goal`` there, holds on a cancel.
    """

    def __init__(self, node: Node, joint: Joint) -> None:
        from control_msgs.action import GripperCommand
        self.action, self.joint = GripperCommand, joint
        self.goals: list = []
        self.canceled_at: float | None = None
        self.server = ActionServer(node, GripperCommand, "gripper_controller/gripper_cmd",
                                   self._execute, cancel_callback=lambda _: CancelResponse.ACCEPT,
                                   callback_group=ReentrantCallbackGroup())

    def _execute(self, handle):
        command = handle.request.command
        self.goals.append((command.position, command.max_effort))
        with self.joint.lock:
            self.joint.target = command.position
        result = self.action.Result()
        while True:
            time.sleep(0.005)
            with self.joint.lock:
                q = self.joint.q
                if handle.is_cancel_requested:
                    self.joint.target = q               # hold the measured position
                    self.canceled_at = q
            result.position = q
            if self.canceled_at is not None:
                handle.canceled()
                return result
            if abs(q - command.position) < 1e-9:
                result.reached_goal = True
                handle.succeed()
                return result


@pytest.mark.skipif(NO_CONTROL_MSGS, reason="control_msgs is not built: squeeze-grasp ros-setup "
                    "--control-msgs DIR (DIR a jazzy checkout of github.com/ros-controls/"
                    "control_msgs)")
def test_the_executor_cancels_an_outside_gripper_action_on_the_slip_alarm(tmp_path):
    scene = yaml.safe_load(SCENE.read_text())
    scene["controller"]["type"] = "gripper_action"
    path = tmp_path / "sponge_gripper_action.yaml"
    path.write_text(yaml.safe_dump(scene))
    # first touch at 55 mm, 2 kN/m, the force stops rising at 10 N (50 mm): short of the plan;
    # closing at 20 mm/s the jaws take 0.2 s from there to the plan (the alarm needs a few
    # 10 ms ticks of the monitor and the executor)
    joint = Joint(OPEN, touch=0.055, stiffness=2000.0, plateau=10.0, speed=0.02)
    rig = Rig(path, joint)
    server = OutsideGripperAction(rig.lab_node(), joint)
    try:
        result = rig.squeeze()
        assert result.termination == ExecuteGrasp.Result.SLIP_ALARM, result.message
        assert not result.success
        # one goal: the planned aperture in joint units; no force curve published, so the
        # controller's own limit, sent explicitly: the stock GripperActionController takes
        # max_effort as given, and 0 would clamp an effort interface's output to nothing
        # (generic_85mm: no max_effort in the scene, the device's 235 N at 1 per N)
        assert len(server.goals) == 1
        position, max_effort = server.goals[0]
        assert position == pytest.approx(joint_of(PLANNED), abs=1e-9)
        assert max_effort == 235.0
        # canceled past the plateau's start, short of the plan, and held there (the grasp goal
        # ends on the alarm's cycle; the cancel reaches the controller right after)
        rig.spin_until(lambda: server.canceled_at is not None, timeout=5.0)
        assert server.canceled_at is not None, "the executor never canceled the gripper goal"
        assert joint_of(0.050) < server.canceled_at < joint_of(PLANNED)
        assert joint.target == server.canceled_at
    finally:
        server.server.destroy()
        rig.close()


class InactiveGripperAction:
    """A GripperCommand server as Jazzy's GripperActionController is while loaded but not
    active: its goal callback accepts every goal, and the update that would move the joint and
    end the goal does not run; a cancel is taken.
    """

    def __init__(self, node: Node) -> None:
        from control_msgs.action import GripperCommand
        self.action = GripperCommand
        self.goals: list[float] = []
        self.canceled = threading.Event()
        self.server = ActionServer(node, GripperCommand, "gripper_controller/gripper_cmd",
                                   self._execute, cancel_callback=lambda _: CancelResponse.ACCEPT,
                                   callback_group=ReentrantCallbackGroup())

    def _execute(self, handle):
        self.goals.append(handle.request.command.position)
        while not handle.is_cancel_requested:
            time.sleep(0.01)
        self.canceled.set()
        handle.canceled()
        return self.action.Result()


@pytest.mark.skipif(NO_CONTROL_MSGS, reason="control_msgs is not built: squeeze-grasp ros-setup "
                    "--control-msgs DIR (DIR a jazzy checkout of github.com/ros-controls/"
                    "control_msgs)")
def test_a_gripper_goal_without_a_result_ends_the_grasp_after_gripper_timeout(tmp_path):
    """Before: a grasp goal through a GripperActionController loaded but not active waited for
    ever (the controller accepts the goal and never ends it); the executor said nothing.
    """
    scene = yaml.safe_load(SCENE.read_text())
    scene["controller"]["type"] = "gripper_action"
    path = tmp_path / "sponge_gripper_action.yaml"
    path.write_text(yaml.safe_dump(scene))
    rig = Rig(path, Joint(OPEN), executor=(Parameter("gripper_timeout", value=0.5),))
    server = InactiveGripperAction(rig.lab_node())
    try:
        result = rig.squeeze()
        assert result.termination == ExecuteGrasp.Result.GRIPPER_ABORTED, result.message
        assert not result.success
        assert f"{joint_of(PLANNED):.6g}" == "0.368397"  # as docs/grippers.md quotes it
        assert ("no result from gripper_controller/gripper_cmd within gripper_timeout 0.5 s of "
                f"its goal (position {joint_of(PLANNED):.6g}, max_effort 235): a stock "
                "GripperActionController that is loaded but not active accepts goals and never "
                "ends them") in result.message, result.message
        assert result.message.endswith("the gripper goal was canceled")
        assert 0.5 <= result.duration < 5.0, result.duration
        assert server.goals == [pytest.approx(joint_of(PLANNED), abs=1e-9)]
        rig.spin_until(server.canceled.is_set, timeout=5.0)
        assert server.canceled.is_set(), "the executor never canceled the gripper goal"
    finally:
        server.server.destroy()
        rig.close()


def test_a_device_without_position_limits_is_named_on_hardware(tmp_path, capfd):
    """A transmission closing the wrong way maps the joint both ways consistently, so the
    executor's own view stays right while the jaws open: only the joint's limits catch it at
    load. A hardware executor whose device gives none says so at start; with them (the shipped
    device), or in simulation, it says nothing.
    """
    device = {k: v for k, v in DEVICE.items()}
    device["transmission"] = {k: v for k, v in DEVICE["transmission"].items()
                              if k != "position_limits"}
    (tmp_path / "unlimited.yaml").write_text(yaml.safe_dump({**device, "name": "unlimited"}))
    scene = yaml.safe_load(SCENE.read_text())
    scene["controller"]["device"] = "unlimited.yaml"
    path = tmp_path / "sponge_unlimited.yaml"
    path.write_text(yaml.safe_dump(scene))
    warning = ("the device unlimited gives no transmission.position_limits: a transmission "
               "that closes the wrong way (position_per_aperture's sign, or the offset) cannot "
               "be caught before the jaws move; give the joint's limits (the URDF's) in its "
               "device file")
    for scene_path, lockstep, said in ((path, False, True), (path, True, False),
                                       (SCENE, False, False)):
        context = Context()
        rclpy.init(context=context)
        try:
            node = ExecutorNode(context=context, parameter_overrides=[
                Parameter("lockstep", value=lockstep),
                Parameter("finger_devices", value=["F1:jaw_f1", "F2:jaw_f2"]),
                Parameter("controller_scene", value=str(scene_path))])
            node.destroy_node()
        finally:
            rclpy.shutdown(context=context)
        assert (warning in capfd.readouterr().err) is said, (scene_path, lockstep)


def test_a_goal_before_the_monitor_saw_the_jaws_waits_then_ends_stale_data():
    # nobody publishes the jaws' poses: the monitor reports them unseen (at the origin)
    rig = Rig(SCENE, Joint(OPEN), reach=None)
    try:
        result = rig.squeeze(seen=False)
        assert result.termination == ExecuteGrasp.Result.STALE_DATA, result.message
        assert "no reading of F1, F2 within stale_budget 1.0 s" in result.message
        assert result.ticks == 0 and not rig.outside.received
        assert rig.executor.goal is None
    finally:
        rig.close()
