# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Plane-stress constant-strain-triangle FEM (paper Sec. 3.1, eqs. 10-14), vectorised.

DOF ordering is the paper's: ``(x_1, y_1, x_2, y_2, ...)``, i.e. node k owns DOFs 2k, 2k+1.
The stiffness is returned **dimensionless** (divided by E*h): in 2-D the CST stiffness does not
depend on the length unit, so K_SI = E*h * K_hat.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from squeeze_grasp_ros.mechanics.elastic.material import unit_elasticity_matrix
from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh, element_areas
from squeeze_grasp_ros.mechanics.errors import InvalidInputError


def strain_displacement(nodes: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Element strain-displacement matrices.

    Returns
    -------
    B : (t, 3, 6) ndarray
        Engineering strains (eps_xx, eps_yy, gamma_xy) = B @ element DOFs, 1/m.
    area : (t,) ndarray
        Element areas, m^2.
    """
    p = nodes[triangles]
    x, y = p[..., 0], p[..., 1]
    b = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1)
    c = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1)
    area = element_areas(nodes, triangles)
    if not np.all(area > 0):  # a zero area divides by zero below: NaN strains, a singular K
        k = int(np.argmin(np.where(np.isnan(area), -np.inf, area)))
        raise InvalidInputError(f"mesh element {k} (nodes {triangles[k].tolist()}) has area "
                                f"{area[k]:.3g} m^2: elements must be counter-clockwise with "
                                "a positive area (a degenerate or flipped triangle)")
    B = np.zeros((len(triangles), 3, 6))
    B[:, 0, 0::2] = b
    B[:, 1, 1::2] = c
    B[:, 2, 0::2] = c
    B[:, 2, 1::2] = b
    B /= (2.0 * area)[:, None, None]
    return B, area


def element_dofs(triangles: np.ndarray) -> np.ndarray:
    """(t, 6) global DOF indices of each element, in the paper's interleaved order."""
    return np.stack([2 * triangles, 2 * triangles + 1], axis=2).reshape(len(triangles), 6)


def stiffness_matrix(mesh: Mesh, nu: float) -> sp.csr_matrix:
    """Dimensionless global stiffness K_hat = K / (E h) as CSR (2n x 2n), symmetric PSD."""
    B, area = strain_displacement(mesh.nodes, mesh.triangles)
    D = unit_elasticity_matrix(nu)
    ke = area[:, None, None] * np.einsum("tki,kl,tlj->tij", B, D, B, optimize=True)
    dofs = element_dofs(mesh.triangles)
    rows = np.repeat(dofs, 6, axis=1).ravel()
    cols = np.tile(dofs, (1, 6)).ravel()
    K = sp.csr_matrix((ke.ravel(), (rows, cols)), shape=(2 * mesh.n, 2 * mesh.n))
    K.sum_duplicates()
    return K


def rigid_modes(nodes: np.ndarray, scale: float) -> np.ndarray:
    """Orthonormal basis (2n, 3) of the rigid motions, the paper's v_{2n-2}, v_{2n-1}, v_{2n} (eq.
    14).

    Columns: x translation, y translation, rotation about the node centroid; orthonormal under
    the unweighted nodal inner product (eq. 16). Coordinates are divided by ``scale`` (m) so the
    construction is dimensionless; the span does not depend on it.
    """
    n = len(nodes)
    R = np.zeros((2 * n, 3))
    R[0::2, 0] = 1.0 / np.sqrt(n)
    R[1::2, 1] = 1.0 / np.sqrt(n)
    q = (nodes - nodes.mean(axis=0)) / scale
    w = np.empty(2 * n)
    w[0::2], w[1::2] = -q[:, 1], q[:, 0]
    R[:, 2] = w / np.linalg.norm(w)
    return R


def rotation_mode_norm(nodes: np.ndarray, scale: float) -> float:
    """||w_perp|| of eq. (13) in units of ``scale``: converts a rotation coefficient to radians."""
    q = (nodes - nodes.mean(axis=0)) / scale
    return float(np.sqrt(np.sum(q * q)))


def element_strains(mesh: Mesh, displacement: np.ndarray) -> np.ndarray:
    """Engineering strains (t, 3) = (eps_xx, eps_yy, gamma_xy) for a nodal displacement (n, 2),
    m.
    """
    B, _ = strain_displacement(mesh.nodes, mesh.triangles)
    de = np.asarray(displacement, float).reshape(-1)[element_dofs(mesh.triangles)]
    return np.einsum("tij,tj->ti", B, de)


def principal_strains(strains: np.ndarray) -> np.ndarray:
    """Principal strains (t, 2) (largest first) from engineering strains (t, 3)."""
    return np.ascontiguousarray(principal_pair(strains[:, 0], strains[:, 1], strains[:, 2]).T)


def principal_pair(exx: np.ndarray, eyy: np.ndarray, gxy: np.ndarray) -> np.ndarray:
    """Principal strains (2, t), largest first, of engineering strains given by component
    (eps_xx, eps_yy, gamma_xy), each (t,): the rows of :func:`principal_strains`' columns.
    """
    mean = 0.5 * (exx + eyy)
    radius = np.sqrt((0.5 * (exx - eyy)) ** 2 + (0.5 * gxy) ** 2)
    out = np.empty((2, len(mean)))
    np.add(mean, radius, out=out[0])
    np.subtract(mean, radius, out=out[1])
    return out

