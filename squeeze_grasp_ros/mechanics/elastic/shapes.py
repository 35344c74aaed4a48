# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Closed planar outlines: the shape library shared by solid meshes and ring middle curves.

Every outline is a counter-clockwise polyline of vertices in metres (the closing edge is
implicit). Smooth shapes are sampled densely; :func:`resample` turns any outline into evenly
spaced vertices while keeping its corners.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.interpolate import CubicSpline

from squeeze_grasp_ros.inputs import InputError, read_text
from squeeze_grasp_ros.mechanics.elastic import portable_math as pm
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ShapeType

DENSE = 2048
"""Number of samples of a smooth outline before resampling."""


@dataclass(frozen=True)
class Outline:
    """A closed simple outline, optionally with holes.

    Parameters
    ----------
    points : (N, 2) ndarray
        Vertices of the outer curve, m, counter-clockwise, without repeating the first one.
    holes : tuple of (M, 2) ndarray
        Vertices of each hole, m (orientation free).
    corners : (K,) ndarray of int
        Indices into ``points`` of vertices that resampling must keep (polygon corners).
    """

    points: np.ndarray
    holes: tuple[np.ndarray, ...] = ()
    corners: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    @property
    def area(self) -> float:
        """Enclosed area, m^2 (holes subtracted)."""
        return signed_area(self.points) - sum(abs(signed_area(h)) for h in self.holes)

    @property
    def size(self) -> float:
        """Characteristic length, m: the larger side of the bounding box."""
        span = self.points.max(axis=0) - self.points.min(axis=0)
        return float(span.max())


def signed_area(points: np.ndarray) -> float:
    """Shoelace signed area of a closed polyline, m^2 (> 0 when counter-clockwise)."""
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _segments_intersect(p: np.ndarray) -> bool:
    """True if the closed polyline ``p`` is not simple: two non-adjacent edges cross or touch
    (a repeated vertex, a vertex on another edge, overlapping edges), or two adjacent edges fold
    back onto each other (a zero-width spike).

    Broad phase: edges sorted by their left end; each edge is only paired with the following
    edges whose x-range starts before its own ends (a sweep over x), then with bounding-box
    overlap in y; narrow phase: orientation tests on the surviving pairs, with collinearity
    judged to 1e-12 of the squared size.
    """
    a, b = p, np.roll(p, -1, axis=0)
    n = len(p)
    size = max(float(np.ptp(p, axis=0).max()), 1e-300)
    tol = 1e-12 * size
    edge = b - a
    before = np.roll(edge, 1, axis=0)
    cross_turn = before[:, 0] * edge[:, 1] - before[:, 1] * edge[:, 0]
    dot_turn = np.einsum("ij,ij->i", before, edge)
    if np.any((np.abs(cross_turn) <= tol * size) & (dot_turn < 0)):
        return True
    lo, hi = np.minimum(a, b) - tol, np.maximum(a, b) + tol
    order = np.argsort(lo[:, 0], kind="mergesort")
    reach = np.searchsorted(lo[order, 0], hi[order, 0], side="right")
    counts = np.maximum(reach - np.arange(n) - 1, 0)
    first = np.repeat(np.arange(n), counts)
    second = first + 1 + (np.arange(len(first)) - np.repeat(np.cumsum(counts) - counts, counts))
    i, j = order[first], order[second]
    keep = (lo[i, 1] <= hi[j, 1]) & (lo[j, 1] <= hi[i, 1])
    gap = np.abs(i - j)
    keep &= (gap > 1) & (gap != n - 1)
    i, j = i[keep], j[keep]

    def orient(o, q, r):
        oq, o_r = q - o, r - o
        value = oq[:, 0] * o_r[:, 1] - oq[:, 1] * o_r[:, 0]
        return np.where(np.abs(value) <= tol * size, 0.0, np.sign(value))

    def on_segment(o, q, r, side):
        inside = np.all((np.minimum(o, q) - tol <= r) & (r <= np.maximum(o, q) + tol), axis=1)
        return (side == 0) & inside

    d1, d2 = orient(a[i], b[i], a[j]), orient(a[i], b[i], b[j])
    d3, d4 = orient(a[j], b[j], a[i]), orient(a[j], b[j], b[i])
    proper = (d1 * d2 < 0) & (d3 * d4 < 0)
    touch = (on_segment(a[i], b[i], a[j], d1) | on_segment(a[i], b[i], b[j], d2)
             | on_segment(a[j], b[j], a[i], d3) | on_segment(a[j], b[j], b[i], d4))
    return bool(np.any(proper | touch))


def validate_polyline(points, name: str = "outline") -> np.ndarray:
    """Return ``points`` as a counter-clockwise (N, 2) array, or raise a clear error.

    Rejects fewer than 3 distinct vertices, non-finite values, zero area and curves that are
    not simple (edges that cross or touch, repeated vertices, zero-width spikes): the mesher
    crashes on those. Repeated consecutive vertices (and a repeated closing vertex) are dropped.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2:
        raise InvalidInputError(f"{name} must be a list of [x, y] pairs, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InvalidInputError(f"{name} has non-finite coordinates")
    step = np.linalg.norm(np.diff(np.vstack([p, p[:1]]), axis=0), axis=1)
    scale = max(float(np.ptp(p, axis=0).max()), 1e-300)
    distinct = p[step > 1e-12 * scale]
    if len(distinct) < 3:
        found = len(distinct) or min(len(p), 1)  # all vertices equal: one distinct vertex
        raise InvalidInputError(f"{name} needs at least 3 distinct vertices, got {found}")
    p = distinct
    area = signed_area(p)
    if abs(area) <= 1e-12 * scale * scale:
        flat = np.linalg.svd(p - p.mean(axis=0), compute_uv=False)[-1] <= 1e-12 * scale
        if not flat:  # a figure eight: its lobes' signed areas cancel
            raise InvalidInputError(f"{name} is self-intersecting: two edges cross (its "
                                    "lobes' signed areas cancel); give a simple closed curve")
        raise InvalidInputError(f"{name} is degenerate (zero enclosed area)")
    if area < 0:
        p = p[::-1].copy()
    if _segments_intersect(p):
        raise InvalidInputError(f"{name} is self-intersecting: two edges cross or touch (a "
                             "repeated vertex, a vertex on another edge or a zero-width spike); "
                             "give a simple closed curve")
    return p


def require_outline(outline) -> None:
    """Refuse anything but an :class:`Outline` with finite loops of at least 3 vertices, the
    outer one counter-clockwise around a positive area: what :func:`polygon`,
    :func:`load_outline` and the other constructors here give (an Outline built by hand skips
    their checks).

    Raises
    ------
    InvalidInputError
        Naming the field (``outline.points``, ``outline.holes[k]``) and what it holds.
    """
    if not isinstance(outline, Outline):
        raise InvalidInputError(
            f"outline must be an Outline (e.g. polygon(points)), got {type(outline).__name__}")
    loops = [("outline.points", outline.points),
             *((f"outline.holes[{k}]", hole) for k, hole in enumerate(outline.holes))]
    for name, loop in loops:
        shape = np.shape(loop)
        if len(shape) != 2 or shape[1] != 2 or shape[0] < 3:
            raise InvalidInputError(f"{name} must be an (N, 2) array of N >= 3 vertices (m), "
                                    f"got shape {shape}")
        if not np.all(np.isfinite(loop)):
            raise InvalidInputError(f"{name} has non-finite coordinates")
    area = signed_area(np.asarray(outline.points, float))
    if not area > 0:
        raise InvalidInputError(
            f"outline.points must run counter-clockwise around a positive area, got a signed "
            f"area of {area:.3g} m^2 (polygon() orients and checks its points)")


def _turning_corners(p: np.ndarray, threshold_deg: float = 20.0) -> np.ndarray:
    """Indices of vertices where the polyline turns by more than ``threshold_deg``."""
    e_in = p - np.roll(p, 1, axis=0)
    e_out = np.roll(p, -1, axis=0) - p
    cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
    turn = np.abs(pm.arctan2(cross, np.einsum("ij,ij->i", e_in, e_out)))
    return np.flatnonzero(turn > np.radians(threshold_deg))


def require_within_reach(points: np.ndarray, point: Sequence[float], name: str) -> None:
    """Refuse a placement ``point`` (m) far from the closed polyline ``points``: it must lie in
    the polyline's bounding box grown by the box's larger side on every side. Beyond it the
    point's nearest boundary place is meaningless (at 1e308 m every distance overflows).

    >>> require_within_reach(rectangle(0.1, 0.1).points, (0.12, 0.0), "point")
    >>> require_within_reach(rectangle(0.1, 0.1).points, (1e308, 0.0), "point")
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: point (1e+308, 0) m is outside the \
object's reach: it must lie within [-0.15, 0.15] x [-0.15, 0.15] m (the object's bounding box \
grown by its size, 0.1 m, on every side)
    """
    lo, hi = points.min(axis=0), points.max(axis=0)
    size = float((hi - lo).max())
    p = np.asarray(point, dtype=float)
    if not np.all((lo - size <= p) & (p <= hi + size)):
        raise InvalidInputError(
            f"{name} ({p[0]:.6g}, {p[1]:.6g}) m is outside the object's reach: it must lie "
            f"within [{lo[0] - size:.6g}, {hi[0] + size:.6g}] x [{lo[1] - size:.6g}, "
            f"{hi[1] + size:.6g}] m (the object's bounding box grown by its size, {size:.6g} m, "
            "on every side)")


def with_boundary_points(outline: Outline, points: Sequence[Sequence[float]]) -> Outline:
    """``outline`` with the boundary point nearest to each of ``points`` as a kept vertex.

    Each point is projected onto the nearest segment of the outer curve and inserted there as a
    corner, so meshing keeps it exactly as a boundary node (a finger placed at a point then
    touches exactly there, not at the nearest node of an evenly resampled boundary). A point
    within 1e-9 of the outline size of an existing vertex reuses that vertex.

    Examples
    --------
    >>> square = with_boundary_points(rectangle(0.1, 0.1), [(-0.06, 0.001)])
    >>> [round(float(v), 6) for v in square.points[square.corners[-1]]]
    [-0.05, 0.001]
    """
    p = np.asarray(outline.points, float)
    corners = np.asarray(outline.corners, int)
    for point in np.asarray(points, float).reshape(-1, 2):
        a, b = p, np.roll(p, -1, axis=0)
        ab = b - a
        t = np.clip(np.einsum("ij,ij->i", point - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        foot = a + t[:, None] * ab
        k = int(np.argmin(np.linalg.norm(foot - point, axis=1)))
        near = np.linalg.norm(p - foot[k], axis=1)
        if near.min() <= 1e-9 * outline.size:
            corners = np.union1d(corners, [int(np.argmin(near))])
            continue
        p = np.insert(p, k + 1, foot[k], axis=0)
        corners = np.union1d(np.where(corners > k, corners + 1, corners), [k + 1])
    return Outline(p, outline.holes, corners.astype(int))


def polygon(points: Sequence[Sequence[float]],
            holes: Sequence[Sequence[Sequence[float]]] = ()) -> Outline:
    """A closed simple polygon through ``points`` (m), its vertices kept as corners, with
    optional polygonal ``holes`` (each a list of [x, y], m) strictly inside it.

    Examples
    --------
    >>> frame = polygon([[0, 0], [4, 0], [4, 4], [0, 4]], holes=[[[1, 1], [3, 1], [3, 3]]])
    >>> frame.area
    14.0
    """
    p = validate_polyline(points, ShapeType.POLYGON)
    inner = tuple(validate_polyline(h, f"polygon.holes[{k}]") for k, h in enumerate(holes))
    _check_holes(p, inner, ShapeType.POLYGON.value)
    return Outline(p, inner, corners=np.arange(len(p)))


def _check_holes(outer: np.ndarray, inner: tuple[np.ndarray, ...], name: str) -> None:
    """Refuse holes that are not strictly inside ``outer`` and apart from each other."""
    for k, hole in enumerate(inner):
        if not _inside(hole[0], outer) or _crosses(outer, hole) or any(
                _crosses(hole, other) or _inside(other[0], hole) for other in inner[:k]):
            raise InvalidInputError(f"{name}.holes[{k}] must lie strictly inside the {name} "
                                    "and apart from the other holes")


def _inside(point: np.ndarray, loop: np.ndarray) -> bool:
    """True if ``point`` is inside the closed polyline ``loop`` (even-odd ray casting)."""
    a, b = loop, np.roll(loop, -1, axis=0)
    x, y = point
    cut = (a[:, 1] > y) != (b[:, 1] > y)
    xs = a[cut, 0] + (y - a[cut, 1]) * (b[cut, 0] - a[cut, 0]) / (b[cut, 1] - a[cut, 1])
    return bool(np.count_nonzero(xs > x) % 2)


def _crosses(a: np.ndarray, b: np.ndarray) -> bool:
    """True if an edge of closed polyline ``a`` crosses or touches an edge of ``b``."""
    a0, a1 = a, np.roll(a, -1, axis=0)
    b0, b1 = b, np.roll(b, -1, axis=0)

    def orient(o, q, r):
        return np.sign((q[..., 0] - o[..., 0]) * (r[..., 1] - o[..., 1])
                       - (q[..., 1] - o[..., 1]) * (r[..., 0] - o[..., 0]))

    A0, A1, B0, B1 = a0[:, None], a1[:, None], b0[None], b1[None]
    overlap = np.all((np.minimum(A0, A1) <= np.maximum(B0, B1))
                     & (np.minimum(B0, B1) <= np.maximum(A0, A1)), axis=-1)
    return bool(np.any(overlap & (orient(A0, A1, B0) * orient(A0, A1, B1) <= 0)
                       & (orient(B0, B1, A0) * orient(B0, B1, A1) <= 0)))


def interior_point(points: np.ndarray) -> np.ndarray:
    """A point strictly inside the simple closed polyline ``points`` (n, 2) (also when it is
    not convex, where the centroid may lie outside): the middle of the first inside span of a
    horizontal line through the middle of its height.
    """
    p = np.asarray(points, float)
    lo, hi = p[:, 1].min(), p[:, 1].max()
    y = lo + (0.5 + 1e-3 * np.pi) * (hi - lo)  # an irrational offset misses the vertices
    a, b = p, np.roll(p, -1, axis=0)
    cut = (a[:, 1] - y) * (b[:, 1] - y) < 0
    x = np.sort(a[cut, 0] + (y - a[cut, 1]) * (b[cut, 0] - a[cut, 0]) / (b[cut, 1] - a[cut, 1]))
    return np.array([0.5 * (x[0] + x[1]), y])


def rectangle(width: float, height: float) -> Outline:
    """Axis-aligned rectangle of ``width`` x ``height`` m centred at the origin."""
    _positive(width=width, height=height)
    w, h = 0.5 * width, 0.5 * height
    return polygon([[-w, -h], [w, -h], [w, h], [-w, h]])


def _smooth(x: np.ndarray, y: np.ndarray, name: str) -> Outline:
    return Outline(validate_polyline(np.column_stack([x, y]), name))


def ellipse(a: float, b: float) -> Outline:
    """Ellipse with semi-axes ``a`` (x) and ``b`` (y), m, centred at the origin."""
    _positive(a=a, b=b)
    t = np.linspace(0.0, 2 * np.pi, DENSE, endpoint=False)
    return _smooth(a * pm.cos(t), b * pm.sin(t), ShapeType.ELLIPSE)


def disk(radius: float) -> Outline:
    """Circle of ``radius`` m centred at the origin."""
    return ellipse(radius, radius)


def superellipse(a: float, b: float, exponent: float) -> Outline:
    """Rounded rectangle |x/a|^p + |y/b|^p = 1 (p = ``exponent`` >= 2; large p -> sharp)."""
    _positive(a=a, b=b)
    if not exponent >= 2.0:
        raise InvalidInputError(f"superellipse.exponent must be >= 2, got {exponent}")
    t = np.linspace(0.0, 2 * np.pi, DENSE, endpoint=False)
    c, s = pm.cos(t), pm.sin(t)
    x = a * np.sign(c) * pm.power(np.abs(c), 2.0 / exponent)
    y = b * np.sign(s) * pm.power(np.abs(s), 2.0 / exponent)
    return _smooth(x, y, ShapeType.SUPERELLIPSE)


def fourier_blob(radius: float, cos: Sequence[float] = (), sin: Sequence[float] = ()) -> Outline:
    """Star-shaped blob r(t) = radius * (1 + sum_k cos[k-1] cos(k t) + sin[k-1] sin(k t)).

    Coefficients are relative (dimensionless); r(t) must stay positive.
    """
    _positive(radius=radius)
    t = np.linspace(0.0, 2 * np.pi, DENSE, endpoint=False)
    r = np.ones_like(t)
    for k, ck in enumerate(cos, start=1):
        r += ck * pm.cos(k * t)
    for k, sk in enumerate(sin, start=1):
        r += sk * pm.sin(k * t)
    if np.min(r) <= 0.05:
        raise InvalidInputError("fourier_blob coefficients make the radius vanish; reduce them")
    return _smooth(radius * r * pm.cos(t), radius * r * pm.sin(t), ShapeType.FOURIER_BLOB)


def _spline_curve(points: Sequence[Sequence[float]], name: str) -> np.ndarray:
    """Dense samples of the closed periodic cubic spline through ``points`` (m)."""
    p = validate_polyline(points, name)
    closed = np.vstack([p, p[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    cs = CubicSpline(s, closed, bc_type="periodic")
    return validate_polyline(cs(np.linspace(0.0, s[-1], DENSE, endpoint=False)), name)


def _corner_indices(corners: Sequence[int], n: int) -> np.ndarray:
    """Validated, sorted, distinct corner vertex indices of an ``n``-point spline."""
    idx = np.asarray(corners, dtype=float).ravel()
    if idx.size and (np.any(idx != np.round(idx)) or idx.min() < 0 or idx.max() >= n):
        raise InvalidInputError(f"spline.corners must be indices of spline.points (integers "
                                f"0 to {n - 1}), got {idx.tolist()}")
    idx = idx.astype(int)
    if len(np.unique(idx)) != len(idx):
        raise InvalidInputError(f"spline.corners must be distinct, got {idx.tolist()}")
    return np.sort(idx)


def _cornered_curve(points: Sequence[Sequence[float]], corners: np.ndarray,
                    name: str) -> tuple[np.ndarray, np.ndarray]:
    """Dense samples of the closed curve through ``points`` whose ``corners`` are kept as
    corners: between two consecutive corners a cubic spline by chord length (not-a-knot; a
    straight segment between adjacent corners), sampled about as densely as :data:`DENSE`
    samples the whole curve. Returns the samples and the corners' indices among them.
    """
    validate_polyline(points, name)
    p = np.asarray(points, dtype=float)
    n = len(p)
    closed = np.linalg.norm(np.diff(np.vstack([p, p[:1]]), axis=0), axis=1).sum()
    pieces, out_corners, count = [], [], 0
    for k, start in enumerate(corners):
        end = corners[(k + 1) % len(corners)] + (n if k + 1 == len(corners) else 0)
        stretch = p[np.arange(start, end + 1) % n]
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(stretch, axis=0),
                                                            axis=1))])
        if s[-1] == 0.0:
            raise InvalidInputError(f"{name}: corners {start} and {end % n} are the same point")
        samples = max(1, int(np.ceil(DENSE * s[-1] / closed)))
        t = np.linspace(0.0, s[-1], samples, endpoint=False)
        if len(stretch) == 2:
            piece = stretch[0] + np.outer(t / s[-1], stretch[1] - stretch[0])
        else:
            piece = CubicSpline(s, stretch, bc_type="not-a-knot" if len(stretch) > 3
                                else "natural")(t)
        out_corners.append(count)
        pieces.append(piece)
        count += len(piece)
    dense, kept = np.vstack(pieces), np.array(out_corners, dtype=int)
    if signed_area(dense) < 0:  # clockwise points: the outline runs the other way
        dense, kept = dense[::-1], np.sort(len(dense) - 1 - kept)
    out = validate_polyline(dense, name)
    if len(out) != len(dense):
        raise InvalidInputError(f"{name} has repeated consecutive points")
    return out, kept


def spline(points: Sequence[Sequence[float]],
           holes: Sequence[Sequence[Sequence[float]]] = (),
           corners: Sequence[int] = ()) -> Outline:
    """Closed periodic cubic spline through the user's ``points`` (m), by chord length, with
    optional ``holes`` (each a list of [x, y], m), smooth splines too, strictly inside it.

    ``corners`` (indices into ``points``) declares vertices where the outer curve may turn
    sharply (a mixed outline: straight edges with real corners and curved stretches, a D shape
    or a rounded rectangle): the curve is then a not-a-knot cubic spline by chord length from
    one corner to the next (straight between adjacent corners), and the corners are kept as
    mesh corners (:attr:`Outline.corners`).

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    >>> ring = spline(np.c_[np.cos(t), np.sin(t)], holes=[0.5 * np.c_[np.cos(t), np.sin(t)]])
    >>> round(ring.area / (0.75 * np.pi), 3), len(ring.corners)
    (1.0, 0)
    >>> a = np.linspace(-np.pi / 2, np.pi / 2, 9)
    >>> d = spline(np.c_[np.cos(a), np.sin(a)], corners=[0, 8])  # a half disk: a D
    >>> round(d.area / (np.pi / 2), 3), len(d.corners)
    (1.0, 2)
    """
    corner = _corner_indices(corners, len(points))
    if len(corner):
        outer, kept = _cornered_curve(points, corner, ShapeType.SPLINE)
    else:
        outer, kept = _spline_curve(points, ShapeType.SPLINE), np.zeros(0, dtype=int)
    inner = tuple(_spline_curve(h, f"spline.holes[{k}]") for k, h in enumerate(holes))
    _check_holes(outer, inner, ShapeType.SPLINE.value)
    return Outline(outer, inner, kept)


def annulus(outer_radius: float, inner_radius: float) -> Outline:
    """Solid ring (disk with a concentric circular hole), radii in m."""
    _positive(outer_radius=outer_radius, inner_radius=inner_radius)
    if not inner_radius < outer_radius:
        raise InvalidInputError("annulus.inner_radius must be smaller than outer_radius")
    hole = disk(inner_radius).points
    return Outline(disk(outer_radius).points, holes=(hole,))


MAX_OUTLINE_POINTS = 100_000
"""Vertices an outline file may have at most."""


def _csv_points(text: str, name: str) -> list[list[float]]:
    """``x,y`` rows of a CSV outline (``#`` comments and blank lines skipped)."""
    pts = []
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        cells = line.split(",")
        try:
            if len(cells) != 2:
                raise ValueError
            pts.append([float(cells[0]), float(cells[1])])
        except ValueError:
            raise InvalidInputError(f"{name}: line {number} is not 'x,y' (two numbers, "
                                 "metres)") from None
        if len(pts) > MAX_OUTLINE_POINTS:
            raise InvalidInputError(f"{name}: more than {MAX_OUTLINE_POINTS} points")
    return pts


def _is_coordinate(value) -> bool:
    """A JSON number that is a finite float (no bool, no integer beyond the float range)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return bool(np.isfinite(float(value)))
    except OverflowError:
        return False


def load_outline(path: str | Path) -> Outline:
    """Read an outline from CSV (``x,y`` per line, m) or JSON (``{"outline": [[x, y], ...]}``,
    optionally ``"holes": [[[x, y], ...], ...]``, as ``squeeze-grasp outline`` writes it).

    The points are the vertices of a polygon; vertices where it turns by more than 20 degrees
    are kept as corners when the outline is resampled. The file is read up to
    :data:`~squeeze_grasp_ros.inputs.MAX_FILE_BYTES` and errors never quote its contents.
    """
    path = Path(path)
    name = f"outline file {path.name}"
    try:
        text = read_text(path, what="outline")
    except InputError as exc:
        raise InvalidInputError(str(exc)) from None
    if path.suffix.lower() == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InvalidInputError(f"{name}: invalid JSON at line {exc.lineno}, column "
                                 f"{exc.colno}") from None
        except RecursionError:
            raise InvalidInputError(f"{name}: JSON nested too deeply") from None
        except ValueError:  # an integer of more than 4,300 digits
            raise InvalidInputError(f"{name}: JSON holds a number too long to read") from None
        if not isinstance(data, dict) or "outline" not in data:
            raise InvalidInputError(f'{name}: JSON outline must be {{"outline": [[x, y], ...]}}')
        pts = data["outline"]
        if not isinstance(pts, list) or len(pts) > MAX_OUTLINE_POINTS or not all(
                isinstance(q, list) and len(q) == 2 and all(map(_is_coordinate, q))
                for q in pts):
            raise InvalidInputError(f"{name}: 'outline' must be a list of at most "
                                 f"{MAX_OUTLINE_POINTS} [x, y] pairs of finite numbers (m)")
        holes = data.get("holes", [])
        if not isinstance(holes, list) or not all(
                isinstance(h, list) and all(isinstance(q, list) and len(q) == 2
                                            and all(map(_is_coordinate, q)) for q in h)
                for h in holes) or sum(map(len, holes)) > MAX_OUTLINE_POINTS:
            raise InvalidInputError(f"{name}: 'holes' must be a list of polygons, each a list "
                                    "of [x, y] pairs of finite numbers (m)")
    else:
        pts, holes = _csv_points(text, name), []
    p = validate_polyline(pts, name)
    with_holes = polygon(p, holes) if holes else Outline(p)
    return Outline(p, with_holes.holes, corners=_turning_corners(p))


def _pieces(
    p: np.ndarray, spacing: float, corners: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Arc-length positions s (N+1,) of the closed polyline ``p``, the anchors (kept vertices,
    plus the first again one loop later) and the number of parts of each piece between them.
    """
    keep = np.union1d(_turning_corners(p), [] if corners is None else corners).astype(int)
    closed = np.vstack([p, p[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    anchors = s[keep] if len(keep) else np.array([0.0])
    anchors = np.append(anchors, anchors[0] + s[-1])
    parts = np.maximum(1, np.round(np.diff(anchors) / spacing)).astype(int)
    return s, anchors, parts


def resampled_count(
    outline_points: np.ndarray, spacing: float, corners: np.ndarray | None = None
) -> int:
    """Number of vertices :func:`resample` gives, computed without making them."""
    return int(_pieces(np.asarray(outline_points, dtype=float), spacing, corners)[2].sum())


def resample(
    outline_points: np.ndarray, spacing: float, corners: np.ndarray | None = None
) -> np.ndarray:
    """Evenly spaced vertices (about ``spacing`` m apart) along a closed polyline.

    Vertices listed in ``corners`` (and sharp turns) are kept exactly; each piece between two
    kept vertices is split into equal arc-length parts (so no edge is longer than 1.5 spacing).
    """
    p = np.asarray(outline_points, dtype=float)
    s, anchors, parts = _pieces(p, spacing, corners)
    closed = np.vstack([p, p[:1]])
    samples = [s0 + (s1 - s0) * np.arange(k) / k
               for s0, s1, k in zip(anchors[:-1], anchors[1:], parts)]
    t = np.mod(np.concatenate(samples), s[-1])
    x = np.interp(t, s, closed[:, 0])
    y = np.interp(t, s, closed[:, 1])
    out = np.column_stack([x, y])
    if len(out) < 3:
        raise InvalidInputError(f"spacing {spacing} m is too coarse for this outline")
    return out


def _positive(**values: float) -> None:
    for name, value in values.items():
        if not (np.isfinite(value) and value > 0):
            raise InvalidInputError(f"{name} must be a positive length in m, got {value}")
