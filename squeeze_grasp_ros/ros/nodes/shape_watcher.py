# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor's shape watch (parameter ``shape_watch``): camera frames against the predicted
deformed boundary (:mod:`squeeze_grasp_ros.perception.shape_watch`, paper App. C).

It reads ``camera/mask``, ``camera/camera_info``, ``camera/pose`` and the planner's latched
``planner/predicted_shapes``. A frame is matched once the monitor has closed the tick of the
frame's stamp (so the depth is the tracker's depth at that tick); the residual goes to
``monitor/shape_residual`` and, when it first exceeds ``shape_mismatch_threshold``, a
``shape_mismatch`` alarm to ``monitor/alarms`` (value: the RMS residual, m; one alarm per
episode). A frame that gives no outline is logged and skipped.
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
from squeeze_grasp_ros.perception.extract import extract_outline
from squeeze_grasp_ros.perception.shape_watch import PredictedShapes as Prediction
from squeeze_grasp_ros.perception.shape_watch import check_frame
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.images import camera_model, camera_pose, image_array
from squeeze_grasp_ros.ros.messages.objects import polygon_points
from squeeze_grasp_ros.ros.nodes import pipeline

DEPTH_HISTORY = 4096
"""Closed ticks whose depth is kept for frames that arrive after their tick closed."""


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
        self.matched = 0
        self.skipped = 0
        sub = node.create_subscription
        sub(Image, pipeline.CAMERA_MASK, self._image, pipeline.LATCHED)
        sub(CameraInfo, pipeline.CAMERA_INFO, self._info, pipeline.LATCHED)
        sub(PoseStamped, pipeline.CAMERA_POSE, self._pose, pipeline.LATCHED)
        sub(PredictedShapes, pipeline.PREDICTED_SHAPES, self._prediction, pipeline.LATCHED)
        self.residual_pub = node.create_publisher(ShapeResidual, pipeline.SHAPE_RESIDUAL,
                                                  pipeline.loop_qos(100))

    def _info(self, msg: CameraInfo) -> None:
        self.camera = camera_model(msg)

    def _pose(self, msg: PoseStamped) -> None:
        self.pose, self.frame_id = camera_pose(msg.pose), msg.header.frame_id

    def _prediction(self, msg: PredictedShapes) -> None:
        self.prediction = Prediction(np.asarray(msg.depths, float), tuple(
            np.asarray(polygon_points(p), float) for p in msg.outlines))

    def _image(self, msg: Image) -> None:
        ns = messages.stamp_ns(msg.header.stamp)
        if ns in self.depths:
            self._match(msg, ns, self.depths[ns])
        else:
            self.waiting[ns] = msg

    def tick(self, ns: int, depth: float) -> None:
        """The monitor closed tick ``ns`` at ``depth`` (m): match the frames up to it."""
        self.depths[ns] = depth
        while len(self.depths) > DEPTH_HISTORY:
            self.depths.popitem(last=False)
        for stamp in sorted(s for s in self.waiting if s <= ns):
            self._match(self.waiting.pop(stamp), stamp, self.depths.get(stamp, depth))

    def _match(self, msg: Image, ns: int, depth: float) -> None:
        if self.prediction is None or self.camera is None or self.pose is None:
            if not self.skipped:  # once: a launched world publishes before the run plans
                self.node.get_logger().warning(
                    "shape watch: frame skipped (no prediction, camera_info or camera pose "
                    "yet); frames before the prediction are not matched")
            self.skipped += 1
            return
        try:
            pixels, encoding = image_array(msg)
            seen = extract_outline(pixels, encoding, self.camera, self.pose,
                                   object_height_m=self.object_height, frame_id=self.frame_id)
        except InvalidInputError as error:
            self.node.get_logger().warning(f"shape watch: no outline at {ns * 1e-9:.3f} s: "
                                           f"{error}")
            return
        match, scale, mismatch = check_frame(seen.outline, self.prediction, depth,
                                             self.threshold)
        self.matched += 1
        self.residual_pub.publish(ShapeResidual(
            header=messages.header(ns, self.frame_id), depth=float(depth), rms=match.rms_m,
            max=match.max_m, scale=float(scale), rotation=float(match.rotation),
            threshold=float(self.threshold)))
        if mismatch and not self.active:
            self.alarm_pub.publish(Alarm(
                header=messages.header(ns), type=Alarm.SHAPE_MISMATCH, finger="",
                value=match.rms_m,
                message=f"seen outline {match.rms_m * 1e3:.3f} mm RMS from the predicted "
                        f"boundary at depth {depth * 1e3:.3f} mm (threshold "
                        f"{self.threshold * 1e3:.3f} mm; similarity scale {scale:.4f})"))
        self.active = mismatch
