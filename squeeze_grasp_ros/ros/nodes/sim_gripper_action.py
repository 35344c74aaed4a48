# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Simulated gripper action controllers of the simulated hardware (docs/grippers.md).

:class:`SimGripperActionController` stands in for ros2_controllers' GripperActionController
(``controller: {type: gripper_action}``: ``control_msgs/action/GripperCommand``) or Jazzy's
ParallelGripperController (``type: parallel_gripper``: ``control_msgs/action/
ParallelGripperCommand``) on ``<controller>/gripper_cmd``, and for the joint_state_broadcaster
(``joint_states``, as :class:`.sim_controllers.SimJaws`). The goal semantics are the stock ones
(:mod:`...control.gripper_action`): reached within ``goal_tolerance``, stalled after
``stall_timeout`` s below ``stall_velocity_threshold``, a new goal preempting the active one, a
cancel holding the measured position; judged every tick in sim time, the result sent at the
tick that ends the goal. No feedback is published (the stock controllers publish none).

Beyond the stock controllers, a goal is rejected (one warning line naming the field) when its
position is not finite or outside the device's opening range, its effort is negative, not
finite or beyond the device's limit, or (parallel) it names a joint other than the controller's;
the ParallelGripperController itself rejects only a position list not of one value.

In lockstep the tick's jaw command is ready once the executor has answered the tick on
``executor/cycle`` (it answers after its goal or cancel requests were acknowledged).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from control_msgs.action import GripperCommand, ParallelGripperCommand
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node
from rclpy.task import Future
from std_msgs.msg import Header

from squeeze_grasp_ros.control.gripper_action import (
    GoalEnd,
    GoalRefused,
    GripperGoal,
    GripperOutcome,
    GripperServo,
    gripper_goal,
)
from squeeze_grasp_ros.mechanics.vocabulary import ControllerKind
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.sim_controllers import SimJaws
from squeeze_grasp_ros.scene.controller import JawController
from squeeze_grasp_ros.sim.world import SimWorld, TickOutput

__all__ = ["SimGripperActionController"]

PREEMPTED = "preempted"
CANCELED = "canceled"


class SimGripperActionController(SimJaws):
    """A simulated gripper action controller and joint_state_broadcaster on ``node``.

    Parameters
    ----------
    node, world, controller, qos
        As :class:`.sim_controllers.SimJaws`.
    now_ns : callable
        The current sim time, ns (the last published tick).
    on_command : callable
        Called when the executor has answered a tick (the lockstep's chance to step).
    """

    def __init__(self, node: Node, world: SimWorld, controller: JawController, qos: Any, *,
                 now_ns: Callable[[], int], on_command: Callable[[], None]) -> None:
        super().__init__(node, world, controller, qos)
        self.now_ns, self.on_command = now_ns, on_command
        self.parallel = controller.kind is ControllerKind.PARALLEL_GRIPPER
        self.action = ParallelGripperCommand if self.parallel else GripperCommand
        self.joint = controller.joints[0]
        self.servo = GripperServo(controller.parameters(),
                                  position=self._joint(self.aperture))
        self.joint_range = tuple(self._joint(a) for a in (controller.gripper.opening.min,
                                                          controller.gripper.opening.max))
        self.position, self.velocity, self.effort = self._joint(self.aperture), 0.0, 0.0
        """The joint's measured position, velocity and effort of the last tick."""
        self.active: tuple[Any, Future] | None = None
        self.outcomes: list[GripperOutcome] = []
        """Every ended goal, in order."""
        self.answered_ns = -1
        node.create_subscription(Header, pipeline.EXECUTOR_CYCLE, self._cycle, qos)
        self.server = ActionServer(node, self.action, controller.topic, self._execute,
                                   goal_callback=self._goal, cancel_callback=self._cancel)

    def _joint(self, aperture: float) -> float:
        return self.controller.joint_positions(aperture)[0]

    @property
    def commanded(self) -> bool:
        """True when the executor has answered the current tick."""
        return self.answered_ns >= self.now_ns() >= 0

    def _cycle(self, msg: Header) -> None:
        self.answered_ns = max(self.answered_ns, messages.stamp_ns(msg.stamp))
        self.on_command()

    # ----------------------------------------------------------------- the action
    def _request(self, goal: Any) -> GripperGoal:
        """The checked goal of an action request."""
        p = self.controller.parameters()
        limits = dict(parameters=p, joint_range=self.joint_range,
                      effort_limit=self.controller.effort_limit)
        if not self.parallel:
            return gripper_goal(goal.command.position, goal.command.max_effort, None, **limits)
        command = goal.command
        if len(command.position) != 1:
            raise GoalRefused(f"command.position has {len(command.position)} values, "
                              "expected 1")
        if list(command.name) not in ([], [self.joint]):
            raise GoalRefused(f"command.name {list(command.name)} is not the controller's "
                              f"joint ['{self.joint}']")
        for field in ("effort", "velocity"):
            if len(getattr(command, field)) > 1:
                raise GoalRefused(f"command.{field} has {len(getattr(command, field))} values, "
                                  "expected 0 or 1")
        return gripper_goal(command.position[0],
                            command.effort[0] if len(command.effort) else None,
                            command.velocity[0] if len(command.velocity) else None, **limits)

    def _goal(self, goal: Any) -> GoalResponse:
        try:
            if self.now_ns() < 0:
                raise GoalRefused("the simulated clock has not started (the controller is not "
                                  "active yet)")
            self._request(goal)
        except GoalRefused as exc:
            self.refusals.append(str(exc))
            self.node.get_logger().warning(f"rejected the goal on {self.topic}: {exc}")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _cancel(self, handle: Any) -> CancelResponse:
        if self.active is not None and self.active[0] is handle:
            self.servo.cancel(self.position)
            self._finish(CANCELED)
        return CancelResponse.ACCEPT

    async def _execute(self, handle: Any) -> Any:
        if self.active is not None:
            self._finish(PREEMPTED)
        done = Future()
        self.active = (handle, done)
        self.servo.accept(self._request(handle.request), now=self.now_ns() * 1e-9)
        outcome = await done
        result = self.action.Result()
        if isinstance(outcome, GripperOutcome):
            self._fill(result, outcome)
            (handle.succeed if outcome.end is GoalEnd.SUCCEEDED else handle.abort)()
        elif outcome == CANCELED:
            handle.canceled()
        else:
            handle.abort()
        return result

    def _fill(self, result: Any, outcome: GripperOutcome) -> None:
        """The result fields: position, effort, stalled, reached_goal (parallel: ``state``)."""
        result.stalled, result.reached_goal = outcome.stalled, outcome.reached_goal
        if self.parallel:
            result.state.name = [self.joint]
            result.state.position = [outcome.position]
            result.state.effort = [outcome.effort]
        else:
            result.position, result.effort = outcome.position, outcome.effort

    def _finish(self, outcome: GripperOutcome | str) -> None:
        """End the active goal with ``outcome`` (a judged end, or preempted / canceled)."""
        if self.active is not None:
            self.active[1].set_result(outcome)
            self.active = None

    # ----------------------------------------------------------------- the ticks
    def setpoints(self, t_ns: int) -> dict[str, np.ndarray]:
        """The jaws' tip setpoints (m) for the step to sim time ``t_ns``, within the joint
        limits (:meth:`.sim_controllers.SimJaws.limit`).
        """
        dt = self.world.dt
        joint = self.servo.command(self.position, self.effort, dt=dt)
        return self.jaw_setpoints(self.limit(t_ns, self.controller.gripper.aperture(joint)))

    def joint_state(self, out: TickOutput) -> tuple[Any, Any]:
        """The joint states of tick ``out``; the active goal is judged on them."""
        previous = self.position
        publisher, msg = super().joint_state(out)
        self.position, self.effort = msg.position[0], msg.effort[0]
        self.velocity = 0.0 if out.index == 0 else (self.position - previous) / self.world.dt
        outcome = self.servo.update(now=out.stamp_ns * 1e-9, position=self.position,
                                    velocity=self.velocity)
        if outcome is not None:
            self.outcomes.append(outcome)
            self._finish(outcome)
        return publisher, msg
