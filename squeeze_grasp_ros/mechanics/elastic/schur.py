# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Sparse LU with chosen DOFs ordered last, whose trailing factor block is their Schur complement.

For a matrix ordered [first; last] and factored without pivots across the two blocks,
L_22 U_22 = K_ll - K_lf K_ff^-1 K_fl: the Schur complement of the last DOFs comes out of the
factorisation itself, instead of one solve per last DOF. The linear compliance
(:class:`~.compliance.FactorizedSolver`, last = the outer boundary) and the nonlinear contact
response (:class:`CondensedLU`, last = the contact DOFs) are both built on it. The first DOFs
are put in a minimum-degree order of their own block (computed once per pattern), so the fill
is that of a direct factorisation of K_ff.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["CondensedLU", "PIVOT_THRESHOLDS", "condense", "minimum_degree_order",
           "trailing_factors"]


def minimum_degree_order(K_ff: "sp.spmatrix") -> np.ndarray:
    """Minimum-degree order (of K + K^T) of the rows and columns of a symmetric block: the
    index of the row at each position, from SuperLU's symbolic analysis of one factorisation.
    """
    lu = spla.splu(sp.csc_matrix(K_ff), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    return np.argsort(lu.perm_c)


def trailing_factors(lu: spla.SuperLU, first: int) -> tuple[np.ndarray, np.ndarray]:
    """Dense trailing blocks (L_22, U_22) of a SuperLU factorisation past position ``first``."""
    return (lu.L.tocsc()[first:, first:].toarray(), lu.U.tocsc()[first:, first:].toarray())


PIVOT_THRESHOLDS = (0.1, 0.0)
"""Partial-pivoting thresholds tried by :func:`condense`: SuperLU's diagonal preference first;
pure diagonal pivots if that moved a pivot across the interior/contact boundary."""


@dataclass(frozen=True)
class CondensedLU:
    """Sparse LU of a whole tangent K, its contact DOFs ordered last and shifted by s I.

    For block LU the trailing block L_22 U_22 is the Schur complement of the matrix, here
    S + s I with S = K_cc - K_cf K_ff^-1 K_fc, so dF/d delta comes out of the factorisation
    itself. The shift makes the whole matrix regular (K alone has the rigid motions of the free
    object in its null space) and leaves K_ff, hence S and every interior solve, unchanged;
    an interior solve K_ff^-1 takes two solves of the whole system.

    Attributes
    ----------
    lu : scipy.sparse.linalg.SuperLU
        Factors of K permuted to [interior in ``order``, contact DOFs].
    order : (f,) ndarray of int
        Interior DOF (index into the free DOFs) at each leading position.
    schur : (c, c) ndarray
        S in the contact DOF order.
    shift : float
        s.
    """

    lu: spla.SuperLU
    order: np.ndarray
    schur: np.ndarray
    shift: float

    def _solve(self, rf: np.ndarray, rc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        f = len(self.order)
        b = np.concatenate([rf[self.order], rc])
        x = self.lu.solve(b)
        xf = np.empty(f)
        xf[self.order] = x[:f]
        return xf, x[f:]

    def interior(self, r: np.ndarray) -> np.ndarray:
        """K_ff^-1 r: the interior part x0 of M^-1 [r; 0], M the shifted matrix, is
        K_ff^-1 r plus the interior's response to its contact part y0.
        """
        x0, y0 = self._solve(r, np.zeros(len(self.schur)))
        return x0 - self.interior_rate(y0)

    def interior_rate(self, d: np.ndarray) -> np.ndarray:
        """-K_ff^-1 K_fc d, the interior's response to contact displacements d: the interior
        part of the solution of M [x; y] = [0; (S + s I) d] (whose contact part is d).
        """
        rc = self.schur @ d + self.shift * d
        return self._solve(np.zeros(len(self.order)), rc)[0]


def condense(K: "spla.spmatrix", free: np.ndarray, cdofs: np.ndarray,
             order: np.ndarray) -> CondensedLU | None:
    """:class:`CondensedLU` of the tangent ``K`` with the interior DOFs ``free`` in the
    fill-reducing ``order`` (indices into ``free``) and ``cdofs`` last; None if every pivoting
    threshold moved a pivot between the two blocks (a singular interior).
    """
    lead = len(free)
    dofs = np.concatenate([free[order], cdofs])
    shift = float(abs(K).max())
    Kp = (K[dofs][:, dofs] + sp.diags(np.r_[np.zeros(lead), np.full(len(cdofs), shift)])).tocsc()
    for threshold in PIVOT_THRESHOLDS:
        lu = spla.splu(Kp, permc_spec="NATURAL", diag_pivot_thresh=threshold,
                       options={"SymmetricMode": True})
        # L U = Pr K Pc: LU row i is K row argsort(perm_r)[i], column j K column
        # argsort(perm_c)[j]; both must stay within their block.
        rows = np.argsort(lu.perm_r)[lead:] - lead
        cols = np.argsort(lu.perm_c)[lead:] - lead
        if rows.min() >= 0 and cols.min() >= 0:
            break
    else:
        return None
    L22, U22 = trailing_factors(lu, lead)
    block = L22 @ U22
    schur = np.empty_like(block)
    schur[np.ix_(rows, cols)] = block
    schur -= shift * np.eye(len(cdofs))
    return CondensedLU(lu, np.asarray(order), 0.5 * (schur + schur.T), shift)
