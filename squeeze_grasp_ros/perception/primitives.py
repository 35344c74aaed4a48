# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Circles, ellipses and rings recognised in a seen outline (issue 32, item 2).

A traced curve that a circle or an ellipse fits within a tolerance is that primitive: its
outline is the fitted curve, sampled finely enough that the chords stay within the
simplification tolerance, and smooth (no vertex is a corner). An outer circle with one circular
hole whose centre lies within the tolerance of the outer one is an ``annulus``. The fits are
scikit-image's ``CircleModel`` (its estimate, :func:`fit_circle`) and ``EllipseModel`` (algebraic
fits; the residuals judged are the
geometric point-to-curve distances of every traced point: the circle's in closed form, the
ellipse's by :func:`ellipse_distances`, vectorised, where scikit-image's ``residuals`` runs one
``scipy.optimize.leastsq`` per point, 30 ms for the 490 points of a square at 1 mm a pixel).

>>> t = np.linspace(0, 2 * np.pi, 90, endpoint=False)
>>> ring = recognise(np.c_[0.1 + 0.05 * np.cos(t), 0.05 * np.sin(t)],
...                  [np.c_[0.1 + 0.02 * np.cos(t), 0.02 * np.sin(t)]], tolerance=1e-4)
>>> ring.shape.value, [round(v, 6) for v in ring.parameters.values()]
('annulus', [0.05, 0.02])
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from squeeze_grasp_ros.mechanics.vocabulary import ShapeType
from squeeze_grasp_ros.perception.simplify import vector_lengths

__all__ = ["Primitive", "ellipse_distance_bound", "ellipse_distances", "fit_circle", "fit_loop",
           "fitted_model", "recognise", "sampled", "scene_shape"]

CIRCLE_OVER_ELLIPSE = 1e-3
"""An ellipse whose axes differ by less than this fraction is reported as a circle."""


@dataclass(frozen=True)
class Primitive:
    """A primitive recognised in one closed curve, or in an outline (outer curve and holes).

    Attributes
    ----------
    shape : ShapeType
        ``disk``, ``ellipse`` or (an outline) ``annulus``.
    centre : (2,) ndarray
        Centre, m.
    parameters : dict of str to float
        The scene shape's parameters, m (``radius``; ``a``, ``b``; ``outer_radius``,
        ``inner_radius``), and ``theta`` (rad, the ``a`` axis from x) for an ellipse.
    residual_m : float
        Largest distance of a traced point from the fitted curve(s), m.
    """

    shape: ShapeType
    centre: np.ndarray
    parameters: dict[str, float] = field(default_factory=dict)
    residual_m: float = 0.0

    def to_json(self) -> dict:
        """The primitive as JSON values (m, rad)."""
        return {"type": self.shape.value, "centre": [float(c) for c in self.centre],
                **{k: float(v) for k, v in self.parameters.items()},
                "residual_m": float(self.residual_m)}


def fit_circle(points: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Centre (2,) and radius of the circle fitted to ``points`` (n, 2), or None when they
    cannot tell one (all at one point, or collinear).

    scikit-image's ``CircleModel`` estimate, step for step (the algebraic fit of Jekel on data
    centred and scaled to unit spread, least squares on [2x, 2y, 1] -> x^2 + y^2, the radius the
    RMS distance to the centre) and so to the bit, without its per-call checks (half its time:
    the corner rebuild fits a hundred stretches of a noisy depth outline).
    """
    origin = points.mean(axis=0)
    data = points - origin
    scale = data.std()
    if not scale >= np.finfo(float).tiny:
        return None
    data /= scale
    design = np.append(data * 2, np.ones((len(data), 1)), axis=1)
    solution, _, rank, _ = np.linalg.lstsq(design, np.sum(data ** 2, axis=1), rcond=None)
    if rank != 3:
        return None
    centre = solution[:2]
    radius = np.sqrt(np.mean(np.sqrt(np.sum((centre - data) ** 2, axis=-1)) ** 2))
    return centre * scale + origin, float(radius * scale)


def fitted_model(kind, points: np.ndarray):
    """A scikit-image model fitted to ``points``, or None when the fit fails."""
    if hasattr(kind, "from_estimate"):  # scikit-image >= 0.26
        model = kind.from_estimate(points)
        return model if model else None
    model = kind()
    return model if model.estimate(points) else None


def fit_loop(points: np.ndarray, tolerance: float) -> Primitive | None:
    """The circle, else the ellipse, that fits closed curve ``points`` (n, 2) with every point
    within ``tolerance`` (m) of it; None when neither does.
    """
    from skimage.measure import EllipseModel

    p = np.asarray(points, float)
    circle = fit_circle(p)
    if circle is not None and np.all(np.isfinite(circle[0])):
        worst = float(np.abs(circle[1] - vector_lengths(p - circle[0])).max())
        if worst <= tolerance:
            return Primitive(ShapeType.DISK, circle[0], {"radius": circle[1]}, worst)
    ellipse = fitted_model(EllipseModel, p)
    if ellipse is None or not np.all(np.isfinite(ellipse.center)):
        return None
    a, b = (float(v) for v in ellipse.axis_lengths)
    theta = float(ellipse.theta)
    if ellipse_distance_bound(p, np.asarray(ellipse.center, float), a, b, theta) > tolerance:
        return None  # a point lies farther than that: the exact distances are not needed
    worst = float(ellipse_distances(p, np.asarray(ellipse.center, float), a, b, theta).max())
    if not worst <= tolerance:  # NaN (a degenerate fit) is no ellipse either
        return None
    if b > a:
        a, b, theta = b, a, theta + 0.5 * np.pi
    theta = (theta + 0.5 * np.pi) % np.pi - 0.5 * np.pi
    if a - b <= CIRCLE_OVER_ELLIPSE * a:
        return Primitive(ShapeType.DISK, np.asarray(ellipse.center, float),
                         {"radius": 0.5 * (a + b)}, worst)
    return Primitive(ShapeType.ELLIPSE, np.asarray(ellipse.center, float),
                     {"a": a, "b": b, "theta": theta}, worst)


def ellipse_distance_bound(points: np.ndarray, centre: np.ndarray, a: float, b: float,
                           theta: float) -> float:
    """A lower bound on the largest distance of ``points`` (n, 2) from the ellipse of
    :func:`ellipse_distances` (units of the points), from the ellipse's implicit norm alone.

    The norm f(x) = |(x_a / a, x_b / b)| of a point's ellipse-frame coordinates is 1 on the
    ellipse and changes by at most 1 / min(a, b) per unit length, so a point where it is f lies
    at least min(a, b) |f - 1| from the ellipse. A curve that is no ellipse (a square's corners
    stand 0.2 of its half side outside the fitted one) is refused from this at the cost of one
    pass over the points, without :func:`ellipse_distances`' bisection.

    >>> p = np.array([[3.0, 0.0], [0.0, 0.25]])  # 1 and 0.75 from the ellipse
    >>> ellipse_distance_bound(p, np.zeros(2), 2.0, 1.0, 0.0)
    0.75
    """
    along_a, along_b = _ellipse_frame(points, centre, theta)
    with np.errstate(divide="ignore", invalid="ignore"):  # a degenerate fit: NaN, no bound
        norm = np.hypot(along_a / a, along_b / b)
        return float(min(a, b) * np.abs(norm - 1.0).max(initial=0.0))


def _ellipse_frame(points: np.ndarray, centre: np.ndarray, theta: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates of ``points`` (n, 2) along the ellipse's ``a`` axis (at ``theta`` rad from
    x) and its ``b`` axis, from ``centre`` (units of the points).
    """
    c, s = np.cos(theta), np.sin(theta)
    d = np.asarray(points, float) - centre
    return c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]


ROOT_BISECTIONS = 160
"""Bisection steps of :func:`ellipse_distances` (each halves the bracket of every point's root;
the loop stops when no bracket shrinks any more, well before this for doubles)."""


def ellipse_distances(points: np.ndarray, centre: np.ndarray, a: float, b: float,
                      theta: float) -> np.ndarray:
    """Distance of each of ``points`` (n, 2) to the ellipse of semi-axes ``a``, ``b`` (the
    ``a`` axis at ``theta`` rad from x) centred at ``centre`` (units of the points).

    Eberly's robust method ("Distance from a point to an ellipse, an ellipsoid, or a
    hyperellipsoid", Geometric Tools, 2013): in the ellipse's frame, folded into the first
    quadrant, the nearest point's Lagrange multiplier is the one root of a monotone function on
    a known bracket, found by bisection for all points at once (bisecting 1 + the multiplier,
    which keeps its relative precision for points near the long axis). Exact to rounding (it
    matches scikit-image's per-point ``leastsq`` to 1e-9 relative), including points at the
    centre and on the axes.

    >>> ellipse_distances(np.array([[3.0, 0.0], [0.0, 0.0], [0.0, 2.5]]), np.zeros(2), 2.0,
    ...                   1.0, 0.0).round(12).tolist()
    [1.0, 1.0, 1.5]
    """
    y = np.abs(np.column_stack(_ellipse_frame(points, centre, theta)))
    if b > a:  # the long axis first
        a, b, y = b, a, y[:, ::-1]
    y0, y1 = y[:, 0], y[:, 1]
    z0, z1 = y0 / a, y1 / b
    g = z0 * z0 + z1 * z1 - 1.0
    r1 = (a * a - b * b) / (b * b)  # (a / b)^2 - 1
    n0 = (r1 + 1.0) * z0
    # the root u = s + 1 of (n0 / (u + r1))^2 + (z1 / u)^2 = 1, bracketed in [z1, |(n0, z1)|]
    # (or [z1, 1] inside): bisecting u rather than s keeps its relative precision near the axis
    lo = z1
    hi = np.where(g < 0.0, 1.0, np.maximum(np.hypot(n0, z1), z1))
    with np.errstate(divide="ignore", invalid="ignore"):  # points on an axis: replaced below
        for _ in range(ROOT_BISECTIONS):
            mid = 0.5 * (lo + hi)
            if not np.any((mid != lo) & (mid != hi)):
                break
            above = (n0 / (mid + r1)) ** 2 + (z1 / mid) ** 2 > 1.0
            lo = np.where(above, mid, lo)
            hi = np.where(above, hi, mid)
        u = 0.5 * (lo + hi)
        general = np.hypot(y0 * (1.0 - (r1 + 1.0) / (u + r1)), y1 * (1.0 - 1.0 / u))
        # on the long axis (y1 = 0): the nearest point is off the axis when y0 is inside the
        # evolute's cusp, else the vertex
        inside = a * y0 < a * a - b * b
        x0 = np.where(inside, a * a * y0 / (a * a - b * b), a)
        axis = np.where(inside, np.hypot(x0 - y0, b * np.sqrt(np.clip(1.0 - (x0 / a) ** 2, 0.0,
                                                                       None))),
                        np.abs(y0 - a))
    out = np.where(y1 > 0.0, np.where(y0 > 0.0, general, np.abs(y1 - b)), axis)
    return np.where((y1 > 0.0) & (y0 > 0.0) & (g == 0.0), 0.0, out)


def recognise(outer: np.ndarray, holes: list[np.ndarray], tolerance: float) -> Primitive | None:
    """The primitive of a traced outline (outer curve and holes, m): a ``disk`` or ``ellipse``
    without holes, an ``annulus`` for a circle with one concentric circular hole (centres
    within ``tolerance``, m); None otherwise (a hole off centre, or not circular, leaves the
    outline unrecognised).
    """
    if len(holes) > 1:
        return None
    out = fit_loop(outer, tolerance)
    if out is None or not holes:
        return out
    hole = fit_loop(holes[0], tolerance)
    if (out.shape != ShapeType.DISK or hole is None or hole.shape != ShapeType.DISK
            or np.linalg.norm(out.centre - hole.centre) > tolerance):
        return None
    radius, inner = out.parameters["radius"], hole.parameters["radius"]
    centre = (out.centre * radius + hole.centre * inner) / (radius + inner)
    return Primitive(ShapeType.ANNULUS, centre, {"outer_radius": radius, "inner_radius": inner},
                     max(out.residual_m, hole.residual_m))


def _ellipse_points(centre: np.ndarray, a: float, b: float, theta: float,
                    tolerance: float) -> np.ndarray:
    """Counter-clockwise samples of an ellipse whose chords stray at most ``tolerance``."""
    step = 2.0 * np.arccos(max(1.0 - tolerance / max(a, b), -1.0))  # sagitta of the arc
    n = max(16, int(np.ceil(2.0 * np.pi / step)))
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    c, s = np.cos(theta), np.sin(theta)
    x, y = a * np.cos(t), b * np.sin(t)
    return np.column_stack([centre[0] + c * x - s * y, centre[1] + s * x + c * y])


CHORD_FRACTION = 0.125
"""The fitted curve's chords stray at most this fraction of the simplification tolerance: the
polygon through the samples then loses at most 2/3 of that times the perimeter in area (0.03 %
for the foam ring's outer circle seen at 1 mm a pixel)."""


def sampled(primitive: Primitive, tolerance: float) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    """The primitive's outer curve and holes, sampled counter-clockwise on the curve with
    chords within :data:`CHORD_FRACTION` of ``tolerance`` (m) of it.
    """
    p, c = primitive.parameters, primitive.centre
    tolerance = CHORD_FRACTION * tolerance
    if primitive.shape == ShapeType.ANNULUS:
        return (_ellipse_points(c, p["outer_radius"], p["outer_radius"], 0.0, tolerance),
                (_ellipse_points(c, p["inner_radius"], p["inner_radius"], 0.0, tolerance),))
    if primitive.shape == ShapeType.DISK:
        return _ellipse_points(c, p["radius"], p["radius"], 0.0, tolerance), ()
    return _ellipse_points(c, p["a"], p["b"], p["theta"], tolerance), ()


def scene_shape(primitive: Primitive, tolerance: float) -> dict | None:
    """The primitive as a scene's named ``object.shape`` (centred at the frame's origin), when
    its centre lies within ``tolerance`` (m) of the origin and an ellipse's axes lie along x and
    y to within ``tolerance`` at their ends; None otherwise (the named shapes have no centre or
    angle).
    """
    if np.linalg.norm(primitive.centre) > tolerance:
        return None
    p = primitive.parameters
    if primitive.shape != ShapeType.ELLIPSE:
        return {"type": primitive.shape.value, **p}
    off = abs(p["theta"]) * p["a"]  # distance of the a axis' end from the x axis
    if off <= tolerance:
        return {"type": ShapeType.ELLIPSE.value, "a": p["a"], "b": p["b"]}
    if abs(0.5 * np.pi - abs(p["theta"])) * p["a"] <= tolerance:
        return {"type": ShapeType.ELLIPSE.value, "a": p["b"], "b": p["a"]}
    return None
