# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Douglas-Peucker simplification of closed curves, vectorised over all open segments.

The algorithm of ``skimage.measure.approximate_polygon`` (and OpenCV's ``approxPolyDP``): keep
the vertex farthest from the chord of a piece while it is farther than the tolerance, and split
the piece there. Here every piece of a round is split at once with numpy, so a 1,000-point
contour takes well under a millisecond instead of scikit-image's Python loop over pieces
(about 8 ms measured on this machine). Distances are to the chord *segment*, so every input
point lies within the tolerance of the simplified curve.

>>> square = np.array([[0, 0], [1, 0.001], [2, 0], [2, 2], [0, 2]], float)
>>> simplify_closed(square, 0.01).tolist()
[[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError

__all__ = ["curve_distances", "kept_vertices", "segment_distances", "sharpen_corners",
           "simplify_closed", "spline_corners", "vertex_turns"]


def segment_distances(points: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 2) to its segment from ``start`` to ``end`` (n, 2 each)."""
    d = end - start
    length2 = np.einsum("ij,ij->i", d, d)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.einsum("ij,ij->i", points - start, d) / length2, 0.0, 1.0)
    t = np.where(length2 > 0, t, 0.0)
    return np.linalg.norm(points - start - t[:, None] * d, axis=1)


def simplify_closed(points: np.ndarray, tolerance: float) -> np.ndarray:
    """The vertices of closed polyline ``points`` (n, 2) kept by Douglas-Peucker (see
    :func:`kept_vertices`).
    """
    return np.asarray(points, float)[kept_vertices(points, tolerance)]


def kept_vertices(points: np.ndarray, tolerance: float) -> np.ndarray:
    """Indices of the vertices of closed polyline ``points`` (n, 2) kept by Douglas-Peucker.

    Parameters
    ----------
    points : (n, 2) ndarray
        Closed curve without a repeated first point.
    tolerance : float
        Largest distance of a dropped point to the simplified curve (units of ``points``).

    Returns
    -------
    (k,) ndarray of int
        The kept vertices' indices, increasing, starting with 0.
    """
    p = np.asarray(points, float)
    n = len(p)
    if n <= 3:
        return np.arange(n)
    far = int(np.argmax(np.linalg.norm(p - p[0], axis=1)))
    kept = np.array([0, far]) if far else np.array([0])
    ring = np.vstack([p, p[:1]])  # index n is point 0 again
    index = np.arange(n)
    while True:
        bounds = np.append(kept, n)
        piece = np.searchsorted(bounds, index, side="right") - 1
        d = segment_distances(p, ring[bounds[piece]], ring[bounds[piece + 1]])
        d[kept] = 0.0
        worst = np.maximum.reduceat(d, kept)
        split = worst > tolerance
        if not split.any():
            return kept
        candidates = np.flatnonzero(split[piece] & (d == worst[piece]))
        _, first = np.unique(piece[candidates], return_index=True)
        kept = np.sort(np.concatenate([kept, candidates[first]]))


CANDIDATE_TURN_DEG = 10.0
"""Kept vertices turning more than this are tried as corners (sharpest first): a rounded acute
tip may spread its turn over several vertices."""


def _line(points: np.ndarray, tolerance: float):
    """Centre and unit direction of the total-least-squares line through ``points``, or None
    when they stray from it by more than ``tolerance`` (they are not straight).
    """
    centre = points.mean(axis=0)
    d = points - centre
    sxx, syy, sxy = d[:, 0] @ d[:, 0], d[:, 1] @ d[:, 1], d[:, 0] @ d[:, 1]
    angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)  # principal axis of the 2 x 2 scatter
    direction = np.array([np.cos(angle), np.sin(angle)])
    off = np.abs(d @ np.array([-direction[1], direction[0]]))
    return (centre, direction) if off.max() <= tolerance else None


def _corner(p: np.ndarray, gap: np.ndarray, skip: float, span: float, tolerance: float,
            max_cut: float, min_turn_deg: float) -> np.ndarray | None:
    """The rebuilt corner from the stretches ``skip`` to ``skip + span`` before and after the
    point at ``gap`` = 0 (signed arc length), or None when it is not a clean corner.
    """
    before = p[(gap <= -skip) & (gap >= -skip - span)]
    after = p[(gap >= skip) & (gap <= skip + span)]
    if len(before) < 3 or len(after) < 3:
        return None
    lines = _line(before, tolerance), _line(after, tolerance)
    if lines[0] is None or lines[1] is None:
        return None
    (c0, d0), (c1, d1) = lines
    det = d0[0] * d1[1] - d0[1] * d1[0]
    if abs(det) < np.sin(np.radians(min_turn_deg)):
        return None
    w = c1 - c0
    corner = c0 + d0 * (w[0] * d1[1] - w[1] * d1[0]) / det
    half_angle = 0.5 * (np.pi - np.arccos(np.clip(abs(d0 @ d1), 0.0, 1.0)))
    cut = np.linalg.norm(p[np.abs(gap) < skip] - corner, axis=1).min(initial=np.inf)
    return corner if cut <= max_cut / np.sin(half_angle) else None


def sharpen_corners(points: np.ndarray, kept: np.ndarray, *, radius: float, span: float,
                    tolerance: float, max_cut: float, min_turn_deg: float = 30.0
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Simplified vertices of closed curve ``points`` with its traced corners made sharp again.

    An iso-contour cuts a corner of the true outline short (by about a third of a pixel at a
    right angle, more at an acute one). At each kept vertex where the simplified curve turns by
    more than ``min_turn_deg``, straight lines are fitted to the traced points from ``radius``
    (or 1.5 or 2.25 times it, for acute tips) to that plus ``span`` away from it on each side
    (arc length); when both are straight to
    ``tolerance``, the vertex moves to their intersection and the kept vertices within
    ``radius`` of it are dropped. Curved stretches (a rounded corner) are left as traced, and so
    is a corner whose rebuilt tip would lie farther than ``max_cut / sin(alpha / 2)`` from the
    traced curve (alpha: the corner's angle; an iso-contour cuts a corner by about that much,
    while lines fitted to slightly curved sides overshoot).

    Parameters
    ----------
    points : (n, 2) ndarray
        The traced closed curve.
    kept : (k,) ndarray of int
        Indices of its simplified vertices (:func:`kept_vertices`).
    radius, span, tolerance, max_cut : float
        Lengths in the units of ``points``.
    min_turn_deg : float
        Smallest turn of a corner, deg.

    Returns
    -------
    vertices : (m, 2) ndarray
        The simplified vertices, corners moved (vertices turning more than
        :data:`CANDIDATE_TURN_DEG` are tried, sharpest first).
    corners : (m,) ndarray of bool
        Which vertices are rebuilt corners (the others lie on the traced curve).
    """
    p = np.asarray(points, float)
    n = len(p)
    q = p[kept]
    e_in, e_out = q - np.roll(q, 1, axis=0), np.roll(q, -1, axis=0) - q
    turn = np.degrees(np.abs(np.arctan2(e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0],
                                        np.einsum("ij,ij->i", e_in, e_out))))
    step = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
    arc = np.concatenate([[0.0], np.cumsum(step)])
    total = arc[-1]
    out = q.copy()
    drop = np.zeros(len(q), bool)
    moved = np.zeros(len(q), bool)
    for c in np.argsort(-turn)[:np.count_nonzero(turn > CANDIDATE_TURN_DEG)]:
        if drop[c]:  # another vertex of the same corner was moved already
            continue
        gap = (arc[:n] - arc[kept[c]] + 0.5 * total) % total - 0.5 * total  # signed arc
        for skip in (radius, 1.5 * radius, 2.25 * radius):  # acute tips are rounded farther
            corner = _corner(p, gap, skip, span, tolerance, max_cut, min_turn_deg)
            if corner is None:
                continue
            if moved.any() and np.linalg.norm(out[moved] - corner, axis=1).min() < skip:
                drop[c] = True  # the same corner, rebuilt from a neighbouring vertex
            else:
                out[c], moved[c] = corner, True
                drop |= (np.abs(gap[kept]) < skip) & ~moved  # the rounded tip's vertices
            break
    return out[~drop], moved[~drop]


def curve_distances(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Distance of each of ``points`` to the closed polyline ``curve`` (dense samples), m: to
    the two curve segments at the nearest sample.
    """
    from scipy.spatial import cKDTree

    _, k = cKDTree(curve).query(points)
    n = len(curve)
    return np.minimum(
        segment_distances(points, curve[(k - 1) % n], curve[k]),
        segment_distances(points, curve[k], curve[(k + 1) % n]))


def vertex_turns(vertices: np.ndarray) -> np.ndarray:
    """Turning angle at each vertex of a closed polyline, deg (positive to the left)."""
    edge = np.diff(np.vstack([vertices[-1:], vertices, vertices[:1]]), axis=0)
    a, b = edge[:-1], edge[1:]
    return np.degrees(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
                                 np.einsum("ij,ij->i", a, b)))


KINK_TURN_DEG = 30.0
"""A simplified vertex turning more than this is a kink the corner rebuild left rounded (a line
meeting a tight arc): a spline through the vertices starts with it as a corner."""


def spline_corners(points: np.ndarray, vertices: np.ndarray, corners: np.ndarray, *,
                   tolerance: float, radius: float) -> np.ndarray:
    """Which ``vertices`` of traced closed curve ``points`` a spline through them must keep as
    corners for every traced point to lie within ``tolerance`` of it.

    Starting from the rebuilt ``corners`` (bool per vertex) and the vertices turning more than
    :data:`KINK_TURN_DEG`, the curve through the vertices is a cubic spline from corner to
    corner (``shapes.spline`` with ``corners``); where traced points stray farther than
    ``tolerance`` from it (a straight edge the spline bends, the end of an arc), both ends of
    the nearest vertex segment become corners, until none strays. All corners is the
    Douglas-Peucker polygon, within tolerance by construction. A spline that crosses itself
    takes its sharpest vertex that is no corner as one more corner. Traced points within
    ``radius`` of a rebuilt corner are not judged (the trace cuts the corner short by more
    than the tolerance).
    """
    from squeeze_grasp_ros.mechanics.elastic.shapes import spline

    corner = np.asarray(corners, bool)
    if corner.any():
        rebuilt = vertices[corner]
        near = np.linalg.norm(points[:, None] - rebuilt[None], axis=2).min(axis=1) < radius
        points = points[~near]
    turn = np.abs(vertex_turns(vertices))
    corner = corner | (turn > KINK_TURN_DEG)
    n = len(vertices)
    while not corner.all():
        try:
            curve = spline(vertices, corners=np.flatnonzero(corner)).points
        except InvalidInputError:  # it crosses itself: the sharpest free vertex is a corner
            corner = corner.copy()
            corner[np.argmax(np.where(corner, -1.0, turn))] = True
            continue
        far = points[curve_distances(points, curve) > tolerance]
        if not len(far):
            break
        ends = vertices[(np.arange(n) + 1) % n]
        segment = np.argmin(np.stack([
            segment_distances(far, np.broadcast_to(a, far.shape), np.broadcast_to(b, far.shape))
            for a, b in zip(vertices, ends)], axis=1), axis=1)
        grown = corner.copy()
        grown[segment] = True
        grown[(segment + 1) % n] = True
        if (grown == corner).all():
            break
        corner = grown
    return corner
