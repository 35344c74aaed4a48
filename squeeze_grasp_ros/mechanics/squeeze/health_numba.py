# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The linear model's grasp-health field pass compiled by numba (the ``fast`` extra): one loop
over the elements for the strain limit's strain, the principal strains in every measure and the
von Mises stress, where the numpy route makes some forty passes over small arrays
(:func:`~.events.grasp_health` chooses the route; :mod:`.fixed_set_kernel`).

The arithmetic is the numpy route's, operation for operation: the deformation gradients are the
CSR product :func:`~..elastic.hyperelastic.gradient_operator` @ u row by row as scipy sums it;
the principal pairs, the Green-Lagrange strains, the stretch ratio, the Biot strain and the
plane-stress von Mises stress (scaled by its power of two) are written as
:mod:`~..elastic.strain_measures`, :func:`~..elastic.fem.principal_pair` and
:func:`~..elastic.stress_measures.von_mises` write them; the linear stress C : eps has two
non-zero terms per entry, whose sum does not depend on their order. Two sums have an order of
their own: the engineering strains B d_e, which numpy's ``einsum`` sums over the six element
DOFs in two interleaved partial sums (even and odd DOFs; on this project's machines), written
so here; and the logarithmic strain, whose ``log1p`` numpy evaluates with its SIMD routines:
the kernel leaves it to numpy (it returns the stretch ratios). A maximum and the first element
within :data:`~..ties.TIE` of it are found as :func:`~..ties.first_max` finds them (a NaN wins).

Every function is compiled on first use and cached on disk (numba's ``cache=True``); each stays
callable from Python as ``f.py_func``, the same code uncompiled.
"""
from __future__ import annotations

import math

import numba
import numpy as np

jit = numba.njit(cache=True, nogil=True)


@jit
def _first_max(values, tie):
    """(largest entry, index of the first entry within ``tie`` (relative) below it) of the
    flat array ``values``; a NaN is the largest (its first), an infinite largest entry its own
    index, as :func:`~..ties.first_max`.
    """
    k = 0
    for i in range(values.shape[0]):
        v = values[i]
        if np.isnan(v):
            return v, i
        if v > values[k]:
            k = i
    top = values[k]
    if not np.isfinite(top):
        return top, k
    floor = top - tie * abs(top)
    for i in range(values.shape[0]):
        if values[i] >= floor:
            return top, i
    return top, k


@jit
def _pair(exx, eyy, gxy):
    """Principal pair (largest first) of engineering strains, as ``principal_pair``."""
    mean = 0.5 * (exx + eyy)
    a, b = 0.5 * (exx - eyy), 0.5 * gxy
    radius = math.sqrt(a * a + b * b)
    return mean + radius, mean - radius


@jit
def _stretch_ratio(e):
    """np.maximum(2 e, -1) (NaN propagates)."""
    x = 2.0 * e
    return x if (x >= -1.0 or np.isnan(x)) else -1.0


@jit
def _biot(two_e):
    """The Biot strain lambda - 1 of a stretch ratio 2 e = lambda^2 - 1."""
    return two_e / (1.0 + math.sqrt(1.0 + two_e))


@jit
def _contract(C, i, j, eps):
    """(C : eps)_ij summed over (k, l) in order (two non-zero terms: any order gives it)."""
    s = 0.0
    for k in range(2):
        for m in range(2):
            s += C[i, j, k, m] * eps[k, m]
    return s


@jit
def _abs_max(current, value):
    """The running ``np.abs(x).max()``: NaN propagates."""
    if np.isnan(current) or np.isnan(value):
        return np.nan
    return max(current, abs(value))


@jit
def linear_fields(u, g_data, g_indices, g_indptr, B, dofs, componentwise, C, E, tie):
    """The linear model's health fields of the dimensionless displacement ``u`` (2n,).

    Parameters
    ----------
    u : (2n,) ndarray
        Nodal displacements / L.
    g_data, g_indices, g_indptr : ndarray
        The CSR arrays of the gradient operator (4t, 2n) in the same unit.
    B, dofs : ndarray
        The strain-displacement matrices (t, 3, 6) and element DOFs (t, 6) in that unit.
    componentwise : bool
        The strain limit's criterion: max(|eps_xx|, |eps_yy|), else the principal strains.
    C : (2, 2, 2, 2) ndarray
        Plane-stress C / E; ``E`` Young's modulus, Pa.
    tie : float
        :data:`~..ties.TIE`.

    Returns
    -------
    tuple
        (strain, its element, von Mises stress Pa, its element, the largest absolute principal
        small, Biot and Green-Lagrange strains, the stretch ratios 2 e of the principal
        Green-Lagrange strains (2, t) for the log strain).
    """
    t = dofs.shape[0]
    work = np.empty(2 * t)
    for e in range(t):  # the strain limit's strain: B d_e as einsum sums it
        eps = np.empty(3)
        for i in range(3):
            even = (B[e, i, 0] * u[dofs[e, 0]] + B[e, i, 2] * u[dofs[e, 2]]) \
                + B[e, i, 4] * u[dofs[e, 4]]
            odd = (B[e, i, 1] * u[dofs[e, 1]] + B[e, i, 3] * u[dofs[e, 3]]) \
                + B[e, i, 5] * u[dofs[e, 5]]
            eps[i] = even + odd
        if componentwise:
            a, b = eps[0], eps[1]
        else:
            a, b = _pair(eps[0], eps[1], eps[2])
        work[2 * e], work[2 * e + 1] = abs(a), abs(b)
    strain, k = _first_max(work, tie)
    small = biot = green = 0.0
    two_e = np.empty((2, t))
    F = np.empty((2, 2))
    sym = np.empty((2, 2))
    for e in range(t):  # F, the principal strains in every measure, the stress
        for r in range(4):  # the CSR product, row by row as scipy sums it
            row = 4 * e + r
            s = 0.0
            for jj in range(g_indptr[row], g_indptr[row + 1]):
                s += g_data[jj] * u[g_indices[jj]]
            F[r // 2, r % 2] = s
        F[0, 0] += 1.0
        F[1, 1] += 1.0
        h00, h01, h10, h11 = F[0, 0] - 1.0, F[0, 1] - 0.0, F[1, 0] - 0.0, F[1, 1] - 1.0
        s1, s2 = _pair(h00, h11, h01 + h10)
        small = _abs_max(_abs_max(small, s1), s2)
        g1, g2 = _pair(h00 + 0.5 * (h00 * h00 + h10 * h10), h11 + 0.5 * (h01 * h01 + h11 * h11),
                       h01 + h10 + (h00 * h01 + h10 * h11))
        green = _abs_max(_abs_max(green, g1), g2)
        two_e[0, e], two_e[1, e] = _stretch_ratio(g1), _stretch_ratio(g2)
        biot = _abs_max(_abs_max(biot, _biot(two_e[0, e])), _biot(two_e[1, e]))
        for i in range(2):
            for j in range(2):
                sym[i, j] = 0.5 * (F[i, j] + F[j, i]) - (1.0 if i == j else 0.0)
        work[e] = _von_mises(E * _contract(C, 0, 0, sym), E * _contract(C, 1, 1, sym),
                             0.5 * (E * _contract(C, 0, 1, sym) + E * _contract(C, 1, 0, sym)))
    vm, k_vm = _first_max(work[:t], tie)
    return strain, k // 2, vm, k_vm, small, biot, green, two_e


@jit
def _von_mises(s11, s22, s12):
    """Plane-stress von Mises stress of (s11, s22, s12), scaled by the largest power of two
    as :func:`~..elastic.stress_measures.von_mises`.
    """
    if np.isnan(s11) or np.isnan(s22) or np.isnan(s12):
        return np.nan
    _, k = math.frexp(max(max(abs(s11), abs(s22)), abs(s12)))
    s11, s22, s12 = math.ldexp(s11, -k), math.ldexp(s22, -k), math.ldexp(s12, -k)
    return math.ldexp(math.sqrt(s11 * s11 - s11 * s22 + s22 * s22 + 3.0 * s12 * s12), k)
