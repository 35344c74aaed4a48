# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The goal semantics of ros2_controllers' gripper action controllers (Jazzy), ROS-free.

Both the GripperActionController (``control_msgs/action/GripperCommand``) and the
ParallelGripperController (``control_msgs/action/ParallelGripperCommand``) control one joint
through its position command interface, and judge the active goal every update from the
joint's position and velocity state, in joint units:

- **reached**: ``|command - position| < goal_tolerance``: the goal succeeds with
  ``reached_goal = true, stalled = false``;
- **stalled**: otherwise, while ``|velocity| > stall_velocity_threshold`` the goal counts as
  moving; once it has not moved for more than ``stall_timeout`` s the goal ends with
  ``stalled = true, reached_goal = false``: aborted, or succeeded with ``allow_stalling``;
- a new goal preempts the active one; a cancel holds the measured position;
- the result's ``effort`` is the controller's computed command, which for a position interface
  is the goal's effort limit (not a measurement: the measured effort is on ``joint_states``).

:class:`GripperServo` is that logic plus what the simulated hardware adds in place of a
gripper's own servo: the commanded position approaches the goal's at the goal's speed limit,
and the jaws stop closing while the jaw effort is at the effort limit (a force-controlled stop:
the jaws then stand still, and the goal stalls).

>>> servo = GripperServo(GripperParameters(goal_tolerance=0.01, stall_timeout=0.5),
...                      position=0.0)
>>> servo.accept(GripperGoal(position=0.1, effort=5.0, velocity=1.0), now=0.0)
>>> round(servo.command(0.0, 0.0, dt=0.01), 6)
0.01
>>> servo.update(now=0.01, position=0.095, velocity=0.5) is None
False
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from squeeze_grasp_ros.mechanics.vocabulary import _Name

__all__ = ["GoalEnd", "GoalRefused", "GripperGoal", "GripperOutcome", "GripperParameters",
           "GripperServo", "gripper_goal"]


class GoalRefused(ValueError):
    """A goal the controller rejects; the message says why."""


class GoalEnd(_Name):
    """How a gripper goal ended."""

    SUCCEEDED = "succeeded"
    ABORTED = "aborted"


@dataclass(frozen=True)
class GripperParameters:
    """The controller's parameters (joint units: rad or m, and their efforts), with the stock
    defaults of the Jazzy ParallelGripperController.

    Attributes
    ----------
    goal_tolerance : float
        A goal is reached within this distance of its position (default 0.01).
    stall_velocity_threshold : float
        Slower than this the joint counts as standing still, per s (default 0.001).
    stall_timeout : float
        Standing still this long (s) while the goal is not reached is a stall (default 1.0).
    allow_stalling : bool
        A stall succeeds instead of aborting (default False).
    max_effort : float
        Effort limit of a goal that gives none (default 10.0).
    max_velocity : float
        Speed limit of a goal that gives none, per s (default 0.1; ``inf``: the command jumps
        to the goal, as the GripperActionController's).
    """

    goal_tolerance: float = 0.01
    stall_velocity_threshold: float = 0.001
    stall_timeout: float = 1.0
    allow_stalling: bool = False
    max_effort: float = 10.0
    max_velocity: float = 0.1


@dataclass(frozen=True)
class GripperGoal:
    """One accepted goal: joint position, effort limit and speed limit (joint units)."""

    position: float
    effort: float
    velocity: float


@dataclass(frozen=True)
class GripperOutcome:
    """The end of a goal: the action's result fields and the goal's end state."""

    end: GoalEnd
    position: float
    effort: float
    reached_goal: bool
    stalled: bool


class GripperServo:
    """The active goal of one gripper joint and the position command it yields.

    Parameters
    ----------
    parameters : GripperParameters
    position : float
        The joint's measured position at activation (the first command holds it).
    """

    def __init__(self, parameters: GripperParameters, *, position: float) -> None:
        self.parameters = parameters
        self.goal: GripperGoal | None = None
        self.target = float(position)
        self.commanded = float(position)
        self.effort = parameters.max_effort
        self.velocity = parameters.max_velocity
        self.last_movement = 0.0

    def accept(self, goal: GripperGoal, *, now: float) -> None:
        """Make ``goal`` active (the caller preempts the previous one); ``now`` in s."""
        self.goal = goal
        self.target, self.effort, self.velocity = goal.position, goal.effort, goal.velocity
        self.last_movement = float(now)

    def cancel(self, position: float) -> None:
        """Drop the active goal and hold ``position`` with the default limits."""
        self.goal = None
        self.target = self.commanded = float(position)
        self.effort, self.velocity = self.parameters.max_effort, self.parameters.max_velocity

    def update(self, *, now: float, position: float, velocity: float) -> GripperOutcome | None:
        """Judge the active goal at time ``now`` (s) from the measured joint ``position`` and
        ``velocity``; the outcome when it ends (the goal is then no longer active).
        """
        if self.goal is None:
            return None
        p = self.parameters
        if abs(self.target - position) < p.goal_tolerance:
            return self._end(GoalEnd.SUCCEEDED, position, reached=True)
        if abs(velocity) > p.stall_velocity_threshold:
            self.last_movement = float(now)
        elif now - self.last_movement > p.stall_timeout:
            return self._end(GoalEnd.SUCCEEDED if p.allow_stalling else GoalEnd.ABORTED,
                             position, reached=False)
        return None

    def _end(self, end: GoalEnd, position: float, *, reached: bool) -> GripperOutcome:
        self.goal = None
        return GripperOutcome(end, float(position), float(self.effort), reached, not reached)

    def command(self, position: float, effort: float, *, dt: float) -> float:
        """The joint position command of the next ``dt`` s, from the measured ``position`` and
        ``effort``: toward the target at the speed limit, and no further toward it than the
        measured position while ``|effort|`` is at the effort limit (also after the goal ended:
        the command and its limit stay, as on the stock controllers).
        """
        step = self.velocity * dt
        self.commanded = min(max(self.target, self.commanded - step), self.commanded + step)
        if abs(effort) >= self.effort > 0.0 and \
                abs(self.target - self.commanded) < abs(self.target - position):
            self.commanded = float(position)
        return self.commanded


def gripper_goal(position: float, effort: float | None, velocity: float | None, *,
                 parameters: GripperParameters, joint_range: tuple[float, float],
                 effort_limit: float) -> GripperGoal:
    """The goal of a request, checked (joint units).

    Parameters
    ----------
    position : float
        The requested joint position.
    effort, velocity : float or None
        The requested effort and speed limits; None or an effort of 0: the parameters'.
    parameters : GripperParameters
    joint_range : (float, float)
        The joint positions of the device's opening range (either order).
    effort_limit : float
        The device's largest joint effort.

    Raises
    ------
    GoalRefused
        Naming the field and its valid range. The stock controllers accept any position and
        effort; this one refuses what the device cannot do.

    >>> p = GripperParameters(max_effort=3.0)
    >>> gripper_goal(0.2, 0.0, None, parameters=p, joint_range=(0.8, 0.0), effort_limit=235.0)
    GripperGoal(position=0.2, effort=3.0, velocity=0.1)
    >>> try:
    ...     gripper_goal(0.9, 1.0, None, parameters=p, joint_range=(0.8, 0.0), effort_limit=9.0)
    ... except GoalRefused as exc:
    ...     print(exc)
    position 0.9 is outside the joint range [0, 0.8]
    """
    lo, hi = sorted(joint_range)
    if not math.isfinite(position):
        raise GoalRefused(f"position {position} is not finite")
    if not lo <= position <= hi:
        raise GoalRefused(f"position {position:g} is outside the joint range [{lo:g}, {hi:g}]")
    if effort is None or effort == 0.0:
        effort = parameters.max_effort
    elif not (math.isfinite(effort) and 0.0 < effort <= effort_limit):
        raise GoalRefused(f"effort {effort:g} is outside (0, {effort_limit:g}], the device's "
                          "effort limit (0: the controller's max_effort)")
    if velocity is None:
        velocity = parameters.max_velocity
    elif not (math.isfinite(velocity) and velocity > 0.0):
        raise GoalRefused(f"velocity {velocity:g} must be finite and > 0")
    return GripperGoal(float(position), float(effort), float(velocity))
