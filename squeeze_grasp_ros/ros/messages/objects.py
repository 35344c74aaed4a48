# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Typed objects and outlines: ``ObjectDescription``, ``SeenOutline`` and polygons."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from geometry_msgs.msg import Point, Point32, Polygon, PolygonStamped

from squeeze_grasp_interfaces.msg import Material, ObjectDescription, SeenOutline, ShapeParameter
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
from squeeze_grasp_ros.planning.typed_objects import FramePose, TypedMaterial, TypedObject
from squeeze_grasp_ros.ros.messages.common import header


def polygon_points(polygon: Polygon) -> list[tuple[float, float]]:
    """The (x, y) of a polygon's points, m (z dropped)."""
    return [(float(p.x), float(p.y)) for p in polygon.points]


def polygon_msg(points: np.ndarray, z: float = 0.0) -> Polygon:
    """A ``geometry_msgs/Polygon`` of (n, 2) points, m, at height ``z`` (float32 fields)."""
    return Polygon(points=[Point32(x=float(x), y=float(y), z=float(z)) for x, y in points])


def typed_object(msg: ObjectDescription) -> TypedObject:
    """The ROS-free :class:`TypedObject` of an ``ObjectDescription``."""
    p, q = msg.frame_pose.position, msg.frame_pose.orientation
    m = msg.material
    return TypedObject(
        material=TypedMaterial(m.youngs_modulus, m.poisson_ratio, m.thickness, m.model),
        outline=polygon_points(msg.outline.polygon),
        holes=[polygon_points(h) for h in msg.holes],
        frame_id=msg.outline.header.frame_id,
        shape=msg.shape,
        shape_parameters={s.name: tuple(s.values) for s in msg.shape_parameters},
        frame_pose=FramePose((p.x, p.y, p.z), (q.x, q.y, q.z, q.w)),
        mesh_max_area=msg.mesh_max_area,
        mesh_nodes=msg.mesh_nodes,
        placements=[(float(pt.x), float(pt.y)) for pt in msg.placements],
        tip_radius=msg.tip_radius,
        mu=msg.mu,
    )


def object_description(outline: Outline, frame_id: str, *, youngs_modulus: float,
                       poisson_ratio: float, thickness: float, model: str = "",
                       placements: Sequence[Sequence[float]] = (), tip_radius: float = 0.0,
                       mu: float = 0.0, mesh_nodes: int = 0) -> ObjectDescription:
    """An ``ObjectDescription`` of an outline (m, in ``frame_id``) and a material."""
    return description_msg(TypedObject(
        material=TypedMaterial(youngs_modulus, poisson_ratio, thickness, model),
        outline=np.asarray(outline.points, float).tolist(),
        holes=[np.asarray(h, float).tolist() for h in outline.holes], frame_id=frame_id,
        mesh_nodes=mesh_nodes, placements=placements, tip_radius=tip_radius, mu=mu))


def description_msg(typed: TypedObject) -> ObjectDescription:
    """The ``ObjectDescription`` of a :class:`TypedObject` (the inverse of
    :func:`typed_object`; the frame pose is left unset, the identity).
    """
    m = typed.material
    msg = ObjectDescription(
        shape=typed.shape, shape_parameters=shape_parameters(typed.shape_parameters),
        holes=[polygon_msg(np.asarray(h, float)) for h in typed.holes],
        material=Material(youngs_modulus=float(m.youngs_modulus),
                          poisson_ratio=float(m.poisson_ratio), thickness=float(m.thickness),
                          model=m.model),
        mesh_max_area=float(typed.mesh_max_area), mesh_nodes=int(typed.mesh_nodes),
        tip_radius=float(typed.tip_radius), mu=float(typed.mu))
    msg.outline = PolygonStamped(polygon=polygon_msg(np.asarray(typed.outline, float)
                                                     .reshape(-1, 2)))
    msg.outline.header.frame_id = typed.frame_id
    msg.placements = [Point(x=float(x), y=float(y)) for x, y in typed.placements]
    return msg


def shape_parameters(parameters: dict[str, Sequence[float] | float]) -> list[ShapeParameter]:
    """``ShapeParameter`` entries of a shape's parameters (scalars or sequences)."""
    return [ShapeParameter(name=k, values=[float(v) for v in np.atleast_1d(values)])
            for k, values in parameters.items()]


def seen_outline_msg(outline: Outline, *, frame_id: str, ns: int, encoding: str,
                     plane_height: float, tolerance: float, pixel_size: float,
                     other_blobs: int, shape: str = "", fit_residual: float = 0.0
                     ) -> SeenOutline:
    """A ``SeenOutline`` of an extracted outline (m, plane frame, top at ``plane_height``),
    recognised as ``shape`` with the fit's largest residual ``fit_residual`` (m).
    """
    return SeenOutline(
        outline=PolygonStamped(header=header(ns, frame_id),
                               polygon=polygon_msg(outline.points, plane_height)),
        holes=[polygon_msg(h, plane_height) for h in outline.holes],
        encoding=str(encoding), area=float(outline.area), tolerance=float(tolerance),
        pixel_size=float(pixel_size), other_blobs=int(other_blobs), shape=str(shape),
        fit_residual=float(fit_residual))
