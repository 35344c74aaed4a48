# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor's shape watch (parameter ``shape_watch``): camera frames against the predicted
deformed boundary (:mod:`squeeze_grasp_ros.perception.shape_watch`, paper App. C).

It reads ``camera/mask``, ``camera/camera_info``, ``camera/pose`` and the planner's latched
``planner/predicted_shapes``. A frame is matched once the monitor has closed the tick of the
frame's stamp (so the depth is the tracker's depth at that tick); the residual goes to
``monitor/shape_residual`` and, when it first exceeds ``shape_mismatch_threshold`` or the
frame shows another number of holes than predicted (a hole closed or vanished), a
``shape_mismatch`` alarm to ``monitor/alarms`` (value: the RMS residual, m; one alarm per
episode). A frame that gives no outline is logged and skipped.

Frames are kept until they can be matched: the world's first frame (tick 0) is latched before
the run has latched the prediction, and the latched topics arrive in any order, so a frame
waits for its tick to close *and* for the prediction, the camera info and the pose. At most
:data:`PENDING_FRAMES` wait; beyond that (no prediction ever comes: a world launched without a
run) the oldest is dropped, with one log line.
"""
from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image

from squeeze_grasp_interfaces.msg import Alarm, PredictedShapes, ShapeResidual
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.perception.extract import MIN_AREA_PX, extract_outline
from squeeze_grasp_ros.perception.shape_watch import PredictedShapes as Prediction
from squeeze_grasp_ros.perception.shape_watch import check_frame
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.images import camera_model, camera_pose, image_array
from squeeze_grasp_ros.ros.messages.objects import polygon_points
from squeeze_grasp_ros.ros.nodes import pipeline

DEPTH_HISTORY = 4096
"""Closed ticks whose depth is kept for frames that arrive after their tick closed."""

PENDING_FRAMES = 64
"""Frames kept while their tick is open or the prediction has not arrived (6.4 s at 10 Hz)."""


class ShapeWatcher:
    """Matches camera frames for ``node`` (the monitor), which calls :meth:`tick`."""

    def __init__(self, node: Node, alarm_pub: Any, threshold: float,
                 object_height: float) -> None:
        self.node, self.alarm_pub = node, alarm_pub
        self.threshold, self.object_height = threshold, object_height
        self.prediction: Prediction | None = None
        self.camera = self.pose = None
        self.frame_id = pipeline.FRAME
        self.waiting: dict[int, Image] = {}
        self.depths: OrderedDict[int, float] = OrderedDict()
        self.active = False
        self.dropped = 0
        sub = node.create_subscription
        sub(Image, pipeline.CAMERA_MASK, self._image, pipeline.CAMERA)
        sub(CameraInfo, pipeline.CAMERA_INFO, self._info, pipeline.CAMERA)
        sub(PoseStamped, pipeline.CAMERA_POSE, self._pose, pipeline.LATCHED)
        sub(PredictedShapes, pipeline.PREDICTED_SHAPES, self._prediction, pipeline.LATCHED)
        self.residual_pub = node.create_publisher(ShapeResidual, pipeline.SHAPE_RESIDUAL,
                                                  pipeline.loop_qos(100))

    def _info(self, msg: CameraInfo) -> None:
        self.camera = camera_model(msg)
        self._flush()

    def _pose(self, msg: PoseStamped) -> None:
        self.pose, self.frame_id = camera_pose(msg.pose), msg.header.frame_id
        self._flush()

    def _prediction(self, msg: PredictedShapes) -> None:
        outlines = [np.asarray(polygon_points(p), float) for p in msg.outlines]
        holes = [np.asarray(polygon_points(p), float) for p in msg.holes]
        per = len(holes) // max(len(outlines), 1)
        if per * len(outlines) != len(holes):
            self.node.get_logger().error(
                f"shape watch: planner/predicted_shapes has {len(holes)} holes for "
                f"{len(outlines)} depths (a multiple is needed); prediction ignored")
            return
        self.prediction = Prediction(np.asarray(msg.depths, float), tuple(outlines), tuple(
            tuple(holes[k * per:(k + 1) * per]) for k in range(len(outlines))) if per else ())
        self._flush()

    def _image(self, msg: Image) -> None:
        self.waiting[messages.stamp_ns(msg.header.stamp)] = msg
        while len(self.waiting) > PENDING_FRAMES:
            dropped = min(self.waiting)
            del self.waiting[dropped]
            if not self.dropped:
                self.node.get_logger().warning(
                    f"shape watch: more than {PENDING_FRAMES} frames wait for the prediction "
                    f"(planner/predicted_shapes), the camera info or the pose; dropping the "
                    f"oldest (first at {dropped * 1e-9:.3f} s)")
            self.dropped += 1
        self._flush()

    def tick(self, ns: int, depth: float) -> None:
        """The monitor closed tick ``ns`` at ``depth`` (m): match the frames up to it."""
        self.depths[ns] = depth
        while len(self.depths) > DEPTH_HISTORY:
            self.depths.popitem(last=False)
        self._flush()

    def _flush(self) -> None:
        """Match the waiting frames whose tick has closed, once the prediction, the camera
        info and the pose are known.
        """
        if self.prediction is None or self.camera is None or self.pose is None \
                or not self.depths:
            return
        closed = next(reversed(self.depths))
        for stamp in sorted(s for s in self.waiting if s <= closed):
            self._match(self.waiting.pop(stamp), stamp,
                        self.depths.get(stamp, self.depths[closed]))

    def _match(self, msg: Image, ns: int, depth: float) -> None:
        try:
            pixels, encoding = image_array(msg)
            seen = extract_outline(pixels, encoding, self.camera, self.pose,
                                   object_height_m=self.object_height, frame_id=self.frame_id)
        except InvalidInputError as error:
            self.node.get_logger().warning(f"shape watch: no outline at {ns * 1e-9:.3f} s: "
                                           f"{error}")
            return
        check = check_frame(seen.outline, self.prediction, depth, self.threshold,
                            min_hole_area=MIN_AREA_PX * seen.pixel_size_m ** 2)
        match = check.match
        self.residual_pub.publish(ShapeResidual(
            header=messages.header(ns, self.frame_id), depth=float(depth), rms=match.rms_m,
            max=match.max_m, scale=float(check.scale), rotation=float(match.rotation),
            threshold=float(self.threshold), holes_predicted=check.holes_predicted,
            holes_seen=check.holes_seen))
        if check.mismatch and not self.active:
            self.alarm_pub.publish(Alarm(
                header=messages.header(ns), type=Alarm.SHAPE_MISMATCH, finger="",
                value=match.rms_m,
                message=f"{check.reason}: seen outline {match.rms_m * 1e3:.3f} mm RMS from the "
                        f"predicted boundary at depth {depth * 1e3:.3f} mm (threshold "
                        f"{self.threshold * 1e3:.3f} mm; similarity scale {check.scale:.4f})"))
        self.active = check.mismatch
