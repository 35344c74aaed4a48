# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The linear model's substeps between events compiled by numba (the ``fast`` extra): advance a
stepper call from one point to the substep before the next event, in one call.

:func:`advance_quiet` runs the substep loop of :meth:`~.stepper.run._Call.run` for a fixed
contact set: the continuation solve at each substep end (:func:`.fixed_set_numba.solve_linear`,
the same floats as the numpy route), the watched event functions there (normal forces, cone
margins, slip rates, the free boundary rows' gaps through the boundary compliance rows, the
area ratio, the pickup margin), the fingers' work and dissipation, and each accepted point's
sample. It returns to Python (:mod:`.stepper.compiled`) before any substep that needs Python:
one on which a watched function may cross zero (it is not above ``margin`` at the end, or
surely below zero at the start), a continuation that fails or would be halved, an element
near inversion before its load gradients are kept, a hold of the chattering bound that expires.
Python then runs that substep as before, so events are located and processed by the same code.

The work, the dissipation and the samples' finger forces are written in numpy's order (a
masked ``sum(axis=0)`` adds rows one after the other from 0.0; a 1-D ``sum`` is numpy's
pairwise sum), so they are the same floats; the watched values only decide whether a substep
is surely quiet, with ``margin`` to spare for the order of their arithmetic.
"""
from __future__ import annotations

import numba
import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.fixed_set_numba import SOLVED, solve_linear

END, CROSSING, SOLVE, LOADS, EXPIRY, FULL = 0, 1, 2, 3, 4, 5
"""Why :func:`advance_quiet` returned: s reached 1, a watched function may cross on the next
substep, its continuation fails (or would be halved), an element is near inversion without its
load gradients, a hold expires at the next substep's start, the sample buffers are full."""
jit = numba.njit(cache=True, nogil=True)
LOAD_GRADIENTS = numba.types.float64[:, :, ::1]
"""The type of one node's load gradients (t, 4, 2) in the kernels' lists (:func:`load_list`)."""


def load_list(gradients) -> numba.typed.List:
    """A contact set's load gradients as the kernels take them: a numba typed list of each
    node's (t, 4, 2) C-contiguous array, in the set's order, not copied (stacking them as one
    (m, t, 4, 2) array copied about 107 MB for a set of the 20,091-node foam square); empty
    while the set's are not kept.
    """
    out = numba.typed.List.empty_list(LOAD_GRADIENTS)
    for g in gradients:
        out.append(g)
    return out


NO_LOADS = load_list(())
"""The empty list: a set whose load gradients are not kept (never appended to)."""


@jit
def _block(a, lo, n):
    """The sum of a[lo:lo + n], n <= 128, in the order of numpy's ``pairwise_sum``."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - n % 8:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@jit
def np_sum(a):
    """``a.sum()`` of a 1-D array, in numpy's order: blocks of at most 128 summed by
    :func:`_block`, longer runs split in halves (multiples of 8) and added, as numpy's
    recursive pairwise sum (written with a stack: numba's cache does not keep recursion).
    """
    ops = np.empty((192, 3), np.int64)  # (start, length, 0: sum it / 1: add the last two)
    vals = np.empty(96)
    ops[0, 0], ops[0, 1], ops[0, 2] = 0, a.shape[0], 0
    top, nv = 1, 0
    while top:
        top -= 1
        lo, n, kind = ops[top, 0], ops[top, 1], ops[top, 2]
        if kind == 1:
            nv -= 1
            vals[nv - 1] = vals[nv - 1] + vals[nv]
        elif n <= 128:
            vals[nv] = _block(a, lo, n)
            nv += 1
        else:
            n2 = n // 2
            n2 -= n2 % 8
            ops[top, 0], ops[top, 1], ops[top, 2] = 0, 0, 1
            ops[top + 1, 0], ops[top + 1, 1], ops[top + 1, 2] = lo + n2, n - n2, 0
            ops[top + 2, 0], ops[top + 2, 1], ops[top + 2, 2] = lo, n2, 0
            top += 3
    return 0.0 + vals[0]


@jit
def _finger_sums(F, finger, f):
    """``F[finger == f].sum(axis=0)`` (rows added in order from 0.0)."""
    s0, s1 = 0.0, 0.0
    for k in range(F.shape[0]):
        if finger[k] == f:
            s0 += F[k, 0]
            s1 += F[k, 1]
    return s0, s1


@jit
def _dot2(x0, x1, y):
    """``np.array([x0, x1]) @ y`` for a 2-vector y (BLAS ddot's order)."""
    return 0.0 + ((0.0 + x0 * y[0]) + x1 * y[1])


@jit
def _tangential(F, nu):
    """f_t = F . t(nu) (m,), as ``np.einsum('ij,ij->i', F, tangent(nu))``."""
    out = np.empty(nu.shape[0])
    for k in range(nu.shape[0]):
        out[k] = (0.0 + F[k, 0] * -np.sin(nu[k])) + F[k, 1] * np.cos(nu[k])
    return out


@jit
def _work(F_a, dF_a, ft_a, dth_a, F_b, dF_b, ft_b, dth_b, a, b, finger, D, radius_c, work,
          dissipation):
    """:meth:`~.stepper.run._Call.integrate_work` over [a, b], in place."""
    h = b - a
    m = finger.shape[0]
    sliding = False
    for k in range(m):
        if dth_a[k] != 0.0 or dth_b[k] != 0.0:
            sliding = True
    pa, pb = np.empty(m), np.empty(m)
    if sliding:
        for k in range(m):
            pa[k] = -ft_a[k] * radius_c[k] * dth_a[k]
            pb[k] = -ft_b[k] * radius_c[k] * dth_b[k]
    for f in range(D.shape[0]):
        n = 0
        for k in range(m):
            if finger[k] == f:
                n += 1
        if n == 0:
            continue
        x0, x1 = _finger_sums(F_a, finger, f)
        ya = _dot2(x0, x1, D[f])
        x0, x1 = _finger_sums(F_b, finger, f)
        yb = _dot2(x0, x1, D[f])
        x0, x1 = _finger_sums(dF_a, finger, f)
        ra = _dot2(x0, x1, D[f])
        x0, x1 = _finger_sums(dF_b, finger, f)
        rb = _dot2(x0, x1, D[f])
        work[f] += 0.5 * h * (ya + yb) + h * h / 12.0 * (ra - rb)
        if sliding:
            qa, qb = np.empty(n), np.empty(n)
            i = 0
            for k in range(m):
                if finger[k] == f:
                    qa[i], qb[i] = pa[k], pb[k]
                    i += 1
            dissipation[f] += 0.5 * h * (np_sum(qa) + np_sum(qb))


@jit
def _element_bounds(delta, F, E, rigid_gradients, bounds):
    """(the rigid part's displacement gradients (4t,), every element's gradient bound B_e)
    as :meth:`~.contact_model.ContactModel.area_ratio` computes them (the same floats).
    """
    rigid = np.dot(rigid_gradients, np.dot(E.T, delta.ravel()))
    norms = np.empty(F.shape[0])
    for k in range(F.shape[0]):
        norms[k] = np.sqrt(F[k, 0] * F[k, 0] + F[k, 1] * F[k, 1])
    bound = np.dot(bounds, norms)
    for e in range(bounds.shape[0]):  # no slice per element: a seventh of the call's time
        r0, r1, r2, r3 = rigid[4 * e], rigid[4 * e + 1], rigid[4 * e + 2], rigid[4 * e + 3]
        bound[e] = bound[e] + np.sqrt(r0 * r0 + r1 * r1 + r2 * r2 + r3 * r3)
    return rigid, bound


@jit
def _area_ratio(delta, F, E, rigid_gradients, bounds, loads, exact_bound, numpys_order):
    """(smallest det F, its element or -1) as :meth:`~.contact_model.ContactModel.area_ratio`
    bounds or computes it: the bound (1 - max B_e)^2 while no B_e reaches ``exact_bound``
    (inf without ``bounds`` rows, when the area is not watched), else the near elements' exact
    det F from the set's ``loads`` (:func:`load_list`: m arrays (t, 4, 2)); NaN when one is
    near and ``loads`` are not given. With ``numpys_order`` its floats are the model's:
    H_e = rigid_e + ((G_0e f_0 + G_1e f_1) + ...), each contact's G_k[near] f_k one BLAS gemv
    of the near elements' rows gathered (n * 4, 2), whose rows are those of numpy's matmul of
    the (n, 4, 2) gather (a gemv per element); else the products are written out (a substep's
    quiet check, which has QUIET_MARGIN to spare).
    """
    t = bounds.shape[0]
    if t == 0:
        return np.inf, -1
    rigid, bound = _element_bounds(delta, F, E, rigid_gradients, bounds)
    largest, near = -np.inf, 0
    for e in range(t):
        if bound[e] >= exact_bound:
            near += 1
        else:
            largest = max(largest, bound[e])
    floor = (1.0 - largest) ** 2 if near < t else np.inf
    if near == 0:
        return floor, -1
    m = F.shape[0]
    if len(loads) != m:
        return np.nan, -1
    which = np.empty(near, np.int64)
    j = 0
    for e in range(t):
        if bound[e] >= exact_bound:
            which[j] = e
            j += 1
    S = np.zeros(4 * near)  # sum_k G_k[which] f_k, (near, 4) raveled
    for k in range(m):
        if numpys_order:
            S += np.dot(loads[k][which].reshape(4 * near, 2), F[k])
        else:
            for j in range(near):
                for i in range(4):
                    S[4 * j + i] += (loads[k][which[j], i, 0] * F[k, 0]
                                     + loads[k][which[j], i, 1] * F[k, 1])
    smallest, element = np.inf, -1
    for j in range(near):
        e = which[j]
        h0, h1 = rigid[4 * e] + S[4 * j], rigid[4 * e + 1] + S[4 * j + 1]
        h2, h3 = rigid[4 * e + 2] + S[4 * j + 2], rigid[4 * e + 3] + S[4 * j + 3]
        det = (1.0 + h0) * (1.0 + h3) - h1 * h2
        if det < smallest:
            smallest, element = det, e
    return (smallest, element) if smallest <= floor else (floor, -1)


@jit
def _area_lower(delta, F, E, watched, bounds_w, rigid_w, rest_top, rigid_top, loads,
                exact_bound):
    """A lower bound of :func:`_area_ratio`'s value for a substep's quiet check, in O(w m) for
    the w elements of ``watched`` instead of O(t m) for all t: the elements whose gradient
    bound can be large (``watched``, their rows ``bounds_w`` (w, m) of the bounds and
    ``rigid_w`` (w, 4, 3) of the rigid modes' gradients) bounded, or computed near inversion,
    one by one as there; the others at once by (1 - U)^2, where U = sum_k rest_top_k |f_k| +
    rigid_top |g| is at least each one's B_e (``rest_top``: their bounds' column maxima,
    ``rigid_top``: the largest Frobenius norm of an element's rigid gradients). -inf when U
    reaches ``exact_bound`` or a watched element nears inversion without ``loads``: then
    every element is checked (:func:`_area_ratio`).
    """
    m = F.shape[0]
    g = np.dot(E.T, delta.ravel())
    norms = np.empty(m)
    top = rigid_top * np.sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2])
    for k in range(m):
        norms[k] = np.sqrt(F[k, 0] * F[k, 0] + F[k, 1] * F[k, 1])
        top += rest_top[k] * norms[k]
    if top >= exact_bound:
        return -np.inf
    lower = (1.0 - top) ** 2
    H = np.empty(4)
    for i in range(watched.shape[0]):
        for r in range(4):
            H[r] = rigid_w[i, r, 0] * g[0] + rigid_w[i, r, 1] * g[1] + rigid_w[i, r, 2] * g[2]
        b = np.sqrt(H[0] * H[0] + H[1] * H[1] + H[2] * H[2] + H[3] * H[3])
        for k in range(m):
            b += bounds_w[i, k] * norms[k]
        if b < exact_bound:
            lower = min(lower, (1.0 - b) ** 2)
            continue
        if len(loads) != m:
            return -np.inf
        e = watched[i]
        for k in range(m):
            for r in range(4):
                H[r] += loads[k][e, r, 0] * F[k, 0] + loads[k][e, r, 1] * F[k, 1]
        lower = min(lower, (1.0 + H[0]) * (1.0 + H[3]) - H[1] * H[2])
    return lower


@jit
def _pickup(mu, fn, ft, stick, finger, fingers, weight):
    """:func:`~.stepper.functions.pickup_margin`, each finger's sum in numpy's order
    (:func:`np_sum` of the finger's entries, sliding nodes' zeros included); inf when
    ``weight`` is NaN (not checked).
    """
    if np.isnan(weight):
        return np.inf
    m = fn.shape[0]
    c = np.empty(m)
    for k in range(m):
        c[k] = np.sqrt(max(mu * mu * fn[k] * fn[k] - ft[k] * ft[k], 0.0)) if stick[k] else 0.0
    least = np.inf
    for f in fingers:
        mine = c[finger == f]
        least = min(least, np_sum(mine))
    return weight / fingers.shape[0] - least


@jit
def _from_tip(x, y, centers_f, flat_f, t0_f, f):
    """The vector from finger ``f``'s tip core (its centre, or the nearest point of its flat
    segment of half-length ``flat_f[f]`` along ``t0_f[f]``) to the point (x, y).
    """
    rx, ry = x - centers_f[f, 0], y - centers_f[f, 1]
    tau = min(max(rx * t0_f[f, 0] + ry * t0_f[f, 1], -flat_f[f]), flat_f[f])
    return rx - tau * t0_f[f, 0], ry - tau * t0_f[f, 1]


@jit
def _watched(delta, F, dtheta, nu, pick, mu, slip, radius_c, rate, A_rows, R_rows, E,
             boundary0, centers_f, radius_f, flat_f, t0_f, out):
    """The watched per-contact values (``pick`` into fn, c+, c-, d laid end to end) and the
    free rows' gaps to every finger, in :meth:`~.stepper.functions.EventFunctions.entries`'s
    order, into ``out``; returns (fn, ft).
    """
    m = nu.shape[0]
    fn, ft = np.empty(m), np.empty(m)
    table = np.empty(4 * m)
    for k in range(m):
        c, s = np.cos(nu[k]), np.sin(nu[k])
        fn[k] = F[k, 0] * c + F[k, 1] * s
        ft[k] = F[k, 0] * -s + F[k, 1] * c
        table[k] = fn[k]
        table[m + k] = mu * fn[k] + ft[k]
        table[2 * m + k] = mu * fn[k] - ft[k]
        table[3 * m + k] = slip[k] * dtheta[k] * radius_c[k] / rate
    for i in range(pick.shape[0]):
        out[i] = table[pick[i]]
    i = pick.shape[0]
    rows = boundary0.shape[0]
    if rows:
        g = np.dot(E.T, delta.ravel())
        u = np.dot(A_rows, F.ravel()) + np.dot(R_rows, g)
        for r in range(rows):
            x, y = boundary0[r, 0] + u[2 * r], boundary0[r, 1] + u[2 * r + 1]
            for f in range(centers_f.shape[0]):
                wx, wy = _from_tip(x, y, centers_f, flat_f, t0_f, f)
                out[i] = np.sqrt(wx * wx + wy * wy) - radius_f[f]
                i += 1
    return fn, ft


@jit
def watched_values(delta, F, dtheta, nu, pick, mu, slip, radius_c, rate, A_rows, R_rows, E,
                   boundary0, centers_f, radius_f, flat_f, t0_f, stick, finger, weight,
                   rigid_gradients, bounds, loads, exact_bound):
    """The watched functions at one solution as the numpy code computes them (the same
    floats, a zero's sign aside): :meth:`~.stepper.functions.EventFunctions.watched`.

    The per-contact values and the free rows' gaps in
    :meth:`~.stepper.functions.EventFunctions.entries`'s order (:func:`_watched`'s arguments;
    ``E`` as the contact set holds it, so that ``E.T @ delta`` is numpy's product), then the
    smallest area ratio and its element (:func:`_area_ratio` in numpy's order: NaN when an
    element nears inversion and the set's ``loads`` are not kept yet; inf without ``bounds``
    rows, when the area is not watched), and the pickup margin (:func:`_pickup`'s arguments,
    the fingers those in ``finger``; inf when ``weight`` is NaN).
    """
    out = np.empty(pick.shape[0] + boundary0.shape[0] * centers_f.shape[0])
    fn, ft = _watched(delta, F, dtheta, nu, pick, mu, slip, radius_c, rate, A_rows, R_rows,
                      E, boundary0, centers_f, radius_f, flat_f, t0_f, out)
    det, element = _area_ratio(delta, F, E, rigid_gradients, bounds, loads, exact_bound, True)
    return out, det, element, _pickup(mu, fn, ft, stick, finger, np.unique(finger), weight)


@jit
def slope_values(delta, F, ddelta, dF, dtheta, nu, kappa, mu, A_rows, R_rows, E, boundary0,
                 centers_f, D, flat_f, t0_f):
    """The slopes d/ds at one solution as :meth:`~.stepper.functions.EventFunctions.slopes`
    computes them in numpy (the same floats): the free rows' gaps (rows, fingers) raveled,
    and each contact's normal force and cone margins (m, 3) raveled.

    ``kappa`` is d nu / d theta per contact, or empty for circular tips (1); ``D`` the
    fingers' translations over the call (their centres' rates); the rest as in
    :func:`_watched`.
    """
    m = nu.shape[0]
    rates = np.empty(3 * m)
    for k in range(m):
        c, s = np.cos(nu[k]), np.sin(nu[k])
        turn = dtheta[k] if kappa.shape[0] == 0 else kappa[k] * dtheta[k]
        fn = F[k, 0] * c + F[k, 1] * s
        ft = F[k, 0] * -s + F[k, 1] * c
        fn_r = (dF[k, 0] * c + dF[k, 1] * s) + turn * ft
        ft_r = (dF[k, 0] * -s + dF[k, 1] * c) - turn * fn
        rates[3 * k] = fn_r
        rates[3 * k + 1] = mu * fn_r + ft_r
        rates[3 * k + 2] = mu * fn_r - ft_r
    rows, nf = boundary0.shape[0], centers_f.shape[0]
    gaps = np.empty(rows * nf)
    if rows:
        u = np.dot(A_rows, F.ravel()) + np.dot(R_rows, np.dot(E.T, delta.ravel()))
        v = np.dot(A_rows, dF.ravel()) + np.dot(R_rows, np.dot(E.T, ddelta.ravel()))
        i = 0
        for r in range(rows):
            x, y = boundary0[r, 0] + u[2 * r], boundary0[r, 1] + u[2 * r + 1]
            for f in range(nf):
                wx, wy = _from_tip(x, y, centers_f, flat_f, t0_f, f)
                vx, vy = v[2 * r] - D[f, 0], v[2 * r + 1] - D[f, 1]
                gaps[i] = (wx * vx + wy * vy) / np.sqrt(wx * wx + wy * wy)
                i += 1
    return gaps, rates


@jit
def point_values(delta, F, dtheta, nu, pick, mu, slip, radius_c, rate, A_rows, R_rows, E,
                 boundary0, centers_f, radius_f, flat_f, t0_f, stick, finger, weight,
                 rigid_gradients, bounds, loads, exact_bound, ddelta, dF, kappa, D):
    """:func:`watched_values` and :func:`slope_values` of the same free rows at one solution
    in one call (the same floats as the two calls; :func:`watched_values`' arguments, then
    the solution's rates ``ddelta``, ``dF``, ``kappa`` and the fingers' translation ``D`` that
    the slopes add): (values, det, element, pickup, the rows' gap slopes, the contacts'
    rates). The pending events at a point read the values and the slopes of the functions
    zero by construction; the next substep's start reads both.
    """
    values, det, element, pickup = watched_values(
        delta, F, dtheta, nu, pick, mu, slip, radius_c, rate, A_rows, R_rows, E, boundary0,
        centers_f, radius_f, flat_f, t0_f, stick, finger, weight, rigid_gradients, bounds,
        loads, exact_bound)
    gaps, rates = slope_values(delta, F, ddelta, dF, dtheta, nu, kappa, mu, A_rows, R_rows, E,
                               boundary0, centers_f, D, flat_f, t0_f)
    return values, det, element, pickup, gaps, rates


@jit
def _sure(start, end, margin):
    """Whether no function goes from > 0 at the start to <= 0 at the end, with ``margin``."""
    for k in range(end.shape[0]):
        if not (end[k] > margin or start[k] < -margin):
            return False
    return True


@jit
def advance_quiet(a, h, theta, dtheta, F, dF, ft, start_values, start_ends,
                  C, p0, stick, slip, phi, radius_c, flat_c, facing_c, finger, fingers,
                  origin, D, newton_tol, max_iterations, backtracks, continuation_iterations,
                  max_angle_jump, pick, mu, rate, A_rows, R_rows, E, boundary0, radius_f,
                  flat_f, t0_f, rigid_gradients, bounds, loads, exact_bound, inversion_ratio,
                  quiet_area, weight, depth0, length, expiry, margin, force_unit, work,
                  dissipation, s_out, theta_out, forces_out, jacobians):
    """Substeps of one contact set from s = a while each is surely quiet (module docstring).

    Parameters
    ----------
    a, h : float
        The current point and the grid substep (in s).
    theta, dtheta, F, dF, ft : ndarray
        The solution at a (angles, their rates, forces, their rates, tangential forces).
    start_values, start_ends : ndarray
        The watched values at a (per contact and gaps; area and pickup margins, inf when not
        watched).
    C, p0, stick, slip, phi, radius_c, flat_c, facing_c : ndarray or float
        The fixed-set problem (:func:`.fixed_set_numba.solve_linear`'s arguments).
    finger, fingers : ndarray of int
        Each contact's finger; the fingers with contacts, ascending.
    origin, D : (f, 2) ndarray
        Each finger's tip reference point at s = 0 and its translation over the call.
    newton_tol, max_iterations, backtracks : float, int, int
        Newton's settings; ``continuation_iterations``, ``max_angle_jump`` the continuation's.
    pick, mu, rate, A_rows, R_rows, E, boundary0, radius_f, flat_f, t0_f
        The watched functions: where each per-contact value is in the table, friction, motion
        per unit s, the rows of the boundary compliance and of the rigid modes of the free
        rows, the rigid map, the rows' undeformed positions and the fingers' tips.
    rigid_gradients, bounds, loads, exact_bound, inversion_ratio
        The area check (:meth:`~.contact_model.ContactModel.area_ratio`); ``loads``
        (:func:`load_list`; empty when not kept).
    quiet_area : tuple
        :func:`_area_lower`'s tables of the set (``watched`` to ``rigid_top``): a substep whose
        area bound from them is above ``inversion_ratio + margin`` needs no pass over every
        element.
    weight : float
        The pickup weight / force unit, NaN when not checked.
    depth0, length, expiry : float
        Depth (m) at s = 0, L (m), the depth at which the next hold expires.
    margin : float
        How far above zero a function must be to be surely positive.
    force_unit : float
    work, dissipation : (f,) ndarray
        Accumulated in place.
    s_out, theta_out, forces_out, jacobians : ndarray
        Each accepted point's s, angles, finger forces (N) and Newton Jacobian.

    Returns
    -------
    tuple
        (accepted substeps, why it returned, largest Newton iterations and residual, and the
        last point's theta, delta, F, dtheta, dF, ddelta, nu, kappa, J, iterations,
        residual).
    """
    m = theta.shape[0]
    nf = origin.shape[0]
    centers = np.empty((m, 2))
    dirs = np.empty((m, 2))
    for k in range(m):
        dirs[k, 0], dirs[k, 1] = D[finger[k], 0], D[finger[k], 1]
    centers_f = np.empty((nf, 2))
    values = np.empty(start_values.shape[0])
    ends = np.empty(2)
    starts, start_e = start_values.copy(), start_ends.copy()
    count, why, most_it, most_res = 0, END, 0, 0.0
    delta_b = np.empty((m, 2))
    ddelta_b, nu_b, kappa_b = np.empty((m, 2)), np.empty(m), np.empty(m)
    J_b = np.empty((0, 0))
    it_b, res_b = 0, 0.0
    theta_a, dtheta_a, F_a, dF_a, ft_a = theta, dtheta, F, dF, ft
    while a < 1.0:
        if count == s_out.shape[0]:
            why = FULL
            break
        if depth0 + a * rate * length >= expiry:
            why = EXPIRY
            break
        b = min(a + h, 1.0)
        guess = theta_a + dtheta_a * (b - a)
        for k in range(m):
            centers[k, 0] = origin[finger[k], 0] + b * D[finger[k], 0]
            centers[k, 1] = origin[finger[k], 1] + b * D[finger[k], 1]
        status, it, res, th, de, Fb, dth, dFb, dde, J, nu, kappa = solve_linear(
            C, p0, centers, dirs, guess, stick, slip, phi, radius_c, flat_c, facing_c,
            newton_tol, max_iterations, backtracks, newton_tol)
        if status != SOLVED or it > continuation_iterations or \
                np.abs(th - guess).max() > max_angle_jump:
            why = SOLVE
            break
        for f in range(nf):
            centers_f[f, 0] = origin[f, 0] + b * D[f, 0]
            centers_f[f, 1] = origin[f, 1] + b * D[f, 1]
        fn, ft_b = _watched(de, Fb, dth, nu, pick, mu, slip, radius_c, rate, A_rows,
                            R_rows, E, boundary0, centers_f, radius_f, flat_f, t0_f, values)
        det = _area_lower(de, Fb, E, *quiet_area, loads, exact_bound)
        if not det - inversion_ratio > margin:  # not surely quiet by the bound: every element
            det, _ = _area_ratio(de, Fb, E, rigid_gradients, bounds, loads, exact_bound, False)
        if np.isnan(det):
            why = LOADS
            break
        ends[0] = det - inversion_ratio
        ends[1] = _pickup(mu, fn, ft_b, stick, finger, fingers, weight)
        if not (_sure(starts, values, margin) and _sure(start_e, ends, margin)):
            why = CROSSING
            break
        ft_b = _tangential(Fb, nu)
        _work(F_a, dF_a, ft_a, dtheta_a, Fb, dFb, ft_b, dth, a, b, finger, D, radius_c, work,
              dissipation)
        most_it, most_res = max(most_it, it), max(most_res, res)
        s_out[count] = b
        theta_out[count] = th
        for f in range(nf):
            x0, x1 = _finger_sums(Fb, finger, f)
            forces_out[count, f, 0], forces_out[count, f, 1] = x0 * force_unit, x1 * force_unit
        if J.shape[0]:
            jacobians[count] = J
        count += 1
        starts[:], start_e[:] = values, ends
        theta_a, dtheta_a, F_a, dF_a, ft_a = th, dth, Fb, dFb, ft_b
        delta_b, ddelta_b, nu_b, kappa_b, J_b, it_b, res_b = de, dde, nu, kappa, J, it, res
        a = b
    return (count, why, most_it, most_res, theta_a, delta_b, F_a, dtheta_a, dF_a, ddelta_b,
            nu_b, kappa_b, J_b, it_b, res_b)
