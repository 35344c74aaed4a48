# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Fingertip shapes behind one formula: the paper's circle and a flat pad with rounded edges.

A tip is rigid and only translates with its finger (it never rotates). Its face is the set of
points at distance rho from a flat segment of half-width a, centred on the tip's reference
point o and perpendicular to its facing direction e(theta0) (from the tip into the object):

- a circle of radius r (the paper's fingertip, Sec. 5, Fig. 5): a = 0, rho = r; o is its
  centre and theta0 plays no part in the geometry;
- a pad of width w whose edges are rounded with radius r_e (a gripper jaw): a = w/2 - r_e,
  rho = r_e; the flat face is 2a wide and o lies rho behind its middle.

**Contact coordinate.** A point of the face is named by q (rad): with u = q - theta0 and
c = clip(u, -a/rho, a/rho),

    normal angle   nu(q) = q - c                       (the contact normal is e(nu), into
                                                        the object)
    point          x(q)  = o + rho (c t(theta0) + e(nu))
    along the face dx/dq = rho t(nu)                   (|dx/dq| = rho everywhere)
    curvature      kappa(q) = d nu / dq                (1 on the rounded parts, 0 on the flat)

For a circle q is the paper's polar angle about the centre (nu = q, kappa = 1). On a pad's
flat, rho (q - theta0) is the distance from the middle of the face, and the normal does not
turn while a contact slides (kappa = 0): the friction cone of a sliding node stays where it
is. Everything the stepper needs (gaps, their slopes, the coordinate of a new contact, the
fixed-set solve's positions, normals and their derivatives) comes from these functions, which
reduce to the circle's formulas bit for bit when a = 0.

**Gap.** The signed distance of a point x outside the face is |w| - rho with
w = rel - clip(rel . t(theta0), -a, a) t(theta0), rel = x - o: the distance to a convex set,
continuously differentiable, with gradient w / |w|.

e(theta) = (cos, sin), t(theta) = (-sin, cos).

>>> pad = TipShape.pad(width=0.02, edge_radius=0.002)
>>> pad.half_flat, TipShape.pad(width=0.004, edge_radius=0.002).half_flat
(0.008, 0.0)
>>> tips = TipGeometry.of([pad], facing=[np.pi / 2])
>>> tips.gaps(np.array([[0.005, 0.003], [0.01, 0.0]]), np.zeros((1, 2))).round(6).tolist()
[[0.001], [0.0]]
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import TipKind

__all__ = ["MAX_TIP_SIZE", "TipGeometry", "TipShape", "cross", "tangent", "unit"]

MAX_TIP_SIZE = 1e3
"""Largest tip radius and pad width, m. A circle's gap to the object is computed from its
centre, so its round-off grows with the radius (about 1e-16 of it): at 1e10 m it is a
micrometre, far above the event tolerance, and the foam square's events changed with the
radius (A 71 B 33 at 1e6 m, A 67 B 19 at 1e10 m); from about 1e20 m the squeeze ended in
"grasp health ... must be finite" with numpy warnings. A flat pad is the shape for a large
flat face."""


def unit(theta) -> np.ndarray:
    """e(theta) = (cos, sin) stacked on the last axis, (..., 2).

    >>> unit([0.0, np.pi / 2]).round(12).tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """
    theta = np.asarray(theta, float)
    out = np.empty(theta.shape + (2,))
    np.cos(theta, out=out[..., 0])
    np.sin(theta, out=out[..., 1])
    return out


def tangent(theta) -> np.ndarray:
    """t(theta) = (-sin, cos) stacked on the last axis, (..., 2)."""
    theta = np.asarray(theta, float)
    out = np.empty(theta.shape + (2,))
    np.negative(np.sin(theta), out=out[..., 0])
    np.cos(theta, out=out[..., 1])
    return out


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """2-D cross product a_x b_y - a_y b_x over the last axis."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


@dataclass(frozen=True)
class TipShape:
    """The shape of one fingertip, as a scene or a gripper declares it (SI).

    Attributes
    ----------
    kind : TipKind
        ``circle`` or ``pad``.
    radius : float
        Circle radius, or the pad's edge radius r_e, m (> 0, at most :data:`MAX_TIP_SIZE`; a
        circle of radius 0 is a point finger, which only the stable and pure squeezes take).
    width : float
        The pad's whole width w, m (in [2 r_e, :data:`MAX_TIP_SIZE`]; the flat face is
        w - 2 r_e wide); 0 for a circle.
    """

    kind: TipKind
    radius: float
    width: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "kind", TipKind(self.kind))
        if not (np.isfinite(self.radius) and 0 <= self.radius <= MAX_TIP_SIZE):
            raise InvalidInputError(f"tip radius must be finite and in [0, {MAX_TIP_SIZE:g}] m, "
                                    f"got {self.radius}")
        if self.kind == TipKind.CIRCLE:
            if self.width != 0.0:
                raise InvalidInputError(f"a circular tip has no width, got {self.width} m")
            return
        if not self.radius > 0:
            raise InvalidInputError(f"tip.edge_radius must be > 0 m, got {self.radius}")
        if not (np.isfinite(self.width) and 2.0 * self.radius <= self.width <= MAX_TIP_SIZE):
            raise InvalidInputError(
                f"tip.width must be in [2 tip.edge_radius, {MAX_TIP_SIZE:g}] m "
                f"([{2.0 * self.radius:g}, {MAX_TIP_SIZE:g}] m), got {self.width} m")

    @classmethod
    def circle(cls, radius: float) -> TipShape:
        """A circle of ``radius`` (m)."""
        return cls(TipKind.CIRCLE, float(radius))

    @classmethod
    def pad(cls, *, width: float, edge_radius: float) -> TipShape:
        """A flat pad ``width`` wide (m) with edges rounded to ``edge_radius`` (m)."""
        return cls(TipKind.PAD, float(edge_radius), float(width))

    @property
    def half_flat(self) -> float:
        """Half the width of the flat face, a = w/2 - r_e, m (0 for a circle)."""
        return max(0.5 * self.width - self.radius, 0.0) if self.kind == TipKind.PAD else 0.0

    def to_json(self) -> dict:
        """``{"shape": "circle", "radius"}`` or ``{"shape": "pad", "width", "edge_radius"}``
        (m), the scene's ``fingers.F?.tip`` entry.
        """
        if self.kind == TipKind.CIRCLE:
            return {"shape": self.kind.value, "radius": self.radius}
        return {"shape": self.kind.value, "width": self.width, "edge_radius": self.radius}

    def clearance(self, points: np.ndarray, centers: np.ndarray, facing) -> np.ndarray:
        """How far (k, p) each of k tips, at reference points ``centers`` (k, 2) and facing
        e(``facing``) (k,), can advance along its facing before its face reaches each of
        ``points`` (p, 2), m; +inf for points beside the tip's swath (|lateral| >= a + rho).

        The face's front at lateral offset l lies sqrt(rho^2 - max(|l| - a, 0)^2) ahead of the
        reference point, so a tip first touches the point of least clearance.
        """
        facing = np.asarray(facing, float)
        rel = points[None, :, :] - np.asarray(centers, float)[:, None, :]
        ahead = np.einsum("kpi,ki->kp", rel, unit(facing))
        beside = np.abs(np.einsum("kpi,ki->kp", rel, tangent(facing))) - self.half_flat
        front = np.sqrt(np.maximum(self.radius ** 2 - np.maximum(beside, 0.0) ** 2, 0.0))
        return np.where(beside < self.radius, ahead - front, np.inf)

    def outline(self, center, facing: float, points: int = 90) -> np.ndarray:
        """Points (k, 2) of the tip's face about ``center`` (m) facing ``facing`` (rad), for
        pictures: the whole circle, or the pad's front (flat and rounded edges) closed by its
        back.
        """
        tips = TipGeometry.of([self], [facing])
        h = self.half_flat / self.radius if self.radius > 0 else 0.0
        span = np.pi if self.kind == TipKind.CIRCLE else 0.5 * np.pi + h
        q = facing + np.linspace(-span, span, points)
        front = np.asarray(center, float) + tips.offset(q, np.zeros(points, int))
        return np.vstack([front, front[:1]])


@dataclass(frozen=True)
class TipGeometry:
    """k placed tips (or one tip per contact node), vectorised; any consistent length unit.

    Attributes
    ----------
    radius : (k,) ndarray
        rho: the circle radius or the pad's edge radius.
    flat : (k,) ndarray
        a: half the width of the flat face (0 for a circle).
    facing : (k,) ndarray
        theta0: angle of the facing direction e(theta0), rad (the middle of the face is at
        q = theta0).
    """

    radius: np.ndarray
    flat: np.ndarray
    facing: np.ndarray

    @classmethod
    def of(cls, shapes: Sequence[TipShape], facing: Sequence[float]) -> TipGeometry:
        """The geometry of ``shapes`` facing ``facing`` (rad), m."""
        return cls(np.array([s.radius for s in shapes], float),
                   np.array([s.half_flat for s in shapes], float), np.asarray(facing, float))

    def take(self, index: np.ndarray) -> TipGeometry:
        """The tips at ``index`` (e.g. each contact node's finger)."""
        return TipGeometry(self.radius[index], self.flat[index], self.facing[index])

    def scaled(self, length: float) -> TipGeometry:
        """The same tips with lengths divided by ``length``."""
        return TipGeometry(self.radius / length, self.flat / length, self.facing)

    def _clip(self, q: np.ndarray, index: np.ndarray | None) -> np.ndarray:
        """The clipped coordinate c = clip(q - theta0, -a/rho, a/rho) per point (tips by
        ``index``, default one each).
        """
        t = self if index is None else self.take(index)
        h = t.flat / t.radius
        return np.clip(np.asarray(q, float) - t.facing, -h, h)

    def normal_angle(self, q: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        """nu(q): the angle of the contact normal e(nu) at coordinates ``q`` (rad)."""
        return np.asarray(q, float) - self._clip(q, index)

    def curvature(self, q: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        """kappa(q) = d nu / d q: 1 on a circle or a rounded edge, 0 on a flat face."""
        t = self if index is None else self.take(index)
        u = np.abs(np.asarray(q, float) - t.facing)
        return np.where((t.flat > 0) & (u <= t.flat / t.radius), 0.0, 1.0)

    def offset(self, q: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        """x(q) - o: the face point at coordinates ``q`` relative to its tip's reference point,
        (m, 2).
        """
        t = self if index is None else self.take(index)
        c = self._clip(q, index)
        nu = np.asarray(q, float) - c
        return t.radius[:, None] * (c[:, None] * t._facing_tangent + unit(nu))

    @cached_property
    def _facing_tangent(self) -> np.ndarray:
        """t(theta0) (k, 2) of every tip (the gaps ask for it at every substep)."""
        return tangent(self.facing)

    def _closest(self, rel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(w, tau) for points ``rel`` (..., k, 2) relative to each tip's reference point:
        w = rel - tau t(theta0), tau = clip(rel . t(theta0), -a, a).
        """
        t0 = self._facing_tangent
        tau = np.clip(np.einsum("...ki,ki->...k", rel, t0), -self.flat, self.flat)
        return rel - tau[..., None] * t0, tau

    def gaps(self, points: np.ndarray, centers: np.ndarray) -> np.ndarray:
        """Signed distances (p, k) of ``points`` (p, 2) outside the k tips at reference points
        ``centers`` (k, 2); negative values are penetrations.
        """
        w, _ = self._closest(points[:, None, :] - centers[None, :, :])
        return np.sqrt((w * w).sum(axis=-1)) - self.radius[None, :]  # np.linalg.norm's sums

    def gap_slopes(self, points: np.ndarray, velocities: np.ndarray, centers: np.ndarray,
                   center_rates: np.ndarray) -> np.ndarray:
        """Rates (p, k) of the gaps of ``points`` moving with ``velocities`` (p, 2) to tips
        moving with ``center_rates`` (k, 2).
        """
        w, _ = self._closest(points[:, None, :] - centers[None])
        rel_rate = velocities[:, None, :] - center_rates[None]
        return np.einsum("rfi,rfi->rf", w, rel_rate) / np.linalg.norm(w, axis=2)

    def coordinate(self, rel: np.ndarray, tip: int, near: float | None = None) -> float:
        """The coordinate q of the face point closest to ``rel`` (2,) (relative to tip ``tip``'s
        reference point), its normal angle taken within pi of ``near``'s (another coordinate
        on the same tip, to keep a segment unwrapped; default the facing direction).
        """
        one = self.take(np.array([tip]))
        w, tau = one._closest(np.asarray(rel, float)[None])
        nu = float(np.arctan2(w[0, 1], w[0, 0]))
        ref = (float(one.facing[0]) if near is None
               else float(one.normal_angle(np.array([near]))[0]))
        nu = ref + float(np.angle(np.exp(1j * (nu - ref))))
        return nu + float(tau[0]) / float(one.radius[0])
