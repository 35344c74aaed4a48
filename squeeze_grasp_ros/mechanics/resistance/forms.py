# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The closed forms of the fixed-contact resistance (paper Sec. 6.1-6.2, App. D), pure linear
algebra.

Given the finger stiffness G = P^T C P (6 x 6) of the contact sets I, J, K of F1, F2, A, the
grasping fingers' work is W_F = 1/2 (d1, d2, 0)^T G (d1, d2, a) (eqs. 53, 94).

* :class:`StableForm`: d2 eliminated by (54), W_F = 1/2 d1^T H d1 + c^T d1 + omega (eq. 57,
  eqs. 86-88, 92-93), d1 = tau t + eta n with eta fixed by (55)/(66) (eq. 59), the parabola
  (60) in tau and its minimum tau* = -b1/b2 (b2 = t^T H t > 0, Theorem 11, Proposition 12).
* :class:`PureForm`: (d1, d2, a) = U tau over an orthonormal basis U of the pure resistances,
  a = Q tau (eq. 62), and the minimiser over Q^+ a + null(Q) for every rank of Q (eqs. 63, 91).

Everything is vectorised over rows of adversary translations a (N, 2); units are whatever G and
the centroids are given in (dimensionless inside :mod:`.resistance`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError

RANK_TOL = 1e-9
"""Singular values of Q (at most 1, U is orthonormal) below this count as zero."""


def perp(u: np.ndarray) -> np.ndarray:
    """``u`` rotated by +90 degrees over the last axis, so that (perp(u) . v) = u x v."""
    return np.stack([-u[..., 1], u[..., 0]], axis=-1)


def expansion_matrix(counts: Sequence[int]) -> np.ndarray:
    """The 2m x 6 expansion P of App. D: Delta = P (d1, d2, a) for set sizes |I|, |J|, |K|."""
    finger = np.repeat(np.arange(3), counts)
    rows = np.arange(len(finger))
    P = np.zeros((2 * len(finger), 6))
    P[2 * rows, 2 * finger] = 1.0
    P[2 * rows + 1, 2 * finger + 1] = 1.0
    return P


def null_basis(M: np.ndarray, rtol: float = 1e-10) -> np.ndarray:
    """Orthonormal basis (columns) of null(M) from the SVD, singular values below rtol*max
    dropped.
    """
    _, s, Vt = np.linalg.svd(M)
    rank = int(np.count_nonzero(s > rtol * max(s.max(initial=0.0), 1e-300)))
    return Vt[rank:].T


@dataclass(frozen=True)
class StableForm:
    """The stable resistance's W_F as a quadratic form in d1 (eq. 57), dimensionless.

    Attributes
    ----------
    H : (2, 2) ndarray
        S^T G S (eqs. 86, 92), positive semi-definite (Theorem 11, Proposition 12).
    c_map : (2, 2) ndarray
        c = c_map @ a (eqs. 87, 93).
    omega_map : (2, 2) ndarray
        Symmetric; omega = a^T omega_map a (eqs. 88, 93).
    eta_map : (2,) ndarray
        eta = d1 . n = eta_map . a, fixed by (55) / (66) (eq. 59).
    t, n : (2,) ndarray
        Unit vector of p - q (contact centroids of F1, F2) and its left normal (t x n = 1).
    ratios : (2,) ndarray
        |I|/|J| and |K|/|J|: d2 = -ratios[0] d1 - ratios[1] a (eq. 54 for segments).
    """

    H: np.ndarray
    c_map: np.ndarray
    omega_map: np.ndarray
    eta_map: np.ndarray
    t: np.ndarray
    n: np.ndarray
    ratios: np.ndarray

    @property
    def b2(self) -> float:
        """t^T H t (eq. 60), > 0 by Theorem 11 / Proposition 12."""
        return float(self.t @ self.H @ self.t)

    def d2(self, d1: np.ndarray, a: np.ndarray) -> np.ndarray:
        """F2's translation from (54) generalised: d2 = -(|I| d1 + |K| a) / |J|, over rows."""
        return -self.ratios[0] * d1 - self.ratios[1] * a

    def line(self, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All stable resistances to a (N, 2): x = x0 + z tau with x0 (N, 4) and z (4, 1)."""
        d1 = np.outer(a @ self.eta_map, self.n)
        z = np.concatenate([self.t, -self.ratios[0] * self.t])
        return np.hstack([d1, self.d2(d1, a)]), z[:, None]

    def coefficients(self, a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(b0, b1, eta), each (N,), of the parabola (60) for adversary translations a (N, 2)."""
        eta = a @ self.eta_map
        c = a @ self.c_map.T
        omega = np.einsum("ni,ij,nj->n", a, self.omega_map, a)
        Ht, Hn = self.H @ self.t, self.H @ self.n
        b1 = eta * (self.n @ Ht) + c @ self.t
        b0 = omega + eta * (0.5 * eta * (self.n @ Hn) + c @ self.n)
        return b0, b1, eta

    def optimum(self, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Optimal (d1, d2) rows (N, 4) and W*_F (N,) for a (N, 2): tau* = -b1/b2 (eqs. 60-61)."""
        b0, b1, eta = self.coefficients(a)
        tau = -b1 / self.b2
        d1 = np.outer(tau, self.t) + np.outer(eta, self.n)
        return np.hstack([d1, self.d2(d1, a)]), b0 - b1 * b1 / (2.0 * self.b2)


def stable_form(G: np.ndarray, counts: Sequence[int], centroids: np.ndarray) -> StableForm:
    """H, c, omega (App. D eqs. 86-88, 92-93) and eta (eq. 59/66) from G and the contact sets.

    Parameters
    ----------
    G : (6, 6) ndarray
        Finger stiffness P^T C P (any consistent units).
    counts : sequence of 3 int
        |I|, |J|, |K|.
    centroids : (3, 2) ndarray
        Contact centroids p, q, r of F1, F2, A (same length unit as a).

    Raises
    ------
    InvalidInputError
        If p = q: the direction t of eq. (59) is undefined.
    """
    nI, nJ, nK = (float(c) for c in counts)
    rIJ, rKJ = nI / nJ, nK / nJ
    I2, Z2 = np.eye(2), np.zeros((2, 2))
    S = np.vstack([I2, -rIJ * I2, Z2])
    c_side = np.vstack([Z2, -rKJ * I2, 0.5 * I2])
    w_left, w_right = np.vstack([Z2, -rKJ * I2, Z2]), np.vstack([Z2, -rKJ * I2, I2])
    omega = 0.5 * w_left.T @ G @ w_right
    p, q, r = np.asarray(centroids, float)
    dist = float(np.linalg.norm(p - q))
    if dist <= 1e-12 * max(float(np.abs(centroids).max()), 1e-300):
        raise InvalidInputError("contact centroids of F1 and F2 coincide: no stable resistance "
                                "line")
    t = (p - q) / dist
    H = S.T @ G @ S
    return StableForm(H=0.5 * (H + H.T), c_map=S.T @ G @ c_side, omega_map=0.5 * (omega + omega.T),
                      eta_map=(nK / (nI * dist)) * perp(q - r), t=t, n=perp(t),
                      ratios=np.array([rIJ, rKJ]))


@dataclass(frozen=True)
class PureForm:
    """Pure resistances x = U tau with a = Q tau (eq. 62) and their minimiser, dimensionless.

    Attributes
    ----------
    U : (6, k) ndarray
        Orthonormal basis of the pure (d1, d2, a): null(E^T P), k = 3 in general.
    rank : int
        rank of Q = (0, I2) U.
    singular_values : ndarray
        Singular values of Q.
    col_Q : (2, rank) ndarray
        Orthonormal basis of col(Q): the adversary translations that can be resisted purely.
    X0 : (4, 2) ndarray
        (d1, d2) of the minimum-norm tau = Q^+ a, per unit a.
    Z : (4, k - rank) ndarray
        (d1, d2) of null(Q): how a pure resistance to a fixed a can vary.
    gain : (4, 2) ndarray
        The optimum (d1*, d2*) = gain @ a for a in col(Q).
    hessian_condition : float
        Condition number of Z^T G_xx Z (1 when k = rank).
    """

    U: np.ndarray
    rank: int
    singular_values: np.ndarray
    col_Q: np.ndarray
    X0: np.ndarray
    Z: np.ndarray
    gain: np.ndarray
    hessian_condition: float

    def outside(self, a: np.ndarray) -> np.ndarray:
        """Relative distance (N,) of each row of a (N, 2) from col(Q); > 0 means unresistable."""
        proj = (a @ self.col_Q) @ self.col_Q.T
        return np.linalg.norm(a - proj, axis=1) / np.maximum(np.linalg.norm(a, axis=1), 1e-300)

    def violation(self, x6: np.ndarray) -> float:
        """Relative distance of x6 = (d1, d2, a) (6,) from the pure resistances span(U)."""
        return float(np.linalg.norm(x6 - self.U @ (self.U.T @ x6))
                     / max(float(np.linalg.norm(x6)), 1e-300))

    def line(self, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All pure resistances to a (N, 2) in col(Q): x = x0 + Z s with x0 (N, 4)."""
        return a @ self.X0.T, self.Z


def pure_form(G: np.ndarray, U: np.ndarray) -> PureForm:
    """Minimiser of W_F over the pure resistances spanned by ``U`` (6, k) (eqs. 62-63, 91, 94).

    Parameters
    ----------
    G : (6, 6) ndarray
        Finger stiffness P^T C P.
    U : (6, k) ndarray
        Orthonormal basis of the admissible (d1, d2, a).
    """
    Q = U[4:]
    Uq, s, Vt = np.linalg.svd(Q, full_matrices=True)
    rank = int(np.count_nonzero(s > RANK_TOL))
    Q_pinv = Vt[:rank].T @ (Uq[:, :rank] / s[:rank]).T
    X = U[:4]
    X0, Z = X @ Q_pinv, X @ Vt[rank:].T
    Gxx, Gxa = G[:4, :4], G[:4, 4:]
    if Z.shape[1] == 0:
        return PureForm(U, rank, s, Uq[:, :rank], X0, Z, X0, 1.0)
    Hs = Z.T @ Gxx @ Z
    gain = X0 - Z @ np.linalg.solve(Hs, Z.T @ (Gxx @ X0 + 0.5 * Gxa))
    return PureForm(U, rank, s, Uq[:, :rank], X0, Z, gain, float(np.linalg.cond(Hs)))
