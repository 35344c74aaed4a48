# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Device streams: poses, wrenches and the lockstep tick."""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from geometry_msgs.msg import PoseStamped, WrenchStamped
from std_msgs.msg import Header

from squeeze_grasp_interfaces.msg import (
    Tick,
)
from squeeze_grasp_ros.mechanics.errors import unit_quaternion
from squeeze_grasp_ros.ros.messages.common import header

# --------------------------------------------------------------------------- pipeline: devices


def pose_msg(position: Sequence[float] | np.ndarray, ns: int, frame_id: str) -> PoseStamped:
    """A fingertip centre (x, y), m, as ``PoseStamped`` (z = 0, identity orientation)."""
    msg = PoseStamped(header=header(ns, frame_id))
    msg.pose.position.x = float(position[0])
    msg.pose.position.y = float(position[1])
    msg.pose.orientation.w = 1.0
    return msg




def pose_position(msg: PoseStamped) -> np.ndarray:
    """The planar position (x, y), m, of a ``PoseStamped``."""
    return np.array([msg.pose.position.x, msg.pose.position.y])


def pose_in_base(values: Sequence[float], frame_id: str) -> PoseStamped:
    """``PoseStamped`` of [x, y, z, qx, qy, qz, qw] (m, unit quaternion) in ``frame_id``, its
    quaternion normalised (:func:`~squeeze_grasp_ros.mechanics.errors.unit_quaternion`).

    Raises
    ------
    ValueError
        Not seven finite numbers, or a quaternion that is not a unit one within tf2's tolerance
        (an :class:`~squeeze_grasp_ros.mechanics.errors.InvalidInputError`).
    """
    values = [float(v) for v in values]
    if len(values) != 7 or not all(math.isfinite(v) for v in values[:3]):
        raise ValueError(f"a pose is 7 finite numbers, x y z (m) qx qy qz qw (a unit "
                         f"quaternion), got {values}")
    msg = PoseStamped(header=Header(frame_id=frame_id))
    p, q = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = values[:3]
    q.x, q.y, q.z, q.w = (float(v) for v in unit_quaternion("its orientation qx qy qz qw",
                                                            values[3:]))
    return msg


def wrench_msg(force: np.ndarray, torque: np.ndarray, ns: int, frame_id: str) -> WrenchStamped:
    """``WrenchStamped`` of a force (3,), N, and torque (3,), N m, in ``frame_id``."""
    msg = WrenchStamped(header=header(ns, frame_id))
    w = msg.wrench
    w.force.x, w.force.y, w.force.z = (float(v) for v in force)
    w.torque.x, w.torque.y, w.torque.z = (float(v) for v in torque)
    return msg




def wrench_force(msg: WrenchStamped) -> np.ndarray:
    """The force (3,), N, of a ``WrenchStamped``."""
    f = msg.wrench.force
    return np.array([f.x, f.y, f.z])


def tick_msg(index: int, ns: int, readings: Sequence[str]) -> Tick:
    """The end-of-tick message of lockstep tick ``index`` at sim time ``ns`` (readings as
    "<device>/<stream>").
    """
    return Tick(header=header(ns), index=int(index), readings=list(readings))
