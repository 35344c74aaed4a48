# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Sparse LU with chosen DOFs ordered last, whose trailing factor block is their Schur complement.

For a matrix ordered [first; last] and factored without pivots across the two blocks,
L_22 U_22 = K_ll - K_lf K_ff^-1 K_fl: the Schur complement of the last DOFs comes out of the
factorisation itself, instead of one solve per last DOF. The linear compliance
(:class:`~.compliance.FactorizedSolver`, last = the outer boundary) is built on it. The first
DOFs are put in a minimum-degree order of their own block (computed once per pattern), so the
fill is that of a direct factorisation of K_ff.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["minimum_degree_order", "trailing_factors"]


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
