# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Root location: which event functions crossed zero in a substep, and where the first did.

A function that changes sign in a substep [a, b] is located to a bracket of depth width <=
``event_tol`` * L: one with slopes at both ends on its cubic Hermite interpolants (2-3
evaluations per event; 1-2 where evaluations are dear and those whose outcome is sure are
skipped: :func:`surely_positive`), the others by a safeguarded Illinois (regula falsi)
iteration (:func:`locate_sign_change`). :func:`earliest_crossing` takes the crossings in the
order of their interpolated roots; one still positive at the start of the earliest bracket
needs no location of its own. The earliest bracket end wins, so the state at an event has the
condition just met; it lands about a quarter tolerance past the root, never on it, where
functions crossing at the same point would have round-off signs.

Everything here is a function of its arguments: the functions are given as callables of
(key, s), so it is tested on known functions as well as on the stepper's.
"""
from __future__ import annotations

from collections.abc import Callable, Collection, Mapping

import numpy as np

from squeeze_grasp_ros.mechanics.errors import NumericalError
from squeeze_grasp_ros.mechanics.squeeze.event_key import EventKey
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import WatchedValues

__all__ = ["MAX_ROOT_ITERATIONS", "SURE_MARGIN", "crossings", "dips_inside",
           "earliest_crossing", "hermite_curvature", "hermite_dips", "hermite_root",
           "locate_sign_change", "surely_positive"]

MAX_ROOT_ITERATIONS = 200

Values = Mapping[EventKey, float]
"""Event-function values (or slopes d/ds) by key, at one point."""


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


def hermite_curvature(a: float, b: float, ga: float, gb: float, ra: float, rb: float) -> float:
    """Largest |d^2/ds^2| on [a, b] of the cubic Hermite interpolant (values ga, gb and slopes
    ra, rb at a, b): its second derivative is linear, so the larger of its end values.

    >>> hermite_curvature(0.0, 2.0, 0.0, 4.0, 0.0, 4.0)  # s^2
    2.0
    """
    h = b - a
    c3, c2, _, _ = _hermite_coefficients(ga, gb, ra, rb, h)
    return float(max(abs(2 * c2), abs(6 * c3 + 2 * c2)) / (h * h))


SURE_MARGIN = 0.2
"""A sign is certain from a Taylor model when the model's value clears zero by this fraction of
the change its slope makes over the step, after the curvature bound: for a gap about 1e-10 L at
the default 1e-9 L event tolerance, far above the round-off of a converged evaluation (with and
without the skips, the neo-Hookean foam square's event depths agree to 4e-16 L)."""


def surely_positive(g: float, r: float, h: float, curvature: float) -> bool:
    """Whether a function with value ``g`` and slope ``r`` at s is surely > 0 at s - h (h > 0),
    given ``curvature``, an estimate of the size of its second derivative: the first-order
    Taylor model g - h r, less twice the remainder that curvature gives (curvature h^2 / 2),
    clears zero by SURE_MARGIN h |r|.

    Event location asks this of the point that would close a bracket from below: the exact
    value and slope at the bracket's end b a quarter tolerance past the root, the point half a
    tolerance back, whose evaluation it can then skip.

    >>> surely_positive(-0.25e-9, -1.0, 0.49e-9, 1.0)  # root 0.25e-9 back: 0.24e-9 to spare
    True
    >>> surely_positive(-0.45e-9, -1.0, 0.49e-9, 1.0)  # 0.04e-9: not sure
    False
    """
    return g - h * r - curvature * h * h > SURE_MARGIN * h * abs(r)


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
    gb: float, tol: float, slopes: tuple[float, float] | None = None, *,
    skip_sure: bool = False,
) -> tuple[float, float, int]:
    """Bracket [a, b] of width <= tol around the first sign change (ga > 0 >= gb).

    Without ``slopes``, Illinois regula falsi; with the slopes (ra, rb) at a and b, ``g``
    returns (value, slope) and each new point is the root of the cubic Hermite interpolant on
    the bracket (fourth-order accurate: a smooth function needs two or three evaluations),
    moved tol / 4 past it, so that the bracket closes with its end b a quarter of the tolerance
    beyond the root rather than on it, where the signs of other functions that cross at the
    same point would be round-off. A point is kept 0.49 tol inside the bracket, so a converged
    estimate closes it from the other side, and every third point bisects a bracket that did
    not halve. With slopes and ``skip_sure`` (evaluations are dear), a point that would close
    the bracket from below (within tol of b) is not evaluated when the exact value and slope at
    b make its sign certain (:func:`surely_positive`, the curvature taken from the Hermite
    interpolant of the first bracket): the bracket closes as that evaluation would have closed
    it, so an event located on its first point costs one evaluation instead of two. Returns
    (a, b, evaluations).

    cos s = 1/2 on [0, 2] (root pi/3): 9 evaluations without slopes, 4 with them, 3 skipping
    the sure one (the same bracket).

    >>> from math import cos, sin, pi
    >>> locate_sign_change(lambda s: cos(s) - 0.5, 0.0, 2.0, 0.5, cos(2) - 0.5, 1e-9)[2]
    9
    >>> a, b, n = locate_sign_change(lambda s: (cos(s) - 0.5, -sin(s)), 0.0, 2.0, 0.5,
    ...                              cos(2) - 0.5, 1e-9, slopes=(0.0, -sin(2)))
    >>> a < pi / 3 <= b, b - a <= 1e-9, n
    (True, True, 4)
    >>> locate_sign_change(lambda s: (cos(s) - 0.5, -sin(s)), 0.0, 2.0, 0.5, cos(2) - 0.5,
    ...                    1e-9, slopes=(0.0, -sin(2)), skip_sure=True) == (a, b, 3)
    True
    """
    evaluations, retained, width = 0, 0, b - a
    ra, rb = slopes if slopes is not None else (0.0, 0.0)
    sure = slopes is not None and skip_sure and b - a > tol
    curvature = hermite_curvature(a, b, ga, gb, ra, rb) if sure else 0.0
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
        if sure and b - c <= tol and surely_positive(gb, rb, b - c, curvature):
            a = c  # the point would close the bracket from below: its sign is certain
            break
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



def crossings(start: Values, end: Values, fresh: Collection[EventKey]) -> list[EventKey]:
    """Keys whose function went from > 0 (or zero by construction: ``fresh``) at the start of
    a substep to <= 0 at its end, in the order of ``end``.

    Two :class:`~.functions.WatchedValues` with the same keys (a substep's ends) are compared
    as arrays: only the functions not positive at the end are looked at one by one.
    """
    out = []
    if (isinstance(start, WatchedValues) and isinstance(end, WatchedValues)
            and start.order is end.order):
        keys, a = start.order.keys, start.values
        for k in np.flatnonzero(~(end.values > 0)).tolist():
            key = keys[k]
            if a[k] > 0 or key.at_node in fresh:
                out.append(key)
        start, end = start.ends, end.ends
    for key, value in end.items():
        if value > 0 or key not in start:
            continue
        if start[key] > 0 or key.at_node in fresh:
            out.append(key)
    return out


def dips_inside(a: float, b: float, start: Values, end: Values, start_slopes: Values,
                end_slopes: Values, fresh: Collection[EventKey]) -> bool:
    """Whether a function with slopes, positive at both ends of [a, b] (and not zero by
    construction at a: ``fresh``), goes to zero inside on its cubic Hermite interpolant.

    Two :class:`~.functions.WatchedValues` with the same keys (a substep's ends) are read as
    arrays at the sloped keys' positions.
    """
    sloped = [key for key in end_slopes if key in start_slopes]
    position = (start.order.position if isinstance(start, WatchedValues)
                and isinstance(end, WatchedValues) and start.order is end.order else {})
    at = [position.get(key) for key in sloped]
    if sloped and None not in at:
        ga, gb = start.values[at], end.values[at]
        keep = (ga > 0) & (gb > 0)
        if fresh:
            keep &= np.array([key.at_node not in fresh for key in sloped])
        ra = np.array([start_slopes[key] for key in sloped])
        rb = np.array([end_slopes[key] for key in sloped])
        return bool(hermite_dips(a, b, ga[keep], gb[keep], ra[keep], rb[keep]).any())
    keys = [key for key in sloped if key in start and key in end and start[key] > 0
            and end[key] > 0 and (not fresh or key.at_node not in fresh)]
    return bool(hermite_dips(a, b, *(np.array([v[key] for key in keys])
                                     for v in (start, end, start_slopes, end_slopes))).any())


def _estimate(key: EventKey, a: float, b: float, start: Values, end: Values,
              start_slopes: Values, end_slopes: Values) -> float:
    """Where ``key``'s function crosses zero in [a, b]: its Hermite root, else the secant's."""
    ga, gb = start[key], end[key]
    if key in start_slopes and key in end_slopes and ga > 0:
        root = hermite_root(a, b, ga, gb, start_slopes[key], end_slopes[key])
        if root is not None:
            return root
    return b if not ga > gb else a + (b - a) * ga / (ga - gb)


def _later(key: EventKey, hi: float, lo: float, a: float, b: float, start: Values, end: Values,
           start_slopes: Values, end_slopes: Values, value: Callable[[EventKey, float], float],
           slope: Callable[[EventKey, float], float]) -> bool:
    """Whether ``key``'s function is surely still > 0 at ``lo``, the start of the earliest
    bracket [lo, hi] (it then crosses no earlier, and needs no location of its own), from its
    exact value and slope at the event point ``hi`` and the curvature of its Hermite
    interpolant on [a, b] (:func:`surely_positive`); False (not sure: evaluate at ``lo``) for
    a function without slopes.
    """
    if key not in start_slopes or key not in end_slopes:
        return False
    curvature = hermite_curvature(a, b, start[key], end[key], start_slopes[key],
                                  end_slopes[key])
    return surely_positive(value(key, hi), slope(key, hi), hi - lo, curvature)


def earliest_crossing(
    crossed: list[EventKey], a: float, b: float, tol: float, *, start: Values, end: Values,
    start_slopes: Values, end_slopes: Values, fresh: Collection[EventKey],
    value: Callable[[EventKey, float], float], slope: Callable[[EventKey, float], float],
    order: Callable[[EventKey], tuple], skip_sure: bool = False,
) -> tuple[float, int]:
    """Bracket the first zero of the ``crossed`` functions in [a, b]; (its end, evaluations).

    Parameters
    ----------
    crossed : list of EventKey
        Functions > 0 at a (or zero there by construction: ``fresh``) and <= 0 at b.
    a, b, tol : float
        The substep and the bracket width wanted.
    start, end : mapping
        Values of (at least) the crossed functions at a and b.
    start_slopes, end_slopes : mapping
        Slopes d/ds at a and b of the functions that have them.
    fresh : collection of EventKey
        Functions zero by construction at a (:attr:`.EventKey.at_node` form): located from
        a + tol, where their sign is that of their slope.
    value, slope : callable
        (key, s) -> the function's value or slope at s.
    order : callable
        Key -> processing order; breaks ties between brackets that end at the same s.
    skip_sure : bool
        Evaluations are dear: skip those whose outcome the exact values and slopes already
        known make certain (:func:`surely_positive`): the closing point of a bracket
        (:func:`locate_sign_change`) and, for a function crossed later than the earliest
        bracket, its value at that bracket's start (from its value and slope at the event
        point). The brackets are those the evaluations would have given.

    Returns
    -------
    (float, int)
        The end of the earliest bracket (the event point) and the evaluations of ``value``
        spent locating (a value with its slope counts once).
    """
    best, evaluations = None, 0

    def estimate(key: EventKey) -> float:
        return _estimate(key, a, b, start, end, start_slopes, end_slopes)

    for key in sorted(crossed, key=estimate):
        hi_end, g_hi, r_hi = b, end[key], end_slopes.get(key)
        if best is not None:
            lo_best = best[-1]
            if lo_best <= a or skip_sure and _later(key, best[0], lo_best, a, b, start, end,
                                                    start_slopes, end_slopes, value, slope):
                continue
            g_hi = value(key, lo_best)
            if g_hi > 0:
                continue
            hi_end = lo_best
            r_hi = slope(key, lo_best) if key in end_slopes else None
        sloped = key in start_slopes and r_hi is not None

        def g(s: float, key: EventKey = key, sloped: bool = sloped):
            g_s = value(key, s)
            return (g_s, slope(key, s)) if sloped else g_s

        lo, glo, r_lo = a, start[key], start_slopes.get(key)
        if key.at_node in fresh or not glo > 0:
            lo = min(a + tol, hi_end)
            glo = g(lo)
            if sloped:
                glo, r_lo = glo
            evaluations += 1
        if glo <= 0:
            hi = lo
        else:
            lo, hi, n = locate_sign_change(g, lo, hi_end, glo, g_hi, tol,
                                           slopes=(r_lo, r_hi) if sloped else None,
                                           skip_sure=skip_sure)
            evaluations += n
        rank = (hi, *order(key), lo)
        best = rank if best is None or rank < best else best
    return best[0], evaluations
