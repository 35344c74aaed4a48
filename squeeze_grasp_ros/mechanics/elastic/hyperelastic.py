# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Finite-deformation material laws on linear triangles, total Lagrangian, vectorised.

Three laws share one interface, :func:`assemble`, which returns the strain energy, the internal
force vector and the consistent tangent stiffness of a displacement field, all divided by E*h
(dimensionless, as :func:`~squeeze_grasp_ros.mechanics.elastic.fem.stiffness_matrix`):

- ``linear``: W = 1/2 eps : C : eps with the small strain eps = sym(F) - I. Its tangent is the
  CST stiffness exactly; it is not frame indifferent (a rigid rotation stores energy).
- ``corotational``: F = R U (polar decomposition, R from the single angle
  atan2(F21 - F12, F11 + F22)), W = 1/2 (U - I) : C : (U - I). For an isotropic C the stress
  S = C : (U - I) is coaxial with U, so P = R S exactly; the tangent adds the rotation's
  derivative. Exact under rigid rotation.
- ``neo_hookean``: the compressible law W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2 of the
  3-D solid with Lame constants of (E, nu), in exact plane stress: the thickness stretch
  lambda3 of every element solves S33 = 0, i.e. mu (lambda3^2 - 1) + lambda ln(J2 lambda3) = 0,
  by Newton; the tangent condenses the 33 component. At small strain it is the plane-stress law
  with the same E and nu. Needs nu < 0.5 (lambda is infinite at 0.5).

C is the plane-stress elasticity of (E, nu); F = I + grad u over the reference (undeformed)
element. An element whose det F <= 0 is inverted: :func:`assemble` raises
:class:`InvertedElementError`, never returns NaN.

>>> import numpy as np
>>> X = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]); tri = np.array([[0, 1, 2]])
>>> turn = np.array([[0.0, -1.0], [1.0, 0.0]])  # a rigid rotation by 90 degrees
>>> u = (X @ turn.T - X).reshape(-1)
>>> [round(assemble(m, X, tri, u, nu=0.3).energy, 12) for m in ("corotational", "neo_hookean")]
[0.0, 0.0]
>>> assemble("linear", X, tri, u, nu=0.3).energy > 0
True
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from squeeze_grasp_ros.mechanics.elastic.fem import element_dofs
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

__all__ = ["Assembly", "InvertedElementError", "MeshGeometry", "area_ratios", "assemble",
           "deformation", "determinants", "gradient_operator", "mesh_geometry",
           "plane_stress_tensor", "stress_and_tangent", "thickness_stretch", "with_tangent"]

_PLANE_STRESS_ITERATIONS = 30
_SKEW = np.array([[0.0, -1.0], [1.0, 0.0]])
_I, _K, _J, _L = np.indices((2, 2, 2, 2)).reshape(4, -1)
"""(i, k, j, l) of the 16 entries of a tangent dP_ij/dF_kl stored in (ik, jl) order, the order
the stiffness product of :func:`assemble` reads them in."""
_OUTER = (2 * _I + _J, 2 * _K + _L)
"""Flat (2x2 -> 4) positions of the factors of g_ij g_kl, entry by entry of such a tangent."""
_CROSS = (2 * _I + _L, 2 * _K + _J)
"""The same for G_il G_kj."""
_IDENTITY = ((_I == _K) & (_J == _L)).astype(float)
"""delta_ik delta_jl in that order."""
_ROW, _COL = np.triu_indices(6)
_UPPER = (_ROW, _COL, 2 * (_COL // 2) + _ROW % 2, 2 * (_ROW // 2) + _COL % 2,
          np.flatnonzero(_ROW % 2 == _COL % 2))
"""The 21 entries (a, i) <= (b, k) of the upper triangle of an element stiffness, rows and
columns flat (2a + i, 2b + k): the flat positions of v_ai and v_bk, of v_bi and v_ak, and the
entries with i = k."""


class InvertedElementError(NumericalError):
    """An element turned inside out (det F <= 0): no elastic state exists there."""


@dataclass(frozen=True)
class Assembly:
    """Energy, internal force and tangent of one displacement field, divided by E*h.

    Attributes
    ----------
    energy : float
        Strain energy / (E h), m^2.
    force : (2n,) ndarray
        Internal nodal forces / (E h), m (the forces the nodes exert on the solid, = dW/du).
    tangent : (2n, 2n) scipy.sparse.csr_matrix or None
        d force / d u, dimensionless, symmetric (None if not assembled).
    min_det : float
        Smallest det F (in-plane) over the elements.
    deformation : (t, 2, 2) ndarray
        The deformation gradients F it was assembled from.
    stretch : (t,) ndarray or None
        The neo-Hookean law's thickness stretches lambda3 of F (None for the other laws), kept
        for :func:`with_tangent`.
    """

    energy: float
    force: np.ndarray
    tangent: sp.csr_matrix | None
    min_det: float
    deformation: np.ndarray
    stretch: np.ndarray | None = None


def _shape_gradients(nodes: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference shape-function gradients (t, 3, 2), 1/m, and element areas (t,), m^2."""
    p = nodes[triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    J = np.stack([d1, d2], axis=2)  # columns: dX/dxi, dX/deta
    det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
    inv = np.stack([np.stack([J[:, 1, 1], -J[:, 0, 1]], -1),
                    np.stack([-J[:, 1, 0], J[:, 0, 0]], -1)], 1) / det[:, None, None]
    dxi = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
    return np.einsum("ak,tkj->taj", dxi, inv), 0.5 * np.abs(det)


def deformation(nodes: np.ndarray, triangles: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Deformation gradients F (t, 2, 2) of the nodal displacement ``u`` (2n,) or (n, 2), m."""
    return _deformation(gradient_operator(nodes, triangles), u)


def _deformation(gradient: sp.csr_matrix, u: np.ndarray) -> np.ndarray:
    """F = I + grad u (t, 2, 2) from the :func:`gradient_operator` of the mesh."""
    F = gradient @ np.asarray(u, float).reshape(-1)
    F[0::4] += 1.0
    F[3::4] += 1.0
    return F.reshape(-1, 2, 2)


def gradient_operator(nodes: np.ndarray, triangles: np.ndarray) -> sp.csr_matrix:
    """Sparse (4t, 2n) map of nodal displacements to displacement gradients: row 4e + 2i + j of
    ``G @ u`` is du_i/dX_j of element e (dimensionless when nodes and u share a unit).
    """
    grad, _ = _shape_gradients(np.asarray(nodes, float), np.asarray(triangles, int))
    t = len(triangles)
    dofs = element_dofs(triangles).reshape(t, 3, 2)
    rows = (4 * np.arange(t)[:, None, None, None] + 2 * np.arange(2)[None, None, :, None]
            + np.arange(2)[None, None, None, :])
    rows = np.broadcast_to(rows, (t, 3, 2, 2))
    cols = np.broadcast_to(dofs[:, :, :, None], (t, 3, 2, 2))
    vals = np.broadcast_to(grad[:, :, None, :], (t, 3, 2, 2))
    return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())),
                         shape=(4 * t, 2 * len(nodes)))


def area_ratios(gradient: sp.csr_matrix, u: np.ndarray) -> np.ndarray:
    """The area ratio det F (t,) of every element: deformed / reference area (<= 0: inverted).

    Parameters
    ----------
    gradient : (4t, 2n) sparse matrix
        :func:`gradient_operator` of the mesh, in the unit that ``u`` is measured in.
    u : (2n,) ndarray
        Nodal displacements.

    >>> import numpy as np
    >>> X = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]); tri = np.array([[0, 1, 2]])
    >>> squash = np.array([0.0, 0.0, 0.0, 0.0, 0.0, -1.5])  # apex pushed through the base
    >>> area_ratios(gradient_operator(X, tri), squash).tolist()
    [-0.5]
    """
    return determinants(_deformation(gradient, u))


def determinants(F: np.ndarray) -> np.ndarray:
    """The area ratios det F (t,) of the deformation gradients F (t, 2, 2)."""
    return F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]


def plane_stress_tensor(nu: float) -> np.ndarray:
    """C / E as a (2, 2, 2, 2) tensor for plane stress."""
    lam, mu2 = nu / (1.0 - nu * nu), 1.0 / (1.0 + nu)
    eye = np.eye(2)
    return (lam * np.einsum("ij,kl->ijkl", eye, eye)
            + 0.5 * mu2 * (np.einsum("ik,jl->ijkl", eye, eye)
                           + np.einsum("il,jk->ijkl", eye, eye)))


def _linear(F: np.ndarray, nu: float, tangent: bool):
    C = plane_stress_tensor(nu)
    eps = 0.5 * (F + np.swapaxes(F, 1, 2)) - np.eye(2)
    P = np.einsum("ijkl,tkl->tij", C, eps)
    W = 0.5 * np.einsum("tij,tij->t", P, eps)
    return W, P, np.broadcast_to(C, (len(F), 2, 2, 2, 2)) if tangent else None


def _rotation(F: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """R (t, 2, 2) of the polar decomposition, and d theta / d F (t, 2, 2)."""
    s, c = F[:, 1, 0] - F[:, 0, 1], F[:, 0, 0] + F[:, 1, 1]
    n2 = s * s + c * c
    theta = np.arctan2(s, c)
    R = np.stack([np.stack([np.cos(theta), -np.sin(theta)], -1),
                  np.stack([np.sin(theta), np.cos(theta)], -1)], 1)
    dtheta = np.stack([np.stack([-s, -c], -1), np.stack([c, -s], -1)], 1) / n2[:, None, None]
    return R, dtheta, n2


def _corotational(F: np.ndarray, nu: float, tangent: bool):
    t = len(F)
    C = plane_stress_tensor(nu).reshape(4, 4)
    R, dtheta, _ = _rotation(F)
    U = np.swapaxes(R, 1, 2) @ F
    E = 0.5 * (U + np.swapaxes(U, 1, 2)) - np.eye(2)
    S = (E.reshape(t, 4) @ C.T).reshape(t, 2, 2)
    W = 0.5 * np.sum(S * E, axis=(1, 2))
    P = R @ S
    if not tangent:
        return W, P, None
    # dU/dF_km = R^T e_k e_m^T - Omega U dtheta/dF_km, for the four (k, m) at once:
    # entry [t, k, m, i, j] of the first term is R[t, k, i] delta_jm.
    dU = (R[:, :, None, :, None] * np.eye(2)[None, None, :, None, :]
          - (_SKEW @ U)[:, None, None] * dtheta[:, :, :, None, None]).reshape(t, 4, 2, 2)
    dS = (0.5 * (dU + np.swapaxes(dU, 2, 3))).reshape(t, 4, 4) @ C.T
    dP = R[:, None] @ ((_SKEW @ S)[:, None] * dtheta.reshape(t, 4, 1, 1)
                       + dS.reshape(t, 4, 2, 2))
    return W, P, dP.reshape(t, 2, 2, 2, 2).transpose(0, 3, 4, 1, 2)


def _lame(nu: float) -> tuple[float, float]:
    """3-D Lame constants / E."""
    return nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), 0.5 / (1.0 + nu)


def _thickness_stretch(J2: np.ndarray, lam: float, mu: float,
                       start: np.ndarray | None = None) -> np.ndarray:
    """lambda3 with mu (l3^2 - 1) + lam ln(J2 l3) = 0 per element (Newton from l3 = 1, or from
    ``start``, the stretches of a nearby state: one or two iterations fewer).
    """
    l3 = np.ones_like(J2) if start is None else start
    for _ in range(_PLANE_STRESS_ITERATIONS):
        g = mu * (l3 * l3 - 1.0) + lam * np.log(J2 * l3)
        dg = 2.0 * mu * l3 + lam / l3
        step = g / dg
        l3 = np.maximum(l3 - step, 0.5 * l3)
        if np.max(np.abs(step)) < 1e-15:
            break
    return l3


def _require_compressible(nu: float) -> None:
    if not nu < 0.5:
        raise InvalidInputError(f"material.nu must be < 0.5 for the neo_hookean model (its "
                                f"lambda is infinite at 0.5), got {nu}")


def _neo_hookean_terms(F: np.ndarray, J2: np.ndarray, nu: float, *,
                       l3: np.ndarray | None = None, start: np.ndarray | None = None,
                       inverse: bool = True) -> tuple:
    """(lam, mu, l3, ln(J2 l3), G = F^-T, a = lam ln J - mu) of the neo-Hookean law at the
    deformation gradients ``F`` with det F = ``J2``; ``l3``: their thickness stretches when
    known, else solved here (from ``start``: :func:`_thickness_stretch`). ``inverse=False``:
    G and a are None (the compiled kernel forms them per element).
    """
    _require_compressible(nu)
    lam, mu = _lame(nu)
    l3 = _thickness_stretch(J2, lam, mu, start) if l3 is None else l3
    lnJ = np.log(J2 * l3)
    if not inverse:
        return lam, mu, l3, lnJ, None, None
    G = np.empty_like(F)  # F^-T
    G[:, 0, 0], G[:, 1, 1] = F[:, 1, 1], F[:, 0, 0]
    G[:, 0, 1], G[:, 1, 0] = -F[:, 1, 0], -F[:, 0, 1]
    G /= J2[:, None, None]
    return lam, mu, l3, lnJ, G, lam * lnJ - mu


def _neo_hookean_stress(F: np.ndarray, terms: tuple) -> tuple[np.ndarray, np.ndarray]:
    """(W (t,), P (t, 2, 2)) of the neo-Hookean law from its :func:`_neo_hookean_terms`."""
    lam, mu, l3, lnJ, G, a = terms
    I1 = np.einsum("tij,tij->t", F, F) + l3 * l3
    W = 0.5 * mu * (I1 - 3.0) - mu * lnJ + 0.5 * lam * lnJ * lnJ
    P = (mu * F.reshape(-1, 4) + a[:, None] * G.reshape(-1, 4)).reshape(-1, 2, 2)
    return W, P


def _condensed(terms: tuple) -> np.ndarray:
    """The g g^T coefficient c = lam - (lam / l3)^2 / w33 (t,) of the neo-Hookean tangent,
    with the thickness direction condensed out (w33: its 33 stiffness).
    """
    lam, mu, l3, lnJ, _, _ = terms
    w33 = mu + mu / l3 ** 2 + lam * (1.0 - lnJ) / l3 ** 2
    return lam - (lam / l3) ** 2 / w33


def _neo_hookean(F: np.ndarray, nu: float, tangent: bool):
    terms = _neo_hookean_terms(F, determinants(F), nu)
    W, P = _neo_hookean_stress(F, terms)
    if not tangent:
        return W, P, None
    # A = mu I + c g g^T - a X with X[ij, kl] = G_il G_kj, as (t, 16) rows in (ik, jl) order
    # built in place (the tangent's arrays are the largest of an assembly); returned as the
    # (i, j, k, l) view of them
    mu, g, a = terms[1], terms[4].reshape(-1, 4), terms[5]
    A = np.take(g, _OUTER[0], axis=1) * np.take(g, _OUTER[1], axis=1)
    A *= _condensed(terms)[:, None]
    A += mu * _IDENTITY
    cross = np.take(g, _CROSS[0], axis=1) * np.take(g, _CROSS[1], axis=1)
    cross *= a[:, None]
    A -= cross
    return W, P, A.reshape(-1, 2, 2, 2, 2).transpose(0, 1, 3, 2, 4)


def _neo_hookean_stiffness(geometry: MeshGeometry, terms: tuple) -> np.ndarray:
    """The CSR values of the neo-Hookean tangent stiffness from the law's
    :func:`_neo_hookean_terms`, in the closed form of the compiled kernel
    (:mod:`.hyperelastic_numba`):
    k[(a, i), (b, k)] = area (mu delta_ik grad N_a . grad N_b + c v_ai v_bk - a v_bi v_ak),
    v_a = F^-T grad N_a, with the kernel's products in the kernel's order, so that its floats
    are the kernel's. Such an entry is symmetric bit for bit, so only the 21 of the upper
    triangle of each element stiffness are formed and summed (in element order) onto the
    upper triangle of K, which is then mirrored: no symmetrisation pass.
    """
    _, mu, _, _, G, a = terms
    x, y = geometry.shape_gradients[:, :, 0].T, geometry.shape_gradients[:, :, 1].T
    v = np.empty((3, 2, len(a)))  # v[b, i, e], flat (2b + i, e): element by element in rows
    v[:, 0] = G[:, 0, 0] * x + G[:, 0, 1] * y
    v[:, 1] = G[:, 1, 0] * x + G[:, 1, 1] * y
    v = v.reshape(6, -1)
    entry = v[_UPPER[0]] * v[_UPPER[1]]  # v_ai v_bk
    entry *= _condensed(terms)
    cross = v[_UPPER[2]] * v[_UPPER[3]]  # v_bi v_ak
    cross *= a
    entry -= cross
    entry[_UPPER[4]] += mu * geometry.gram
    entry *= geometry.area
    data = np.bincount(geometry.upper_slots, weights=entry.T.reshape(-1),
                       minlength=len(geometry.indices))
    data[geometry.lower] = data[geometry.transpose[geometry.lower]]
    return data


def thickness_stretch(model: MaterialModel | str, F: np.ndarray, *, nu: float) -> np.ndarray:
    """Out-of-plane stretch lambda3 (t,) of each element under plane stress (sigma33 = 0).

    ``neo_hookean``: the root of mu (lambda3^2 - 1) + lambda ln(det F lambda3) = 0 that the law
    solves. ``corotational``: the 2-D law is the plane-stress reduction of the 3-D isotropic
    law T = lambda tr(E) I + 2 mu E on the Biot strain E = U - I, whose T33 = 0 gives
    lambda3 = 1 - nu / (1 - nu) tr(U - I). The linear model has no thickness stretch.

    Parameters
    ----------
    model : MaterialModel or str
        ``corotational`` or ``neo_hookean``.
    F : (t, 2, 2) ndarray
        In-plane deformation gradients (det F > 0).
    nu : float
        Poisson's ratio.
    """
    model = MaterialModel(model)
    F = np.asarray(F, float)
    if model == MaterialModel.COROTATIONAL:
        _, _, n2 = _rotation(F)  # tr U = |(F11 + F22, F21 - F12)|
        return 1.0 - nu / (1.0 - nu) * (np.sqrt(n2) - 2.0)
    if model == MaterialModel.NEO_HOOKEAN:
        _require_compressible(nu)
        lam, mu = _lame(nu)
        return _thickness_stretch(determinants(F), lam, mu)
    raise InvalidInputError("the linear model has no thickness stretch (small strain: its "
                            "stress is C : eps on the reference configuration)")


_LAWS = {MaterialModel.LINEAR: _linear, MaterialModel.COROTATIONAL: _corotational,
         MaterialModel.NEO_HOOKEAN: _neo_hookean}


def stress_and_tangent(model: MaterialModel | str, F: np.ndarray, *, nu: float,
                       tangent: bool = True):
    """Energy density W / E (t,), first Piola-Kirchhoff stress P / E (t, 2, 2) and its
    derivative dP/dF / E (t, 2, 2, 2, 2) (None unless ``tangent``) of each deformation gradient
    in ``F`` (t, 2, 2).
    """
    try:
        law = _LAWS[MaterialModel(model)]
    except ValueError:
        raise InvalidInputError(f"material.model must be one of {MaterialModel.values()}, got "
                                f"{model!r}") from None
    return law(np.asarray(F, float), nu, tangent)


def assemble(model: MaterialModel | str, nodes: np.ndarray, triangles: np.ndarray,
             u: np.ndarray, *, nu: float, geometry: MeshGeometry | None = None,
             tangent: bool = True, deformation: np.ndarray | None = None,
             stretch: np.ndarray | None = None) -> Assembly:
    """Energy, internal forces and tangent stiffness of the displacement ``u`` (2n,), m.

    Parameters
    ----------
    model : MaterialModel or str
        "linear", "corotational" or "neo_hookean".
    nodes : (n, 2) ndarray
        Reference node positions, m.
    triangles : (t, 3) ndarray of int
        Counter-clockwise elements.
    u : (2n,) ndarray
        Nodal displacements, m, DOF order (x1, y1, x2, y2, ...).
    nu : float
        Poisson's ratio.
    geometry : MeshGeometry, optional
        :func:`mesh_geometry` of ``nodes`` and ``triangles``, when many states of one mesh are
        assembled (computed here otherwise).
    tangent : bool
        Assemble the tangent stiffness too (False: energy and forces only, about half the
        work; ``Assembly.tangent`` is None).
    deformation : (t, 2, 2) ndarray, optional
        F of ``u`` (:meth:`MeshGeometry.deformation`) when the caller has it already, as after
        testing a state for inverted elements (computed here otherwise).
    stretch : (t,) ndarray, optional
        Neo-Hookean: the thickness stretches of a nearby state (``Assembly.stretch``, as of
        Newton's current iterate for its trial), to start this state's thickness Newton from;
        it then stops at the same tolerance in fewer iterations, at stretches that may differ
        from a start at 1 in the last bits.

    Raises
    ------
    InvertedElementError
        If an element has det F <= 0.
    """
    geometry = mesh_geometry(nodes, triangles) if geometry is None else geometry
    F = geometry.deformation(u) if deformation is None else deformation
    det = determinants(F)
    worst = int(np.argmin(det))
    if not det[worst] > 0:
        raise InvertedElementError(f"element {worst} inverted (det F = {det[worst]:.3g})",
                                   residuals={"det_F": det[worst]})
    neo = MaterialModel(model) == MaterialModel.NEO_HOOKEAN
    terms = (_neo_hookean_terms(F, det, nu, start=stretch, inverse=not geometry.compiled)
             if neo else None)
    if neo and geometry.compiled:
        energy, force, data = _compiled_neo_hookean(geometry, F, terms, tangent)
    else:
        if neo:
            W, P = _neo_hookean_stress(F, terms)
            data = _neo_hookean_stiffness(geometry, terms) if tangent else None
        else:
            W, P, A = stress_and_tangent(model, F, nu=nu, tangent=tangent)
            data = _stiffness_data(geometry, A) if tangent else None
        energy = float(np.einsum("t,t->", W, geometry.area))
        force = geometry.force_operator @ P.reshape(-1)  # f[(a, i)] = sum_e area g_aj P_ij
    K = None if data is None else _csr(geometry, data)
    return Assembly(energy, force, K, float(det[worst]), F, terms[2] if neo else None)


def with_tangent(model: MaterialModel | str, assembly: Assembly, *, nu: float,
                 geometry: MeshGeometry) -> Assembly:
    """``assembly`` (of :func:`assemble` with ``geometry``, forces only) with its tangent
    stiffness: the tangent of its deformation gradients (and, neo-Hookean, of the thickness
    stretches it holds: no second solve of them), its energy and forces kept; the floats of
    ``assemble(..., tangent=True)`` of the same state and ``stretch`` start.
    """
    if assembly.tangent is not None:
        return assembly
    F = assembly.deformation
    if MaterialModel(model) == MaterialModel.NEO_HOOKEAN:
        terms = _neo_hookean_terms(F, determinants(F), nu, l3=assembly.stretch,
                                   inverse=not geometry.compiled)
        data = (_compiled_neo_hookean(geometry, F, terms, True)[2] if geometry.compiled
                else _neo_hookean_stiffness(geometry, terms))
    else:
        data = _stiffness_data(geometry, stress_and_tangent(model, F, nu=nu)[2])
    return replace(assembly, tangent=_csr(geometry, data))


def _csr(geometry: MeshGeometry, data: np.ndarray) -> sp.csr_matrix:
    """The tangent stiffness of the CSR values ``data`` in the pattern of ``geometry``."""
    return sp.csr_matrix((data, geometry.indices, geometry.indptr),
                         shape=(geometry.n2, geometry.n2))


def _compiled_neo_hookean(geometry: MeshGeometry, F: np.ndarray, terms: tuple,
                          tangent: bool) -> tuple[float, np.ndarray, np.ndarray | None]:
    """(energy, forces, the tangent's CSR values or None) of the neo-Hookean law of the
    deformation gradients ``F`` by the compiled kernel (:mod:`.hyperelastic_numba`), given
    the law's :func:`_neo_hookean_terms` (thickness stretches, logarithms) as numpy has them.
    """
    from squeeze_grasp_ros.mechanics.elastic import hyperelastic_numba

    lam, mu, l3, lnJ = terms[:4]
    force = np.zeros(geometry.n2)
    data = np.zeros(len(geometry.indices) if tangent else 0)
    energy = hyperelastic_numba.neo_hookean(F, l3, lnJ, geometry.shape_gradients,
                                            geometry.area,
                                            geometry.dofs, geometry.slots.reshape(len(F), 36),
                                            lam, mu, force, data)
    return float(energy), force, (data if tangent else None)


def _stiffness_data(geometry: MeshGeometry, A: np.ndarray) -> np.ndarray:
    """The CSR values (in the pattern of ``geometry``) of the stiffness of the tangents
    ``A`` = dP/dF (t, 2, 2, 2, 2), symmetrised.

    Element e adds k[(a, i), (b, k)] = area sum_jl g_aj g_bl A_ijkl: one (9 x 4) @ (4 x 4)
    product per element, of the mesh's area-weighted g_aj g_bl (rows ab, columns jl) and A
    ordered (ik, jl); its (a, b, i, k) entries go to their CSR positions by one bincount, and
    the symmetric part is taken once on the assembled values (K_sym = (K + K^T) / 2).
    """
    t = len(A)
    # (i, j, k, l) -> (i, k, j, l): rows ik, columns jl (no copy for a law that stores A so)
    ordered = np.ascontiguousarray(np.transpose(A, (0, 1, 3, 2, 4))).reshape(t, 4, 4)
    ke = geometry.weighted_outer @ np.swapaxes(ordered, 1, 2)
    data = np.bincount(geometry.slots, weights=ke.reshape(-1), minlength=len(geometry.indices))
    data += data[geometry.transpose]
    data *= 0.5
    return data


@dataclass(frozen=True)
class MeshGeometry:
    """What :func:`assemble` needs of a mesh that does not change with the displacement.

    Attributes
    ----------
    gradient : (4t, 2n) scipy.sparse.csr_matrix
        :func:`gradient_operator` of the mesh.
    area : (t,) ndarray
        Element areas.
    force_operator : (2n, 4t) scipy.sparse.csr_matrix
        The internal forces of the element stresses: (area-weighted ``gradient``)^T, so that
        ``force_operator @ P.reshape(-1)`` sums area g_aj P_ij onto DOF (a, i).
    weighted_outer : (t, 9, 4) ndarray
        area * g_aj g_bl, rows (a, b), columns (j, l).
    n2 : int
        Number of DOFs.
    slots : (36t,) ndarray of int
        CSR position of each element entry (a, b, i, k) -> row (a, i), column (b, k).
    indices, indptr : ndarray of int
        The CSR pattern of the stiffness (column indices, row pointers; sorted).
    transpose : (nnz,) ndarray of int
        CSR position of the transposed entry of each entry.
    shape_gradients : (t, 3, 2) ndarray
        Reference shape-function gradients g_aj.
    dofs : (t, 6) ndarray of int
        The DOFs of each element, (a, i) order.
    upper_slots : (21t,) ndarray of int
        CSR position of the upper-triangle entry (row <= column) of each element entry
        (a, i) <= (b, k), element by element, in the order of ``np.triu_indices(6)``.
    lower : ndarray of int
        CSR positions of the entries below the diagonal.
    gram : (12, t) ndarray
        grad N_a . grad N_b of the upper-triangle entries with i = k, in their order.
    compiled : bool
        :func:`assemble` runs the neo-Hookean law by the compiled kernel of
        :mod:`.hyperelastic_numba` (the ``fast`` extra), the other laws by numpy.
    """

    gradient: sp.csr_matrix
    area: np.ndarray
    force_operator: sp.csr_matrix
    weighted_outer: np.ndarray
    n2: int
    slots: np.ndarray
    indices: np.ndarray
    indptr: np.ndarray
    transpose: np.ndarray
    shape_gradients: np.ndarray
    dofs: np.ndarray
    upper_slots: np.ndarray
    lower: np.ndarray
    gram: np.ndarray
    compiled: bool = False

    def deformation(self, u: np.ndarray) -> np.ndarray:
        """Deformation gradients F = I + grad u (t, 2, 2) of the displacement ``u`` (2n,)."""
        return _deformation(self.gradient, u)


def mesh_geometry(nodes: np.ndarray, triangles: np.ndarray, *,
                  compiled: bool = False) -> MeshGeometry:
    """The displacement-independent part of :func:`assemble` for ``nodes`` (n, 2) and
    ``triangles`` (t, 3); build it once and pass it as ``geometry`` to assemble many states.

    The stiffness pattern and the place of every element entry in it are computed here once
    per mesh, so that an assembly is a product per element and one scatter. ``compiled``: the
    neo-Hookean law is assembled by the compiled kernel (:mod:`.hyperelastic_numba`; needs
    numba, the ``fast`` extra).
    """
    nodes = np.asarray(nodes, float)
    triangles = np.asarray(triangles, int)
    t = len(triangles)
    grad, area = _shape_gradients(nodes, triangles)
    weighted = area[:, None, None] * grad
    outer = np.einsum("taj,tbl->tabjl", weighted, grad).reshape(t, 9, 4)
    dofs = element_dofs(triangles).reshape(t, 3, 2)
    n2 = 2 * len(nodes)
    # element entry (a, b, i, k): row dof(a, i), column dof(b, k)
    rows = np.broadcast_to(dofs[:, :, None, :, None], (t, 3, 3, 2, 2)).reshape(-1)
    cols = np.broadcast_to(dofs[:, None, :, None, :], (t, 3, 3, 2, 2)).reshape(-1)
    keys, slots = np.unique(rows * n2 + cols, return_inverse=True)
    row_of, col_of = keys // n2, keys % n2
    indptr = np.searchsorted(row_of, np.arange(n2 + 1))
    transpose = np.searchsorted(keys, col_of * n2 + row_of)  # the pattern is symmetric
    gradient = gradient_operator(nodes, triangles)
    forces = sp.csr_matrix(gradient.multiply(np.repeat(area, 4)[:, None]).T)
    # the upper triangle of each element stiffness, to its place in the upper triangle of K
    local = np.stack([_ROW // 2, _COL // 2, _ROW % 2, _COL % 2])  # a, b, i, k
    upper = slots.reshape(t, 3, 3, 2, 2)[:, local[0], local[1], local[2], local[3]]
    upper = np.where(row_of[upper] <= col_of[upper], upper, transpose[upper])
    same = _UPPER[4]
    x, y = grad[:, :, 0], grad[:, :, 1]
    gram = (x[:, local[0, same]] * x[:, local[1, same]]
            + y[:, local[0, same]] * y[:, local[1, same]]).T
    return MeshGeometry(gradient, area, forces, outer, n2, slots.reshape(-1), col_of, indptr,
                        transpose, grad, dofs.reshape(t, 6), upper.reshape(-1),
                        np.flatnonzero(row_of > col_of), np.ascontiguousarray(gram), compiled)
