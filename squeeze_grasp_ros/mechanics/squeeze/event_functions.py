# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The pure parts of the event-driven stepper: event functions, the mode test of a contact,
the pickup margin and the location of a sign change (paper Sec. 5.1-5.3).

Every function here is a function of its arguments (dimensionless arrays of one contact set);
:mod:`.stepper` keeps the mutable state of a run and calls them.

>>> import numpy as np
>>> values = event_values(mu=0.5, fn=np.array([1.0]), ft=np.array([0.2]), slip=np.array([0]),
...                       dtheta=np.zeros(1), radius=np.ones(1), rate=1.0, gaps=np.zeros((0, 2)))
>>> float(values.c_plus[0]), float(values.c_minus[0])
(0.7, 0.3)
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import NumericalError

__all__ = ["EventValues", "MAX_ROOT_ITERATIONS", "event_values", "hermite_dips",
           "hermite_root", "locate_sign_change", "mode_violations", "pickup_margin"]

MAX_ROOT_ITERATIONS = 200


def pickup_margin(
    mu: float,
    fn: np.ndarray,
    ft: np.ndarray,
    stick: np.ndarray,
    finger: np.ndarray,
    fingers: list[int],
    weight: float,
) -> float:
    """How far the grasp is from lifting the object, in force units (> 0: cannot lift yet).

    The object lies on a horizontal plane and is lifted out of it. A contact node with normal
    force f_n and in-plane tangential force f_t can supply at most
    c_k = sqrt(mu^2 f_n^2 - f_t^2) of vertical friction (Sec. 5.1); a sliding node (force on the
    cone edge) supplies none. The object is picked up when every finger with contacts can
    supply its share: min over those fingers of sum_k c_k >= w / (number of such fingers)
    (torque balance by friction assumed, as in the paper). Returns w / n_f - min_f sum_k c_k.
    """
    c = np.where(stick, np.sqrt(np.maximum(mu * mu * fn * fn - ft * ft, 0.0)), 0.0)
    totals = [c[finger == f].sum() for f in fingers]
    return float(weight / len(fingers) - min(totals))


def _hermite_coefficients(ga: float, gb: float, ra: float, rb: float, h: float) -> np.ndarray:
    """Coefficients (t^3, t^2, t, 1) of the cubic Hermite interpolant on t = (s - a) / h."""
    return np.array([2 * ga + h * ra - 2 * gb + h * rb, -3 * ga - 2 * h * ra + 3 * gb - h * rb,
                     h * ra, ga])


def hermite_root(a: float, b: float, ga: float, gb: float, ra: float, rb: float) -> float | None:
    """First root in (a, b) of the cubic that has values ga, gb and slopes ra, rb at a, b.

    >>> round(hermite_root(0.0, 2.0, 1.0, -3.0, -2.0, -2.0), 12)  # 1 - 2 s
    0.5
    >>> hermite_root(0.0, 1.0, 1.0, 1.0, -3.0, 3.0) is None  # dips to 0.25 only
    True
    >>> hermite_root(0.0, 1.0, 1.0, 1.0 + 5e-324, 5e-324, 0.0) is None  # constant to round-off
    True
    """
    c = _hermite_coefficients(ga, gb, ra, rb, b - a)
    # leading coefficients below 1e-14 of the largest only add roots beyond 1e14 (and overflow
    # np.roots when subnormal): the roots in (0, 1) are those of the rest
    lead = np.flatnonzero(np.abs(c) > 1e-14 * np.abs(c).max())
    t = np.roots(c[lead[0]:]) if len(lead) else np.zeros(0)
    t = np.sort(t[(np.abs(t.imag) < 1e-12) & (t.real > 0) & (t.real < 1)].real)
    return float(a + t[0] * (b - a)) if len(t) else None


def hermite_dips(a: float, b: float, ga, gb, ra, rb) -> np.ndarray:
    """Whether the cubic Hermite interpolant of each function (values ga, gb > 0 and slopes
    ra, rb at a, b; arrays) goes to or below zero inside (a, b): a double root (a node grazing
    a tip, a force touching zero and growing again) that the end values alone would miss.

    >>> hermite_dips(0.0, 1.0, [1.0, 1.0], [1.0, 1.0], [-3.0, -6.0], [3.0, 6.0])
    array([False,  True])
    """
    ga, gb, ra, rb = (np.asarray(x, float) for x in (ga, gb, ra, rb))
    c3, c2, c1, c0 = _hermite_coefficients(ga, gb, ra, rb, b - a)
    # stationary points: 3 c3 t^2 + 2 c2 t + c1 = 0
    qa, qb = 3 * c3, 2 * c2
    disc = np.maximum(qb * qb - 4 * qa * c1, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        roots = np.stack([(-qb + np.sqrt(disc)) / (2 * qa), (-qb - np.sqrt(disc)) / (2 * qa),
                          -c1 / qb])
    roots = np.where(np.isfinite(roots) & (roots > 0) & (roots < 1), roots, 0.0)
    low = ((c3 * roots + c2) * roots + c1) * roots + c0
    return np.any((low <= 0) & (roots > 0), axis=0)


def locate_sign_change(
    g: Callable[[float], float | tuple[float, float]], a: float, b: float, ga: float,
    gb: float, tol: float, slopes: tuple[float, float] | None = None,
) -> tuple[float, float, int]:
    """Bracket [a, b] of width <= tol around the first sign change (ga > 0 >= gb).

    Without ``slopes``, Illinois regula falsi; with the slopes (ra, rb) at a and b, ``g``
    returns (value, slope) and each new point is the root of the cubic Hermite interpolant on
    the bracket (fourth-order accurate: a smooth function needs two or three evaluations),
    moved tol / 4 past it, so that the bracket closes with its end b a quarter of the tolerance
    beyond the root rather than on it, where the signs of other functions that cross at the
    same point would be round-off. A point is kept 0.49 tol inside the bracket, so a converged
    estimate closes it from the other side, and every third point bisects a bracket that did
    not halve. Returns (a, b, evaluations).

    cos s = 1/2 on [0, 2] (root pi/3): 9 evaluations without slopes, 4 with them.

    >>> from math import cos, sin, pi
    >>> locate_sign_change(lambda s: cos(s) - 0.5, 0.0, 2.0, 0.5, cos(2) - 0.5, 1e-9)[2]
    9
    >>> a, b, n = locate_sign_change(lambda s: (cos(s) - 0.5, -sin(s)), 0.0, 2.0, 0.5,
    ...                              cos(2) - 0.5, 1e-9, slopes=(0.0, -sin(2)))
    >>> a < pi / 3 <= b, b - a <= 1e-9, n
    (True, True, 4)
    """
    evaluations, retained, width = 0, 0, b - a
    ra, rb = slopes if slopes is not None else (0.0, 0.0)
    while b - a > tol:
        if evaluations >= MAX_ROOT_ITERATIONS:
            raise NumericalError(
                f"event location did not converge in {evaluations} evaluations",
                residuals={"bracket": b - a, "tolerance": tol},
            )
        c = None
        if evaluations % 3 == 2 and b - a > 0.5 * width:
            c = 0.5 * (a + b)
        elif slopes is not None:
            c = hermite_root(a, b, ga, gb, ra, rb)
            c = None if c is None else c + 0.25 * tol
        if c is None:
            c = (a * gb - b * ga) / (gb - ga) if gb != ga else 0.5 * (a + b)
        c = min(max(c, a + 0.49 * tol), b - 0.49 * tol)
        if evaluations % 3 == 2:
            width = b - a
        gc = g(c)
        evaluations += 1
        if slopes is not None:
            gc, rc = gc
        if gc > 0:
            a, ga = c, gc
            if slopes is not None:
                ra = rc
            elif retained == 1:
                gb *= 0.5
            retained = 1
        else:
            b, gb = c, gc
            if slopes is not None:
                rb = rc
            elif retained == -1:
                ga *= 0.5
            retained = -1
    return a, b, evaluations


@dataclass(frozen=True)
class EventValues:
    """Event-function values at one solution (:mod:`.stepper`'s table).

    Attributes
    ----------
    fn : (m,) ndarray
        Normal forces (Event B at 0).
    c_plus, c_minus : (m,) ndarray
        Cone margins mu f_n + f_t and mu f_n - f_t (Event C at 0).
    d : (m,) ndarray
        Slip rates of sliding nodes along their slip direction (Event D at 0).
    gaps : (k, f) ndarray
        Gaps of free boundary nodes to every fingertip (Event A at 0).
    strain, pickup : float
        Termination margins (inf when not checked).
    area : float
        Smallest element area ratio det F less the inversion threshold (termination at 0; inf
        when not checked).
    """

    fn: np.ndarray
    c_plus: np.ndarray
    c_minus: np.ndarray
    d: np.ndarray
    gaps: np.ndarray
    strain: float
    pickup: float
    area: float = np.inf


def event_values(*, mu: float, fn: np.ndarray, ft: np.ndarray, slip: np.ndarray,
                 dtheta: np.ndarray, radius: np.ndarray, rate: float, gaps: np.ndarray,
                 strain: float = np.inf, pickup: float = np.inf,
                 area: float = np.inf) -> EventValues:
    """The event functions of one contact set at one solution.

    ``slip`` is each node's slip direction (0 when sticking), ``dtheta`` d theta/ds, ``radius``
    the tip radius of its finger, ``rate`` the length of the fingers' motion per unit s.
    """
    d = slip * dtheta * radius / (rate if rate > 0 else 1.0)
    return EventValues(fn, mu * fn + ft, mu * fn - ft, d, gaps, strain, pickup, area)


def mode_violations(*, mu: float, fn: float, ft: float, fn_rate: float, ft_rate: float,
                    dtheta: float, stick: bool, slip: int, frictionless: bool,
                    zero: set[str]) -> int:
    """Violated conditions of a mode hypothesis for one contact (0 = consistent).

    A function whose kind is in ``zero`` ("B", "C+", "C-": zero by construction now) must grow
    along the motion; any other must be positive. Stick: normal force and both cone margins;
    slip: normal force and slip rate of the assumed sign (Algorithm 1's hypothesis-and-test).
    """
    def ok(kind: str, value: float, rate: float) -> bool:
        return rate > 0 if kind in zero else value > 0

    bad = int(not ok("B", fn, fn_rate))
    if stick:
        bad += int(not ok("C+", mu * fn + ft, mu * fn_rate + ft_rate))
        bad += int(not ok("C-", mu * fn - ft, mu * fn_rate - ft_rate))
    elif not frictionless:
        bad += int(slip * dtheta <= 0)
    return bad
