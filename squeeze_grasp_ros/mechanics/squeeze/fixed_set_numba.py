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


@jit
def _violations(idx, combo, options, F, dF, dtheta, nu, kappa, zero, mu, frictionless,
                rate_floor):
    """:func:`~.stepper.modes.mode_violations` of contacts ``idx`` in their options ``combo``
    summed, from a solution's arrays (the floats of :class:`~.contact_model.Solution`'s force
    components: e(nu) . F and t(nu) . F as numpy's einsum sums them).
    """
    bad = 0
    for j in range(idx.shape[0]):
        k, o = idx[j], combo[j]
        c, s = np.cos(nu[k]), np.sin(nu[k])
        turn = kappa[k] * dtheta[k]
        fn = F[k, 0] * c + F[k, 1] * s
        ft = F[k, 0] * -s + F[k, 1] * c
        fn_r = (dF[k, 0] * c + dF[k, 1] * s) + turn * ft
        ft_r = (dF[k, 0] * -s + dF[k, 1] * c) - turn * fn
        bad += not (fn_r > rate_floor if zero[j, 0] else fn > 0)
        if options[o, 0]:
            bad += not (mu * fn_r + ft_r > rate_floor if zero[j, 1] else mu * fn + ft > 0)
            bad += not (mu * fn_r - ft_r > rate_floor if zero[j, 2] else mu * fn - ft > 0)
        elif not frictionless:
            bad += options[o, 1] * dtheta[k] <= 0
    return bad


@jit
def _attempt(C, p0, centers, dirs, theta0, stick, slip, phi, radius, flat, facing, tol,
             max_iterations, backtracks, newton_tol, log, Js, a):
    """:func:`solve_linear` in modes ``stick``, ``slip``, its status, iterations, residual and
    sliding nodes n written to ``log[a]`` and its Jacobian to ``Js[a, :n, :n]``.
    """
    status, it, residual, theta, _, F, dtheta, dF, _, J, nu, kappa = solve_linear(
        C, p0, centers, dirs, theta0, stick, slip, phi, radius, flat, facing, tol,
        max_iterations, backtracks, newton_tol)
    n = J.shape[0]
    log[a, 0], log[a, 1], log[a, 2], log[a, 3] = status, it, residual, n
    Js[a, :n, :n] = J
    return status == SOLVED, theta, F, dtheta, dF, nu, kappa


@jit
def decide_linear(C, p0, centers, dirs, theta0, stick, slip, phi, radius, flat, facing, tol,
                  max_iterations, backtracks, newton_tol, idx, options, zero, mu, rate_floor,
                  by_node):
    """The mode decision of contacts ``idx`` (:func:`~.stepper.modes.decide_modes`) in one
    call, each hypothesis solved by :func:`solve_linear` and its violations counted: every
    combination of their ``options`` (rows (stick, slip), in the order tried) in
    :func:`itertools.product`'s order, the first consistent one winning, else the first with
    fewest; or, ``by_node``, the node-by-node search's two passes
    (:func:`~.stepper.modes._node_by_node`) and then its one combination.

    ``zero`` (len(idx), 3) marks each node's normal force and cone margins (+, -) that are
    zero by construction (they must grow faster than ``rate_floor``); mu = 0 is frictionless.
    The other arguments are :func:`solve_linear`'s.

    Returns
    -------
    tuple
        (whether a combination was solved, the chosen one's violations, stick, slip and
        theta (m,) of the whole set; the solves in order: (status, iterations, residual,
        sliding nodes n) rows and their Jacobians ``Js[a, :n, :n]``).
    """
    k, n_options = idx.shape[0], options.shape[0]
    n_combos = 1 if by_node else n_options ** k
    n_solves = n_combos + (2 * k * n_options if by_node else 0)
    free = ~stick
    for j in range(k):
        free[idx[j]] = True
    most = np.count_nonzero(free)  # the most sliding nodes of any hypothesis
    log, Js = np.zeros((n_solves, 4)), np.zeros((n_solves, most, most))
    combo = np.zeros(k, np.int64)
    st, sl = stick.copy(), slip.copy()
    frictionless, a = mu == 0.0, 0
    if by_node:
        for _ in range(2):
            for j in range(k):
                for o in range(n_options):
                    st[idx[j]], sl[idx[j]] = options[o, 0] != 0, options[o, 1]
                    solved, _, F, dtheta, dF, nu, kappa = _attempt(
                        C, p0, centers, dirs, theta0, st, sl, phi, radius, flat, facing, tol,
                        max_iterations, backtracks, newton_tol, log, Js, a)
                    a += 1
                    if solved and _violations(
                            idx[j:j + 1], np.array([o]), options, F, dF, dtheta, nu, kappa,
                            zero[j:j + 1], mu, frictionless, rate_floor) == 0:
                        combo[j] = o
                        break
                st[idx[j]], sl[idx[j]] = options[combo[j], 0] != 0, options[combo[j], 1]
    best, best_bad = -1, 0
    best_stick, best_slip, best_theta = stick.copy(), slip.copy(), theta0.copy()
    for c in range(n_combos):
        if not by_node:
            rest = c
            for j in range(k - 1, -1, -1):
                combo[j] = rest % n_options
                rest //= n_options
        st, sl = stick.copy(), slip.copy()
        for j in range(k):
            st[idx[j]], sl[idx[j]] = options[combo[j], 0] != 0, options[combo[j], 1]
        solved, theta, F, dtheta, dF, nu, kappa = _attempt(
            C, p0, centers, dirs, theta0, st, sl, phi, radius, flat, facing, tol,
            max_iterations, backtracks, newton_tol, log, Js, a)
        a += 1
        if not solved:
            continue
        bad = _violations(idx, combo, options, F, dF, dtheta, nu, kappa, zero, mu,
                          frictionless, rate_floor)
        if best < 0 or bad < best_bad:
            best, best_bad = c, bad
            best_stick, best_slip, best_theta = st, sl, theta
        if bad == 0:
            break
    return best >= 0, best_bad, best_stick, best_slip, best_theta, log[:a], Js[:a]
