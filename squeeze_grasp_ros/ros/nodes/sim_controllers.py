# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Simulated stock ros2_control controllers of the simulated hardware (docs/grippers.md).

:class:`SimJointTrajectoryController` stands in for a JointTrajectoryController on a scene's
gripper (``controller: {type: joint_trajectory, ...}``) and for its joint_state_broadcaster:

- it subscribes ``<controller>/joint_trajectory`` (``trajectory_msgs/JointTrajectory``) and
  follows the accepted trajectory in sim time (:class:`..control.joint_trajectory.
  TrajectoryFollower`: position interface, linear interpolation); each tick, the commanded
  aperture, saturated by the joint limits (the opening range, and the device file's
  ``max_speed`` of the aperture), becomes the jaws' tip setpoints on the jaw line, which the
  world's devices follow as any setpoint (their own speed limit, actuator lag); while the
  measured jaw force is at the device's ``max_force`` the jaws close no further (the drive's
  effort limit: the stock controller itself limits no effort on a position interface);
- a refused trajectory (joint names other than the controller's, sizes that do not match,
  non-finite positions, an aperture beyond the opening range, an end in the past) is
  logged as one warning line and not followed: the active trajectory stays (before tick 0 the
  controller is inactive and refuses every trajectory);
- it publishes ``sensor_msgs/JointState`` on ``joint_states`` every tick, stamped with the
  tick: each joint's position at the measured aperture and its effort for the jaw force (the
  mean of the two jaws' ground-truth forces along the closing line), through the transmission.

In lockstep, a tick's jaw setpoints are ready once a trajectory was accepted since the
previous step (the executor sends one per control cycle).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from rclpy.node import Node
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from squeeze_grasp_ros.control.barrett import JOINTS, ReachError
from squeeze_grasp_ros.control.joint_trajectory import (
    JointFollower,
    TrajectoryFollower,
    TrajectoryRefused,
)
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline
from squeeze_grasp_ros.ros.nodes.pipeline import JOINT_STATES
from squeeze_grasp_ros.scene.controller import HandController, JawController
from squeeze_grasp_ros.sim.world import SimWorld, TickOutput


def trajectory_points(msg: JointTrajectory, joints: tuple[str, ...], now: int
                      ) -> list[tuple[int, list[float]]]:
    """(absolute time ns, positions in the order of ``joints``) of each point of ``msg``, as a
    JointTrajectoryController reads it at sim time ``now`` (a zero stamp: on receipt).

    Raises
    ------
    TrajectoryRefused
        The controller inactive (``now`` < 0), joint names other than ``joints`` (any order),
        a point's positions not one per joint.
    """
    if now < 0:
        raise TrajectoryRefused("the simulated clock has not started (the controller is not "
                                "active yet)")
    names = list(msg.joint_names)
    if sorted(names) != sorted(joints):
        raise TrajectoryRefused(f"its joint_names {names} are not the controller's joints "
                                f"{list(joints)}")
    order = [names.index(j) for j in joints]
    start = messages.stamp_ns(msg.header.stamp) or now
    points = []
    for k, point in enumerate(msg.points):
        if len(point.positions) != len(order):
            raise TrajectoryRefused(f"point {k} has {len(point.positions)} positions for "
                                    f"{len(order)} joints")
        tfs = point.time_from_start.sec * 1_000_000_000 + point.time_from_start.nanosec
        points.append((start + tfs, [point.positions[i] for i in order]))
    return points


class TrajectoryTopic:
    """A simulated controller's ``<controller>/joint_trajectory`` subscription: what it does
    with a message. The owner has ``now_ns``, ``on_command``, ``node``, ``topic``,
    ``refusals`` and ``commanded``.
    """

    def _receive(self, msg: JointTrajectory, joints: tuple[str, ...],
                 accept: Callable[[list, int], None]) -> None:
        """Read ``msg`` for ``joints`` and ``accept(points, now)``; a refusal is logged as one
        warning line and kept in ``refusals``, an acceptance is the lockstep's chance to step.
        """
        now = self.now_ns()
        try:
            accept(trajectory_points(msg, joints, now), now)
        except TrajectoryRefused as exc:
            self.refusals.append(str(exc))
            self.node.get_logger().warning(f"refused the trajectory on {self.topic}: {exc}")
            return
        self.commanded = True
        self.on_command()


class SimJaws:
    """What every simulated controller of a parallel gripper shares: the jaw line (fixed by the
    jaws' initial tips) and the joint_state_broadcaster.

    Parameters
    ----------
    node : Node
        The simulated hardware node.
    world : SimWorld
    controller : JawController
        The scene's resolved ``controller:`` section.
    qos : QoSProfile
        Of the controller's own topics; the joint states go out with its depth,
        transient-local (a lockstep topic a recorder awaits, :func:`.pipeline.loop_qos`).
    """

    def __init__(self, node: Node, world: SimWorld, controller: JawController, qos: Any) -> None:
        self.node, self.world, self.controller = node, world, controller
        first, second = controller.jaws
        self.line = controller.jaw_line(world.positions)
        self.aperture = self.line.aperture(world.positions[first], world.positions[second])
        """The measured aperture of the last tick, m."""
        self.force = 0.0
        """The measured jaw force of the last tick, N."""
        self.limited = (0, self.aperture)
        """(sim time ns, aperture m) of the last command after the joint limits."""
        self.topic = node.resolve_topic_name(controller.topic)
        self.refusals: list[str] = []
        """Why each refused command was refused, in order."""
        self.state_pub = node.create_publisher(JointState, JOINT_STATES,
                                                pipeline.loop_qos(qos.depth, kept=True))
        self.state_msg = JointState(name=list(controller.joints))

    @property
    def fingers(self) -> tuple[str, str]:
        """The fingers whose setpoints this controller gives."""
        return self.controller.jaws

    def limit(self, t_ns: int, aperture: float) -> float:
        """``aperture`` (m) commanded for sim time ``t_ns``, saturated by the joint limits as
        ros2_control's limit enforcement does to a position command: within the opening range,
        and moving at most ``max_speed`` (the device file's aperture speed) times the time since
        the last command; and, as the gripper's drive does (not the controller: a position
        interface carries no effort), closing no further than the measured aperture while the
        measured jaw force is at or above the device's ``max_force``.
        """
        gripper = self.controller.gripper
        reach = gripper.max_speed * max(t_ns - self.limited[0], 0) * 1e-9
        aperture = float(np.clip(aperture, self.limited[1] - reach, self.limited[1] + reach))
        aperture = float(np.clip(aperture, gripper.opening.min, gripper.opening.max))
        if self.force >= gripper.max_force:
            aperture = max(aperture, self.aperture)
        self.limited = (t_ns, aperture)
        return aperture

    def jaw_setpoints(self, aperture: float) -> dict[str, np.ndarray]:
        """The jaws' tip setpoints (m) at ``aperture`` (m) on the jaw line."""
        return dict(zip(self.fingers, self.line.positions(aperture)))

    def measure(self, out: TickOutput) -> tuple[float, float]:
        """(aperture m, jaw force N) of tick ``out``: the measured aperture, and the mean of the
        two jaws' ground-truth forces along the closing line.
        """
        first, second = self.fingers
        positions = {r.finger: r.position for r in out.readings}
        aperture = self.line.aperture(positions[first], positions[second])
        u = self.line.direction
        force = 0.5 * (float(np.dot(out.state.finger_force(first)[:2], u))
                       - float(np.dot(out.state.finger_force(second)[:2], u)))
        return aperture, force

    def joint_state(self, out: TickOutput) -> tuple[Any, JointState]:
        """(publisher, message) of the joint states of tick ``out``: each joint's position at the
        measured aperture and its effort for the jaw force, through the transmission.
        """
        aperture, force = self.measure(out)
        self.aperture, self.force = aperture, force
        msg = self.state_msg
        messages.set_stamp(msg.header.stamp, out.stamp_ns)
        msg.position = [float(p) for p in self.controller.joint_positions(aperture)]
        msg.effort = [float(e) for e in self.controller.joint_efforts(force)]
        return self.state_pub, msg


class SimJointTrajectoryController(SimJaws, TrajectoryTopic):
    """A simulated JointTrajectoryController and joint_state_broadcaster on ``node``.

    Parameters
    ----------
    node, world, controller, qos
        As :class:`SimJaws` (``qos`` also of the trajectory subscription).
    now_ns : callable
        The current sim time, ns (the last published tick).
    on_command : callable
        Called after each accepted trajectory (the lockstep's chance to step).
    """

    def __init__(self, node: Node, world: SimWorld, controller: JawController, qos: Any, *,
                 now_ns: Callable[[], int], on_command: Callable[[], None]) -> None:
        super().__init__(node, world, controller, qos)
        self.now_ns, self.on_command = now_ns, on_command
        opening = controller.gripper.opening
        self.follower = TrajectoryFollower(self.aperture, opening=(opening.min, opening.max))
        self.commanded = False
        node.create_subscription(JointTrajectory, controller.topic, self._trajectory, qos)

    def _trajectory(self, msg: JointTrajectory) -> None:
        self._receive(msg, self.controller.joints, lambda points, now: self.follower.accept(
            points, now_ns=now, to_aperture=self.controller.gripper.aperture,
            measured=self.aperture))

    def setpoints(self, t_ns: int) -> dict[str, np.ndarray]:
        """The jaws' tip setpoints (m) at sim time ``t_ns``, within the joint limits
        (:meth:`SimJaws.limit`); the command is consumed.
        """
        self.commanded = False
        return self.jaw_setpoints(self.limit(t_ns, self.follower.sample(t_ns)))


class SimHandTrajectoryController(TrajectoryTopic):
    """A simulated JointTrajectoryController and joint_state_broadcaster of the Barrett hand
    (``controller: {type: joint_trajectory, device: bh8, palm: ...}``) on ``node``.

    It follows the accepted trajectory of the hand's eight joints in sim time (linear in joint
    space, :class:`..control.joint_trajectory.JointFollower`; positions outside a joint's range
    refused); each tick the commanded joints become the carried fingers' tip setpoints through
    the forward kinematics (:mod:`..control.barrett`), which the world's devices follow as any
    setpoint. ``joint_states`` carries every joint's position, from the inverse kinematics of
    the measured tips (the closest configuration, distal joints coupled), and its effort: the
    statics of the planar model, tau = J^T F at each carried finger's joints for the finger's
    ground-truth push F on the object (:meth:`..control.barrett.BarrettHand.efforts`; each
    joint's own torque; 0 at the joints of fingers the scene does not carry).

    Parameters
    ----------
    node, world, qos, now_ns, on_command
        As :class:`SimJointTrajectoryController`.
    controller : HandController
        The scene's resolved ``controller:`` section.

    Raises
    ------
    ParameterError
        The fingers' initial tips (the scene's placements) out of the hand's reach from its
        palm pose.
    """

    def __init__(self, node: Node, world: SimWorld, controller: HandController, qos: Any, *,
                 now_ns: Callable[[], int], on_command: Callable[[], None]) -> None:
        self.node, self.world, self.controller = node, world, controller
        self.now_ns, self.on_command = now_ns, on_command
        self.hand = controller.hand
        try:
            self.joints = self.hand.inverse(self._measured(world.positions)).joints
            """The joints of the last measured tips, rad."""
        except ReachError as exc:
            raise ParameterError(f"controller.palm {list(controller.spec.palm)}: the fingers' "
                                 f"initial tips are out of the hand's reach: {exc}") from None
        self.follower = JointFollower([self.joints[j] for j in JOINTS],
                                      limits=self.hand.limits(), names=JOINTS)
        self.topic = node.resolve_topic_name(controller.topic)
        self.refusals: list[str] = []
        self.commanded = False
        self.state_pub = node.create_publisher(JointState, JOINT_STATES,
                                               pipeline.loop_qos(qos.depth, kept=True))
        self.state_msg = JointState(name=list(JOINTS))
        node.create_subscription(JointTrajectory, controller.topic, self._trajectory, qos)

    @property
    def fingers(self) -> tuple[str, ...]:
        """The fingers whose setpoints this controller gives."""
        return self.controller.jaws

    def _measured(self, positions: dict) -> dict:
        return {hand_finger: positions[finger]
                for finger, hand_finger in self.controller.fingers.items()}

    def _trajectory(self, msg: JointTrajectory) -> None:
        self._receive(msg, JOINTS, lambda points, now: self.follower.accept(
            points, now_ns=now, measured=[self.joints[j] for j in JOINTS]))

    def setpoints(self, t_ns: int) -> dict[str, np.ndarray]:
        """The carried fingers' tip setpoints (m) at sim time ``t_ns``: the forward kinematics
        of the commanded joints; the command is consumed.
        """
        self.commanded = False
        tips = self.hand.forward(dict(zip(JOINTS, self.follower.sample(t_ns))))
        return {finger: tips[hand_finger]
                for finger, hand_finger in self.controller.fingers.items()}

    def joint_state(self, out: TickOutput) -> tuple[Any, JointState]:
        """(publisher, message) of the joint states of tick ``out``."""
        positions = {r.finger: r.position for r in out.readings}
        self.joints = self.hand.inverse(self._measured(positions), rest=self.joints,
                                        tolerance=np.inf).joints
        efforts = self.hand.efforts(self.joints, {
            hand_finger: out.state.finger_force(finger)[:2]
            for finger, hand_finger in self.controller.fingers.items()})
        msg = self.state_msg
        messages.set_stamp(msg.header.stamp, out.stamp_ns)
        msg.position = [float(self.joints[j]) for j in JOINTS]
        msg.effort = [efforts[j] for j in JOINTS]
        return self.state_pub, msg
