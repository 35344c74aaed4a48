# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor's goal, feedback, result and status."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from geometry_msgs.msg import Vector3

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.msg import (
    ContactEvent,
    ExecutorStatus,
    MonitorStatus,
)
from squeeze_grasp_ros.control.motion import (
    DEFAULT_ATTEMPTS,
    DEFAULT_CLEARANCE,
    DEFAULT_MARGIN,
    Command,
    GraspGoal,
    GraspProgram,
    Observation,
)
from squeeze_grasp_ros.ros.messages.cdr import monitor_status_cdr_reading
from squeeze_grasp_ros.ros.messages.common import float64_array, header, stamp_ns, vector3

# --------------------------------------------------------------------------- pipeline: executor


def observation(msg: MonitorStatus) -> Observation:
    """The executor's :class:`Observation` of a ``MonitorStatus``."""
    fingers = list(msg.fingers)
    return Observation(
        stamp_ns(msg.header.stamp),
        {f: np.array([p.x, p.y]) for f, p in zip(fingers, msg.positions)},
        {f: np.array([v.x, v.y]) for f, v in zip(fingers, msg.forces)},
        {f: np.array([v.x, v.y]) for f, v in zip(fingers, msg.normals)},
        tuple((a.type, a.finger) for a in msg.alarms),
        tuple(e.type for e in msg.events),
        float(msg.depth),
    )


def observation_cdr(data: bytes) -> Observation | None:
    """The :class:`Observation` of a serialised ``MonitorStatus``, read from its bytes
    (:mod:`.cdr`; the same numbers as :func:`observation` of the message), when the status
    carries no event and no alarm, as at most ticks; None when it carries any.
    """
    read = monitor_status_cdr_reading(data)
    if read is None:
        return None
    ns, fingers, *vectors, depth = read
    positions, forces, normals = (dict(zip(fingers, v[:, :2].copy())) for v in vectors)
    return Observation(ns, positions, forces, normals, (), (), depth)


def _planar(vectors: Sequence[Vector3]) -> np.ndarray:
    return np.array([[v.x, v.y] for v in vectors], float).reshape(-1, 2)


def grasp_goal(msg: ExecuteGrasp.Goal) -> GraspGoal:
    """The :class:`GraspGoal` of an ``ExecuteGrasp`` goal (shapes are checked by
    :func:`..control.motion.goal_problem`).
    """
    fingers = tuple(msg.fingers)
    waypoints = _planar(msg.resist_waypoints)
    k = len(msg.resist_travel)
    shaped = (
        waypoints.reshape(k, len(fingers), 2)
        if k and len(waypoints) == k * len(fingers)
        else waypoints.reshape(1, -1, 2)
    )
    return GraspGoal(
        fingers,
        _planar(msg.directions),
        float(msg.depth),
        float(msg.relative_per_depth),
        msg.on_slip_alarm or "hold",
        _planar(msg.pure_directions) if msg.pure_directions else None,
        int(msg.max_attempts) or DEFAULT_ATTEMPTS,
        float(msg.resqueeze_margin) or DEFAULT_MARGIN,
        float(msg.release_clearance) or DEFAULT_CLEARANCE,
        msg.adversary if msg.resist else "",
        np.array([msg.adversary_translation.x, msg.adversary_translation.y]),
        np.asarray(msg.resist_travel, float),
        shaped,
    )


def goal_msg_problem(msg: ExecuteGrasp.Goal) -> str | None:
    """Why goal ``msg`` asks for what :func:`grasp_goal` cannot carry, or None: ``resist``
    without an ``adversary`` (a :class:`GraspGoal` resists exactly when it names one). Before,
    such a goal, e.g. ``ros2 action send_goal ... "{..., resist: true}"``, ran the squeeze alone
    and ended ``depth_reached``, SUCCEEDED, without a word of the resistance.
    """
    if msg.resist and not msg.adversary:
        return ("resist is true but adversary is empty: name the adversary finger, with "
                "adversary_translation, resist_travel and resist_waypoints")
    return None


def grasp_goal_msg(goal: GraspGoal) -> ExecuteGrasp.Goal:
    """The ``ExecuteGrasp`` goal of a :class:`GraspGoal`."""
    msg = ExecuteGrasp.Goal(
        fingers=list(goal.fingers),
        directions=[vector3(d) for d in goal.directions],
        depth=float(goal.depth),
        relative_per_depth=float(goal.relative_per_depth),
        on_slip_alarm=goal.on_slip_alarm,
        max_attempts=int(goal.max_attempts),
        resqueeze_margin=float(goal.resqueeze_margin),
        release_clearance=float(goal.release_clearance),
        resist=goal.resist,
        adversary=goal.adversary,
        adversary_translation=vector3(goal.adversary_translation),
        resist_travel=float64_array(goal.resist_travel),
        resist_waypoints=[vector3(w) for w in goal.resist_waypoints.reshape(-1, 2)],
    )
    if goal.pure_directions is not None:
        msg.pure_directions = [vector3(d) for d in goal.pure_directions]
    return msg


def grasp_feedback(
    state: str,
    obs: Observation,
    fingers: Sequence[str],
    events: Sequence[ContactEvent],
    relative_per_depth: float,
    attempt: int,
    depth: float,
) -> ExecuteGrasp.Feedback:
    """``ExecuteGrasp`` feedback: the squeeze under way (from 1) and its measured ``depth`` (m,
    :meth:`.GraspProgram.depth`), the measured forces, events since the last feedback.
    """
    return ExecuteGrasp.Feedback(
        state=state,
        attempt=int(attempt),
        depth=float(depth),
        relative_depth=depth * relative_per_depth,
        fingers=list(fingers),
        forces=[vector3(obs.forces.get(f, np.zeros(2))) for f in fingers],
        latest_events=list(events),
    )


def grasp_result(
    program: GraspProgram,
    command: Command,
    obs: Observation | None,
    events: Sequence[ContactEvent],
    duration: float,
    success_terminations: Sequence[str],
) -> ExecuteGrasp.Result:
    """``ExecuteGrasp`` result of a finished :class:`GraspProgram` (measured numbers; the depth
    of the last squeeze, from its first contact).
    """
    fingers = list(program.fingers)
    forces = obs.forces if obs is not None else {}
    depth = program.depth(obs) if obs is not None else 0.0
    return ExecuteGrasp.Result(
        success=command.termination in success_terminations,
        termination=command.termination,
        message=command.message,
        depth=depth,
        relative_depth=depth * program.goal.relative_per_depth,
        ticks=program.ticks,
        duration=float(duration),
        hold_ticks=program.hold_ticks,
        redirected=program.redirected,
        attempts=program.attempts,
        resqueezed=program.attempts > 1,
        planned_depth=float(program.planned_depth),
        fingers=fingers,
        forces=[vector3(forces.get(f, np.zeros(2))) for f in fingers],
        work=float64_array([program.work[f] for f in fingers]),
        events=list(events),
    )


def invalid_goal_result(message: str) -> ExecuteGrasp.Result:
    """The result of a goal that cannot be executed."""
    return ExecuteGrasp.Result(
        success=False, termination=ExecuteGrasp.Result.INVALID_GOAL, message=message
    )


def executor_status_msg(state: str, depth: float, message: str, ns: int) -> ExecutorStatus:
    """``ExecutorStatus`` of the executor (depth: the squeeze's measured depth, m)."""
    return ExecutorStatus(header=header(ns), state=state, depth=float(depth), message=message)
