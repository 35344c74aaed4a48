# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Contact compliance: the pseudo-inverse K+ applied by sparse factorisation (docs/design.md §3).

The paper's A (eq. 23) is the contact block of K+. Two routes compute K+ b for equilibrated
loads:

* ``"factorized"`` (default): K with three rigid-body DOFs pinned is SPD; factor it once
  (SuperLU, symmetric mode), solve, and project the rigid modes out: K+ = P K_pin^-1 P with
  P = I - R R^T. Exact because an equilibrated load produces no reactions at the pins.
* ``"spectral"``: the paper's dense eigendecomposition (eqs. 15-24), with the rigid modes
  deflated explicitly (eigenproblem of K on the orthogonal complement of col(R)), kept as a
  reference to cross-check and to time against.

Everything inside is dimensionless: coordinates by the object size L, forces by E*h*L. The
boundary compliance (K+ restricted to the outer boundary DOFs) is cached on first use so any
contact set on the boundary costs a gather, independent of the mesh size.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from functools import cached_property
from typing import Literal

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from squeeze_grasp_ros.mechanics.elastic.fem import (
    rigid_modes,
    rotation_mode_norm,
    stiffness_matrix,
)
from squeeze_grasp_ros.mechanics.elastic.hyperelastic import gradient_operator
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh
from squeeze_grasp_ros.mechanics.elastic.schur import minimum_degree_order, trailing_factors
from squeeze_grasp_ros.mechanics.errors import ConditioningWarning, InvalidInputError

Route = Literal["factorized", "spectral"]
GRADIENT_BOUND_BYTES = 128 * 2**20
"""Memory an object keeps for :meth:`ElasticObject.load_gradients` (9 t floats per node)."""
ROUTES: tuple[str, ...] = ("factorized", "spectral")
CONDITION_WARN = 1e12
"""Condition estimate of a factorised or reduced matrix above which a ConditioningWarning is
issued."""


def node_dofs(nodes) -> np.ndarray:
    """Interleaved DOF indices (2m,) of ``nodes``: x_1, y_1, x_2, y_2, ..."""
    nodes = np.asarray(nodes, dtype=int).reshape(-1)
    dofs = np.empty(2 * nodes.size, int)
    np.multiply(nodes, 2, out=dofs[0::2])
    np.add(dofs[0::2], 1, out=dofs[1::2])
    return dofs


class FactorizedSolver:
    """K+ by a sparse factorisation of K with three rigid DOFs pinned.

    The free DOFs are ordered interior first (minimum-degree order of the interior block) and
    outer-boundary DOFs last, so the trailing block of the LU factors is the boundary Schur
    complement S: the pinned compliance on the boundary is S^-1, a dense (2b x 2b) inverse,
    instead of 2b sparse solves.
    """

    def __init__(self, K: sp.csr_matrix, R: np.ndarray, nodes: np.ndarray,
                 boundary_dofs: np.ndarray) -> None:
        self.K, self.R = K, R
        self.pins = self._pins(nodes, boundary_dofs)
        n_dof = K.shape[0]
        last = boundary_dofs[~np.isin(boundary_dofs, self.pins)]
        interior = np.setdiff1d(np.arange(n_dof), boundary_dofs)
        if len(interior):
            interior = interior[minimum_degree_order(K[interior][:, interior])]
        self.order = np.concatenate([interior, last])
        self.n_last = len(last)
        Kp = K[self.order][:, self.order].tocsc()
        self.lu = spla.splu(Kp, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                            options={"SymmetricMode": True})
        self.pivoted = not np.array_equal(self.lu.perm_r, np.arange(len(self.order)))
        self.factor_copies: tuple[sp.csc_matrix, sp.csc_matrix] | tuple[()] = ()
        self.condition = _condition_estimate(Kp, self.lu)

    @staticmethod
    def _pins(nodes: np.ndarray, boundary_dofs: np.ndarray) -> np.ndarray:
        """Three DOFs on the outer boundary that fix the rigid motions: both DOFs of the
        leftmost node and, at the node farthest from it, the DOF most perpendicular to the line.
        """
        bnodes = boundary_dofs[0::2] // 2
        a = int(bnodes[np.argmin(nodes[bnodes, 0] + 1e-3 * nodes[bnodes, 1])])
        b = int(bnodes[np.argmax(np.linalg.norm(nodes[bnodes] - nodes[a], axis=1))])
        d = nodes[b] - nodes[a]
        perp_dof = 2 * b + (0 if abs(d[1]) > abs(d[0]) else 1)
        return np.array(sorted([2 * a, 2 * a + 1, perp_dof]))

    def project(self, x: np.ndarray) -> np.ndarray:
        """Remove the rigid-mode components of the columns of ``x`` (P x)."""
        return x - self.R @ (self.R.T @ x)

    def pinned_solve(self, b: np.ndarray) -> np.ndarray:
        """X b with X = K_pin^-1 padded by zeros at the pinned DOFs."""
        y = np.zeros_like(b)
        y[self.order] = self.lu.solve(np.asfortranarray(b[self.order]))
        return y

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """K+ rhs for a (2n,) or (2n, k) right-hand side."""
        return self.solve_projected(rhs)[0]

    def solve_projected(self, rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(K+ rhs, P rhs): the solve and the projected right-hand side it solved for."""
        projected = self.project(np.asarray(rhs, float))
        return self.project(self.pinned_solve(projected)), projected

    def boundary_block(self, boundary_dofs: np.ndarray) -> np.ndarray:
        """K+ restricted to ``boundary_dofs`` (the DOFs ordered last), from the Schur complement.

        (P X P)_BB = X_BB - R_B (XR)_B^T - (XR)_B R_B^T + R_B (R^T X R) R_B^T, with X_BB = S^-1
        and XR from three solves.
        """
        n_first = len(self.order) - self.n_last
        if self.pivoted:
            E = np.zeros((self.K.shape[0], len(boundary_dofs)))
            E[boundary_dofs, np.arange(len(boundary_dofs))] = 1.0
            return self.solve(E)[boundary_dofs]
        L, U = trailing_factors(self.lu, n_first)
        # SuperLU keeps the sparse L and U it built for trailing_factors for as long as it
        # lives (scipy caches them: as large as the factorisation itself). Holding them here
        # too costs nothing and lets memory accounting (planning.resident_bytes) count them.
        self.factor_copies = (self.lu.L, self.lu.U)
        X = np.zeros((len(boundary_dofs), len(boundary_dofs)))
        where = np.full(self.K.shape[0], -1)
        where[boundary_dofs] = np.arange(len(boundary_dofs))
        idx = where[self.order[n_first:]]
        X[np.ix_(idx, idx)] = la.lu_solve((np.triu(U) + np.tril(L, -1), np.arange(len(L))),
                                          np.eye(len(L)))
        XR = self.pinned_solve(self.R)
        RB, XRB = self.R[boundary_dofs], XR[boundary_dofs]
        RXR = self.R.T @ XR
        return X - RB @ XRB.T - XRB @ RB.T + RB @ RXR @ RB.T


class SpectralSolver:
    """The paper's dense route: K = V Lambda V^T with the rigid modes deflated explicitly."""

    def __init__(self, K: sp.csr_matrix, R: np.ndarray) -> None:
        Q, _ = np.linalg.qr(R, mode="complete")
        Qc = Q[:, 3:]
        Kc = Qc.T @ (K @ Qc)
        lam, W = la.eigh(0.5 * (Kc + Kc.T))
        if lam[0] <= 0:
            raise InvalidInputError("stiffness matrix has a non-rigid zero mode (mesh not "
                                    "connected?)")
        self.V = Qc @ W
        self.lam = lam
        self.condition = float(lam[-1] / lam[0])

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """K+ rhs = V Lambda^-1 V^T rhs."""
        rhs = np.asarray(rhs, float)
        coeff = self.V.T @ rhs
        scaled = coeff / (self.lam[:, None] if coeff.ndim == 2 else self.lam)
        return self.V @ scaled

    def block(self, dofs: np.ndarray) -> np.ndarray:
        """The contact block of K+ (eq. 23) in O(m^2 n)."""
        Vc = self.V[dofs]
        return (Vc / self.lam) @ Vc.T


def _condition_estimate(Kr: sp.csc_matrix, lu) -> float:
    """1-norm condition estimate of the pinned stiffness from a few solves (Hager's method).

    One probe column (``t=1``): SciPy's default of two draws the second from numpy's global
    random state, so the reported estimate changed from run to run; with one it is a function
    of the matrix (a lower bound of the 1-norm condition number, as before).
    """
    n = Kr.shape[0]
    inv = spla.LinearOperator((n, n), matvec=lu.solve, rmatvec=lambda x: lu.solve(x, trans="T"),
                              dtype=float)
    return float(spla.norm(Kr, 1) * spla.onenormest(inv, t=1))


@dataclass(frozen=True)
class ElasticObject:
    """A meshed elastic object with its stiffness and a cached contact-compliance solver.

    Parameters
    ----------
    mesh : Mesh
        The triangulation (SI coordinates, m).
    material : Material
        E (Pa), nu, thickness h (m).
    route : {"factorized", "spectral"}
        How K+ is applied (see module docstring).
    """

    mesh: Mesh
    material: Material
    route: Route = "factorized"
    _diag: dict = field(default_factory=dict, repr=False, compare=False)
    _load_gradients: dict = field(default_factory=dict, repr=False, compare=False)
    _shared: dict = field(default_factory=dict, repr=False, compare=False)
    """What the users of this object keep with it, by their own keys, so that all of its
    users share it: the contact models' reduced contact sets
    (:meth:`~squeeze_grasp_ros.mechanics.squeeze.contact_model.ContactModel.set_data`)."""

    def __post_init__(self) -> None:
        if self.route not in ROUTES:
            raise InvalidInputError(f"solver route must be one of {ROUTES}, got {self.route!r}")

    @property
    def scale(self) -> float:
        """Length scale L, m, used to make coordinates dimensionless."""
        return self.mesh.size

    @cached_property
    def stiffness(self) -> sp.csr_matrix:
        """Dimensionless stiffness K_hat = K / (E h), CSR 2n x 2n."""
        return stiffness_matrix(self.mesh, self.material.nu)

    @cached_property
    def rigid(self) -> np.ndarray:
        """Orthonormal rigid modes R (2n, 3) (eq. 14)."""
        return rigid_modes(self.mesh.nodes, self.scale)

    @cached_property
    def rotation_norm(self) -> float:
        """||w_perp|| of eq. (13) in units of L."""
        return rotation_mode_norm(self.mesh.nodes, self.scale)

    @cached_property
    def solver(self) -> FactorizedSolver | SpectralSolver:
        """The K+ solver of the selected route (built on first use)."""
        if self.route == "spectral":
            s = SpectralSolver(self.stiffness, self.rigid)
        else:
            s = FactorizedSolver(self.stiffness, self.rigid, self.mesh.nodes / self.scale,
                                 node_dofs(self.mesh.boundary))
        self._diag["condition_estimate"] = s.condition
        self._diag["rigid_mode_residual"] = float(
            np.abs(self.stiffness @ self.rigid).max() / np.abs(self.stiffness).max())
        if s.condition > CONDITION_WARN:
            warnings.warn(f"stiffness condition estimate {s.condition:.3g} exceeds "
                          f"{CONDITION_WARN:.0e}: expect lost digits", ConditioningWarning)
        return s

    @cached_property
    def gradient(self) -> sp.csr_matrix:
        """Sparse (4t, 2n) map of dimensionless displacements to displacement gradients
        (:func:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic.gradient_operator`, X / L).
        """
        return gradient_operator(self.mesh.nodes / self.scale, self.mesh.triangles)

    @cached_property
    def rigid_gradients(self) -> np.ndarray:
        """Displacement gradients (4t, 3) of the rigid modes R (a rotation's is uniform)."""
        return self.gradient @ self.rigid

    def _gradients_of(self, nodes) -> list[tuple[np.ndarray, np.ndarray]]:
        """(gradients (t, 4, 2), their per-element Frobenius norms (t,)) per node, cached."""
        nodes = [int(k) for k in nodes]
        missing = sorted(set(nodes) - set(self._load_gradients))
        if missing:
            dofs = node_dofs(np.array(missing))
            loads = np.zeros((2 * self.mesh.n, len(dofs)))
            loads[dofs, np.arange(len(dofs))] = 1.0
            H = (self.gradient @ self.pinv_apply(loads)).reshape(-1, 4, len(missing), 2)
            for i, k in enumerate(missing):
                g = np.ascontiguousarray(H[:, :, i, :])
                self._load_gradients[k] = (g, np.sqrt((g * g).sum(axis=(1, 2))))
        out = [self._load_gradients[k] for k in nodes]
        keep = max(len(nodes), GRADIENT_BOUND_BYTES // (72 * len(self.mesh.triangles)))
        for k in list(self._load_gradients)[:max(len(self._load_gradients) - keep, 0)]:
            del self._load_gradients[k]
        return out

    def load_gradients(self, nodes) -> list[np.ndarray]:
        """For each mesh node k of ``nodes``: the displacement gradients (t, 4, 2) of every
        element per unit dimensionless load at k in x and in y (rows 2i + j: du_i/dX_j), so the
        field K+ f of loads f_k at those nodes has grad u_e = sum_k G_k[e] @ f_k.

        A node's gradients are computed on its first use (one solve with two right-hand sides)
        and kept, the least recently computed dropped beyond GRADIENT_BOUND_BYTES.
        """
        return [g for g, _ in self._gradients_of(nodes)]

    def gradient_bounds(self, nodes) -> np.ndarray:
        """Per element e and node k of ``nodes`` (t, len(nodes)): the Frobenius norm of
        :meth:`load_gradients` of element e per unit load at k in its worst direction, so that
        ||grad u_e|| <= sum_k bounds[e, k] ||f_k|| for the field K+ f of loads f_k.
        """
        return np.column_stack([n for _, n in self._gradients_of(nodes)])

    def pinv_apply(self, rhs: np.ndarray) -> np.ndarray:
        """Dimensionless K_hat+ applied to ``rhs`` (2n,) or (2n, k); records the residual."""
        if isinstance(self.solver, FactorizedSolver):  # it projects rhs: P rhs once
            x, P_rhs = self.solver.solve_projected(rhs)
        else:
            x = self.solver.solve(rhs)
            P_rhs = rhs - self.rigid @ (self.rigid.T @ rhs)
        res = np.linalg.norm(self.stiffness @ x - P_rhs) / max(np.linalg.norm(P_rhs), 1e-300)
        self._diag["last_solve_relative_residual"] = float(res)
        return x

    def compliance_block(self, nodes) -> np.ndarray:
        """Dimensionless contact compliance A_hat (2m, 2m) at mesh ``nodes`` (eq. 23).

        Boundary nodes come from the cached boundary compliance; other nodes by direct solves.
        """
        nodes = np.asarray(nodes, dtype=int)
        pos = self.boundary_positions(nodes)
        if np.all(pos >= 0):
            d = node_dofs(pos)
            return self.boundary_compliance[np.ix_(d, d)]
        dofs = node_dofs(nodes)
        if isinstance(self.solver, SpectralSolver):
            return self.solver.block(dofs)
        E = np.zeros((2 * self.mesh.n, len(dofs)))
        E[dofs, np.arange(len(dofs))] = 1.0
        return self.pinv_apply(E)[dofs]

    def boundary_positions(self, nodes) -> np.ndarray:
        """Position of each node in the outer boundary loop, -1 where it is not on it."""
        return self._boundary_lookup[np.asarray(nodes, dtype=int)]

    @cached_property
    def _boundary_lookup(self) -> np.ndarray:
        """Position in the outer boundary loop of every mesh node (n,), -1 off it."""
        lookup = -np.ones(self.mesh.n, dtype=int)
        lookup[self.mesh.boundary] = np.arange(len(self.mesh.boundary))
        lookup.flags.writeable = False
        return lookup

    @cached_property
    def boundary_compliance(self) -> np.ndarray:
        """Dimensionless K_hat+ restricted to the outer boundary DOFs (2b x 2b), symmetric."""
        dofs = node_dofs(self.mesh.boundary)
        if isinstance(self.solver, SpectralSolver):
            Ab = self.solver.block(dofs)
        else:
            Ab = self.solver.boundary_block(dofs)
        self._diag["boundary_compliance_asymmetry"] = float(
            np.abs(Ab - Ab.T).max() / np.abs(Ab).max())
        return 0.5 * (Ab + Ab.T)

    def boundary_rigid(self) -> np.ndarray:
        """Rows of R (2b, 3) at the outer boundary DOFs."""
        return self.rigid[node_dofs(self.mesh.boundary)]

    def diagnostics(self) -> dict[str, float]:
        """Condition estimate, rigid-mode residual ||K R||/||K||, last solve residual,
        asymmetry.
        """
        _ = self.solver
        return dict(self._diag)

    def precompute(self) -> "ElasticObject":
        """Build the stiffness, the factorisation and the boundary compliance now; returns self."""
        _ = self.boundary_compliance
        return self
