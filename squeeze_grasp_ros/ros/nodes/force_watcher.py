# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor's force watch (parameter ``force_watch``): measured finger forces against the
planner's force curve (:mod:`squeeze_grasp_ros.control.force_watch`).

The curve comes with the planner's latched prediction (``planner/predicted_events``: its
``force_depths``, ``force_f1``, ``force_f2``); a prediction without one switches the watch off.
At every tick the monitor closes within the predicted depth (past its first
``force_min_fraction``), the measured force on the object of each finger with a wrench or
tactile sensor (the negated wrench, else the taxel sum) along its measured motion (its position
against its first) is compared with the prediction at the measured depth:
``monitor/force_residual`` (``ForceResidual``), and a ``force_mismatch`` alarm for a finger
whose relative error exceeds ``force_tolerance`` (value: the relative error).
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from rclpy.node import Node

from squeeze_grasp_interfaces.msg import ContactEventArray, ForceResidual
from squeeze_grasp_ros.control.force_watch import PredictedForces, check_forces, force_along_motion
from squeeze_grasp_ros.control.tracker import FingerSample, TrackedAlarm, TrackerOutput
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline


class MotionForces:
    """Each finger's measured force on the object along its measured motion (its position
    against its first), tick by tick; the force watch and the shape watch each keep one.
    """

    def __init__(self) -> None:
        self.start: dict[str, np.ndarray] = {}

    def measure(self, out: TrackerOutput,
                samples: Mapping[str, FingerSample]) -> dict[str, float]:
        """Finger -> force along its motion (N), for the fingers with a wrench or tactile
        reading (or a joint effort in its place) in ``samples``.
        """
        for finger, position in out.positions.items():
            self.start.setdefault(finger, position)
        return {f: force_along_motion(out.forces[f], out.positions[f], self.start[f])
                for f, s in samples.items() if f in out.positions
                and (s.force is not None or s.normal is not None)}


class ForceWatcher:
    """Compares forces for ``node`` (the monitor), which calls :meth:`tick` before its status."""

    def __init__(self, node: Node, tolerance: float, min_fraction: float, qos: Any, *,
                 every: bool) -> None:
        self.tolerance, self.min_fraction = tolerance, min_fraction
        self.prediction: PredictedForces | None = None
        self.motion = MotionForces()
        self.heard = pipeline.Heard(every=every)
        """Whether the residual is written (the monitor's ``every_output``)."""
        self.residual_pub = node.create_publisher(ForceResidual, pipeline.FORCE_RESIDUAL, qos,
                                                  event_callbacks=self.heard.callbacks)

    def set_prediction(self, msg: ContactEventArray) -> None:
        """Take the force curve of the planner's prediction (none: the watch is idle)."""
        self.prediction = messages.predicted_forces(msg)

    def tick(self, out: TrackerOutput, samples: Mapping[str, FingerSample],
             frame_id: str) -> tuple[list[tuple[Any, Any]], tuple[TrackedAlarm, ...]]:
        """The tick's residual message (as ``(publisher, serialised message)``) and its
        alarms; only fingers with a wrench or tactile reading in ``samples`` are judged.
        """
        measured = self.motion.measure(out, samples)
        if self.prediction is None:
            return [], ()
        check = check_forces(self.prediction, out.depth, measured, tolerance=self.tolerance,
                             min_fraction=self.min_fraction)
        if check is None:
            return [], ()
        if not self.heard:
            return [], check.alarms
        fingers = list(check.measured)
        data = messages.force_residual_cdr(
            out.stamp_ns, frame_id, check.depth, fingers, [check.measured[f] for f in fingers],
            [check.predicted[f] for f in fingers], [check.relative_error[f] for f in fingers],
            float(self.tolerance))
        return [(self.residual_pub, data)], check.alarms
