# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""How far an observed outline is from the predicted deformed boundary (App. C, live).

The predicted boundary's nodes P and the observed outline (a polygon, no correspondence) are
matched by iterating closest points: each node is paired with its closest point on the observed
curve, App. C's closed-form least-squares similarity (:func:`~squeeze_grasp_ros.mechanics.
calibration.matching.match_similarity`, eqs. 72-85) maps the observed pairs onto the nodes,
and the pairing is redone on the moved curve until the mean squared distance stops falling.
The residual is then each node's distance to the moved observed curve (point to curve, m), and
its reverse (each observed vertex to the predicted polygon) catches what the prediction lacks.

Pairing points with points lets them slide along the curve, which converges slowly; so App. C's
similarity gives the coarse alignment and the rounds then minimise the distances of the nodes to
the tangent lines at their closest points (point to line, linearised: a few rounds). With
``ShapeFit.RIGID`` the scale stays 1 (a calibrated camera knows it) and only the point-to-line
rounds run; with ``ShapeFit.NONE`` the curves are compared where they are.

A predicted boundary of 40 nodes, seen 10 % larger and shifted by 1 cm:

>>> from squeeze_grasp_ros.mechanics.elastic.shapes import ellipse, resample
>>> nodes = Outline(resample(ellipse(0.05, 0.03).points, 0.006))
>>> seen = Outline(nodes.points * 1.1 + [0.01, 0.0])
>>> match = shape_residual(seen, nodes)
>>> print(f"{len(nodes.points)} nodes: scale {match.scale:.4f}, residual below 1 um:",
...       match.max_m < 1e-6)
43 nodes: scale 0.9091, residual below 1 um: True
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.calibration.matching import match_similarity
from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite
from squeeze_grasp_ros.mechanics.vocabulary import ShapeFit

__all__ = ["ShapeMatch", "closest_on_curves", "deformed_outline", "shape_residual"]

SETTLED = 1e-9
"""Relative fall of the mean squared distance below which the closest-point rounds stop."""

CHUNK = 2048
"""Points per block of the brute-force closest-point search (bounds its memory)."""


@dataclass(frozen=True)
class ShapeMatch:
    """An observed outline matched to a predicted boundary.

    Attributes
    ----------
    fit : ShapeFit
    scale : float
        s of the transform that maps the observed curve onto the prediction.
    rotation : float
        theta, rad.
    translation : (2,) ndarray
        t, m.
    distances : (n,) ndarray
        Each predicted node's distance to the moved observed curve, m.
    reverse_max_m : float
        Largest distance of a moved observed vertex to the predicted polygon, m.
    iterations : int
        Closest-point rounds taken.
    converged : bool
        Whether the mean squared distance settled (relative fall below :data:`SETTLED`) within
        the allowed rounds.
    """

    fit: ShapeFit
    scale: float
    rotation: float
    translation: np.ndarray
    distances: np.ndarray
    reverse_max_m: float
    iterations: int
    converged: bool

    @property
    def rms_m(self) -> float:
        """Root mean square of the point-to-curve distances, m."""
        return float(np.sqrt(np.mean(self.distances ** 2)))

    @property
    def max_m(self) -> float:
        """Largest point-to-curve distance, m."""
        return float(self.distances.max())

    def to_json(self) -> dict:
        """``{"fit", "scale", "rotation", "translation", "rms_m", "max_m", "reverse_max_m",
        "iterations", "converged"}``.
        """
        return {"fit": str(self.fit), "scale": self.scale, "rotation": self.rotation,
                "translation": self.translation.tolist(), "rms_m": self.rms_m,
                "max_m": self.max_m, "reverse_max_m": self.reverse_max_m,
                "iterations": self.iterations, "converged": self.converged}


def deformed_outline(mesh: Mesh, displacement: np.ndarray) -> Outline:
    """The deformed boundary of ``mesh`` under nodal ``displacement`` (n, 2), m: the outer
    boundary nodes and each hole's loop, moved.

    Examples
    --------
    >>> from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
    >>> from squeeze_grasp_ros.mechanics.elastic.shapes import annulus
    >>> mesh = generate_mesh(annulus(0.05, 0.02), 2e-5)
    >>> stretched = deformed_outline(mesh, 0.01 * mesh.nodes)  # 1 % larger everywhere
    >>> print(f"{stretched.area / deformed_outline(mesh, 0 * mesh.nodes).area:.4f}")
    1.0201
    """
    displacement = np.asarray(displacement, float)
    if displacement.size != mesh.nodes.size:
        raise InvalidInputError(f"displacement must be (n, 2) with n = {mesh.n} nodes (or its "
                                f"{2 * mesh.n} entries flat), got shape {displacement.shape}")
    moved = mesh.nodes + displacement.reshape(-1, 2)
    require_finite("displacement", moved)
    return Outline(moved[mesh.boundary], tuple(moved[loop] for loop in mesh.inner_boundaries))


def _loops(outline: Outline) -> list[np.ndarray]:
    return [np.asarray(outline.points, float)] + [np.asarray(h, float) for h in outline.holes]


def closest_on_curves(points: np.ndarray, loops: list[np.ndarray]) -> tuple[np.ndarray, ...]:
    """Closest points (n, 2) on closed polylines ``loops`` to ``points`` (n, 2), their
    distances (n,) and the unit normals (n, 2) of the segments they lie on, by exact
    point-to-segment distances over every segment.
    """
    start = np.concatenate(loops)
    d = np.concatenate([np.roll(loop, -1, axis=0) for loop in loops]) - start
    length2 = np.maximum(d[:, 0] ** 2 + d[:, 1] ** 2, 1e-300)
    normal = np.column_stack([d[:, 1], -d[:, 0]]) / np.sqrt(length2)[:, None]
    best = np.empty((len(points), 2))
    dist = np.empty(len(points))
    side = np.empty((len(points), 2))
    for lo in range(0, len(points), CHUNK):
        px, py = points[lo:lo + CHUNK, :1], points[lo:lo + CHUNK, 1:]
        rx, ry = px - start[:, 0], py - start[:, 1]
        t = np.clip((rx * d[:, 0] + ry * d[:, 1]) / length2, 0.0, 1.0)
        gx, gy = rx - t * d[:, 0], ry - t * d[:, 1]
        gap = gx * gx + gy * gy
        k = np.argmin(gap, axis=1)
        rows = np.arange(len(k))
        tk = t[rows, k][:, None]
        best[lo:lo + CHUNK] = start[k] + tk * d[k]
        dist[lo:lo + CHUNK] = np.sqrt(gap[rows, k])
        side[lo:lo + CHUNK] = normal[k]
    return best, dist, side


def _line_step(P: np.ndarray, closest: np.ndarray, normals: np.ndarray, fit: ShapeFit):
    """Scale, rotation and translation of the small update that minimises the squared
    point-to-line distances sum (n_i . (P_i - (A q_i + dt)))^2 of the nodes to the tangent lines
    at their closest points q_i (linearised in the rotation; minimum-norm where a direction is
    unobservable, e.g. turning a circle).
    """
    n, q = normals, closest
    columns = [np.einsum("ij,ij->i", n, q), n[:, 1] * q[:, 0] - n[:, 0] * q[:, 1],
               n[:, 0], n[:, 1]]
    if fit == ShapeFit.RIGID:
        columns = columns[1:]
    x = np.linalg.lstsq(np.column_stack(columns), np.einsum("ij,ij->i", n, P - q),
                        rcond=1e-10)[0]
    if fit == ShapeFit.RIGID:
        return 1.0, float(x[0]), x[1:]
    alpha, beta = x[0], x[1]
    return float(np.hypot(1.0 + alpha, beta)), float(np.arctan2(beta, 1.0 + alpha)), x[2:]


def _move(points: np.ndarray, scale: float, rotation: float, translation: np.ndarray):
    c, s = np.cos(rotation), np.sin(rotation)
    return scale * points @ np.array([[c, s], [-s, c]]) + translation


def shape_residual(observed: Outline, predicted: Outline, *,
                   fit: ShapeFit | str = ShapeFit.SIMILARITY,
                   max_iterations: int = 50) -> ShapeMatch:
    """Match ``observed`` onto ``predicted`` and measure the point-to-curve residual.

    Parameters
    ----------
    observed : Outline
        The outline seen by the camera (e.g. :attr:`ObjectOutline.outline`), m.
    predicted : Outline
        The predicted deformed boundary (:func:`deformed_outline`), m; its vertices are the
        nodes whose distances are measured.
    fit : ShapeFit
        Transform fitted before measuring (similarity: App. C; rigid; none).
    max_iterations : int
        Most closest-point rounds.

    Raises
    ------
    InvalidInputError
        For an unknown fit, non-finite curves, fewer than 3 vertices on a curve, or
        ``max_iterations`` not an integer >= 1.
    """
    try:
        fit = ShapeFit(fit)
    except ValueError:
        raise InvalidInputError(f"fit must be one of {list(ShapeFit.values())}, got "
                                f"{fit!r}") from None
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, int) \
            or max_iterations < 1:
        raise InvalidInputError(f"max_iterations must be an integer >= 1, got "
                                f"{max_iterations!r}")
    seen, model = _loops(observed), _loops(predicted)
    for name, loops in (("observed outline", seen), ("predicted boundary", model)):
        for loop in loops:
            require_finite(name, loop)
            if loop.ndim != 2 or loop.shape[1] != 2 or len(loop) < 3:
                raise InvalidInputError(f"{name}: each curve needs at least 3 [x, y] vertices")
    P = np.concatenate(model)
    transform: tuple[float, float, np.ndarray] = (1.0, 0.0, np.zeros(2))
    if fit == ShapeFit.SIMILARITY:  # App. C on closest-point pairs: the coarse alignment
        closest, _, _ = closest_on_curves(P, seen)
        m = match_similarity(P, closest)
        transform = (m.scale, m.rotation, m.translation)
    previous, converged, rounds = np.inf, fit == ShapeFit.NONE, 0
    while not converged and rounds < max_iterations:
        rounds += 1
        closest, dist, normals = closest_on_curves(P, [_move(loop, *transform) for loop in seen])
        mean2 = float(np.mean(dist ** 2))
        if mean2 == 0.0 or (np.isfinite(previous) and previous - mean2 <= SETTLED * previous):
            converged = True
            break
        previous = mean2
        scale, rotation, translation = _line_step(P, closest, normals, fit)
        transform = (scale * transform[0], rotation + transform[1],
                     _move(transform[2], scale, rotation, translation))
    moved = [_move(loop, *transform) for loop in seen]
    _, dist, _ = closest_on_curves(P, moved)
    _, back, _ = closest_on_curves(np.concatenate(moved), model)
    return ShapeMatch(fit, float(transform[0]), float(transform[1]), np.asarray(transform[2]),
                      dist, float(back.max()), rounds, converged)
