# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event location of the linear model compiled by numba (the ``fast`` extra): the earliest
crossing of a substep in one call, with the fixed-set solve at each trial point inside.

:func:`earliest_crossing` runs :func:`~.stepper.location.earliest_crossing` for crossed
functions the kernel evaluates (a contact's normal force, cone margins and slip rate, a free
boundary row's gap, the pickup margin): the crossings in the order of their estimated roots,
each located by :func:`~.stepper.location.locate_sign_change` (the Hermite steps, Illinois for
a slip rate, the skips of ``skip_sure``), the trial points solved by continuation from the
nearest point solved so far (:class:`~.stepper.solving.SolvedPoints`, by
:func:`.fixed_set_numba.solve_linear`) and the functions valued there as the numpy code values
them (:mod:`.substeps_numba`'s arithmetic).
The roots of a Hermite cubic are the eigenvalues of numpy's companion matrix by the LAPACK
routine numpy's ``eigvals`` calls (dgeev), so every bracket, evaluation count and solution is
the Python location's. A solve that fails, or a location that does not converge, is reported
(``ok`` False) and the caller runs the Python location, which raises the error.
"""
from __future__ import annotations

import numba
import numpy as np
from numba import types
from numba.np.linalg import _LAPACK

from squeeze_grasp_ros.mechanics.squeeze.fixed_set_numba import SOLVED, solve_linear
from squeeze_grasp_ros.mechanics.squeeze.substeps_numba import _from_tip, _pickup

NORMAL_FORCE, CONE_PLUS, CONE_MINUS, SLIP_RATE, GAP, PICKUP = 0, 1, 2, 3, 4, 5
"""The functions the kernel values (a crossed key's ``kind``)."""
jit = numba.njit(cache=True, nogil=True)
_geev = _LAPACK().numba_ez_rgeev(types.float64)
_REAL, _NO_VECTORS = ord("d"), ord("N")


@jit
def _eigvals(A):
    """(real, imaginary parts) of the eigenvalues of A by dgeev, as ``np.linalg.eigvals``."""
    n = A.shape[0]
    work = np.asfortranarray(A)
    wr, wi = np.empty(n), np.empty(n)
    vl, vr = np.empty(1), np.empty(1)
    _geev(_REAL, _NO_VECTORS, _NO_VECTORS, n, work.ctypes, n, wr.ctypes, wi.ctypes, vl.ctypes,
          1, vr.ctypes, 1)
    return wr, wi


@jit
def _coefficients(ga, gb, ra, rb, h):
    """:func:`~.stepper.location._hermite_coefficients` (t^3, t^2, t, 1)."""
    c = np.empty(4)
    c[0] = 2 * ga + h * ra - 2 * gb + h * rb
    c[1] = -3 * ga - 2 * h * ra + 3 * gb - h * rb
    c[2] = h * ra
    c[3] = ga
    return c


@jit
def hermite_root(a, b, ga, gb, ra, rb):
    """:func:`~.stepper.location.hermite_root`; NaN for None (np.roots' companion matrix)."""
    c = _coefficients(ga, gb, ra, rb, b - a)
    big = 0.0
    for i in range(4):
        big = max(big, abs(c[i]))
    first = 4
    for i in range(4):
        if abs(c[i]) > 1e-14 * big:
            first = i
            break
    last = 3
    while last >= first and c[last] == 0.0:
        last -= 1
    best = np.inf
    if last < first:
        return np.nan
    n = last - first  # the degree; trailing zeros are roots at 0, outside (0, 1)
    if n > 0:
        A = np.zeros((n, n))
        for i in range(1, n):
            A[i, i - 1] = 1.0
        for j in range(n):
            A[0, j] = -c[first + 1 + j] / c[first]
        wr, wi = _eigvals(A)
        for i in range(n):
            if abs(wi[i]) < 1e-12 and wr[i] > 0 and wr[i] < 1 and wr[i] < best:
                best = wr[i]
    return a + best * (b - a) if best < np.inf else np.nan


@jit
def hermite_curvature(a, b, ga, gb, ra, rb):
    """:func:`~.stepper.location.hermite_curvature`."""
    h = b - a
    c = _coefficients(ga, gb, ra, rb, h)
    x, y = abs(2 * c[1]), abs(6 * c[0] + 2 * c[1])
    return (y if y > x else x) / (h * h)


@jit
def surely_positive(g, r, h, curvature, margin):
    """:func:`~.stepper.location.surely_positive` (``margin``: SURE_MARGIN)."""
    return g - h * r - curvature * h * h > margin * h * abs(r)


@jit
def _value(kind, k, key, p, s, pts, fun):
    """The value of crossed key ``key`` (``kind``, contact or finger ``k``) at solved point p
    (s), as the numpy code computes it (:meth:`~.stepper.functions.EventFunctions.value`).
    """
    _, _, delta, F, dtheta, _, _, nu, _, _, _, _ = pts
    (mu, slip, radius_c, rate, GA, GR, B0, E, origin, D, radius_f, flat_f, t0_f, stick,
     finger, fingers, weight) = fun
    if kind == PICKUP:
        m = nu.shape[1]
        fn, ft = np.empty(m), np.empty(m)
        for j in range(m):
            c, sn = np.cos(nu[p, j]), np.sin(nu[p, j])
            fn[j] = F[p, j, 0] * c + F[p, j, 1] * sn
            ft[j] = F[p, j, 0] * -sn + F[p, j, 1] * c
        return _pickup(mu, fn, ft, stick, finger, fingers, weight)
    if kind == GAP:
        g = np.dot(E.T, delta[p].ravel())
        u = np.dot(GA[key], F[p].ravel()) + np.dot(GR[key], g)
        x, y = B0[key, 0] + u[0], B0[key, 1] + u[1]
        wx, wy = _from_tip(x, y, origin + s * D, flat_f, t0_f, k)
        return np.sqrt(wx * wx + wy * wy) - radius_f[k]
    if kind == SLIP_RATE:
        return slip[k] * dtheta[p, k] * radius_c[k] / rate
    c, sn = np.cos(nu[p, k]), np.sin(nu[p, k])
    fn = F[p, k, 0] * c + F[p, k, 1] * sn
    ft = F[p, k, 0] * -sn + F[p, k, 1] * c
    if kind == NORMAL_FORCE:
        return fn
    return mu * fn + ft if kind == CONE_PLUS else mu * fn - ft


@jit
def _slope(kind, k, key, p, s, pts, fun):
    """The slope d/ds of crossed key ``key`` at solved point p (s), as
    :func:`.substeps_numba.slope_values` computes it (a function with a slope: not the
    pickup margin).
    """
    _, _, delta, F, dtheta, dF, ddelta, nu, kappa, _, _, _ = pts
    mu, _, _, _, GA, GR, B0, E, origin, D, _, flat_f, t0_f, _, _, _, _ = fun
    if kind == GAP:
        u = np.dot(GA[key], F[p].ravel()) + np.dot(GR[key], np.dot(E.T, delta[p].ravel()))
        v = np.dot(GA[key], dF[p].ravel()) + np.dot(GR[key], np.dot(E.T, ddelta[p].ravel()))
        x, y = B0[key, 0] + u[0], B0[key, 1] + u[1]
        wx, wy = _from_tip(x, y, origin + s * D, flat_f, t0_f, k)
        vx, vy = v[0] - D[k, 0], v[1] - D[k, 1]
        return (wx * vx + wy * vy) / np.sqrt(wx * wx + wy * wy)
    c, sn = np.cos(nu[p, k]), np.sin(nu[p, k])
    turn = kappa[p, k] * dtheta[p, k]
    fn = F[p, k, 0] * c + F[p, k, 1] * sn
    ft = F[p, k, 0] * -sn + F[p, k, 1] * c
    fn_r = (dF[p, k, 0] * c + dF[p, k, 1] * sn) + turn * ft
    ft_r = (dF[p, k, 0] * -sn + dF[p, k, 1] * c) - turn * fn
    if kind == NORMAL_FORCE:
        return fn_r
    return mu * fn_r + ft_r if kind == CONE_PLUS else mu * fn_r - ft_r


@jit
def _at(s, n, pts, prob):
    """(index of the solved point at s, points solved): the first point at s, else a new one
    solved by continuation from the nearest (:meth:`~.stepper.solving.SolvedPoints.at`);
    index -1 when the continuation fails or no room is left.
    """
    at, theta, delta, F, dtheta, dF, ddelta, nu, kappa, its, res, Js = pts
    (C, p0, stick, slip, phi, radius, flat, facing, finger, origin, D, newton_tol,
     max_iterations, backtracks, continuation_iterations, max_angle_jump) = prob
    near, distance = 0, abs(at[0] - s)
    for i in range(n):
        if at[i] == s:
            return i, n
        if abs(at[i] - s) < distance:
            near, distance = i, abs(at[i] - s)
    if n == at.shape[0]:
        return -1, n
    m = theta.shape[1]
    guess = theta[near] + dtheta[near] * (s - at[near])
    centers, dirs = np.empty((m, 2)), np.empty((m, 2))
    for k in range(m):
        f = finger[k]
        centers[k, 0], centers[k, 1] = origin[f, 0] + s * D[f, 0], origin[f, 1] + s * D[f, 1]
        dirs[k, 0], dirs[k, 1] = D[f, 0], D[f, 1]
    status, it, r, th, de, Fs, dth, dFs, dde, J, nu_s, kappa_s = solve_linear(
        C, p0, centers, dirs, guess, stick, slip, phi, radius, flat, facing, newton_tol,
        max_iterations, backtracks, newton_tol)
    if status != SOLVED or it > continuation_iterations or \
            np.abs(th - guess).max() > max_angle_jump:
        return -1, n
    at[n], theta[n], delta[n], F[n], dtheta[n], dF[n], ddelta[n] = s, th, de, Fs, dth, dFs, dde
    nu[n], kappa[n], its[n], res[n] = nu_s, kappa_s, it, r
    if J.shape[0]:
        Js[n] = J
    return n, n + 1


@jit
def _locate(kind, k, key, a, b, ga, gb, tol, sloped, ra, rb, skip_sure, settings, n, pts,
            fun, prob):
    """:func:`~.stepper.location.locate_sign_change` of crossed key ``key`` on [a, b] (its
    values, and slopes when ``sloped``, at the ends): (a, b, evaluations, points solved), the
    evaluations -1 when a solve fails or it does not converge.
    """
    margin, most = settings
    evaluations, retained, width = 0, 0, b - a
    sure = sloped and skip_sure and b - a > tol
    curvature = hermite_curvature(a, b, ga, gb, ra, rb) if sure else 0.0
    while b - a > tol:
        if evaluations >= most:
            return a, b, -1, n
        c = np.nan
        if evaluations % 3 == 2 and b - a > 0.5 * width:
            c = 0.5 * (a + b)
        elif sloped:
            c = hermite_root(a, b, ga, gb, ra, rb) + 0.25 * tol
        if np.isnan(c):
            c = (a * gb - b * ga) / (gb - ga) if gb != ga else 0.5 * (a + b)
        if a + 0.49 * tol > c:
            c = a + 0.49 * tol
        if b - 0.49 * tol < c:
            c = b - 0.49 * tol
        if evaluations % 3 == 2:
            width = b - a
        if sure and b - c <= tol and surely_positive(gb, rb, b - c, curvature, margin):
            a = c
            break
        p, n = _at(c, n, pts, prob)
        if p < 0:
            return a, b, -1, n
        gc = _value(kind, k, key, p, c, pts, fun)
        evaluations += 1
        if gc > 0:
            a, ga = c, gc
            if sloped:
                ra = _slope(kind, k, key, p, c, pts, fun)
            elif retained == 1:
                gb *= 0.5
            retained = 1
        else:
            b, gb = c, gc
            if sloped:
                rb = _slope(kind, k, key, p, c, pts, fun)
            elif retained == -1:
                ga *= 0.5
            retained = -1
    return a, b, evaluations, n


@jit
def _estimates(a, b, start, end, has_start, start_slopes, has_end, end_slopes):
    """:func:`~.stepper.location._estimate` of every crossed key."""
    out = np.empty(start.shape[0])
    for i in range(start.shape[0]):
        ga, gb = start[i], end[i]
        root = np.nan
        if has_start[i] and has_end[i] and ga > 0:
            root = hermite_root(a, b, ga, gb, start_slopes[i], end_slopes[i])
        if not np.isnan(root):
            out[i] = root
        else:
            out[i] = b if not ga > gb else a + (b - a) * ga / (ga - gb)
    return out


@jit
def _before(x, y):
    """Whether the rank x (hi, order..., lo) is below y, as Python compares tuples."""
    for i in range(x.shape[0]):
        if x[i] != y[i]:
            return x[i] < y[i]
    return False


@jit
def earliest_crossing(a, b, tol, skip_sure, settings, kinds, index, start, end, has_start,
                      start_slopes, has_end, end_slopes, fresh, order, n, pts, fun, prob):
    """:func:`~.stepper.location.earliest_crossing` of crossed functions the kernel values.

    Parameters
    ----------
    a, b, tol : float
        The substep and the bracket width wanted.
    skip_sure : bool
        Skip the evaluations whose outcome is sure.
    settings : tuple
        (SURE_MARGIN, MAX_ROOT_ITERATIONS).
    kinds, index : (k,) ndarray of int
        Each crossed key's function (:data:`NORMAL_FORCE` ... :data:`PICKUP`) and its
        contact (the finger for a gap, unused for the pickup margin).
    start, end, has_start, start_slopes, has_end, end_slopes : (k,) ndarray
        Their values at a and b, whether they have slopes there and the slopes.
    fresh : (k,) ndarray of bool
        Zero by construction at a.
    order : (k, 3) ndarray
        Their processing order (ties between brackets ending at the same s).
    n : int
        Points solved so far (a and b: the first two of ``pts``).
    pts : tuple
        The solved points' arrays (s, theta, delta, F, dtheta, dF, ddelta, nu, kappa,
        iterations, residual, Jacobian), room for as many points as they have rows.
    fun : tuple
        The functions' tables (mu, slip, each contact's finger radius, rate, each gap key's
        rows of the boundary compliance and of the rigid modes and its undeformed position,
        the rigid map E, the fingers' origins, translations and tips, then the pickup
        margin's: each contact's stick flag and finger, the fingers with contacts and the
        weight, NaN when the pickup is not checked).
    prob : tuple
        The fixed-set problem (:func:`.fixed_set_numba.solve_linear`'s tables, each contact's
        finger, the fingers' origins and translations, Newton's and the continuation's
        settings).

    Returns
    -------
    tuple
        (the event point, the evaluations, points solved); evaluations -1 when the Python
        location must run (a solve failed, a location did not converge, no room was left).
    """
    estimate = _estimates(a, b, start, end, has_start, start_slopes, has_end, end_slopes)
    keys = np.arange(kinds.shape[0])
    for i in range(1, keys.shape[0]):  # a stable insertion sort, as ``sorted``
        j = i
        while j > 0 and estimate[keys[j]] < estimate[keys[j - 1]]:
            keys[j], keys[j - 1] = keys[j - 1], keys[j]
            j -= 1
    best = np.empty(5)
    found, evaluations = False, 0
    rank = np.empty(5)
    margin = settings[0]
    for key in keys:
        kind, k = kinds[key], index[key]
        hi_end, g_hi, r_hi, sloped_hi = b, end[key], end_slopes[key], has_end[key]
        if found:
            lo_best = best[4]
            if lo_best <= a:
                continue
            if skip_sure and has_start[key] and has_end[key]:
                curvature = hermite_curvature(a, b, start[key], end[key], start_slopes[key],
                                              end_slopes[key])
                p, n = _at(best[0], n, pts, prob)
                if p < 0:
                    return b, -1, n
                if surely_positive(_value(kind, k, key, p, best[0], pts, fun),
                                   _slope(kind, k, key, p, best[0], pts, fun),
                                   best[0] - lo_best, curvature, margin):
                    continue
            p, n = _at(lo_best, n, pts, prob)
            if p < 0:
                return b, -1, n
            g_hi = _value(kind, k, key, p, lo_best, pts, fun)
            if g_hi > 0:
                continue
            hi_end = lo_best
            if has_end[key]:
                r_hi = _slope(kind, k, key, p, lo_best, pts, fun)
        sloped = has_start[key] and sloped_hi
        lo, glo, r_lo = a, start[key], start_slopes[key]
        if fresh[key] or not glo > 0:
            lo = hi_end if hi_end < a + tol else a + tol
            p, n = _at(lo, n, pts, prob)
            if p < 0:
                return b, -1, n
            glo = _value(kind, k, key, p, lo, pts, fun)
            if sloped:
                r_lo = _slope(kind, k, key, p, lo, pts, fun)
            evaluations += 1
        if glo <= 0:
            hi = lo
        else:
            lo, hi, used, n = _locate(kind, k, key, lo, hi_end, glo, g_hi, tol, sloped, r_lo,
                                      r_hi, skip_sure, settings, n, pts, fun, prob)
            if used < 0:
                return b, -1, n
            evaluations += used
        rank[0], rank[1:4], rank[4] = hi, order[key], lo
        if not found or _before(rank, best):
            best[:] = rank
            found = True
    return best[0], evaluations, n
