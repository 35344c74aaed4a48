# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The neo-Hookean assembly compiled by numba (the ``fast`` extra): one pass over the elements
for the energy, the internal forces and the tangent's CSR values.

:func:`~.hyperelastic.assemble` runs this instead of the numpy route when the mesh's
:class:`~.hyperelastic.MeshGeometry` was built with ``compiled=True`` (the nonlinear contact
model asks for it when the fixed-set kernel route is numba:
:mod:`~squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel`). The law
is the numpy route's (:func:`~.hyperelastic._neo_hookean`), whose vectorised thickness-stretch
Newton and logarithms (numpy's SIMD ``log``, several times faster than a compiled scalar one)
it is given; the kernel does the rest. The element stiffness is written in closed form: with
v_ai = (F^-T grad N_a)_i and the law's A = mu I + c g g^T - a X,

    k[(a, i), (b, k)] = area (mu delta_ik grad N_a . grad N_b + c v_ai v_bk - a v_bi v_ak),

whose products are formed so that k is symmetric bit for bit; scattered in one element order
into the CSR values, the assembled tangent is symmetric bit for bit with no symmetrisation pass.
The numpy route forms the same closed form with the same products
(:func:`~.hyperelastic._neo_hookean_stiffness`), so the tangents of the two routes are equal
bit for bit; the energy and forces differ in the last bits (the order of the sums), by about
1e-15 relative (``test_hyperelastic_kernel.py`` compares the two routes).

Every function is compiled on first use and cached on disk (numba's ``cache=True``); each stays
callable from Python as ``f.py_func``, the same code uncompiled.
"""
from __future__ import annotations

import numba
import numpy as np

jit = numba.njit(cache=True, nogil=True)


@jit
def neo_hookean(F, l3, lnJ, grad, area, dofs, slots, lam, mu, force, data):
    """Energy of the deformation gradients ``F`` (t, 2, 2) with their thickness stretches
    ``l3`` and ln(det F l3) ``lnJ`` (t,); the forces (2n,) and, when ``data`` has entries, the
    tangent's CSR values (nnz,) added into ``force`` and ``data`` (zeroed by the caller).
    ``grad`` (t, 3, 2), ``area`` (t,), ``dofs`` (t, 6): the element's DOFs in (a, i) order;
    ``slots`` (t, 36): CSR positions of its entries in (a, b, i, k) order.
    """
    tangent = data.shape[0] > 0
    energy = 0.0
    v = np.empty((3, 2))
    for e in range(F.shape[0]):
        f00, f01, f10, f11 = F[e, 0, 0], F[e, 0, 1], F[e, 1, 0], F[e, 1, 1]
        J2, stretch, ln_j = f00 * f11 - f01 * f10, l3[e], lnJ[e]
        g00, g01, g10, g11 = f11 / J2, -f10 / J2, -f01 / J2, f00 / J2  # F^-T
        I1 = f00 * f00 + f01 * f01 + f10 * f10 + f11 * f11 + stretch * stretch
        energy += area[e] * (0.5 * mu * (I1 - 3.0) - mu * ln_j + 0.5 * lam * ln_j * ln_j)
        a = lam * ln_j - mu
        p00, p01 = mu * f00 + a * g00, mu * f01 + a * g01
        p10, p11 = mu * f10 + a * g10, mu * f11 + a * g11
        w = area[e]
        for b in range(3):
            x, y = grad[e, b, 0], grad[e, b, 1]
            force[dofs[e, 2 * b]] += w * (x * p00 + y * p01)
            force[dofs[e, 2 * b + 1]] += w * (x * p10 + y * p11)
            v[b, 0] = g00 * x + g01 * y
            v[b, 1] = g10 * x + g11 * y
        if not tangent:
            continue
        w33 = mu + mu / stretch ** 2 + lam * (1.0 - ln_j) / stretch ** 2
        c = lam - (lam / stretch) ** 2 / w33
        for p in range(3):
            for q in range(3):
                laplace = mu * (grad[e, p, 0] * grad[e, q, 0] + grad[e, p, 1] * grad[e, q, 1])
                for i in range(2):
                    for k in range(2):
                        entry = c * (v[p, i] * v[q, k]) - a * (v[q, i] * v[p, k])
                        if i == k:
                            entry += laplace
                        data[slots[e, 12 * p + 4 * q + 2 * i + k]] += w * entry
    return energy
