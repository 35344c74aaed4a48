# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Planning from what the camera sees (scene key ``camera.plan_from_images``).

The run never hands the planner the scene's shape. It waits for the simulated camera's first
frame (``camera/mask``, ``camera/camera_info``, ``camera/pose``; latched, published by
``sim_hardware`` before tick 0), extracts the outline
(:func:`~squeeze_grasp_ros.perception.extract.extract_outline`), and describes the object to
``load_object`` with typed fields: the seen outline, plus what a robot is told rather than
sees (the material, the mesh size, where the fingers are, their radius, the friction). The
summary then says how far the seen outline was from the scene's true one
(:func:`seen_report`: point-to-curve distances, no fit).
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import CameraInfo, Image

from squeeze_grasp_interfaces.msg import ObjectDescription, PredictedShapes
from squeeze_grasp_ros.control.tracker import mirror_tolerance_for
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import Finger, ShapeFit
from squeeze_grasp_ros.perception.extract import ObjectOutline, extract_outline
from squeeze_grasp_ros.perception.shape_match import shape_residual
from squeeze_grasp_ros.perception.shape_watch import predict_shapes
from squeeze_grasp_ros.planning import PlannerError
from squeeze_grasp_ros.planning.typed_objects import seen_object
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.images import camera_model, camera_pose, image_array
from squeeze_grasp_ros.ros.messages.objects import description_msg, polygon_msg
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.run.options import RunError
from squeeze_grasp_ros.scene import GraspSetup, Scene, SensorsSpec, build_outline

__all__ = ["first_outline", "predicted_shapes_msg", "seen_description", "seen_mirror_tolerance",
           "seen_report"]


def first_outline(node: Any, spin_until: Callable[..., None], scene: Scene,
                  timeout: float) -> ObjectOutline:
    """The outline in the camera's first frame (mask), read over ROS by ``node``.

    Raises
    ------
    RunError
        When the frame does not arrive in ``timeout`` s.
    InvalidInputError
        When the scene's view gives no outline (its reason: no object in view, cut by the
        border, ...).
    """
    got: dict[str, Any] = {}
    subscriptions = [
        node.create_subscription(msg_type, topic, lambda msg, k=topic: got.setdefault(k, msg),
                                 pipeline.LATCHED if topic == pipeline.CAMERA_POSE
                                 else pipeline.CAMERA)
        for topic, msg_type in ((pipeline.CAMERA_MASK, Image), (pipeline.CAMERA_INFO, CameraInfo),
                                (pipeline.CAMERA_POSE, PoseStamped))]
    try:
        spin_until(lambda: len(got) == len(subscriptions), timeout, "the camera's first frame")
    finally:
        for subscription in subscriptions:
            node.destroy_subscription(subscription)
    pose_msg = got[pipeline.CAMERA_POSE]
    try:
        pixels, encoding = image_array(got[pipeline.CAMERA_MASK])
        return extract_outline(pixels, encoding, camera_model(got[pipeline.CAMERA_INFO]),
                               camera_pose(pose_msg.pose),
                               object_height_m=scene.object.material.thickness,
                               frame_id=pose_msg.header.frame_id)
    except ValueError as error:  # the scene's own view: its camera or its object
        raise InvalidInputError(f"camera.plan_from_images: the first frame gives no outline: "
                                f"{error}; check the scene's camera (camera.pose, size, "
                                "intrinsics) and its object's place") from None


def seen_description(scene: Scene, seen: ObjectOutline) -> ObjectDescription:
    """The typed ``load_object`` object of a seen outline
    (:func:`~squeeze_grasp_ros.planning.typed_objects.seen_object`).

    Raises
    ------
    RunError
        When the scene's fingers cannot be described with it (placements not by point, tip
        radii that differ).
    """
    try:
        return description_msg(seen_object(scene, seen.to_scene_shape(), seen.frame_id))
    except PlannerError as error:
        raise RunError(f"camera.plan_from_images: {error}") from None


def seen_report(scene: Scene, seen: ObjectOutline) -> dict:
    """How far the seen outline is from the scene's true one: point-to-curve distances of the
    seen vertices from the true outline (no fit), m, and the areas, m^2.
    """
    truth = build_outline(scene.object.shape)
    match = shape_residual(truth, seen.outline, fit=ShapeFit.NONE)
    return {"recognised": seen.shape.value,
            "fit_residual_m": None if seen.primitive is None else seen.primitive.residual_m,
            "vertices": int(len(seen.outline.points)), "holes": len(seen.outline.holes),
            "rms_m": match.rms_m, "max_m": max(match.max_m, match.reverse_max_m),
            "area_m2": seen.outline.area, "true_area_m2": truth.area,
            "pixel_m": seen.pixel_size_m, "tolerance_m": seen.tolerance_m}


def seen_mirror_tolerance(model: GraspSetup, scene: Scene, seen: ObjectOutline) -> dict:
    """The monitor's ``mirror_tolerance`` for a run planned from the camera
    (:func:`~squeeze_grasp_ros.control.tracker.mirror_tolerance_for`): the planner's model
    ``model`` (the seen object's typed scene, meshed) gives the boundary spacing h (median over
    its outer loop), the extraction's stated tolerance the outline error e, ``scene`` the
    fingertip radius (F1's: the typed route has one) and the taxel pitch.

    Returns
    -------
    dict
        ``value`` (fraction of a mirror pair's separation), and what it came from:
        ``spacing_m``, ``outline_error_m``, ``tip_radius_m``, ``taxel_pitch_rad``.
    """
    mesh = model.solid.mesh
    loop = mesh.nodes[mesh.boundary]
    spacing = float(np.median(np.linalg.norm(loop - np.roll(loop, 1, axis=0), axis=1)))
    sensors = scene.sensors or SensorsSpec()
    pitch = float(np.radians(sensors.taxel_span_deg) / (sensors.taxels - 1))
    radius = float(scene.fingers[Finger.F1].tip_radius)
    return {"value": mirror_tolerance_for(spacing, seen.tolerance_m, tip_radius=radius,
                                          taxel_pitch=pitch),
            "spacing_m": spacing, "outline_error_m": float(seen.tolerance_m),
            "tip_radius_m": radius, "taxel_pitch_rad": pitch}


def predicted_shapes_msg(model: GraspSetup, depth: float, ns: int,
                         frame_id: str = pipeline.FRAME) -> PredictedShapes:
    """The ``PredictedShapes`` of the planner's model (``model``: the seen object's typed scene
    on the camera route, built and precomputed) squeezed to ``depth`` (m), for the monitor's
    shape watch: the outer boundary and, depth-major, the holes.
    """
    predicted = predict_shapes(model, depth)
    return PredictedShapes(header=messages.header(ns, frame_id),
                           depths=[float(d) for d in predicted.depths],
                           outlines=[polygon_msg(o) for o in predicted.outlines],
                           holes=[polygon_msg(h) for loops in predicted.holes for h in loops])
