# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor's side of a stock JointTrajectoryController (docs/grippers.md).

Every control cycle the executor's program gives each jaw a fingertip setpoint; the two become
one aperture on the jaw line (:class:`..control.joint_trajectory.JawLine`, fixed by the jaws'
measured tips at the goal's first cycle) and, through the gripper's transmission, one
``trajectory_msgs/JointTrajectory`` on ``<controller>/joint_trajectory`` with **one point**:
the joint positions at ``time_from_start`` = one control period after ``header.stamp`` (the
cycle's tick in lockstep; zero, "on receipt", on hardware). One point because the program is
reactive: each setpoint depends on the newest status, so the executor commits to the next
period only, and the controller interpolates from its current command to it; a longer horizon
would be replaced by the next cycle's message anyway.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from builtin_interfaces.msg import Duration
from rclpy.node import Node
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from squeeze_grasp_ros.control.joint_trajectory import JawLine
from squeeze_grasp_ros.control.motion import Observation
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.scene.controller import JawController


class JawCommands:
    """Jaw setpoints -> ``JointTrajectory`` messages of one controller.

    Parameters
    ----------
    node : Node
    controller : JawController
    period : float
        The control period, s (each message's ``time_from_start``).
    qos : QoSProfile
        Its depth is the publisher's; the publisher is transient-local (a lockstep topic a
        recorder awaits, :func:`.pipeline.loop_qos`).
    """

    def __init__(self, node: Node, controller: JawController, period: float, qos: Any) -> None:
        self.controller = controller
        self.topic = node.resolve_topic_name(controller.topic)
        self.publisher = node.create_publisher(JointTrajectory, controller.topic,
                                               pipeline.loop_qos(qos.depth, kept=True))
        self.period_ns = int(round(period * 1e9))
        self.line: JawLine | None = None
        self.msg = JointTrajectory(joint_names=list(controller.joints), points=[
            JointTrajectoryPoint(time_from_start=Duration(sec=self.period_ns // 1_000_000_000,
                                                          nanosec=self.period_ns % 1_000_000_000))
        ])

    @property
    def fingers(self) -> tuple[str, str]:
        """The fingers the jaws carry."""
        return self.controller.jaws

    def start(self, obs: Observation) -> None:
        """Fix the jaw line from the jaws' measured tips (a goal's first cycle)."""
        self.line = self.controller.jaw_line(obs.positions)

    def trajectory(self, setpoints: Mapping[str, np.ndarray], start_ns: int
                   ) -> tuple[Any, JointTrajectory]:
        """(publisher, message) commanding the jaws' ``setpoints`` (m) one period after
        ``start_ns`` (the message's ``header.stamp``; 0 = on receipt).
        """
        first, second = self.fingers
        aperture = self.line.aperture(setpoints[first], setpoints[second])
        msg = self.msg
        messages.set_stamp(msg.header.stamp, start_ns)
        msg.points[0].positions = [float(p) for p in self.controller.joint_positions(aperture)]
        return self.publisher, msg
