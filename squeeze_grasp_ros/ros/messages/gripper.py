# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``plan_gripper_grasp``: a gripper plan as ``PlanGripperGrasp`` response."""
from __future__ import annotations

import math

import numpy as np
from geometry_msgs.msg import PoseStamped

from squeeze_grasp_interfaces.msg import GripperGrasp
from squeeze_grasp_interfaces.srv import PlanGripperGrasp
from squeeze_grasp_ros.mechanics.errors import unit_quaternion
from squeeze_grasp_ros.mechanics.squeeze.gripper_grasp import GripperCandidate
from squeeze_grasp_ros.ros.messages.common import float64_array, header, int32_array, success
from squeeze_grasp_ros.scene.gripper_plan import GripperPlan

OBJECT_FRAME = "object"
"""The frame of the poses: the scene's object frame (the pipeline's ``FRAME``)."""


def gripper_pose(candidate: GripperCandidate) -> PoseStamped:
    """The gripper centre with its x axis along the closing direction (a yaw about z)."""
    msg = PoseStamped(header=header(0, OBJECT_FRAME))
    msg.pose.position.x, msg.pose.position.y = (float(v) for v in candidate.center)
    msg.pose.orientation.z = math.sin(0.5 * candidate.yaw)
    msg.pose.orientation.w = math.cos(0.5 * candidate.yaw)
    return msg


PLANAR_TILT = 0.01
"""Largest out-of-plane component of a gripper pose's closing direction (its x axis), as the
sine of its tilt from the object plane (0.57 degrees)."""


def gripper_line_pose(msg: PoseStamped, frame_id: str) -> tuple[np.ndarray, float]:
    """The gripper centre (x, y), m, and closing direction's yaw, rad, of a ``PoseStamped`` in
    the object frame ``frame_id``: the inverse of :func:`gripper_pose` (the x axis of the pose's
    orientation is the closing direction; its projection on the plane is taken).

    Raises
    ------
    ValueError
        Another frame, a position not finite, an orientation that is not a unit quaternion
        within tf2's tolerance (:func:`~squeeze_grasp_ros.mechanics.errors.unit_quaternion`),
        or an x axis tilted out of the object plane beyond :data:`PLANAR_TILT`.
    """
    if msg.header.frame_id != frame_id:
        raise ValueError(f"the gripper pose is in frame '{msg.header.frame_id}', not the object "
                         f"frame '{frame_id}' (transform it with tf2 first)")
    p, q = msg.pose.position, msg.pose.orientation
    centre = np.array([p.x, p.y])
    if not np.all(np.isfinite(centre)):
        raise ValueError(f"the gripper pose's position ({p.x}, {p.y}) must be finite")
    x, y, z, w = unit_quaternion("the gripper pose's orientation", [q.x, q.y, q.z, q.w])
    axis = np.array([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)])
    if abs(axis[2]) > PLANAR_TILT:
        raise ValueError(f"the gripper pose's closing direction (its x axis) leaves the object "
                         f"plane: its z component is {axis[2]:.4g}, at most {PLANAR_TILT:g} "
                         "allowed")
    return centre, float(np.arctan2(axis[1], axis[0]))


def gripper_grasps(plan: GripperPlan) -> list[GripperGrasp]:
    """One ``GripperGrasp`` per ranked candidate, the evaluated ones with their command."""
    evaluated = {e.candidate.rank: e for e in plan.evaluations}
    out = []
    for c in plan.candidates:
        msg = GripperGrasp(pose=gripper_pose(c), rank=c.rank, nodes=int32_array(c.nodes),
                           first_contacts=int32_array(c.first_contacts),
                           aperture_at_contact=c.aperture, stiffness=c.stiffness,
                           work_quality=c.work_quality)
        e = evaluated.get(c.rank)
        if e is not None:
            command = plan.command(e)
            msg.evaluated = True
            msg.closing, msg.aperture_planned, msg.jaw_force = e.closing, e.aperture, e.jaw_force
            msg.termination = str(e.termination)
            msg.has_limit = e.limit is not None
            msg.limit_closing = e.limit_closing or 0.0
            msg.limit_termination = "" if e.limit is None else str(e.limit)
            msg.limit_searched_to = e.limit_search
            msg.command_force, msg.exceeds_max_force = command["jaw_force"], e.exceeds_max_force
            msg.lift_force = e.lift_force or 0.0
            msg.holds_weight = bool(e.holds_weight)
            msg.joint_names = command["joints"]
            msg.joint_positions = float64_array(command["positions"])
            msg.joint_efforts = float64_array(command["efforts"])
        out.append(msg)
    return out


def plan_gripper_grasp_response(plan: GripperPlan, digest: str) -> PlanGripperGrasp.Response:
    """A successful response carrying ``plan``."""
    return success(PlanGripperGrasp.Response, object_digest=digest, gripper=plan.gripper.name,
                   candidates=gripper_grasps(plan))
