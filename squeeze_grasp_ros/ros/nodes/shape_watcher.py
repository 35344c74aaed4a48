# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor's shape watch (parameter ``shape_watch``): camera frames against the predicted
deformed boundary (:mod:`squeeze_grasp_ros.perception.shape_watch`, paper App. C).

It reads ``camera/mask``, ``camera/camera_info``, ``camera/pose`` and the planner's latched
``planner/predicted_shapes`` and ``planner/predicted_events`` (its force curve). A frame is
matched once the monitor has closed the tick of the frame's stamp (so the depth and the force
are the tracker's at that tick) twice: at the measured depth, and at the depth the prediction's
pair force curve gives for the measured pair force (the mean of the fingers' forces along their
motion; :func:`~squeeze_grasp_ros.perception.shape_watch.depth_at_force`, skipped below
``shape_min_force``, outside the curve or where it is not rising, with the reason in the
message). The residuals go to ``monitor/shape_residual``; when the equal-depth RMS first exceeds
``shape_mismatch_threshold``, the frame shows another number of holes than predicted (a hole
closed or vanished), or the equal-force RMS exceeds ``shape_at_force_threshold`` (a wrong E), a
``shape_mismatch`` alarm goes to ``monitor/alarms`` (value: the RMS residual that exceeded its
threshold, m; the message names it; one alarm per episode). A frame that gives no outline is
logged and skipped.

Frames are kept until they can be matched: the world's first frame (tick 0) is latched before
the run has latched the prediction, and the latched topics arrive in any order, so a frame
waits for its tick to close *and* for the predictions, the camera info and the pose. At most
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

from squeeze_grasp_interfaces.msg import Alarm, ContactEventArray, PredictedShapes, ShapeResidual
from squeeze_grasp_ros.control.force_watch import PredictedForces
from squeeze_grasp_ros.control.tracker import FingerSample, TrackerOutput
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.perception.extract import MIN_AREA_PX, extract_outline
from squeeze_grasp_ros.perception.shape_watch import (
    AtForce,
    DepthAtForce,
    check_frame,
    depth_at_force,
    pair_force,
)
from squeeze_grasp_ros.perception.shape_watch import PredictedShapes as Prediction
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.images import image_array
from squeeze_grasp_ros.ros.messages.objects import polygon_points
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.camera_inputs import CameraInputs
from squeeze_grasp_ros.ros.nodes.force_watcher import MotionForces

DEPTH_HISTORY = 4096
"""Closed ticks whose depth and force are kept for frames that arrive after their tick
closed."""

PENDING_FRAMES = 64
"""Frames kept while their tick is open or the prediction has not arrived (6.4 s at 10 Hz)."""


class ShapeWatcher:
    """Matches camera frames for ``node`` (the monitor), which calls :meth:`tick`.

    Parameters
    ----------
    threshold, at_force_threshold : float
        m, the RMS residuals at equal depth and at equal force that raise ``shape_mismatch``.
    object_height : float
        m, the object's top face above the support plane.
    min_force : float
        N, the smallest pair force matched at equal force.
    frame_id : str, optional
        The plane frame: the prediction's, and the one ``camera/pose`` must be in.
    """

    def __init__(self, node: Node, alarm_pub: Any, *, threshold: float,
                 at_force_threshold: float, object_height: float, min_force: float,
                 frame_id: str = pipeline.FRAME) -> None:
        self.node, self.alarm_pub = node, alarm_pub
        self.threshold, self.object_height = threshold, object_height
        self.at_force_threshold, self.min_force = at_force_threshold, min_force
        self.prediction: Prediction | None = None
        self.forces: PredictedForces | None = None
        self.has_events = False
        """The planner's ``predicted_events`` (with or without a force curve) has arrived."""
        self.motion = MotionForces()
        self.inputs = CameraInputs(frame_id)
        self.refused = ""
        """The last reason logged for a refused camera input or skipped frame."""
        self.waiting: dict[int, Image] = {}
        self.depths: OrderedDict[int, tuple[float, float | None]] = OrderedDict()
        """Closed tick -> (depth m, pair force N or None)."""
        self.skipped: AtForce | None = None
        self.active = False
        self.dropped = 0
        sub = node.create_subscription
        sub(Image, pipeline.CAMERA_MASK, self._image, pipeline.CAMERA)
        sub(CameraInfo, pipeline.CAMERA_INFO, self._info, pipeline.CAMERA)
        sub(PoseStamped, pipeline.CAMERA_POSE, self._pose, pipeline.LATCHED)
        sub(PredictedShapes, pipeline.PREDICTED_SHAPES, self._prediction, pipeline.LATCHED)
        sub(ContactEventArray, pipeline.PREDICTION, self._events, pipeline.LATCHED)
        self.residual_pub = node.create_publisher(ShapeResidual, pipeline.SHAPE_RESIDUAL,
                                                  pipeline.loop_qos(100))

    def _info(self, msg: CameraInfo) -> None:
        self._log(self.inputs.take_info(msg))  # e.g. uncalibrated (k all zero)
        self._flush()

    def _pose(self, msg: PoseStamped) -> None:
        self._log(self.inputs.take_pose(msg))  # e.g. another frame, not a unit quaternion
        self._flush()

    def _log(self, reason: str) -> None:
        """Log why frames are not matched (a refused camera input, an image of another camera),
        once until the reason changes.
        """
        if reason and reason != self.refused:
            self.node.get_logger().error(f"shape watch: frames are not matched: {reason}")
        self.refused = reason

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

    def _events(self, msg: ContactEventArray) -> None:
        self.forces, self.has_events = messages.predicted_forces(msg), True
        self._flush()

    def _image(self, msg: Image) -> None:
        self.waiting[messages.stamp_ns(msg.header.stamp)] = msg
        while len(self.waiting) > PENDING_FRAMES:
            dropped = min(self.waiting)
            del self.waiting[dropped]
            if not self.dropped:
                self.node.get_logger().warning(
                    f"shape watch: more than {PENDING_FRAMES} frames wait for the prediction "
                    f"(planner/predicted_shapes, planner/predicted_events), the camera info or "
                    f"the pose; dropping the "
                    f"oldest (first at {dropped * 1e-9:.3f} s)")
            self.dropped += 1
        self._flush()

    def tick(self, ns: int, out: TrackerOutput, samples: dict[str, FingerSample]) -> None:
        """The monitor closed tick ``ns`` (its tracker output and samples): match the frames up
        to it.
        """
        self.close(ns, out.depth, pair_force(self.motion.measure(out, samples)))

    def close(self, ns: int, depth: float, force: float | None) -> None:
        """Tick ``ns`` closed at ``depth`` (m) with the pair ``force`` (N; None: not
        measured): match the frames up to it.
        """
        self.depths[ns] = (depth, force)
        while len(self.depths) > DEPTH_HISTORY:
            self.depths.popitem(last=False)
        self._flush()

    def _flush(self) -> None:
        """Match the waiting frames whose tick has closed, once the predictions, the camera
        info and the pose are known.
        """
        inputs = self.inputs
        if self.prediction is None or not self.has_events or not self.depths \
                or (inputs.camera is None and not inputs.camera_refused) \
                or (inputs.pose is None and not inputs.pose_refused):
            return
        closed = next(reversed(self.depths))
        for stamp in sorted(s for s in self.waiting if s <= closed):
            self._match(self.waiting.pop(stamp), stamp,
                        *self.depths.get(stamp, self.depths[closed]))

    def _at_force(self, force: float | None) -> DepthAtForce:
        """The predicted depth for the measured pair ``force``, or why there is none."""
        if self.forces is None:
            return DepthAtForce(AtForce.NO_FORCE_CURVE, 0.0)
        if force is None:
            return DepthAtForce(AtForce.NO_FORCE, 0.0)
        return depth_at_force(self.forces, force, min_force=self.min_force)

    def _match(self, msg: Image, ns: int, depth: float, force: float | None) -> None:
        inputs = self.inputs
        if reason := inputs.image_problem(msg):
            if not (inputs.camera_refused or inputs.pose_refused):  # those are logged on arrival
                self._log(reason)
            return
        self.refused = ""
        try:
            pixels, encoding = image_array(msg)
            seen = extract_outline(pixels, encoding, inputs.camera, inputs.pose,
                                   object_height_m=self.object_height, frame_id=inputs.frame_id)
        except (InvalidInputError, NumericalError) as error:  # e.g. undistortion diverged
            self.node.get_logger().warning(f"shape watch: no outline at {ns * 1e-9:.3f} s: "
                                           f"{error}")
            return
        smallest = MIN_AREA_PX * seen.pixel_size_m ** 2
        check = check_frame(seen.outline, self.prediction, depth, self.threshold,
                            min_hole_area=smallest)
        match = check.match
        inverted = self._at_force(force)
        at_force = check_frame(seen.outline, self.prediction, inverted.depth,
                               self.at_force_threshold, min_hole_area=smallest).match \
            if inverted.matched else None
        if not inverted.matched and inverted.status is not self.skipped:
            self.node.get_logger().info(
                f"shape watch: no equal-force match from {ns * 1e-9:.3f} s on: "
                f"{inverted.reason(self.min_force)}")
        self.skipped = None if inverted.matched else inverted.status
        self.residual_pub.publish(ShapeResidual(
            header=messages.header(ns, inputs.frame_id), depth=float(depth), rms=match.rms_m,
            max=match.max_m, scale=float(check.scale), rotation=float(match.rotation),
            threshold=float(self.threshold), holes_predicted=check.holes_predicted,
            holes_seen=check.holes_seen, force=float(inverted.force),
            at_force=inverted.status.value, depth_at_force=inverted.depth,
            rms_at_force=at_force.rms_m if at_force else 0.0,
            max_at_force=at_force.max_m if at_force else 0.0,
            threshold_at_force=float(self.at_force_threshold)))
        wrong_e = at_force is not None and at_force.rms_m > self.at_force_threshold
        mismatch = check.mismatch or wrong_e
        if mismatch and not self.active:
            if check.mismatch:
                value, message = match.rms_m, (
                    f"{check.reason}: seen outline {match.rms_m * 1e3:.3f} mm RMS from the "
                    f"predicted boundary at depth {depth * 1e3:.3f} mm (equal-depth residual; "
                    f"threshold {self.threshold * 1e3:.3f} mm; similarity scale "
                    f"{check.scale:.4f})")
            else:
                value, message = at_force.rms_m, (
                    f"equal-force residual above the threshold: seen outline "
                    f"{at_force.rms_m * 1e3:.3f} mm RMS from the boundary the model predicts "
                    f"for the measured pair force {inverted.force:.4g} N, at depth "
                    f"{inverted.depth * 1e3:.3f} mm against the measured {depth * 1e3:.3f} mm "
                    f"(threshold {self.at_force_threshold * 1e3:.3f} mm; equal-depth residual "
                    f"{match.rms_m * 1e3:.3f} mm): the object is "
                    f"{'softer' if inverted.depth < depth else 'stiffer'} than the model")
            self.alarm_pub.publish(Alarm(header=messages.header(ns), type=Alarm.SHAPE_MISMATCH,
                                         finger="", value=value, message=message))
        self.active = mismatch
