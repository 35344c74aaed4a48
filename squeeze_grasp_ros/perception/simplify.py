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

from squeeze_grasp_ros.mechanics.elastic.shapes import signed_area
from squeeze_grasp_ros.mechanics.errors import InvalidInputError

__all__ = ["centred_vertices", "curve_distances", "joined_curve", "kept_vertices",
           "segment_distances", "sharpen_corners", "simplify_closed", "smoothed_curve",
           "spline_corners", "vector_lengths", "vertex_turns"]


def vector_lengths(vectors: np.ndarray) -> np.ndarray:
    """Length of each 2-vector of ``vectors`` (..., 2): ``np.linalg.norm(vectors, axis=-1)`` to
    the bit (the square root of x * x + y * y), without its general reduction over a 2-long
    axis (7-20 times faster on a few hundred vectors; the curve steps call it about 40 times a
    frame).

    >>> vector_lengths(np.array([[3.0, 4.0], [1.0, 0.0]])).tolist()
    [5.0, 1.0]
    """
    x, y = vectors[..., 0], vectors[..., 1]
    return np.sqrt(x * x + y * y)


def segment_distances(points: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 2) to its segment from ``start`` to ``end`` (n, 2 each)."""
    d = end - start
    length2 = np.einsum("ij,ij->i", d, d)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.einsum("ij,ij->i", points - start, d) / length2, 0.0, 1.0)
    t = np.where(length2 > 0, t, 0.0)
    return vector_lengths(points - start - t[:, None] * d)


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
    far = int(np.argmax(vector_lengths(p - p[0])))
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


def _stretch_fits(p: np.ndarray, gaps: np.ndarray, starts: np.ndarray, span: float,
                  tolerance: float) -> dict[str, np.ndarray]:
    """The traced stretches beside every corner candidate, and the total-least-squares line
    fitted to each and the circle fitted to those a line-arc corner reads, all at once.

    Stretch (c, i, s, j) holds the traced points whose signed arc length from candidate c's
    vertex, times -1 before it (s = 0) and +1 after it (s = 1), lies in [``starts[i]``,
    ``starts[i] + STRETCH_SPANS[j] * span``], in the trace's order (``gaps``: (C, n) signed arc
    lengths). The circle is scikit-image ``CircleModel``'s algebraic fit
    (:func:`~.primitives.fit_circle`: data centred and scaled to unit spread, least squares on
    [2x, 2y, 1] -> x^2 + y^2, the radius the RMS distance to the centre), solved here by its
    3 x 3 normal equations for all stretches at once; it is fitted only where
    :func:`_arc_side` asks for it (a stretch of :data:`SIDE_SPANS` with at least 3 points, not
    straight, the other side straight over :data:`LINE_BESIDE_ARC` spans), the others are
    not circular.

    Returns
    -------
    dict
        ``points`` (m, 2): the stretches' points one after the other; per stretch, shaped
        (C, I, 2, J): ``first`` and ``count`` (where it starts in ``points``, how many),
        ``straight`` (every point within ``tolerance`` of its line), ``circular`` (fitted, at
        least 3 points, every point within ``tolerance`` of its circle), ``radius``; and
        (C, I, 2, J, 2): ``centre``, ``direction`` (the line's), ``centre_of_circle``.
    """
    lengths = np.array(STRETCH_SPANS) * span
    hi = starts[:, None] + lengths[None, :]
    # the points any stretch of a side may hold (a few dozen of the n), in the trace's order
    side = np.stack([-gaps, gaps], axis=1).reshape(-1, gaps.shape[1])  # (2 C, n)
    near_row, near = np.nonzero((side >= starts.min()) & (side <= hi.max()))
    held = np.bincount(near_row, minlength=len(side))
    slot = np.arange(len(near)) - np.repeat(np.cumsum(held) - held, held)
    window = np.zeros((len(side), max(int(held.max(initial=0)), 1)), int)
    window[near_row, slot] = near
    seen = np.full(window.shape, np.inf)
    seen[near_row, slot] = side[near_row, near]
    seen = seen.reshape(len(gaps), 1, 2, 1, window.shape[1])  # (C, 1, 2, 1, w)
    lo = starts[None, :, None, None, None]
    inside = (seen >= lo) & (seen <= hi[None, :, None, :, None])  # (C, I, 2, J, w)
    shape = inside.shape[:-1]
    row, at = np.nonzero(inside.reshape(-1, inside.shape[-1]))  # row-major: the trace's order
    count = np.bincount(row, minlength=int(np.prod(shape)))
    first = np.cumsum(count) - count
    sides = np.arange(len(gaps))[:, None, None, None] * 2 + np.arange(2)[None, None, :, None]
    points = p[window[np.broadcast_to(sides, shape).ravel()[row], at]]
    out = {"points": points, "first": first, "count": count,
           **{k: np.full((len(count), 2), np.nan)
              for k in ("centre", "direction", "centre_of_circle")},
           "radius": np.full(len(count), np.nan), "straight": np.zeros(len(count), bool),
           "circular": np.zeros(len(count), bool)}
    used = count > 0
    at, size = first[used], count[used]
    if len(at):
        mean = np.add.reduceat(points, at, axis=0) / size[:, None]
        d = points - np.repeat(mean, size, axis=0)
        sxx, syy, sxy = (np.add.reduceat(d[:, 0] * d[:, 0], at),
                         np.add.reduceat(d[:, 1] * d[:, 1], at),
                         np.add.reduceat(d[:, 0] * d[:, 1], at))
        angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)  # principal axis of the 2 x 2 scatter
        cos, sin = np.cos(angle), np.sin(angle)
        off = np.abs(np.repeat(cos, size) * d[:, 1] - np.repeat(sin, size) * d[:, 0])
        out["centre"][used], out["direction"][used] = mean, np.column_stack([cos, sin])
        out["straight"][used] = np.maximum.reduceat(off, at) <= tolerance
        straight = out["straight"].reshape(shape)
        beside = straight[:, :, ::-1, STRETCH_SPANS.index(LINE_BESIDE_ARC), None]
        arc = np.isin(STRETCH_SPANS, SIDE_SPANS) & beside & ~straight
        wanted = np.flatnonzero((arc.ravel() & (count >= 3))[used])
        if len(wanted):
            _circle_fits(out, np.flatnonzero(used)[wanted], points, d, mean[wanted],
                         sxx[wanted] + syy[wanted], tolerance)
    return {k: v if k == "points" else v.reshape(*shape, *v.shape[1:]) for k, v in out.items()}


def _circle_fits(out: dict[str, np.ndarray], which: np.ndarray, points: np.ndarray,
                 d: np.ndarray, mean: np.ndarray, spread: np.ndarray, tolerance: float) -> None:
    """Fit the circles of stretches ``which`` (:func:`_stretch_fits`' flat stretch indices;
    ``d`` their points centred on their ``mean``, ``spread`` the sums of squares of ``d``) and
    write them into ``out``.
    """
    size = out["count"][which]
    at = np.cumsum(size) - size
    take = np.repeat(out["first"][which] - at, size) + np.arange(size.sum())
    points, d = points[take], d[take]

    def sums(values: np.ndarray) -> np.ndarray:
        return np.add.reduceat(values, at, axis=0)

    def each(values: np.ndarray) -> np.ndarray:
        return np.repeat(values, size, axis=0)

    # on the centred points scaled to unit spread (std over both columns)
    scale = np.sqrt(spread / (2 * size))
    with np.errstate(divide="ignore", invalid="ignore"):
        u = d / each(scale)[:, None]
    f = u[:, 0] * u[:, 0] + u[:, 1] * u[:, 1]
    suu = sums(u[:, 0] * u[:, 1])
    normal = np.empty((len(at), 3, 3))
    normal[:, 0, 0], normal[:, 1, 1] = 4.0 * sums(u[:, 0] ** 2), 4.0 * sums(u[:, 1] ** 2)
    normal[:, 0, 1] = normal[:, 1, 0] = 4.0 * suu
    normal[:, :2, 2] = 2.0 * sums(u)
    normal[:, 2, :2] = normal[:, :2, 2]
    normal[:, 2, 2] = size
    rhs = np.column_stack([2.0 * sums(u * f[:, None]), sums(f)])
    # the design [2x, 2y, 1] has rank 3 (lstsq's test): away from a collinear or tiny set
    fit = (size >= 3) & (scale >= np.finfo(float).tiny) & np.all(np.isfinite(normal),
                                                                  axis=(1, 2))
    fit[fit] &= np.abs(np.linalg.det(normal[fit])) > 1e-10 * size[fit] ** 3
    solved = np.linalg.solve(np.where(fit[:, None, None], normal, np.eye(3)),
                             np.where(fit[:, None], rhs, 0.0)[..., None])[..., 0]
    c = solved[:, :2]
    with np.errstate(invalid="ignore"):
        w = u - each(c)
        radius = np.sqrt(sums(w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1]) / size) * scale
        centre = c * scale[:, None] + mean
        stray = np.maximum.reduceat(np.abs(each(radius) - vector_lengths(
            points - each(centre))), at)
        circular = fit & np.all(np.isfinite(centre), axis=1) & (stray <= tolerance)
    out["centre_of_circle"][which], out["radius"][which] = centre, radius
    out["circular"][which] = circular


SIDE_SPANS = (4.0, 2.0)
"""Lengths (multiples of ``span``) of the longer stretches beside a corner that are fitted as
a line or a circle, longest first. A 40 px arc strays only 0.1 px from a line over 8 px (one
span), and a circle fitted to 8 px of it has its radius off by half (the corner then 0.5 px
off): the longer stretches tell an arc from a line."""

LINE_BESIDE_ARC = 2.0
"""A straight side meets an arc at a corner only when it is straight over this many spans (a
D's diameter is; a gently curved side, straight to the tolerance over one span only, is not)."""

STRETCH_SPANS = tuple(sorted({1.0, LINE_BESIDE_ARC, *SIDE_SPANS}))
"""Every stretch length (multiples of ``span``) the corner rebuild fits a line to."""


class _Stretches:
    """The stretches beside one corner candidate at one skip (a view of :func:`_stretch_fits`'
    results), side 0 before the vertex and 1 after it, ``spans`` one of
    :data:`STRETCH_SPANS`.
    """

    def __init__(self, fits: dict[str, np.ndarray], c: int, i: int):
        self.fits, self.c, self.i = fits, c, i

    def _at(self, side: int, spans: float) -> tuple[int, int, int, int]:
        return self.c, self.i, side, STRETCH_SPANS.index(spans)

    def count(self, side: int, spans: float) -> int:
        """How many traced points the stretch holds."""
        return int(self.fits["count"][self._at(side, spans)])

    def line(self, side: int, spans: float):
        """(centre, direction) of the stretch's line, or None when it is not straight."""
        k = self._at(side, spans)
        if not self.fits["straight"][k]:
            return None
        return self.fits["centre"][k], self.fits["direction"][k]

    def circle(self, side: int, spans: float):
        """(centre, radius) of the stretch's circle, or None when it is not circular."""
        k = self._at(side, spans)
        if not self.fits["circular"][k]:
            return None
        return self.fits["centre_of_circle"][k], float(self.fits["radius"][k])


def _arc_side(stretches: _Stretches, side: int):
    """The circle (centre, radius) of the longest stretch (of :data:`SIDE_SPANS`) on ``side``
    that is circular and not straight, or None.
    """
    for factor in SIDE_SPANS:
        if stretches.count(side, factor) >= 3 and stretches.line(side, factor) is None:
            circle = stretches.circle(side, factor)
            if circle is not None:
                return circle
    return None


def _line_meets_arc(line, circle, near: np.ndarray, arc_after: bool):
    """The point where ``line`` (centre, direction) meets ``circle`` (centre, radius) nearest to
    ``near``, and the two sides' directions there (line first when the arc comes after), or
    None when they do not meet.
    """
    (c0, d0), (cc, r) = line, circle
    w = c0 - cc
    b, c = d0 @ w, w @ w - r * r
    disc = b * b - c
    if disc < 0.0:
        return None
    roots = -b + np.array([-1.0, 1.0]) * np.sqrt(disc)
    hits = c0 + roots[:, None] * d0
    corner = hits[np.argmin(vector_lengths(hits - near))]
    radial = corner - cc
    tangent = np.array([-radial[1], radial[0]]) / r
    return (corner, d0, tangent) if arc_after else (corner, tangent, d0)


def _corner(p: np.ndarray, gap: np.ndarray, skip: float, stretches: _Stretches,
            max_cut: float, min_turn_deg: float) -> np.ndarray | None:
    """The rebuilt corner from the ``stretches`` from ``skip`` on before and after the point at
    ``gap`` = 0 (signed arc length), or None when it is not a clean corner: a straight side
    (over :data:`LINE_BESIDE_ARC` spans) and a circular arc (a D shape's diameter meeting its
    arc) meet where the line meets the circle; two sides straight over a span meet at the
    intersection of their lines.
    """
    if stretches.count(0, 1.0) < 3 or stretches.count(1, 1.0) < 3:
        return None
    long_line = [stretches.line(side, LINE_BESIDE_ARC) for side in (0, 1)]
    arcs = [None if long_line[1 - side] is None else _arc_side(stretches, side)
            for side in (0, 1)]
    if arcs[0] is not None or arcs[1] is not None:
        arc_after = arcs[1] is not None
        line, arc = (long_line[0], arcs[1]) if arc_after else (long_line[1], arcs[0])
        met = _line_meets_arc(line, arc, p[np.argmin(np.abs(gap))], arc_after)
        if met is None:
            return None
        corner, d0, d1 = met
        if abs(d0[0] * d1[1] - d0[1] * d1[0]) < np.sin(np.radians(min_turn_deg)):
            return None  # a tangent join (a straight edge running into an arc): no corner
    else:
        lines = stretches.line(0, 1.0), stretches.line(1, 1.0)
        if lines[0] is None or lines[1] is None:
            return None
        (c0, d0), (c1, d1) = lines
        det = d0[0] * d1[1] - d0[1] * d1[0]
        if abs(det) < np.sin(np.radians(min_turn_deg)):
            return None
        w = c1 - c0
        corner = c0 + d0 * (w[0] * d1[1] - w[1] * d1[0]) / det
    half_angle = 0.5 * (np.pi - np.arccos(np.clip(abs(d0 @ d1), 0.0, 1.0)))
    cut = vector_lengths(p[np.abs(gap) < skip] - corner).min(initial=np.inf)
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
    step = vector_lengths(np.roll(p, -1, axis=0) - p)
    arc = np.concatenate([[0.0], np.cumsum(step)])
    total = arc[-1]
    out = q.copy()
    drop = np.zeros(len(q), bool)
    moved = np.zeros(len(q), bool)
    candidates = np.argsort(-turn)[:np.count_nonzero(turn > CANDIDATE_TURN_DEG)]
    skips = np.array([radius, 1.5 * radius, 2.25 * radius])  # acute tips are rounded farther
    gaps = (arc[None, :n] - arc[kept[candidates]][:, None] + 0.5 * total) % total - 0.5 * total
    fits = _stretch_fits(p, gaps, skips, span, tolerance)
    for k, c in enumerate(candidates):
        if drop[c]:  # another vertex of the same corner was moved already
            continue
        gap = gaps[k]  # signed arc length from the vertex
        for i, skip in enumerate(skips):
            corner = _corner(p, gap, skip, _Stretches(fits, k, i), max_cut, min_turn_deg)
            if corner is None:
                continue
            # the same corner, rebuilt from a neighbouring vertex: near it in the plane and
            # along the curve (across a slit a pixel wide, the next corner is only near)
            same = ((vector_lengths(out - corner) < skip) & moved
                    & (np.abs(gap[kept]) < skip + span))
            if same.any():
                drop[c] = True
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


def centred_vertices(points: np.ndarray, vertices: np.ndarray, fixed: np.ndarray, *,
                     window: float) -> np.ndarray:
    """``vertices`` of traced closed curve ``points`` (n, 2), each moved onto the quadratic (in
    arc length) fitted by least squares to the traced points within ``window`` (arc length, m)
    of its nearest traced point, except the ``fixed`` ones (bool each: rebuilt corners).

    Douglas-Peucker keeps the traced point farthest from a chord, on a convex stretch the
    outermost of the trace's sub-pixel wobble: a spline through the kept vertices lies outside
    the trace (by 0.04-0.07 px on average, measured on anti-aliased masks of a stadium and a
    D; areas 0.2-0.55 % too large), while the trace itself is unbiased (0.002-0.015 px). The
    local fit averages part of the wobble out (the spline then lies 0.03-0.04 px outside, areas
    within 0.4 %); being quadratic, it does not pull a vertex towards the centre of curvature
    as a local mean would (by window^2 / (6 R)).
    """
    from scipy.spatial import cKDTree

    p = np.asarray(points, float)
    n = len(p)
    step = vector_lengths(np.roll(p, -1, axis=0) - p)
    arc = np.concatenate([[0.0], np.cumsum(step)])[:n]
    total = arc[-1] + step[-1]
    _, nearest = cKDTree(p).query(vertices)
    out = np.array(vertices, float)
    for i in np.flatnonzero(~np.asarray(fixed, bool)):
        t = (arc - arc[nearest[i]] + 0.5 * total) % total - 0.5 * total  # signed arc length
        near = np.abs(t) <= window
        if np.count_nonzero(near) >= 5:
            basis = np.column_stack([np.ones(near.sum()), t[near], t[near] ** 2])
            out[i] = np.linalg.lstsq(basis, p[near], rcond=None)[0][0]
    return out


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
        near = vector_lengths(points[:, None] - rebuilt[None]).min(axis=1) < radius
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


JOIN_TURN_DEG = 20.0
"""A break of the piecewise spline (:func:`joined_curve`) where the built curve turns by more
than this is a corner; below it is a tangent join (a straight edge running into an arc). The
mesher's own threshold for a vertex it keeps (``shapes._turning_corners``)."""


def joined_curve(vertices: np.ndarray, breaks: np.ndarray, *, spacing: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Even samples of the piecewise spline through ``vertices`` that breaks at ``breaks``
    (bool per vertex, :func:`spline_corners`), and which of the samples are corners.

    The spline pieces meet at the breaks; where the curve turns there by at most
    :data:`JOIN_TURN_DEG` the break is a tangent join (a straight edge running into an arc: a
    stadium, a rounded rectangle), and the samples run through it evenly, with nothing kept:
    the mesh then places its boundary nodes as on the true, smooth curve (a join kept as a
    mesh corner anchors the nodes there, and moves those around the fingers by up to a node
    spacing). Breaks turning more are corners (a D shape's). Every break is sampled exactly.

    Parameters
    ----------
    vertices : (n, 2) ndarray
        The simplified vertices, counter-clockwise, m.
    breaks : (n,) ndarray of bool
        Where the spline pieces meet (at least one).
    spacing : float
        Largest distance between consecutive samples along the curve, m.

    Returns
    -------
    samples : (m, 2) ndarray
        Counter-clockwise samples, m; a smooth spline through them (``shapes.spline`` with
        ``corners``) follows the piecewise curve.
    corners : (k,) ndarray of int
        Indices of the samples that are corners.
    """
    from squeeze_grasp_ros.mechanics.elastic.shapes import spline

    built = spline(vertices, corners=np.flatnonzero(breaks))
    dense, at = built.points, built.corners
    closed = np.vstack([dense, dense[:1]])
    s = np.concatenate([[0.0], np.cumsum(vector_lengths(np.diff(closed, axis=0)))])
    ends = np.append(s[at], s[at[0]] + s[-1])
    pieces = [np.linspace(a, b, max(1, int(np.ceil((b - a) / spacing))), endpoint=False)
              for a, b in zip(ends[:-1], ends[1:])]
    first = np.cumsum([0] + [len(p) for p in pieces[:-1]])  # the breaks among the samples
    t = np.mod(np.concatenate(pieces), s[-1])
    samples = np.column_stack([np.interp(t, s, closed[:, 0]), np.interp(t, s, closed[:, 1])])
    return samples, first[np.abs(vertex_turns(dense))[at] > JOIN_TURN_DEG]


def smoothed_curve(points: np.ndarray, vertices: np.ndarray, corners: np.ndarray, *,
                   tolerance: float, spacing: float, clearance: float, noise: float
                   ) -> tuple[np.ndarray, np.ndarray] | None:
    """Even samples of the smoothing cubic spline (FITPACK ``splprep``) fitted to traced
    closed curve ``points`` between the ``vertices`` flagged ``corners`` (bool each), and the
    corners' indices among the samples; None when no fit keeps every traced point within
    ``tolerance`` of the samples.

    A spline *through* simplified vertices inherits their extremal bias (Douglas-Peucker keeps
    the crests of the trace's wobble) and, where a straight edge runs into an arc, bends
    (an interpolating cubic cannot jump in curvature: a rounded rectangle's spline turned by
    -26 degrees at a join). A least-squares smoothing spline fits the trace itself: unbiased,
    tangent-continuous through the joins, its residual sum of squares at most ``noise``^2 per
    traced point (quartered until every point is within ``tolerance``). Between two corners the
    curve is an open smoothing spline pinned at both (straight when fewer than 8 traced points
    lie between them); without corners the spline is periodic.
    Traced points within ``clearance`` of a corner are not fitted (the trace cuts it short);
    None when that leaves none (a noisy trace whose kinks are all corners).

    Parameters
    ----------
    points : (n, 2) ndarray
        The traced closed curve, m (the samples run counter-clockwise).
    vertices, corners : (k, 2) ndarray, (k,) ndarray of bool
        Its simplified vertices and which are corners (rebuilt, or kinks).
    tolerance, spacing, clearance, noise : float
        Lengths, m: the largest distance of a fitted traced point from the curve, the largest
        distance between samples, the clearance around corners and the trace's noise.
    """
    from scipy.interpolate import splev, splprep

    p = np.asarray(points, float)
    n = len(p)
    corner_xy = np.asarray(vertices, float)[np.asarray(corners, bool)]
    fitted = np.ones(n, bool)
    if len(corner_xy):
        distance = vector_lengths(p[:, None] - corner_xy[None])  # (n, corners)
        fitted = distance.min(axis=1) >= clearance
        at = np.argmin(distance, axis=0)  # each corner's nearest traced point
        order = np.argsort(at)  # in the trace's order
        corner_xy, at = corner_xy[order], at[order]
        if not fitted.any():  # every traced point near a corner (a noisy trace's kinks)
            return None

    def piece(chain: np.ndarray, ends: tuple | None, smooth: float) -> np.ndarray:
        """Dense samples of one stretch (``ends``: its two corners, or None: periodic)."""
        if ends is None:
            data, weights, periodic = chain, np.ones(len(chain)), 1
        else:
            data = np.vstack([ends[0], chain, ends[1]])
            weights = np.r_[1e3, np.ones(len(chain)), 1e3]
            periodic = 0
        gaps = vector_lengths(np.diff(data, axis=0))
        keep = np.r_[True, gaps > 1e-9 * max(gaps.max(), 1e-300)]
        data, weights = data[keep], weights[keep]
        u = np.concatenate([[0.0], np.cumsum(vector_lengths(np.diff(data, axis=0)))])
        length = u[-1] + (np.linalg.norm(data[0] - data[-1]) if periodic else 0.0)
        tck, _ = splprep(data.T, w=weights, u=u / length, s=smooth * len(data), k=3,
                         per=periodic, quiet=2)
        count = max(8, int(np.ceil(length / spacing)))
        return np.column_stack(splev(np.linspace(0.0, 1.0, count, endpoint=not periodic),
                                     tck))[:-1 if not periodic else None]

    smooth = noise ** 2
    for _ in range(6):
        if not len(corner_xy):
            if fitted.sum() < 8:
                return None
            samples, anchors = piece(p, None, smooth), np.zeros(0, int)
        else:
            parts, anchors, count = [], [], 0
            for k in range(len(at)):
                a, b = at[k], at[(k + 1) % len(at)]
                run = p[np.arange(a, b + (n if b <= a else 0)) % n]
                run = run[fitted[np.arange(a, b + (n if b <= a else 0)) % n]]
                ends = corner_xy[k], corner_xy[(k + 1) % len(at)]
                if len(run) < 8:  # too short to fit: straight
                    length = np.linalg.norm(ends[1] - ends[0])
                    m = max(1, int(np.ceil(length / spacing)))
                    part = ends[0] + np.outer(np.arange(m) / m, ends[1] - ends[0])
                else:
                    part = piece(run, ends, smooth)
                anchors.append(count)
                parts.append(part)
                count += len(part)
            samples, anchors = np.vstack(parts), np.array(anchors)
        if curve_distances(p[fitted], samples).max() <= tolerance:
            if signed_area(samples) < 0:  # the trace ran clockwise
                return samples[::-1], np.sort(len(samples) - 1 - anchors)
            return samples, anchors
        smooth *= 0.25
    return None
