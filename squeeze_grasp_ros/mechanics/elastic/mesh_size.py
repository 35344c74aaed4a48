# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""How large a mesh will be, known before meshing: boundary nodes, interior nodes and the nodes
that features thinner than the element size force on the mesher.

A quality mesher (Triangle with a minimum angle) cannot put an element of the requested size
across a feature thinner than that size: it refines down to the feature's width along its whole
length. A strip of width w and length l then takes about 2 l / w nodes whatever node count was
asked for (a 0.1 m x 1e-7 m rectangle with ``mesh.nodes: 500`` gave 2.1 million nodes). So the
width of the object is measured at every boundary vertex before meshing: the distance to the
nearest piece of boundary that is not the vertex's own neighbourhood (more than two element
sizes away along the loop, or on another loop). Where it is below the element size h, the
vertex's share ds of the boundary needs about ds (1/width - 1/h) extra nodes; their sum is
:attr:`MeshEstimate.thin_nodes`. A sharp corner adds a few (a 10 degree wedge about 7), a thin
strip or a narrow gap between a hole and the outer edge adds thousands to millions.

>>> from squeeze_grasp_ros.mechanics.elastic import shapes
>>> strip = shapes.rectangle(0.1, 3e-5)
>>> estimate = estimate_mesh(strip, 4.8e-9)
>>> print(f"{estimate.thinnest.width:.1e} m thin, about {estimate.thin_nodes:.1e} extra nodes")
3.0e-05 m thin, about 4.8e+03 extra nodes
>>> estimate_mesh(shapes.rectangle(0.1, 0.05), 1e-5).thinnest is None
True
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.spatial import cKDTree

from squeeze_grasp_ros.mechanics.elastic.shapes import (
    Outline,
    resample,
    resampled_count,
    signed_area,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError

MAX_MESH_NODES = 250_000
"""Largest mesh the mesher is asked for (interior and thin-feature nodes together); beyond it a
solve takes minutes and gigabytes, so the request is refused before meshing."""

MAX_BOUNDARY_NODES = 3_000
"""Most outer and hole boundary nodes of a mesh. The boundary compliance is a dense
(2b x 2b) matrix computed from the factorisation; measured on this project's 2-core machine, an
all-boundary strip took 17 s and 1.1 GB at b = 2,082 and 33 s and 2.1 GB at b = 2,946. Meshes
of ordinary shapes stay far below at the node limit (a disk of 250,000 nodes has about 1,300
boundary nodes, a 10:1 rectangle about 2,600)."""

NODES_PER_AREA = 0.8
"""Mesh nodes per ``max_area`` of object area that Triangle gives with a 30 degree minimum
angle (the inverse of :func:`~squeeze_grasp_ros.mechanics.elastic.mesh.target_max_area`)."""

THIN_ALLOWANCE = 1_000
"""Extra nodes thin features may always add, whatever the mesh asked for (a coarse mesh of a
polygon with a sliver or a sharp notch); beyond it they may at most double the mesh."""

NEAREST = 32
"""Boundary vertices near each vertex whose edges are measured against it: the work is bounded
by vertices x NEAREST (own neighbours are a few, the far side of a thin feature is among the
nearest), not by the pairs within an element size, which a boundary folded many times within
one element makes quadratic."""

NEIGHBOURHOOD = 2.0
"""Boundary within this many element sizes along the same loop is a vertex's own neighbourhood,
not a feature across the material."""


def element_spacing(max_area: float) -> float:
    """Edge length, m, of an equilateral element of area ``max_area`` (m^2): the boundary
    spacing the mesher is given.
    """
    return float(np.sqrt(4.0 * max_area / np.sqrt(3.0)))


def max_area_for_spacing(spacing: float) -> float:
    """The ``max_area`` (m^2) whose equilateral element has edges of ``spacing`` m."""
    return float(np.sqrt(3.0) / 4.0 * spacing * spacing)


@dataclass(frozen=True)
class ThinFeature:
    """The narrowest place of an object at a given element size.

    Attributes
    ----------
    width : float
        Distance across the material (or between two loops), m.
    point : tuple of float
        Boundary vertex where it was measured, m.
    where : str
        Which loops: "across the outer boundary", "across hole 1", "between the outer boundary
        and hole 1", ...
    """

    width: float
    point: tuple[float, float]
    where: str


@dataclass(frozen=True)
class MeshEstimate:
    """The size of a mesh before it is made.

    Attributes
    ----------
    spacing : float
        Element size h, m (edge of an equilateral element of ``max_area``).
    area_nodes : int
        Nodes the object's area gives at ``max_area`` (``NODES_PER_AREA`` area / max_area).
    boundary_nodes : int
        Vertices of the resampled outer and hole boundaries.
    boundary_length : float
        Length of the outer and hole boundaries, m.
    area : float
        The object's area, m^2.
    thin_nodes : float
        Extra nodes forced by features thinner than ``spacing`` (inf where two loops touch).
    thinnest : ThinFeature or None
        The narrowest feature thinner than ``spacing``; None if there is none.
    loops : tuple of ndarray
        The resampled boundary loops the mesher is given (outer first, then the holes,
        counter-clockwise), m.
    """

    spacing: float
    area_nodes: int
    boundary_nodes: int
    boundary_length: float
    area: float
    thin_nodes: float
    thinnest: Optional[ThinFeature]
    loops: tuple[np.ndarray, ...]

    @property
    def nodes(self) -> float:
        """Expected node count of the mesh: the larger of the area's and the boundary's, plus
        the thin features' (within a factor of 2 of Triangle's count on strips, annuli, stars
        and wedges; ``test/test_mesh_bounds.py``).
        """
        return max(self.area_nodes, self.boundary_nodes) + self.thin_nodes


def _loop_name(k: int) -> str:
    return "the outer boundary" if k == 0 else f"hole {k}"


def _point_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distances (N,) from points p to segments ab, and the foot's parameter t in [0, 1]."""
    ab = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / length2, 0.0, 1.0)
    return np.linalg.norm(a + t[:, None] * ab - p, axis=1), t


def thin_features(loops: list[np.ndarray], spacing: float) -> tuple[float, Optional[ThinFeature]]:
    """Extra nodes forced by features thinner than ``spacing`` (m), and the thinnest of them.

    ``loops`` are closed polylines (outer boundary first) whose edges are at most 1.5 spacing
    long, as :func:`~squeeze_grasp_ros.mechanics.elastic.shapes.resample` gives. See the module
    docstring for the measure; each vertex is measured against the edges at its
    :data:`NEAREST` nearest vertices within reach.
    """
    sizes = [len(loop) for loop in loops]
    pts = np.concatenate(loops)
    loop_of = np.repeat(np.arange(len(loops)), sizes)
    start = np.repeat(np.cumsum([0] + sizes[:-1]), sizes)
    size = np.repeat(sizes, sizes)
    local = np.arange(len(pts)) - start
    nxt = start + (local + 1) % size
    prev = start + (local - 1) % size
    seg_len = np.linalg.norm(pts[nxt] - pts, axis=1)
    arc = np.concatenate([np.concatenate([[0.0], np.cumsum(seg_len[s:s + n])[:-1]])
                          for s, n in zip(np.cumsum([0] + sizes[:-1]), sizes)])
    perimeter = np.repeat([seg_len[loop_of == k].sum() for k in range(len(loops))], sizes)
    radius = spacing + 0.5 * float(seg_len.max())
    k = min(NEAREST, len(pts))
    _, near = cKDTree(pts).query(pts, k=k, distance_upper_bound=radius)
    i = np.repeat(np.arange(len(pts)), k)
    j = near.ravel()
    keep = (j < len(pts)) & (j != i)
    if not np.any(keep):
        return 0.0, None
    i, j = np.concatenate([i[keep], i[keep]]), np.concatenate([j[keep], prev[j[keep]]])
    dist, t = _point_segment(pts[i], pts[j], pts[nxt[j]])
    same = loop_of[i] == loop_of[j]
    along = np.abs(arc[i] - (arc[j] + t * seg_len[j]))
    along = np.minimum(along, perimeter[i] - along)
    across = (~same | (along >= NEIGHBOURHOOD * spacing)) & (dist < spacing)
    if not np.any(across):
        return 0.0, None
    i, j, dist = i[across], j[across], dist[across]
    gap = np.full(len(pts), np.inf)
    np.minimum.at(gap, i, dist)
    thin = np.flatnonzero(np.isfinite(gap))
    share = 0.5 * (seg_len[thin] + seg_len[prev[thin]])
    with np.errstate(divide="ignore"):
        extra = float(np.sum(share * (1.0 / gap[thin] - 1.0 / spacing)))
    k = int(np.argmin(dist))
    a, b = loop_of[i[k]], loop_of[j[k]]
    where = (f"across {_loop_name(a)}" if a == b
             else f"between {_loop_name(min(a, b))} and {_loop_name(max(a, b))}")
    point = (float(pts[i[k], 0]), float(pts[i[k], 1]))
    return extra, ThinFeature(float(dist[k]), point, where)


def smallest_spacing(area: float, length: float, max_nodes: int) -> float:
    """The smallest element size, m, whose mesh stays within ``max_nodes`` nodes and
    :data:`MAX_BOUNDARY_NODES` boundary nodes, for an object of ``area`` m^2 whose boundaries
    are ``length`` m long.
    """
    by_area = element_spacing(NODES_PER_AREA * area / max_nodes)
    return max(by_area, length / MAX_BOUNDARY_NODES)


def _thin_error(thin: ThinFeature, spacing: float, cost: str, remedy: str) -> InvalidInputError:
    return InvalidInputError(
        f"the object is only {thin.width:.3g} m wide near ({thin.point[0]:.6g}, "
        f"{thin.point[1]:.6g}) m ({thin.where}), less than the element size {spacing:.3g} m: "
        f"{cost}; {remedy}")


def _unmeshable(thin: ThinFeature, smallest: float) -> str:
    return (f"it cannot be meshed within the limits at any element size: make it wider than "
            f"{smallest:.3g} m")


def estimate_mesh(outline: Outline, max_area: float, *, max_nodes: int = MAX_MESH_NODES
                  ) -> MeshEstimate:
    """Size of the mesh of ``outline`` at ``max_area`` (m^2), without meshing.

    The boundary is resampled at the element size only once its vertex count (from its length,
    the element size and the corners it keeps) is known to be at most
    :data:`MAX_BOUNDARY_NODES`.

    Raises
    ------
    InvalidInputError
        If the boundary needs more than :data:`MAX_BOUNDARY_NODES` vertices: because of a
        feature thinner than any element size within the limits (named, with its width and
        where it is), because of too many corners, or because the elements are too small.
    """
    spacing = element_spacing(max_area)
    sources = [(outline.points, outline.corners)]
    sources += [(h if signed_area(h) > 0 else h[::-1], None) for h in outline.holes]
    count = sum(resampled_count(p, spacing, c) for p, c in sources)
    length = float(sum(np.linalg.norm(np.diff(np.vstack([p, p[:1]]), axis=0), axis=1).sum()
                       for p, _ in sources))
    if count > MAX_BOUNDARY_NODES:
        smallest = smallest_spacing(outline.area, length, max_nodes)
        coarse = 1.01 * max(smallest, spacing)
        if sum(resampled_count(p, coarse, c) for p, c in sources) > MAX_BOUNDARY_NODES:
            raise InvalidInputError(
                f"the outline keeps more than {MAX_BOUNDARY_NODES:,} corners (vertices where "
                "it turns by more than 20 deg) as boundary nodes at any element size; at most "
                f"{MAX_BOUNDARY_NODES:,} boundary nodes are allowed: simplify the outline")
        _, thin = thin_features([resample(p, coarse, c) for p, c in sources], coarse)
        if thin is not None:
            cost = f"its boundary alone would need about {count:,} nodes"
            raise _thin_error(thin, spacing, cost, _unmeshable(thin, smallest))
        raise InvalidInputError(
            f"the boundary is {length:.3g} m long, so elements of {spacing:.3g} m need about "
            f"{count:,} boundary nodes; at most {MAX_BOUNDARY_NODES:,} are allowed (the "
            f"boundary compliance is a dense 2b x 2b matrix): use elements of at least "
            f"{smallest:.3g} m (mesh.max_area >= {max_area_for_spacing(smallest):.3g} m^2)")
    loops = [resample(p, spacing, c) for p, c in sources]
    extra, thinnest = thin_features(loops, spacing)
    return MeshEstimate(spacing, int(np.ceil(NODES_PER_AREA * outline.area / max_area)),
                        count, length, outline.area, extra, thinnest, tuple(loops))


def check_mesh_size(estimate: MeshEstimate, max_nodes: int) -> None:
    """Refuse a mesh of more than ``max_nodes`` nodes, or one that thin features would more
    than double (beyond :data:`THIN_ALLOWANCE` extra nodes): the message names the feature,
    its width, where it is, the element size and the limit.
    """
    thin = estimate.thinnest
    allowed = max(estimate.area_nodes, THIN_ALLOWANCE)
    if estimate.nodes <= max_nodes and (thin is None or estimate.thin_nodes <= allowed):
        return
    if thin is None:
        raise InvalidInputError(
            f"about {estimate.nodes:,.0f} nodes at elements of {estimate.spacing:.3g} m; at "
            f"most {max_nodes:,} are allowed")
    smallest = smallest_spacing(estimate.area, estimate.boundary_length, max_nodes)
    if thin.width >= smallest:
        remedy = (f"use elements no larger than the feature (mesh.max_area <= "
                  f"{max_area_for_spacing(thin.width):.3g} m^2) or make it wider")
    else:
        remedy = _unmeshable(thin, smallest)
    extra = (f"about {estimate.thin_nodes:,.0f}" if np.isfinite(estimate.thin_nodes)
             else "unboundedly many")
    cost = (f"meshing would add {extra} nodes to the {estimate.area_nodes:,} asked for (thin "
            f"features may add at most {allowed:,}; limit {max_nodes:,} nodes)")
    raise _thin_error(thin, estimate.spacing, cost, remedy)
