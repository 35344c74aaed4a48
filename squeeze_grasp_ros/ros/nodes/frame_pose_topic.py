# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner's frame pose topic: where a typed object's outline frame is, from a
``geometry_msgs/PoseStamped`` topic instead of the request's ``frame_pose`` field.

With the planner parameters ``frame_pose_topic`` (e.g. ``camera_plane/pose``) and
``frame_pose_frame`` (the frame whose pose the topic carries, e.g. ``camera_plane``), the planner
keeps the newest pose published there (``header.frame_id``: the planner's ``object`` frame, or
empty). A ``load_object`` whose outline is in ``frame_pose_frame`` and whose ``frame_pose`` is
left at its default (a new ``Pose``'s identity, or all zeros) uses it; a ``frame_pose`` given in
the request wins. The pose must be fresh: at
most ``frame_pose_max_age`` seconds from the outline's ``header.stamp`` (or, for an unstamped
outline, from the planner's clock; 0 = any age). No pose yet, a stale one, or one in another
parent frame refuses the request (INVALID_ARGUMENT) with what to do.

This is what a robot with tf2 feeds from a listener (``lookup_transform("object", frame,
stamp)`` -> ``PoseStamped``), or from a ``static_transform_publisher``'s numbers, latched.
"""
from __future__ import annotations

import dataclasses
from typing import Any

from geometry_msgs.msg import PoseStamped
from rclpy.node import Node

from squeeze_grasp_interfaces.msg import ObjectDescription
from squeeze_grasp_ros.planning.errors import invalid
from squeeze_grasp_ros.planning.typed_objects import OBJECT_FRAME, FramePose, TypedObject
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline

__all__ = ["FramePoseTopic", "frame_pose_topic"]


def _unset(msg: ObjectDescription) -> bool:
    """Whether the request leaves ``frame_pose`` at its default: the identity of a new
    ``geometry_msgs/Pose`` (w = 1), or all zeros.
    """
    p, q = msg.frame_pose.position, msg.frame_pose.orientation
    return not any((p.x, p.y, p.z, q.x, q.y, q.z)) and q.w in (0.0, 1.0)


class FramePoseTopic:
    """The newest pose of frame ``frame`` in the object frame, from ``topic`` (latched QoS:
    transient-local, reliable; a latched publisher's pose arrives however late the planner
    starts).

    Parameters
    ----------
    node : Node
        The planner.
    topic, frame : str
        The ``PoseStamped`` topic and the frame whose pose it carries.
    max_age : float
        s, largest distance between the pose's stamp and the outline's (0 = any).
    """

    def __init__(self, node: Node, topic: str, frame: str, max_age: float) -> None:
        if not frame or frame == OBJECT_FRAME:
            raise ParameterError(f"parameter frame_pose_frame must name the outline frame whose "
                                 f"pose {topic} carries (not '' or {OBJECT_FRAME!r}), got "
                                 f"{frame!r}")
        if not max_age >= 0:
            raise ParameterError(f"parameter frame_pose_max_age must be >= 0 s (0 = any age), "
                                 f"got {max_age!r}")
        pipeline.check_topic("frame_pose_topic", topic)
        self.node, self.topic, self.frame, self.max_age = node, topic, frame, float(max_age)
        self.latest: PoseStamped | None = None
        node.create_subscription(PoseStamped, topic, self._pose, pipeline.LATCHED)

    def _pose(self, msg: PoseStamped) -> None:
        self.latest = msg  # one reference swap: the worker threads read a whole message

    def resolve(self, msg: ObjectDescription, typed: TypedObject) -> TypedObject:
        """``typed`` with the topic's pose when its outline is in :attr:`frame` and the request
        leaves ``frame_pose`` unset; else ``typed`` unchanged.

        Raises
        ------
        PlannerError
            INVALID_ARGUMENT: no pose received yet, a pose in another parent frame, or a stale
            one.
        """
        if typed.frame_id != self.frame or not _unset(msg):
            return typed
        latest = self.latest
        where = (f"object.outline.header.frame_id is {self.frame!r} and object.frame_pose is "
                 f"unset, so its pose comes from {self.topic}")
        if latest is None:
            raise invalid(f"{where}, where nothing has arrived yet (the planner subscribes "
                          "transient-local: publish the pose latched, or fill "
                          "object.frame_pose)")
        if latest.header.frame_id not in ("", OBJECT_FRAME):
            raise invalid(f"{where}, whose pose is in frame {latest.header.frame_id!r}: it must "
                          f"be the pose of {self.frame!r} in {OBJECT_FRAME!r}")
        stamp = messages.stamp_ns(msg.outline.header.stamp)
        reference = stamp or self.node.get_clock().now().nanoseconds
        age = abs(reference - messages.stamp_ns(latest.header.stamp)) * 1e-9
        if self.max_age and age > self.max_age:
            against = "the outline's stamp" if stamp else "the planner's clock"
            raise invalid(f"{where}, whose newest pose is {age:.3f} s from {against} "
                          f"(frame_pose_max_age = {self.max_age:g} s): stale; publish a fresh "
                          "pose or fill object.frame_pose")
        p, q = latest.pose.position, latest.pose.orientation
        return dataclasses.replace(typed, frame_pose=FramePose(
            (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)))


def frame_pose_topic(node: Node, value: Any) -> FramePoseTopic | None:
    """The planner's :class:`FramePoseTopic` from its parameters (``value(name)``); None when
    ``frame_pose_topic`` is empty.
    """
    topic = value("frame_pose_topic")
    if not topic:
        return None
    return FramePoseTopic(node, topic, value("frame_pose_frame"),
                          float(value("frame_pose_max_age")))
