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

__all__ = ["EventValues", "MAX_ROOT_ITERATIONS", "event_values", "locate_sign_change",
           "mode_violations", "pickup_margin"]

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


def locate_sign_change(
    g: Callable[[float], float], a: float, b: float, ga: float, gb: float, tol: float
) -> tuple[float, float, int]:
    """Bracket [a, b] of width <= tol around the first sign change (ga > 0 >= gb).

    Illinois regula falsi with a bisection safeguard; returns (a, b, evaluations).
    """
    evaluations, retained, width = 0, 0, b - a
    while b - a > tol:
        if evaluations >= MAX_ROOT_ITERATIONS:
            raise NumericalError(
                f"event location did not converge in {evaluations} evaluations",
                residuals={"bracket": b - a, "tolerance": tol},
            )
        if evaluations % 3 == 2 and b - a > 0.5 * width:
            c = 0.5 * (a + b)
        else:
            c = (a * gb - b * ga) / (gb - ga) if gb != ga else 0.5 * (a + b)
        c = min(max(c, a + 0.49 * tol), b - 0.49 * tol)
        if evaluations % 3 == 2:
            width = b - a
        gc = g(c)
        evaluations += 1
        if gc > 0:
            a, ga = c, gc
            if retained == 1:
                gb *= 0.5
            retained = 1
        else:
            b, gb = c, gc
            if retained == -1:
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
