# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Least-squares similarity matching of corresponding planar point sets (paper App. C).

Given simulated points P = {p_i} and measured points Q = {q_i} (same count and order), find
the scale s, rotation theta and translation t = (t_x, t_y) that applied to Q minimise

    E = sum_i || p_i - (s R(theta) q_i + t) ||^2                       (eqs. 72-73)

in closed form. With p_i = (x_i, y_i), q_i = (u_i, v_i) and the means

    (c1, ..., c10) = mean(x, y, u, v, x u, x v, y u, y v, u^2, v^2),   D = c9 + c10 - c3^2 - c4^2,

the minimiser is (eqs. 82-85; the text extraction of eq. 84 lost its square root)

    t_x   = (c4 (c7 - c6) - c3 (c5 + c8) + c1 (c9 + c10)) / D
    t_y   = (c2 (c9 + c10) - c4 (c5 + c8) - c3 (c7 - c6)) / D
    s     = sqrt((c1 c3 + c2 c4 - (c5 + c8))^2 + (c1 c4 - c2 c3 + (c7 - c6))^2) / D
    theta = atan2(c7 - c6 + c1 c4 - c2 c3, c5 + c8 - (c1 c3 + c2 c4)).

The paper derives these assuming c3^2 + c4^2 != 0 and shows that the special case
c3 = c4 = 0 (measured points centred at the origin) gives the same expressions, reduced to
t = (c1, c2), s = sqrt((c7 - c6)^2 + (c5 + c8)^2) / (c9 + c10), theta = atan2(c7 - c6, c5 + c8);
so one formula serves both. D > 0 unless all measured points coincide. Units: P and Q in m,
t in m (the frame of P), theta in rad, s dimensionless.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite

MAX_COORDINATE = 1e6
"""Largest coordinate magnitude of a matched point, m: the closed form's second moments
(u^2, x u) overflow beyond about 1e154 m (points at 1e308 m were matched with scale inf and
a NaN error, exit 0); a kilometre-sized lab is far inside."""


def _require_points(name: str, points: np.ndarray) -> None:
    """Refuse points (n, 2), m, that are not finite, lie beyond :data:`MAX_COORDINATE` or
    coincide (their spread D = mean(u^2 + v^2) - |mean(q)|^2 is 0 to round-off).

    Parameters
    ----------
    name : str
        ``simulated`` or ``measured``, as the message names them.
    points : (n, 2) ndarray
        The points, m.
    """
    require_finite(f"{name} points", points)
    largest = float(np.abs(points).max())
    if largest > MAX_COORDINATE:
        raise InvalidInputError(f"{name} points must lie within {MAX_COORDINATE:g} m of the "
                                f"origin (coordinates in m), got a coordinate of {largest:g}")
    u, v = points[:, 0], points[:, 1]
    second = np.mean(u * u) + np.mean(v * v)
    if not second - (np.mean(u) ** 2 + np.mean(v) ** 2) > 1e-30 * max(second, 1e-300):
        raise InvalidInputError(f"the {name} points coincide: the similarity transform is "
                                "undefined")


@dataclass(frozen=True)
class Match:
    """A similarity transform from the measured frame to the simulated one.

    Attributes
    ----------
    scale : float
        s (dimensionless).
    rotation : float
        theta, rad (counter-clockwise).
    translation : (2,) ndarray
        t, m.
    matched : (n, 2) ndarray
        s R q_i + t: the measured points in the simulated frame, m.
    errors : (n,) ndarray
        ||p_i - (s R q_i + t)||, m.
    """

    scale: float
    rotation: float
    translation: np.ndarray
    matched: np.ndarray
    errors: np.ndarray

    @property
    def mean_error(self) -> float:
        """Mean error per node, m (the paper reports 1.3 mm for Table 1)."""
        return float(self.errors.mean())

    @property
    def rms_error(self) -> float:
        """sqrt(E / n), m."""
        return float(np.sqrt(np.mean(self.errors ** 2)))

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Map points (k, 2) from the measured frame to the simulated frame."""
        c, s = np.cos(self.rotation), np.sin(self.rotation)
        R = np.array([[c, -s], [s, c]])
        return self.scale * np.asarray(points, float) @ R.T + self.translation

    def to_json(self) -> dict:
        """``{"scale", "rotation", "rotation_deg", "translation", "mean_error", "rms_error",
        "max_error", "errors"}``.
        """
        return {"scale": self.scale, "rotation": self.rotation,
                "rotation_deg": float(np.degrees(self.rotation)),
                "translation": self.translation.tolist(), "mean_error": self.mean_error,
                "rms_error": self.rms_error, "max_error": float(self.errors.max()),
                "errors": self.errors.tolist()}


def match_similarity(simulated, measured) -> Match:
    """Closed-form least-squares similarity transform of ``measured`` onto ``simulated``.

    Parameters
    ----------
    simulated, measured : (n, 2) array_like
        Corresponding points P and Q, m, n >= 2.

    Raises
    ------
    InvalidInputError
        For mismatched shapes, fewer than two points, non-finite input, a coordinate beyond
        :data:`MAX_COORDINATE`, or coincident simulated or measured points (D = 0: with
        coincident simulated points the transform was scale 0 and every error 0).

    Examples
    --------
    Measured points that are the simulated ones scaled by 1/2, turned by -0.3 rad and shifted:

    >>> p = np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.05], [0.08, 0.07]])
    >>> c, s = np.cos(-0.3), np.sin(-0.3)
    >>> q = 0.5 * p @ np.array([[c, -s], [s, c]]).T + [0.2, -0.1]
    >>> m = match_similarity(p, q)
    >>> print(f"scale {m.scale:.4f}, rotation {m.rotation:.4f} rad", bool(m.errors.max() < 1e-12))
    scale 2.0000, rotation 0.3000 rad True
    """
    P = np.asarray(simulated, float)
    Q = np.asarray(measured, float)
    if P.ndim != 2 or P.shape[1] != 2 or P.shape != Q.shape:
        raise InvalidInputError(f"simulated and measured points must both be (n, 2) arrays of the "
                             f"same n, got {P.shape} and {Q.shape}")
    if len(P) < 2:
        raise InvalidInputError(f"matching needs at least 2 corresponding points, got {len(P)}")
    _require_points("simulated", P)
    _require_points("measured", Q)
    x, y = P[:, 0], P[:, 1]
    u, v = Q[:, 0], Q[:, 1]
    c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = (
        np.mean(a) for a in (x, y, u, v, x * u, x * v, y * u, y * v, u * u, v * v))
    D = c9 + c10 - (c3 * c3 + c4 * c4)
    tx = (c4 * (c7 - c6) - c3 * (c5 + c8) + c1 * (c9 + c10)) / D
    ty = (c2 * (c9 + c10) - c4 * (c5 + c8) - c3 * (c7 - c6)) / D
    s = np.hypot(c1 * c3 + c2 * c4 - (c5 + c8), c1 * c4 - c2 * c3 + (c7 - c6)) / D
    theta = np.arctan2(c7 - c6 + c1 * c4 - c2 * c3, c5 + c8 - (c1 * c3 + c2 * c4))
    partial = Match(float(s), float(theta), np.array([tx, ty]), np.zeros((0, 2)), np.zeros(0))
    matched = partial.apply(Q)
    return Match(partial.scale, partial.rotation, partial.translation, matched,
                 np.linalg.norm(P - matched, axis=1))
