# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Hardware mode (``lockstep: false``) against an outside JointTrajectoryController, in wall time.

The controller here is not ours: a plain rclpy node that takes ``JointTrajectory`` on
``gripper_controller/joint_trajectory``, moves its one joint toward the last point at the
device's speed and publishes ``joint_states`` at 100 Hz, as joint_state_broadcaster would; and
a stand-in for the lab's forward kinematics that publishes the jaws' tips once. Our monitor and
executor run in hardware mode on wall-clock timers. The test reads the commands as a controller
would: topic, joint names, positions in the device file's joint convention (0 rad open, 0.8 rad
closed), ``time_from_start`` and the "on receipt" stamp.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest
import rclpy
import yaml
from geometry_msgs.msg import PoseStamped
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_ros.control.motion import GraspGoal
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "config" / "scenes" / "sponge_gripper.yaml"
DEVICE = yaml.safe_load((ROOT / "config" / "devices" / "generic_85mm.yaml").read_text())
PERIOD = 0.01
"""The executor's control period here, s."""


def joint_of(aperture: float) -> float:
    """The device file's joint position of a jaw aperture, by its stated linear transmission."""
    t = DEVICE["transmission"]
    return t["position_per_aperture"] * aperture + t["position_offset"]


class OutsideController(Node):
    """A JTC-like controller of one joint: follows the last point at the device's joint speed."""

    def __init__(self, context: Context, aperture: float) -> None:
        super().__init__("outside_gripper", context=context)
        self.q = joint_of(aperture)
        self.target = self.q
        self.speed = abs(DEVICE["transmission"]["position_per_aperture"]) * DEVICE["max_speed"]
        self.received: list[tuple[float, JointTrajectory]] = []
        self.create_subscription(JointTrajectory, "gripper_controller/joint_trajectory",
                                 self._command, 10)
        self.states = self.create_publisher(JointState, "joint_states", 10)
        self.dt = 0.01
        self.create_timer(self.dt, self._step)

    def _command(self, msg: JointTrajectory) -> None:
        self.received.append((time.monotonic(), msg))
        self.target = float(msg.points[-1].positions[0])

    def _step(self) -> None:
        step = self.speed * self.dt
        self.q += float(np.clip(self.target - self.q, -step, step))
        msg = JointState(name=["finger_joint"], position=[self.q], effort=[0.0])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.states.publish(msg)


def test_the_executor_drives_an_outside_jtc_in_wall_time():
    context = Context()
    rclpy.init(context=context)
    spin = SingleThreadedExecutor(context=context)
    open_aperture = 0.06
    outside = OutsideController(context, open_aperture)
    common = [Parameter("lockstep", value=False),
              Parameter("finger_devices", value=["F1:jaw_f1", "F2:jaw_f2"]),
              Parameter("controller_scene", value=str(SCENE))]
    monitor = MonitorNode(context=context, parameter_overrides=common + [
        Parameter("streams", value=[""]), Parameter("rate", value=100.0),
        Parameter("stale_after", value=0.1), Parameter("force_watch", value=False)])
    executor = ExecutorNode(context=context, parameter_overrides=common + [
        Parameter("period", value=PERIOD), Parameter("stale_budget", value=1.0)])
    kinematics = Node("jaw_kinematics", context=context)
    poses = {d: kinematics.create_publisher(PoseStamped, pipeline.device_topic(d, "pose"),
                                            pipeline.LATCHED) for d in ("jaw_f1", "jaw_f2")}
    client_node = Node("grasp_client", context=context)
    client = ActionClient(client_node, ExecuteGrasp, pipeline.ACTION)
    for node in (outside, monitor, executor, kinematics, client_node):
        spin.add_node(node)

    def spin_until(condition, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while not condition() and time.monotonic() < deadline:
            spin.spin_once(timeout_sec=0.02)

    try:
        now = kinematics.get_clock().now().nanoseconds
        for device, y in (("jaw_f1", -open_aperture / 2), ("jaw_f2", open_aperture / 2)):
            poses[device].publish(messages.pose_msg((0.0, y), now, pipeline.FRAME))
        spin_until(lambda: client.server_is_ready() and monitor.jaws.line is not None)
        assert monitor.jaws.line is not None, "the monitor never fixed the jaw line"
        # the squeeze: each jaw moves 1/sqrt(2) per unit depth (depth: the stacked translation)
        depth = 0.01
        s = 1.0 / math.sqrt(2.0)
        goal = GraspGoal(("F1", "F2"), np.array([[0.0, s], [0.0, -s]]), depth)
        sent = client.send_goal_async(messages.grasp_goal_msg(goal))
        spin_until(lambda: sent.done())
        handle = sent.result()
        assert handle.accepted
        done = handle.get_result_async()
        spin_until(lambda: done.done(), timeout=60.0)
        result = done.result().result
        assert result.termination == ExecuteGrasp.Result.DEPTH_REACHED, result.message
        commands = [msg for _, msg in outside.received]
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
        # the last command is the planned aperture in the device's joint convention
        planned = open_aperture - 2.0 * s * depth
        assert q[-1] == pytest.approx(joint_of(planned), abs=1e-3 * DEVICE["opening"]["max"]
                                      * abs(DEVICE["transmission"]["position_per_aperture"]))
        assert outside.q == pytest.approx(q[-1], abs=0.02)
        assert result.depth == pytest.approx(depth, rel=0.05)
    finally:
        spin.shutdown()
        for node in (outside, monitor, executor, kinematics, client_node):
            node.destroy_node()
        rclpy.shutdown(context=context)
