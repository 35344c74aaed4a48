# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The builders: a validated scene's outline, mesh, material, ring model and finger nodes.

These are the steps :class:`~.setup.GraspSetup` composes; everything outside the ``scene``
package builds its mechanics through :class:`~.setup.GraspSetup`, not through these
(``test/test_layers.py`` checks it).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import (
    CLOSE_VERTICES,
    CLOSE_VERTICES_ERROR,
    MAX_MESH_NODES,
    Mesh,
    generate_mesh,
    target_max_area,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.ring.model import RingModel, ring_from_outline
from squeeze_grasp_ros.mechanics.vocabulary import Finger, ObjectModel, ShapeType
from squeeze_grasp_ros.scene.specs import PlacementSpec, Scene, SceneError, named_placements

SHAPE_BUILDERS: dict[ShapeType, Callable[..., shapes.Outline]] = {
    ShapeType.RECTANGLE: shapes.rectangle,
    ShapeType.SQUARE: lambda side: shapes.rectangle(side, side),
    ShapeType.DISK: shapes.disk,
    ShapeType.ELLIPSE: shapes.ellipse,
    ShapeType.SUPERELLIPSE: shapes.superellipse,
    ShapeType.FOURIER_BLOB: shapes.fourier_blob,
    ShapeType.POLYGON: shapes.polygon,
    ShapeType.SPLINE: shapes.spline,
    ShapeType.FILE: shapes.load_outline,
    ShapeType.ANNULUS: shapes.annulus,
}
"""The outline of each shape type, called with the shape's parameters (:data:`.specs.SHAPES`)."""


def build_outline(shape: Mapping[str, Any]) -> shapes.Outline:
    """The :class:`~squeeze_grasp_ros.mechanics.elastic.shapes.Outline` of a validated shape
    mapping.
    """
    kind = ShapeType(shape["type"])
    try:
        return SHAPE_BUILDERS[kind](**{k: v for k, v in shape.items() if k != "type"})
    except InvalidInputError as exc:
        raise SceneError(f"object.shape: {exc}") from None
    except TypeError as exc:
        raise SceneError(f"object.shape ({kind}): {exc}") from None


def scene_material(scene: Scene) -> Material:
    """The object's :class:`Material`."""
    m = scene.object.material
    return Material(m.E, m.nu, m.thickness)


def placement_points(scene: Scene) -> list[tuple[float, float]]:
    """The placements given as points (fingers, then the adversary), m."""
    return [p.point for _, p in named_placements(scene) if p.point is not None]


def _check_reach(points: np.ndarray, placement: PlacementSpec, where: str) -> None:
    """A placement point must be near the object (:func:`shapes.require_within_reach`)."""
    if placement.point is not None:
        try:
            shapes.require_within_reach(points, placement.point, f"{where}.placement.point")
        except InvalidInputError as exc:
            raise SceneError(str(exc)) from None


def build_mesh(scene: Scene, *, outline: shapes.Outline | None = None,
               max_nodes: int = MAX_MESH_NODES) -> Mesh:
    """Triangulate the scene's solid object with its mesh settings.

    A placement given as a point becomes a boundary node exactly (its projection on the
    outline is a kept vertex of the mesh), so the finger touches where the scene says. A mesh
    that would have more than ``max_nodes`` nodes is refused before meshing. ``outline``
    replaces :func:`build_outline` of ``object.shape`` when it was read already.

    A ``spline`` keeps its resampled boundary (``generate_mesh(split_boundary=False)``): it is
    a curve through samples, a user's or a camera's (``squeeze-grasp outline``, the camera
    route), and its boundary nodes then follow from its arc length and corners alone, so a seen
    outline within micrometres of the true one gets the true one's boundary nodes. The other
    shapes let the mesher split boundary segments, as they always have (keeping theirs too
    would move shipped scenes' boundary nodes: the foam square's 131 to 130).
    """
    if outline is None:
        outline = build_outline(scene.object.shape)
    for where, placement in named_placements(scene):
        _check_reach(outline.points, placement, where)
    outline = shapes.with_boundary_points(outline, placement_points(scene))
    ms = scene.object.mesh
    if ms.max_area is not None:
        area = ms.max_area
    else:
        area = target_max_area(outline, ms.nodes if ms.nodes is not None else 600)
    try:
        return generate_mesh(outline, area, min_angle=ms.min_angle, max_nodes=max_nodes,
                             split_boundary=ShapeType(scene.object.shape["type"])
                             != ShapeType.SPLINE)
    except InvalidInputError as exc:
        crowded = str(exc).startswith(CLOSE_VERTICES_ERROR) and _crowded_placement(scene, outline)
        raise SceneError(f"{crowded or 'object.mesh'}: {exc}") from None


def _crowded_placement(scene: Scene, outline: shapes.Outline) -> str | None:
    """The field of the first placement point whose vertex on ``outline`` (the outline with the
    placements inserted) lies within :data:`CLOSE_VERTICES` of the size of a neighbour, or None.
    """
    p = outline.points
    for where, placement in named_placements(scene):
        if placement.point is None:
            continue
        k = int(np.argmin(np.linalg.norm(p - np.asarray(placement.point), axis=1)))
        gaps = np.linalg.norm(p[[k - 1, (k + 1) % len(p)]] - p[k], axis=1)
        if gaps.min() < CLOSE_VERTICES * outline.size:
            return f"{where}.placement.point"
    return None


def scene_solid(scene: Scene) -> ElasticObject:
    """The scene's solid object: its mesh (:func:`build_mesh`) and plane-stress material."""
    return ElasticObject(build_mesh(scene), scene_material(scene))


def build_ring(scene: Scene) -> RingModel:
    """The curved-beam model of a ring scene (``object.model: ring``): the shape is the middle
    curve, ``material.thickness`` the out-of-plane width w, ``ring.wall_thickness`` the wall h.

    Its nodes act as boundary nodes, so :func:`finger_nodes` places fingers on it.
    """
    obj = scene.object
    if obj.model != ObjectModel.RING:
        raise SceneError(f"object.model must be ring for the ring model, got {obj.model!r}")
    try:
        return ring_from_outline(
            build_outline(obj.shape),
            scene_material(scene),
            obj.ring.wall_thickness,
            obj.ring.elements,
        )
    except InvalidInputError as exc:
        raise SceneError(f"object.ring: {exc}") from None


def placement_node(
    mesh: Mesh, placement: PlacementSpec, where: str, positions: np.ndarray | None = None
) -> int:
    """Mesh node index of a finger placement on the outer boundary (or ``positions`` loop)."""
    loop = mesh.boundary
    pts = mesh.nodes[loop] if positions is None else positions
    if placement.node is not None:
        if placement.node >= mesh.n or placement.node not in set(loop.tolist()):
            raise SceneError(
                f"{where}.placement.node {placement.node} is not an outer-boundary "
                f"node (boundary has {len(loop)} nodes; see `squeeze-grasp mesh`)"
            )
        return int(placement.node)
    if placement.point is not None:
        _check_reach(pts, placement, where)
        k = np.argmin(np.linalg.norm(pts - np.asarray(placement.point), axis=1))
        return int(loop[k])
    c = mesh.centroid
    ang = np.arctan2(pts[:, 1] - c[1], pts[:, 0] - c[0])
    target = np.radians(placement.angle_deg)
    k = np.argmin(np.abs(np.angle(np.exp(1j * (ang - target)))))
    return int(loop[k])


def finger_nodes(scene: Scene, mesh: Mesh) -> tuple[int, int]:
    """Initial contact nodes (F1, F2) of the scene's fingers on ``mesh``."""
    i = placement_node(mesh, scene.fingers[Finger.F1].placement, "fingers.F1")
    j = placement_node(mesh, scene.fingers[Finger.F2].placement, "fingers.F2")
    if i == j:
        raise SceneError("fingers.F1 and fingers.F2 are placed on the same boundary node")
    return i, j


def requested_nodes(scene: Scene) -> int | None:
    """Nodes the scene asks for before anything is built; None for the mesher's default size.

    A ring asks for ``object.ring.elements``; a solid for ``object.mesh.nodes``, or about
    0.8 * area / max_area for ``object.mesh.max_area`` (the inverse of
    :func:`~squeeze_grasp_ros.mechanics.elastic.mesh.target_max_area`).
    """
    obj = scene.object
    if obj.model == ObjectModel.RING:
        return obj.ring.elements
    if obj.mesh.nodes is not None:
        return obj.mesh.nodes
    if obj.mesh.max_area is None:
        return None
    area = build_outline(obj.shape).area
    return math.ceil(0.8 * area / min(obj.mesh.max_area, 0.25 * area))
