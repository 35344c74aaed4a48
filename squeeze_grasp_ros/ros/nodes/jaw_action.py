# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor's side of a stock gripper action controller (docs/grippers.md).

A squeeze of the jaws is one goal: at the grasp goal's first cycle the executor fixes the jaw
line from the jaws' measured tips (as :mod:`.jaw_commands`), and sends
``control_msgs/action/GripperCommand`` (``type: gripper_action``) or
``ParallelGripperCommand`` (``type: parallel_gripper``) on ``<controller>/gripper_cmd`` with

- **position** = the planned aperture (the jaws' tips after the planned depth along the goal's
  directions, measured between the pad faces on the jaw line) through the device's
  transmission: the controller joint's position, in its convention (the generic 85 mm
  gripper's: a Robotiq-style knuckle angle, 0.8 rad closed, 0 rad open at 85 mm; a device with
  ``position_per_aperture: 1`` takes the jaw gap in m);
- **max_effort** (parallel: ``effort[0]``) = the planned jaw force at that depth (the planner's
  force curve, ``planner/predicted_events``, mean of the two jaws) times the controller
  section's ``effort_margin``, through the transmission, capped at the device's limit; without
  a force curve, the controller's own ``max_effort`` (parallel: no effort sent; ``GripperCommand``,
  which has no "none": the scene's ``max_effort`` sent explicitly, since the stock
  GripperActionController takes 0 literally). In lockstep the executor is ready only
  once the force curve is here when somebody publishes one (a run latches it before its nodes
  start).

The grasp goal then ends on the gripper goal's result: ``reached_goal`` -> depth_reached;
``stalled`` -> gripper_stalled (success only if the controller allows stalling); a rejection
-> gripper_rejected; another end (preempted) -> gripper_aborted; no result within the
executor's ``gripper_timeout`` of the executor's time -> gripper_aborted, the gripper goal
canceled (Jazzy's GripperActionController accepts every goal, active or not, and computes only
while active: a controller loaded but not activated takes the goal and never ends it). A
cancel, an imminent slip of a jaw, a lost contact or a pick-up cancels the gripper goal (the
controller holds the measured position) and ends the grasp goal as on the setpoint route.

A re-squeeze (``on_slip_alarm: resqueeze``, docs/grippers.md) is three gripper goals: the
first squeeze's, canceled at the slip alarm; one to the release aperture (the controller's own
effort limit, as above) whose result is not the grasp goal's; and, once the jaws are there and
the monitor reported them free, one to the re-squeeze's aperture and effort, whose result ends
the grasp goal.

In lockstep the executor answers each tick on ``executor/cycle`` once its request of that tick
(goal or cancel) has been answered, so the simulated controller has it before the step.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from control_msgs.action import GripperCommand, ParallelGripperCommand
from rclpy.action import ActionClient
from rclpy.node import Node
from std_msgs.msg import Header

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_ros.control.joint_trajectory import JawLine
from squeeze_grasp_ros.control.motion import GraspGoal, Observation
from squeeze_grasp_ros.mechanics.vocabulary import ControllerKind
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.jaw_commands import PlannedJawForce, squeeze_end, start_line
from squeeze_grasp_ros.scene.controller import JawController

__all__ = ["JawAction"]

GOAL_STATUS_SUCCEEDED = 4
"""action_msgs/GoalStatus STATUS_SUCCEEDED."""


class JawAction:
    """Grasp goals -> one gripper action goal of one controller.

    Parameters
    ----------
    node : Node
    controller : JawController
    qos : QoSProfile
        Its depth is the cycle publisher's; that publisher is transient-local (a lockstep
        topic a recorder awaits, :func:`.pipeline.loop_qos`).
    awaited : bool
        Whether the planner's force curve is sure to come (:class:`.PlannedJawForce`).
    """

    def __init__(self, node: Node, controller: JawController, qos: Any, *,
                 awaited: bool) -> None:
        self.node, self.controller = node, controller
        self.parallel = controller.kind is ControllerKind.PARALLEL_GRIPPER
        self.action = ParallelGripperCommand if self.parallel else GripperCommand
        self.topic = pipeline.action_name(node, controller.topic)
        self.client = ActionClient(node, self.action, controller.topic)
        self.publisher = node.create_publisher(Header, pipeline.EXECUTOR_CYCLE,
                                               pipeline.loop_qos(qos.depth, kept=True))
        self.plan = PlannedJawForce(node, controller, awaited=awaited)
        self.line: JawLine | None = None
        self.handle: Any = None
        self.outcome: tuple[str, bool, str] | None = None
        """(termination, success, message) once the gripper goal ended."""
        self.sent: dict[str, float] = {}
        self.sent_ns: int | None = None
        """The executor's time (ns) the running gripper goal was sent at; None when none runs."""

    @property
    def fingers(self) -> tuple[str, str]:
        """The fingers the jaws carry."""
        return self.controller.jaws

    def ready(self) -> bool:
        """The executor's lockstep readiness: the controller's action server is ready (the
        goal request, sent once at the grasp goal's first cycle, would otherwise be lost and
        the loop wait for its answer for ever), and the planner's force curve is here or not
        coming (:meth:`.PlannedJawForce.ready`: its first goal's effort depends on it).
        """
        return self.client.server_is_ready() and self.plan.ready()

    def cycle_msg(self, ns: int) -> tuple[Any, Header]:
        """(publisher, message) answering tick ``ns``."""
        return self.publisher, messages.header(ns)

    # ----------------------------------------------------------------- the goal
    def tolerance_problem(self, goal: GraspGoal) -> str | None:
        """Why grasp goal ``goal`` would be reached where it starts, or None
        (:meth:`.JawController.tolerance_problem` of its largest closing: its depth times the
        jaws' speeds per unit depth, both along the jaw line).
        """
        speed = sum(float(np.linalg.norm(d)) for f, d in zip(goal.fingers, goal.directions)
                    if f in self.fingers)
        return self.controller.tolerance_problem(goal.depth * speed)

    def start(self, obs: Observation, goal: GraspGoal) -> str | None:
        """Fix the jaw line from grasp goal ``goal``'s first observation ``obs`` (as
        :meth:`.JawCommands.start`); why its squeeze
        leaves the device's opening range, or None (:meth:`.JawController.opening_problem`).
        """
        self.line, problem = start_line(self.controller, obs, goal)
        return problem

    def target(self, goal: GraspGoal, obs: Observation) -> tuple[float, float]:
        """(joint position, joint effort limit) of grasp goal ``goal`` from its first
        observation (after :meth:`start`).
        """
        return self.squeeze(goal, obs.positions, goal.depth)

    def squeeze(self, goal: GraspGoal, start: Mapping[str, np.ndarray],
                depth: float) -> tuple[float, float]:
        """(joint position, joint effort limit) of a squeeze of ``goal``'s fingers from
        ``start`` (m) to ``depth`` (m) along its directions, on the fixed jaw line.
        """
        end = squeeze_end(goal, start, depth)
        position = self.opening({f: end.get(f, start[f]) for f in self.fingers})
        effort = 0.0
        force = self.plan.at(depth)
        if force is not None:
            effort = min(abs(self.controller.joint_efforts(force)[0])
                         * self.controller.spec.effort_margin, self.controller.effort_limit)
        return position, effort

    def opening(self, tips: Mapping[str, np.ndarray]) -> float:
        """The joint position putting the jaws' tips at ``tips`` (m) on the fixed jaw line."""
        first, second = self.fingers
        return float(self.controller.joint_positions(self.line.aperture(tips[first],
                                                                        tips[second]))[0])

    def send(self, position: float, effort: float, on_answer: Callable[[], None], *,
             at_ns: int) -> None:
        """Send the goal at the executor's time ``at_ns``; ``on_answer`` once the controller
        accepted or rejected it.
        """
        goal = self.action.Goal()
        if self.parallel:
            goal.command.name = [self.controller.joints[0]]
            goal.command.position = [float(position)]
            goal.command.effort = [float(effort)] if effort > 0.0 else []
        else:
            if not effort > 0.0:
                # GripperCommand cannot leave the effort to the controller: the stock
                # GripperActionController takes max_effort as given, 0 included (an effort
                # interface clamps its PID output to it: no effort, the jaws stay). Send the
                # controller's max_effort (the scene's, else the device's limit) explicitly.
                effort = min(self.controller.parameters().max_effort,
                             self.controller.effort_limit)
            goal.command.position, goal.command.max_effort = float(position), float(effort)
        self.sent = {"position": float(position), "max_effort": float(effort)}
        self.outcome, self.handle, self.sent_ns = None, None, at_ns
        if not self.client.server_is_ready():
            self.outcome = (ExecuteGrasp.Result.GRIPPER_REJECTED, False,
                            f"no action server on {self.topic} answers (is the gripper "
                            f"controller running and active?): the goal (position "
                            f"{self.sent['position']:.6g}, max_effort "
                            f"{self.sent['max_effort']:.6g}) was not sent")
            on_answer()
            return

        def answered(future: Any) -> None:
            self.handle = future.result()
            if not self.handle.accepted:
                self.outcome = (ExecuteGrasp.Result.GRIPPER_REJECTED, False,
                                f"{self.controller.topic} rejected the goal (position "
                                f"{self.sent['position']:.6g}, max_effort "
                                f"{self.sent['max_effort']:.6g}): its log says why")
            else:
                handle = self.handle
                handle.get_result_async().add_done_callback(lambda f: self._result(f, handle))
            on_answer()

        self.client.send_goal_async(goal).add_done_callback(answered)

    def _result(self, future: Any, handle: Any) -> None:
        if handle is not self.handle:           # canceled, or an earlier grasp goal's
            return
        response = future.result()
        result = response.result
        position = result.state.position[0] if self.parallel and len(result.state.position) \
            else getattr(result, "position", 0.0)
        effort = result.state.effort[0] if self.parallel and len(result.state.effort) \
            else getattr(result, "effort", 0.0)
        detail = (f"{self.controller.topic}: reached_goal {result.reached_goal}, stalled "
                  f"{result.stalled}, position {position:.6g}, effort {effort:.6g} (goal: "
                  f"position {self.sent['position']:.6g}, max_effort "
                  f"{self.sent['max_effort']:.6g})")
        succeeded = response.status == GOAL_STATUS_SUCCEEDED
        if result.reached_goal:
            self.outcome = (ExecuteGrasp.Result.DEPTH_REACHED, True, detail)
        elif result.stalled:
            self.outcome = (ExecuteGrasp.Result.GRIPPER_STALLED, succeeded, detail)
        elif self.outcome is None:
            self.outcome = (ExecuteGrasp.Result.GRIPPER_ABORTED, False, detail)

    def cancel(self, on_answer: Callable[[], None]) -> bool:
        """Cancel the running gripper goal (the controller holds position); ``on_answer`` once
        the cancel was answered. False when no goal runs (nothing to wait for).
        """
        if self.handle is None or not self.handle.accepted or self.outcome is not None:
            return False
        self.handle.cancel_goal_async().add_done_callback(lambda _: on_answer())
        self.handle, self.sent_ns = None, None
        return True

    def overdue(self, ns: int, timeout: float) -> str | None:
        """Why the gripper goal sent is overdue at the executor's time ``ns`` (sent more than
        ``timeout`` s before, not canceled, no result yet), or None (also for ``timeout`` 0).
        """
        if (not timeout or self.sent_ns is None or self.outcome is not None
                or (ns - self.sent_ns) * 1e-9 <= timeout):
            return None
        said = (f"no result from {self.controller.topic} within gripper_timeout {timeout:g} s "
                f"of its goal (position {self.sent['position']:.6g}, max_effort "
                f"{self.sent['max_effort']:.6g})")
        if self.handle is None:
            return f"{said}: the controller never answered the goal request"
        return (f"{said}: a stock GripperActionController that is loaded but not active "
                "accepts goals and never ends them (ros2 control list_controllers shows its "
                "state); the gripper goal was canceled")
