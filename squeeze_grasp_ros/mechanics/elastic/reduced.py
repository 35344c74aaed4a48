# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Reduced stiffness of a contact set (paper Sec. 3.2-3.4, eqs. 22-33).

The saddle matrix M = [[A, B], [B^T, 0]] (eq. 27) mixes blocks of very different scale, so it
is never inverted. With Z an orthonormal basis of null(B^T) (B has full column rank 3 for
m >= 2, Lemma 3), the blocks of M^-1 (eq. 29) are

    C = Z (Z^T A Z)^-1 Z^T,   E^T = (B^T B)^-1 B^T (I - A C),   H = -(B^T B)^-1 B^T A E,

which satisfy eq. (30) exactly; C is symmetric PSD with null(C) = col(B) by construction
(Theorem 7). Z^T A Z is SPD by Lemma 4 and is factored by Cholesky.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as la

from squeeze_grasp_ros.mechanics.elastic.compliance import CONDITION_WARN, ElasticObject, node_dofs
from squeeze_grasp_ros.mechanics.errors import (
    ConditioningWarning,
    InvalidInputError,
    node_indices,
    require_finite,
)

REDUCED_KEPT = 1024
"""Reduced stiffnesses an object keeps for :func:`reduced_stiffness` (the oldest dropped)."""


@dataclass(frozen=True)
class ReducedStiffness:
    """Blocks of M and M^-1 for one contact set, in SI units.

    Attributes
    ----------
    contacts : (m,) ndarray of int
        Mesh node indices of the contact nodes.
    A : (2m, 2m) ndarray
        Contact compliance, m/N (eq. 23).
    B : (2m, 3) ndarray
        Contact rows of the orthonormal rigid modes (eq. 24), dimensionless.
    C : (2m, 2m) ndarray
        Reduced stiffness, N/m: contact forces F = C * contact displacements (eq. 31).
    E : (2m, 3) ndarray
        Rigid-component map: g = E^T * contact displacements, m (eq. 31).
    H : (3, 3) ndarray
        Lower-right block of M^-1, m/N (A E + B H = 0 gives H the units of A).
    condition : float
        2-norm condition number of Z^T A Z (the only matrix inverted).
    """

    contacts: np.ndarray
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    E: np.ndarray
    H: np.ndarray
    condition: float

    @property
    def m(self) -> int:
        """Number of contact nodes."""
        return len(self.contacts)

    def forces(self, delta: np.ndarray) -> np.ndarray:
        """Contact forces F = C delta (2m,), N, for contact displacements ``delta`` (2m,), m."""
        return self.C @ delta

    def rigid_coefficients(self, delta: np.ndarray) -> np.ndarray:
        """G = E^T delta (3,), m: the displacement field's components on the rigid modes."""
        return self.E.T @ delta

    def energy(self, delta: np.ndarray) -> float:
        """Strain energy U = 1/2 delta^T C delta, J (eq. 33)."""
        return 0.5 * float(delta @ self.C @ delta)

    def pure_part(self, delta: np.ndarray) -> np.ndarray:
        """(A C) delta: the pure contact displacement with the same deformation (Theorem 8)."""
        return self.A @ (self.C @ delta)


def null_space_basis(B: np.ndarray) -> np.ndarray:
    """Orthonormal basis Z (2m, 2m-3) of null(B^T) from a complete QR of B."""
    Q, _ = np.linalg.qr(B, mode="complete")
    return Q[:, B.shape[1] :]


def reduce_blocks(
    A_hat: np.ndarray, B: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Dimensionless (C_hat, E, H_hat, condition) from A_hat and B by the null-space form."""
    Z = null_space_basis(B)
    S = Z.T @ A_hat @ Z
    S = 0.5 * (S + S.T)
    try:
        cho = la.cho_factor(S)
    except la.LinAlgError:
        raise InvalidInputError(
            "Z^T A Z is not positive definite: contact nodes coincide or the compliance is corrupt"
        ) from None
    eig = np.linalg.eigvalsh(S)
    condition = float(eig[-1] / eig[0])
    if condition > CONDITION_WARN:
        warnings.warn(
            f"reduced compliance condition {condition:.3g} exceeds {CONDITION_WARN:.0e}",
            ConditioningWarning,
        )
    C = Z @ la.cho_solve(cho, Z.T)
    C = 0.5 * (C + C.T)
    BtB = B.T @ B
    Et = np.linalg.solve(BtB, B.T @ (np.eye(len(A_hat)) - A_hat @ C))
    E = Et.T
    H = -np.linalg.solve(BtB, B.T @ A_hat @ E)
    return C, E, 0.5 * (H + H.T), condition


def reduced_stiffness(obj: ElasticObject, contacts) -> ReducedStiffness:
    """Reduced stiffness of ``obj`` for contact nodes ``contacts`` (m >= 2 distinct nodes).

    The object keeps the last REDUCED_KEPT of them (by the nodes in their order), for all of
    its users: a sweep plans every parameter set of a placement on the same pair. The arrays
    are shared: do not write to them.

    Examples
    --------
    >>> from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
    >>> obj = scene_solid(load_scene(scene_file("disk")))
    >>> mesh = obj.mesh
    >>> i, j = (int(mesh.boundary[k]) for k in (0, len(mesh.boundary) // 2))
    >>> red = reduced_stiffness(obj, [i, j])
    >>> red.C.shape, bool(np.allclose(red.C, red.C.T, atol=1e-9 * abs(red.C).max()))
    ((4, 4), True)
    """
    contacts = node_indices("contacts", contacts, obj.mesh.n)
    if len(contacts) < 2:
        raise InvalidInputError(f"contacts needs at least 2 nodes (Lemma 2), got {len(contacts)}")
    if len(np.unique(contacts)) != len(contacts):
        raise InvalidInputError(f"contacts must be distinct nodes, got {contacts.tolist()}")
    kept = obj._shared.setdefault("reduced_stiffness", {})
    tag = tuple(contacts.tolist())
    red = kept.get(tag)
    if red is None:
        A_hat = obj.compliance_block(contacts)
        B = obj.rigid[node_dofs(contacts)]
        C_hat, E, H_hat, condition = reduce_blocks(A_hat, B)
        eh = obj.material.force_scale
        red = ReducedStiffness(contacts, A_hat / eh, B, C_hat * eh, E, H_hat / eh, condition)
        require_finite("reduced stiffness", red.C)
        if len(kept) >= REDUCED_KEPT:
            kept.pop(next(iter(kept)), None)
        kept[tag] = red
    return red


def rotation_angle(obj: ElasticObject, g: np.ndarray) -> float:
    """Angle (rad) of the rigid-rotation component for rigid coefficients ``g`` (m) (eqs.
    13-14).
    """
    return float(g[2] / (obj.scale * obj.rotation_norm))


def nodal_forces(obj: ElasticObject, contacts: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """Full nodal force vector (2n,), N, with ``forces`` (2m,) at ``contacts`` and zero
    elsewhere.
    """
    F = np.zeros(2 * obj.mesh.n)
    F[node_dofs(contacts)] = forces
    return F


def displacement_field(obj: ElasticObject, red: ReducedStiffness, delta: np.ndarray) -> np.ndarray:
    """Displacement of every node (n, 2), m, for contact displacements ``delta`` (eq. 32).

    One sparse solve: Delta = K+ F + R g with F = C delta, g = E^T delta.
    """
    F_hat = nodal_forces(obj, red.contacts, red.forces(delta)) / (
        obj.material.force_scale * obj.scale
    )
    u_hat = obj.pinv_apply(F_hat) + obj.rigid @ (red.rigid_coefficients(delta) / obj.scale)
    return (u_hat * obj.scale).reshape(-1, 2)


def boundary_displacement(
    obj: ElasticObject, red: ReducedStiffness, delta: np.ndarray
) -> np.ndarray:
    """Displacement of the outer-boundary nodes (b, 2), m, from the cached boundary compliance.

    Costs O(b m) after the precompute: no solve.
    """
    pos = obj.boundary_positions(red.contacts)
    if np.any(pos < 0):
        return displacement_field(obj, red, delta)[obj.mesh.boundary]
    F_hat = red.forces(delta) / (obj.material.force_scale * obj.scale)
    Abc = obj.boundary_compliance[:, node_dofs(pos)]
    u_hat = Abc @ F_hat + obj.boundary_rigid() @ (red.rigid_coefficients(delta) / obj.scale)
    return (u_hat * obj.scale).reshape(-1, 2)
