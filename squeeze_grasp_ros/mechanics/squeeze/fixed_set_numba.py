# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The linear model's fixed-set Newton compiled by numba (the ``fast`` extra): loops over the
contacts of one set, no Python objects per iteration (:mod:`.fixed_set_kernel` chooses the
route and wraps the result).

Every function is compiled on first use and cached on disk (numba's ``cache=True``); each one
stays callable from Python as ``f.py_func``, the same code uncompiled.
"""
from __future__ import annotations

import numba
import numpy as np

SOLVED, NOT_CONVERGED, SINGULAR, NON_FINITE = 0, 1, 2, 3
"""How :func:`solve_linear` ended (its first return value)."""
jit = numba.njit(cache=True, nogil=True)


@jit
def _forces(C, p0, centers, theta, radius, h, facing, delta, F):
    """Fill delta = centers + x(theta) - p0 and F = C delta (m, 2) in place."""
    m = theta.shape[0]
    for k in range(m):
        c = min(max(theta[k] - facing[k], -h[k]), h[k])
        nu = theta[k] - c
        delta[k, 0] = centers[k, 0] + radius[k] * (c * -np.sin(facing[k]) + np.cos(nu)) - p0[k, 0]
        delta[k, 1] = centers[k, 1] + radius[k] * (c * np.cos(facing[k]) + np.sin(nu)) - p0[k, 1]
    F[:] = np.dot(C, delta.ravel()).reshape(m, 2)


@jit
def _cone(theta, F, P, slip, phi, h, facing, R):
    """R_i = F_p x e(nu_p - slip_p phi) over the sliding nodes p = P[i], in place."""
    for i in range(P.shape[0]):
        p = P[i]
        c = min(max(theta[p] - facing[p], -h[p]), h[p])
        a = theta[p] - c - slip[p] * phi
        R[i] = F[p, 0] * np.sin(a) - F[p, 1] * np.cos(a)


@jit
def _jacobian(C, theta, F, P, slip, phi, radius, h, facing, J, G):
    """The Newton Jacobian J (|P|, |P|) and G = dF / dq_P (2m, |P|), in place."""
    m, n = theta.shape[0], P.shape[0]
    V = np.zeros((2 * m, n))
    for j in range(n):
        q = P[j]
        c = min(max(theta[q] - facing[q], -h[q]), h[q])
        nu = theta[q] - c
        V[2 * q, j], V[2 * q + 1, j] = radius[q] * -np.sin(nu), radius[q] * np.cos(nu)
    G[:] = np.dot(C, V)
    for i in range(n):
        p = P[i]
        u = theta[p] - facing[p]
        c = min(max(u, -h[p]), h[p])
        a = theta[p] - c - slip[p] * phi
        e0, e1 = np.cos(a), np.sin(a)
        for j in range(n):
            J[i, j] = G[2 * p, j] * e1 - G[2 * p + 1, j] * e0
        flat = h[p] > 0.0 and abs(u) <= h[p]
        J[i, i] = J[i, i] + (F[p, 0] * e0 + F[p, 1] * e1) * (0.0 if flat else 1.0)


@jit
def _solve(A, b, x):
    """Fill x = A^-1 b by LAPACK's gesv (numpy.linalg.solve's routine); False when A is
    singular.
    """
    try:
        x[:] = np.linalg.solve(A, b)
    except Exception:  # numpy.linalg.LinAlgError: a zero pivot
        return False
    return True


@jit
def solve_linear(C, p0, centers, dirs, theta0, stick, slip, phi, radius, flat, facing, tol,
                 max_iterations, backtracks, newton_tol):
    """Newton on the sliding coordinates of one contact set with F = C delta (dimensionless):
    the numpy route's iteration (:func:`~.contact_model.attempt_fixed_set`) as loops.

    Parameters
    ----------
    C : (2m, 2m) ndarray
        The set's reduced stiffness.
    p0, centers, dirs : (m, 2) ndarray
        Undeformed node positions, tip reference points, tip translation per unit s.
    theta0 : (m,) ndarray
        Contact coordinates (exact for sticking nodes, the guess for sliding ones), rad.
    stick : (m,) ndarray of bool
        The sticking nodes (the others slide).
    slip : (m,) ndarray of int
        Slip directions (+1/-1; 0 for sticking nodes).
    phi : float
        Friction angle, rad.
    radius, flat, facing : (m,) ndarray
        Each node's tip: rho, a, theta0 (:class:`~.tip_shapes.TipGeometry`).
    tol : float
        The cone residual's stopping bound is ``tol`` times the force scale max |C| max rho.
    max_iterations, backtracks : int
    newton_tol : float
        The step size below which Newton stops (rad).

    Returns
    -------
    tuple
        (:data:`SOLVED`, :data:`NOT_CONVERGED`, :data:`SINGULAR` or :data:`NON_FINITE`;
        iterations, residual, theta, delta, F, dtheta, dF, ddelta, J, nu, kappa): J is the last
        Jacobian (k, k), for its condition number; nu and kappa the normal angles and
        curvatures (:meth:`~.tip_shapes.TipGeometry.normal_angle`, ``curvature``) at theta.
    """
    P = np.flatnonzero(~stick)
    h = flat / radius
    force_scale = max(np.abs(C).max() * radius.max(), 1e-300)
    m, n = theta0.shape[0], P.shape[0]
    theta = theta0.copy()
    nu, kappa = np.empty(m), np.empty(m)
    delta, F = np.empty((m, 2)), np.empty((m, 2))
    t_delta, t_F = np.empty((m, 2)), np.empty((m, 2))
    R, t_R, step, trial = np.empty(n), np.empty(n), np.empty(n), np.empty(m)
    J, G = np.zeros((n, n)), np.empty((2 * m, n))
    _forces(C, p0, centers, theta, radius, h, facing, delta, F)
    _cone(theta, F, P, slip, phi, h, facing, R)
    it, residual = 0, 0.0
    dtheta, dF, ddelta = np.zeros(m), np.empty((m, 2)), np.empty((m, 2))
    while n > 0:
        _jacobian(C, theta, F, P, slip, phi, radius, h, facing, J, G)
        residual = np.abs(R).max()
        if residual <= tol * force_scale:
            break
        if it >= max_iterations:
            return NOT_CONVERGED, it, residual, theta, delta, F, dtheta, dF, ddelta, J, nu, \
                kappa
        if not _solve(J, R, step):
            return SINGULAR, it, residual, theta, delta, F, dtheta, dF, ddelta, J, nu, kappa
        it += 1
        for _ in range(backtracks):
            trial[:] = theta
            for i in range(n):
                trial[P[i]] -= step[i]
            _forces(C, p0, centers, trial, radius, h, facing, t_delta, t_F)
            _cone(trial, t_F, P, slip, phi, h, facing, t_R)
            if np.abs(t_R).max() < residual or np.abs(step).max() < newton_tol:
                break
            step *= 0.5
        theta[:] = trial
        delta[:], F[:], R[:] = t_delta, t_F, t_R
        if np.abs(step).max() < newton_tol:
            residual = np.abs(R).max()
            break
    dF[:] = np.dot(C, dirs.ravel()).reshape(m, 2)
    if n > 0:
        _jacobian(C, theta, F, P, slip, phi, radius, h, facing, np.empty((n, n)), G)
        rhs = np.empty(n)
        for i in range(n):
            p = P[i]
            c = min(max(theta[p] - facing[p], -h[p]), h[p])
            a = theta[p] - c - slip[p] * phi
            rhs[i] = dF[p, 0] * np.sin(a) - dF[p, 1] * np.cos(a)
        if not _solve(J, rhs, step):
            return SINGULAR, it, residual, theta, delta, F, dtheta, dF, ddelta, J, nu, kappa
        for i in range(n):
            dtheta[P[i]] = -step[i]
        rate = dtheta[P]
        for k in range(m):  # numpy's (m, 2, k) @ (k,): one product per contact
            dF[k] += np.dot(G[2 * k:2 * k + 2], rate)
    for k in range(m):
        u = theta[k] - facing[k]
        nu[k] = theta[k] - min(max(u, -h[k]), h[k])
        kappa[k] = 0.0 if flat[k] > 0.0 and abs(u) <= h[k] else 1.0
        ddelta[k, 0] = dirs[k, 0] + radius[k] * dtheta[k] * -np.sin(nu[k])
        ddelta[k, 1] = dirs[k, 1] + radius[k] * dtheta[k] * np.cos(nu[k])
    finite = np.all(np.isfinite(F)) and np.all(np.isfinite(dF)) and np.all(np.isfinite(theta))
    return SOLVED if finite else NON_FINITE, it, residual, theta, delta, F, dtheta, dF, ddelta, \
        J, nu, kappa
