# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Quality triangular meshes of planar outlines, with ordered boundary loops and normals.

The mesher sits behind the small :class:`Mesher` protocol. The default,
:class:`TriangleMesher`, uses the ``triangle`` package (J. R. Shewchuk's Triangle), which is
robust and fast but **not free for commercial use**; any mesher returning nodes and
counter-clockwise triangles of a planar straight-line graph can replace it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Protocol

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.mesh_size import (
    MAX_MESH_NODES,
    NODES_PER_AREA,
    check_mesh_size,
    estimate_mesh,
)
from squeeze_grasp_ros.mechanics.elastic.shapes import (
    Outline,
    interior_point,
    require_outline,
    signed_area,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite

ANGLE_SLACK = 1.0
"""Degrees by which a mesh kept to its resampled boundary may miss ``min_angle`` before it is
meshed again with boundary splits allowed. Without splits Triangle's angle bound no longer holds
at the boundary: on the mixed outlines of ``test/test_perception_mixed.py`` (300 to 4,000
nodes) it missed 30 degrees by 0.02 at most, while a 4 mm strip meshed with 2 cm elements had
a 2.7 degree triangle (``test/test_mesh_boundary.py``)."""


class Mesher(Protocol):
    """Triangulates a planar straight-line graph with quality controls."""

    def triangulate(
        self,
        vertices: np.ndarray,
        segments: np.ndarray,
        holes: np.ndarray,
        max_area: float,
        min_angle: float,
        max_nodes: int,
        *,
        split_boundary: bool = True,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(nodes (n, 2), triangles (t, 3))`` covering the region.

        ``segments`` are index pairs into ``vertices`` that must stay edges (split by the
        mesher where its quality refinement needs it, unless ``split_boundary`` is False: then
        the segments' vertices are the only nodes on them); ``holes`` are points inside holes;
        ``max_area`` (m^2) and ``min_angle`` (degrees) are the quality bounds; the mesher stops
        adding nodes at ``max_nodes`` (the caller refuses a mesh that reached it).
        """


class TriangleMesher:
    """Mesher backed by the ``triangle`` package (Shewchuk's Triangle; non-commercial licence)."""

    def triangulate(self, vertices, segments, holes, max_area, min_angle, max_nodes, *,
                    split_boundary=True):
        import triangle

        data = {"vertices": vertices, "segments": segments}
        if len(holes):
            data["holes"] = holes
        area = np.format_float_positional(max_area, trim="-")  # Triangle cannot parse 1e-5
        steiner = max(max_nodes - len(vertices), 0)  # S: most nodes Triangle may add
        keep = "" if split_boundary else "Y"  # Y: no Steiner points on the boundary
        out = triangle.triangulate(data, f"pq{min_angle:.6g}a{area}S{steiner}{keep}Q")
        return np.asarray(out["vertices"], float), np.asarray(out["triangles"], int)


@dataclass(frozen=True)
class Mesh:
    """A triangulated planar object.

    Attributes
    ----------
    nodes : (n, 2) ndarray
        Node coordinates, m, in the object frame.
    triangles : (t, 3) ndarray of int
        Counter-clockwise node indices of each element.
    boundary : (b,) ndarray of int
        The outer boundary loop, counter-clockwise (the nodes fingers can touch).
    inner_boundaries : tuple of ndarray
        Loops around holes (clockwise as seen from the object).
    normals : (b, 2) ndarray
        Outward unit normals at the ``boundary`` nodes (mean of the adjacent edge normals).
    """

    nodes: np.ndarray
    triangles: np.ndarray
    boundary: np.ndarray
    inner_boundaries: tuple[np.ndarray, ...]
    normals: np.ndarray

    @property
    def n(self) -> int:
        """Number of nodes."""
        return len(self.nodes)

    @cached_property
    def size(self) -> float:
        """Characteristic length L, m: the larger side of the bounding box."""
        return float(np.ptp(self.nodes, axis=0).max())

    @cached_property
    def centroid(self) -> np.ndarray:
        """Area centroid of the object, m."""
        p = self.nodes[self.triangles]
        a = element_areas(self.nodes, self.triangles)
        return (a[:, None] * p.mean(axis=1)).sum(axis=0) / a.sum()

    def boundary_position(self, node: int) -> int:
        """Position of mesh ``node`` in the ``boundary`` loop; error if it is not on it."""
        pos = np.flatnonzero(self.boundary == node)
        if len(pos) == 0:
            raise InvalidInputError(f"node {node} is not on the outer boundary")
        return int(pos[0])

    def normal_at(self, node: int) -> np.ndarray:
        """Outward unit normal (2,) at boundary ``node``."""
        return self.normals[self.boundary_position(node)]

    def min_angle_deg(self) -> float:
        """Smallest interior angle over all elements, degrees."""
        p = self.nodes[self.triangles]
        angles = []
        for k in range(3):
            u = p[:, (k + 1) % 3] - p[:, k]
            v = p[:, (k + 2) % 3] - p[:, k]
            cos = np.einsum("ij,ij->i", u, v) / (
                np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
            )
            angles.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
        return float(np.min(angles))


def element_areas(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Signed areas (t,) of the triangles, m^2 (> 0 when counter-clockwise)."""
    p = nodes[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def boundary_loops(triangles: np.ndarray) -> list[np.ndarray]:
    """Closed loops of edges that belong to exactly one triangle, in the triangles' orientation."""
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    key = np.sort(edges, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    free = edges[counts[inverse.ravel()] == 1]
    successor = dict(zip(free[:, 0].tolist(), free[:, 1].tolist()))
    if len(successor) != len(free):
        raise InvalidInputError("mesh boundary is not manifold (a node has two outgoing edges)")
    loops = []
    while successor:
        start = next(iter(successor))
        loop = [start]
        node = successor.pop(start)
        while node != start:
            loop.append(node)
            node = successor.pop(node)
        loops.append(np.array(loop, dtype=int))
    return loops


def vertex_normals(points: np.ndarray) -> np.ndarray:
    """Outward unit normals at the vertices of a counter-clockwise closed polyline."""
    e_out = np.roll(points, -1, axis=0) - points
    e_in = points - np.roll(points, 1, axis=0)

    def edge_normal(e):
        nrm = np.column_stack([e[:, 1], -e[:, 0]])
        return nrm / np.linalg.norm(nrm, axis=1, keepdims=True)

    nrm = edge_normal(e_out) + edge_normal(e_in)
    return nrm / np.linalg.norm(nrm, axis=1, keepdims=True)


def target_max_area(outline: Outline, nodes: int) -> float:
    """The ``max_area`` (m^2) that gives roughly ``nodes`` mesh nodes for ``outline``."""
    if not 10 <= nodes <= MAX_MESH_NODES:
        raise InvalidInputError(f"mesh.nodes must be in [10, {MAX_MESH_NODES}], got {nodes}")
    return 1.6 * outline.area / (2.0 * nodes)  # = NODES_PER_AREA * area / nodes


def generate_mesh(
    outline: Outline,
    max_area: float,
    *,
    min_angle: float = 30.0,
    mesher: Mesher | None = None,
    max_nodes: int = MAX_MESH_NODES,
    split_boundary: bool = True,
) -> Mesh:
    """Mesh ``outline`` with elements of area <= ``max_area`` m^2 and angles >= ``min_angle``.

    The boundary is first resampled to the edge length of an equilateral element of the target
    area, so boundary nodes are evenly spaced and corners are kept. The mesh's size is bounded
    before meshing (:mod:`~squeeze_grasp_ros.mechanics.elastic.mesh_size`): its boundary
    nodes, its interior nodes and the nodes that features thinner than the element size would
    force; the mesher itself stops at ``max_nodes``.

    With ``split_boundary`` (the default) the mesher's quality refinement may split boundary
    segments. Whether it does is a tie: a resampled segment a hair longer than the element size
    carries a triangle a hair over ``max_area``, whose circumcentre encroaches on the segment,
    so two outlines a few micrometres apart can differ by several boundary nodes. With
    ``split_boundary=False`` the boundary nodes are exactly the resampled loops (Triangle's
    ``Y`` switch), so they depend only on the outline's arc length and corners; if that mesh
    misses ``min_angle`` (a feature thinner than the element size needs boundary nodes closer
    than the spacing), the outline is meshed again with splits allowed.

    Raises
    ------
    InvalidInputError
        If ``outline`` is not an :class:`~.shapes.Outline` of finite loops, the outer one
        counter-clockwise (:func:`~.shapes.require_outline`); if ``max_area`` is not
        positive, ``min_angle`` is outside (0, 34] degrees (Triangle's
        guaranteed-termination range) or ``max_nodes`` is not an integer >= 3; if the mesh
        would have more than ``max_nodes`` nodes or more than
        :data:`~.mesh_size.MAX_BOUNDARY_NODES` boundary nodes, or a thin feature would more
        than double it (the message names the feature, its width and where it is).

    Examples
    --------
    >>> from squeeze_grasp_ros.mechanics.elastic import shapes
    >>> mesh = generate_mesh(shapes.rectangle(0.1, 0.05), 1e-4, min_angle=30.0)
    >>> bool(element_areas(mesh.nodes, mesh.triangles).max() <= 1e-4)
    True
    >>> print(f"{element_areas(mesh.nodes, mesh.triangles).sum():.6f} m^2")
    0.005000 m^2
    """
    require_outline(outline)
    require_finite("mesh.max_area", max_area)
    require_finite("mesh.min_angle", min_angle)
    if not max_area > 0:
        raise InvalidInputError(f"mesh.max_area must be > 0 m^2, got {max_area}")
    if not 0 < min_angle <= 34:
        raise InvalidInputError(f"mesh.min_angle must be in (0, 34] degrees, got {min_angle}")
    if isinstance(max_nodes, bool) or not isinstance(max_nodes, (int, np.integer)) \
            or max_nodes < 3:
        raise InvalidInputError(f"mesh.max_nodes must be an integer >= 3, got {max_nodes!r}")
    if max_area > outline.area:
        max_area = outline.area / 4.0
    if NODES_PER_AREA * outline.area / max_area > max_nodes:
        smallest = NODES_PER_AREA * outline.area / max_nodes
        raise InvalidInputError(
            f"mesh.max_area {max_area:.3g} m^2 would give about "
            f"{NODES_PER_AREA * outline.area / max_area:.3g} nodes on this "
            f"{outline.area:.3g} m^2 object; at most {max_nodes} are "
            f"allowed (max_area >= {smallest:.3g} m^2)"
        )
    estimate = estimate_mesh(outline, max_area, max_nodes=max_nodes)
    check_mesh_size(estimate, max_nodes)
    loops = estimate.loops
    vertices = np.concatenate(loops)
    segments, offset = [], 0
    for loop in loops:
        k = np.arange(len(loop)) + offset
        segments.append(np.column_stack([k, np.roll(k, -1)]))
        offset += len(loop)
    holes = np.array([interior_point(h) for h in outline.holes]).reshape(-1, 2)
    segments = np.concatenate(segments)
    mesher = mesher or TriangleMesher()

    def triangulated(split: bool) -> Mesh:
        nodes, tris = mesher.triangulate(vertices, segments, holes, max_area, min_angle,
                                         max_nodes, split_boundary=split)
        if len(nodes) >= max_nodes:
            raise InvalidInputError(
                f"the mesher reached the limit of {max_nodes:,} nodes before it met the "
                f"element size {estimate.spacing:.3g} m and angle {min_angle:g} deg: use "
                "larger elements (mesh.nodes or mesh.max_area) or a simpler outline")
        if _has_degenerate_elements(nodes, tris):
            close = _close_vertices_error(loops)
            if close is not None:
                raise close
        return mesh_from_triangles(nodes, tris)

    mesh = triangulated(split_boundary)
    if not split_boundary and mesh.min_angle_deg() < min_angle - ANGLE_SLACK:
        mesh = triangulated(True)
    return mesh


CLOSE_VERTICES = 1e-6
"""Vertices of an outline closer than this fraction of its size are named when its mesh fails
with elements of (almost) zero area: Triangle grades its elements down to their distance, and
:func:`mesh_from_triangles` refuses elements below :data:`DEGENERATE_AREA` of the size
squared. A square of side 0.1 m with a vertex 1e-8 m from a corner failed so (1e-10 m is one
vertex, 3e-8 m meshed)."""


CLOSE_VERTICES_ERROR = "the outline has vertices"
"""How the error of :data:`CLOSE_VERTICES` begins (a scene names the placement behind it)."""

DEGENERATE_AREA = 1e-14
"""Elements of an area at most this fraction of the square of the mesh's extent are refused as
degenerate (:func:`mesh_from_triangles`)."""


def _has_degenerate_elements(nodes: np.ndarray, triangles: np.ndarray) -> bool:
    """Whether :func:`mesh_from_triangles` would refuse an element of ``triangles`` as
    degenerate.
    """
    scale = float(np.ptp(nodes, axis=0).max()) ** 2
    return bool(np.any(np.abs(element_areas(nodes, triangles)) <= DEGENERATE_AREA * scale))


def _close_vertices_error(loops: list[np.ndarray]) -> InvalidInputError | None:
    """The error naming the closest consecutive vertices of ``loops`` (m) when they are closer
    than :data:`CLOSE_VERTICES` of the outline's size, else None.
    """
    points = np.concatenate(loops)
    size = float(np.ptp(points, axis=0).max())
    gaps = np.concatenate([np.linalg.norm(np.roll(loop, -1, axis=0) - loop, axis=1)
                           for loop in loops])
    k = int(np.argmin(gaps))
    gap, where = float(gaps[k]), points[k]
    if not gap < CLOSE_VERTICES * size:
        return None
    return InvalidInputError(
        f"{CLOSE_VERTICES_ERROR} {gap:.3g} m apart at ({where[0]:.6g}, {where[1]:.6g}) m "
        f"({gap / size:.2g} of its size {size:.4g} m): the mesh there has elements of almost "
        "zero area; make them one vertex or move them apart")


def mesh_from_triangles(nodes: np.ndarray, triangles: np.ndarray) -> Mesh:
    """Build a :class:`Mesh` (boundary loops, normals) from raw nodes and triangles.

    Unused nodes are dropped, triangles are oriented counter-clockwise, and degenerate (zero
    area) elements are rejected.
    """
    nodes = np.asarray(nodes, float)
    triangles = np.asarray(triangles, int)
    if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
        raise InvalidInputError("mesh needs at least one triangle given as [i, j, k]")
    used = np.unique(triangles)
    remap = -np.ones(len(nodes), dtype=int)
    remap[used] = np.arange(len(used))
    nodes, triangles = nodes[used], remap[triangles]
    if _has_degenerate_elements(nodes, triangles):
        raise InvalidInputError("mesh has degenerate (zero-area) elements")
    area = element_areas(nodes, triangles)
    flip = area < 0
    triangles[flip] = triangles[flip][:, [0, 2, 1]]
    loops = boundary_loops(triangles)
    areas = [signed_area(nodes[loop]) for loop in loops]
    outer = int(np.argmax(areas))
    boundary = loops[outer]
    inner = tuple(loop for i, loop in enumerate(loops) if i != outer)
    return Mesh(nodes, triangles, boundary, inner, vertex_normals(nodes[boundary]))
