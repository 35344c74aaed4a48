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
period only, and the controller interpolates to it from the joint's state when it takes the
message (Jazzy's default; from its last command with ``interpolate_from_desired_state``); a
longer horizon would be replaced by the next cycle's message anyway.

A position-interface JointTrajectoryController does not limit effort (a trajectory point's
``effort`` goes to an effort command interface only, and ros2_control's joint limiters clamp
an effort *command* at ``max_effort``, not the force a position-controlled drive exerts): the
gripper's drive stops at its own limit. So the executor refuses a grasp goal whose planned jaw
force (the planner's force curve at the goal's depth, :class:`PlannedJawForce`) is beyond the
device's ``max_force``: the jaws would stall short of the planned aperture.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from builtin_interfaces.msg import Duration
from rclpy.node import Node
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from squeeze_grasp_interfaces.msg import ContactEventArray
from squeeze_grasp_ros.control.barrett import JOINTS, HandSolution, ReachError
from squeeze_grasp_ros.control.joint_trajectory import JawLine
from squeeze_grasp_ros.control.motion import GraspGoal, Observation
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.scene.controller import HandController, JawController

REACH_TOLERANCE = 1e-6
"""m: how far the hand's closest reachable joints may put a fingertip from its setpoint before
the executor warns (a thousandth of a millimetre, far below the hand's resolution; setpoints of a
tilted squeeze fall about 1e-8 m off a finger's line by round-off alone)."""


class PlannedJawForce:
    """The planner's force curve (``planner/predicted_events``, latched) as the jaw force of a
    squeeze depth: the mean of the two jaws' predicted forces.

    Parameters
    ----------
    node : Node
    controller : JawController
    awaited : bool
        Whether a force curve is sure to come (the executor's ``await_prediction``): then the
        curve is awaited even while no publisher of it has been discovered yet.
    """

    def __init__(self, node: Node, controller: JawController, *, awaited: bool) -> None:
        self.node, self.controller = node, controller
        self.awaited = awaited
        self.seen = False
        """A prediction arrived (with or without a force curve)."""
        self.forces = None
        node.create_subscription(ContactEventArray, pipeline.PREDICTION, self._prediction,
                                 pipeline.LATCHED)

    def _prediction(self, msg: ContactEventArray) -> None:
        self.seen = True
        self.forces = messages.predicted_forces(msg)

    def ready(self) -> bool:
        """True once the prediction is here (a force curve or none), or when none is awaited
        and nobody publishes one (the executor's lockstep readiness: its first goal is judged
        on it; :func:`.pipeline.prediction_ready`).
        """
        return pipeline.prediction_ready(self.node, seen=self.seen, awaited=self.awaited)

    def at(self, depth: float) -> float | None:
        """The planned jaw force at squeeze depth ``depth`` (m), N; None without a curve."""
        if self.forces is None:
            return None
        jaws = [f for f in self.controller.jaws if f in self.forces.forces]
        return 0.5 * sum(self.forces.at(f, depth) for f in jaws) if jaws else None


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
    awaited : bool
        Whether the planner's force curve is sure to come (:class:`PlannedJawForce`).
    """

    def __init__(self, node: Node, controller: JawController, period: float, qos: Any, *,
                 awaited: bool) -> None:
        self.controller = controller
        self.topic = node.resolve_topic_name(controller.topic)
        self.publisher = node.create_publisher(JointTrajectory, controller.topic,
                                               pipeline.loop_qos(qos.depth, kept=True))
        self.period_ns = int(round(period * 1e9))
        self.plan = PlannedJawForce(node, controller, awaited=awaited)
        self.line: JawLine | None = None
        self.msg = one_point_trajectory(controller.joints, self.period_ns)

    @property
    def fingers(self) -> tuple[str, str]:
        """The fingers the jaws carry."""
        return self.controller.jaws

    def ready(self) -> bool:
        """The executor's lockstep readiness (:meth:`PlannedJawForce.ready`)."""
        return self.plan.ready()

    def effort_problem(self, goal: GraspGoal) -> str | None:
        """Why grasp goal ``goal`` is beyond the device's effort, or None: its planned jaw
        force at the goal's depth is above the device's ``max_force`` (without a force curve,
        nothing is known and nothing refused).
        """
        force = self.plan.at(goal.depth)
        gripper = self.controller.gripper
        if force is None or force <= gripper.max_force:
            return None
        return (f"the plan needs a jaw force of {force:.4g} N at depth {goal.depth * 1e3:.4g} "
                f"mm, beyond {gripper.name}'s max_force {gripper.max_force:.4g} N (a position "
                f"JointTrajectoryController does not limit effort: the drive would stall short "
                f"of the planned aperture); plan a shallower squeeze or a stronger gripper")

    def start(self, obs: Observation, goal: GraspGoal) -> str | None:
        """Fix the jaw line from the jaws' measured tips (a goal's first cycle); why ``goal``'s
        squeeze leaves the device's opening range, or None
        (:meth:`.JawController.opening_problem`).
        """
        self.line, problem = start_line(self.controller, obs, goal)
        return problem

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


def start_line(controller: JawController, obs: Observation, goal: GraspGoal
               ) -> tuple[JawLine, str | None]:
    """The jaw line fixed from the jaws' measured tips in a goal's first observation ``obs``,
    and why ``goal``'s squeeze leaves the device's opening range, or None
    (:meth:`.JawController.opening_problem`).
    """
    line = controller.jaw_line(obs.positions)
    return line, controller.opening_problem(line, obs.positions,
                                            squeeze_end(goal, obs.positions, goal.depth))


def squeeze_end(goal: GraspGoal, start: Mapping[str, np.ndarray], depth: float
                ) -> dict[str, np.ndarray]:
    """The tips of ``goal``'s fingers (m) after a squeeze from ``start`` to ``depth`` (m)
    along its directions.
    """
    return {f: np.asarray(start[f], float) + depth * np.asarray(d, float)
            for f, d in zip(goal.fingers, goal.directions)}


def one_point_trajectory(joints: Sequence[str], period_ns: int) -> JointTrajectory:
    """A ``JointTrajectory`` of ``joints`` with one point at ``time_from_start`` =
    ``period_ns``.
    """
    return JointTrajectory(joint_names=list(joints), points=[JointTrajectoryPoint(
        time_from_start=Duration(sec=period_ns // 1_000_000_000,
                                 nanosec=period_ns % 1_000_000_000))])


class HandCommands:
    """Fingertip setpoints of the Barrett hand's fingers -> ``JointTrajectory`` messages of its
    JointTrajectoryController: each cycle the inverse kinematics of the carried fingers'
    setpoints (:mod:`..control.barrett`: the spread from finger 1 or 2, the distal joints
    coupled), one point one control period ahead, all eight joints (as :class:`JawCommands`).

    A setpoint the hand cannot reach (off a finger's closing line, or beyond its range along
    it) is commanded as the closest reachable joints, as a parallel gripper's setpoints are taken
    along its jaw line; when that is more than :data:`REACH_TOLERANCE` away, a warning names the
    finger, the target and the reach (once per goal).

    Parameters
    ----------
    node, period, qos
        As :class:`JawCommands`.
    controller : HandController
    """

    def __init__(self, node: Node, controller: HandController, period: float, qos: Any
                 ) -> None:
        self.node, self.controller = node, controller
        self.topic = node.resolve_topic_name(controller.topic)
        self.publisher = node.create_publisher(JointTrajectory, controller.topic,
                                               pipeline.loop_qos(qos.depth, kept=True))
        self.msg = one_point_trajectory(JOINTS, int(round(period * 1e9)))
        self.solution: HandSolution | None = None
        """The last inverse kinematics sent."""
        self.warned = False

    @property
    def fingers(self) -> tuple[str, ...]:
        """The fingers the hand carries."""
        return self.controller.jaws

    def ready(self) -> bool:
        """The executor's lockstep readiness: nothing to wait for."""
        return True

    def effort_problem(self, goal: GraspGoal) -> str | None:
        """None: no effort limit of the hand is modelled."""
        del goal
        return None

    def _targets(self, tips: Mapping[str, np.ndarray]) -> dict:
        return {hand_finger: tips[finger]
                for finger, hand_finger in self.controller.fingers.items()}

    def start(self, obs: Observation, goal: GraspGoal | None = None) -> None:
        """The joints of the measured tips (a goal's first cycle; a setpoint out of the hand's
        reach is warned about per cycle, not refused: None).
        """
        self.solution = self.controller.hand.inverse(self._targets(obs.positions),
                                                     tolerance=np.inf)
        self.warned = False

    def trajectory(self, setpoints: Mapping[str, np.ndarray], start_ns: int
                   ) -> tuple[Any, JointTrajectory]:
        """(publisher, message) commanding the carried fingers' ``setpoints`` (m) one period
        after ``start_ns`` (the message's ``header.stamp``; 0 = on receipt).
        """
        targets = self._targets(setpoints)
        self.solution = self.controller.hand.inverse(targets, rest=self.solution.joints,
                                                     tolerance=np.inf)
        if self.solution.residual > REACH_TOLERANCE and not self.warned:
            try:
                self.controller.hand.inverse(targets, rest=self.solution.joints,
                                             tolerance=REACH_TOLERANCE)
            except ReachError as exc:
                self.node.get_logger().warning(f"{self.topic}: commanding the closest reachable "
                                               f"joints: {exc}")
            self.warned = True
        msg = self.msg
        messages.set_stamp(msg.header.stamp, start_ns)
        msg.points[0].positions = [float(self.solution.joints[j]) for j in JOINTS]
        return self.publisher, msg
