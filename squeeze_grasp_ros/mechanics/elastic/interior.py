# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The interior block of a contact set's tangent: its LDL^T factorisation and the contact
stiffness dF/d delta as an operator.

With the contact DOFs c prescribed, the interior (free) DOFs f of the tangent K carry the
equilibrium. :class:`TangentFactor` factorises K_ff by LDL^T (QDLDL, with its own
approximate-minimum-degree order; no pivoting: K_ff of a stable state is positive definite),
holding the contact DOFs as identity rows, so that one pattern, ordering and solver serve every
contact set of an object. :class:`InteriorBlocks` gathers a set's K_fc and K_cc out of the
assembled tangent through index maps built once per set. :class:`ContactStiffness` is
S = K_cc - K_cf K_ff^-1 K_fc of one state applied to vectors, one interior solve per vector
(memoised): the stepper needs S times the finger motion (and one more vector per sliding
contact), never the whole matrix.

>>> import numpy as np, scipy.sparse as sp
>>> K = sp.csr_matrix(np.array([[4.0, 1, 0], [1, 3, 1], [0, 1, 2]]))
>>> blocks = InteriorBlocks(K, free=np.array([0, 1]), cdofs=np.array([2]))
>>> S = blocks.contact_stiffness(K, blocks.factor(K))
>>> round(float((S @ np.ones(1))[0]), 12)  # 2 - [0 1] [[4 1] [1 3]]^-1 [0 1]^T = 2 - 4/11
1.636363636364
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

__all__ = ["ContactStiffness", "InteriorBlocks", "TangentFactor"]


def _gather(K: sp.csr_matrix, rows: np.ndarray, cols: np.ndarray, *,
            upper: bool = False) -> tuple[sp.csc_matrix, np.ndarray]:
    """The block K[rows][:, cols] (its upper triangle if ``upper``) as a CSC pattern and the
    positions of its entries in ``K.data``.
    """
    coded = sp.csr_matrix((np.arange(1, K.nnz + 1, dtype=float), K.indices, K.indptr),
                          shape=K.shape)
    block = coded[rows][:, cols]
    block = (sp.triu(block) if upper else block).tocsc()
    block.sort_indices()
    return block, block.data.astype(np.int64) - 1


def _values(block: sp.csc_matrix, at: np.ndarray, K: sp.csr_matrix) -> sp.csc_matrix:
    """The ``block`` pattern from :func:`_gather` filled with the entries of the tangent ``K``."""
    out = block.copy()
    out.data = K.data[at]
    return out


@dataclass
class TangentFactor:
    """LDL^T factorisation of tangents of one mesh with a set of DOFs held: their rows and
    columns replaced by those of the identity, which leaves K_ff of the other DOFs. Every contact
    set of an object so shares one sparsity pattern, one ordering and one QDLDL solver, which
    refactors in place (mutable).

    Attributes
    ----------
    owner : object
        Token of the state whose factorisation is held (set by :meth:`factor`).
    held : tuple of int or None
        The held DOFs of that factorisation.
    tangent : scipy.sparse.csr_matrix or None
        Its tangent.
    """

    owner: object = None
    held: tuple | None = None
    tangent: sp.csr_matrix | None = field(default=None, repr=False)
    _solver: "object | None" = field(default=None, repr=False)
    _masks: dict = field(default_factory=dict, repr=False)

    def _layout(self, K: sp.csr_matrix) -> None:
        self._upper, self._upper_at = _gather(K, np.arange(K.shape[0]), np.arange(K.shape[1]),
                                              upper=True)
        coo = self._upper.tocoo()
        self._rows, self._cols = coo.row, coo.col

    def _mask(self, held: tuple) -> tuple[np.ndarray, np.ndarray]:
        """(entries in a held row or column, held diagonal entries) of the upper pattern."""
        if held not in self._masks:
            dofs = np.array(held)
            off = np.isin(self._rows, dofs) | np.isin(self._cols, dofs)
            self._masks[held] = (np.flatnonzero(off),
                                 np.flatnonzero(off & (self._rows == self._cols)))
        return self._masks[held]

    def factor(self, K: sp.csr_matrix, held: tuple, owner: object = None) -> None:
        """Factorise the tangent ``K`` with the DOFs ``held`` held, for the state ``owner``.

        Raises
        ------
        RuntimeError
            If K_ff is singular (QDLDL meets a zero pivot).
        """
        if self._solver is None:
            self._layout(K)
        data = K.data[self._upper_at]
        off, diagonal = self._mask(held)
        data[off] = 0.0
        data[diagonal] = 1.0
        self._upper.data = data
        if self._solver is None:
            import qdldl  # only the large-deformation models need it (``pip install qdldl``)

            self._solver = qdldl.Solver(self._upper, upper=True)
        else:
            self._solver.update(self._upper, upper=True)
        self.owner, self.held, self.tangent = owner, held, K

    def solve(self, b: np.ndarray) -> np.ndarray:
        """The solution of (K with the held DOFs held) x = b; a b that is zero on the held
        DOFs gives an x that is zero there, K_ff^-1 b on the others.
        """
        return self._solver.solve(b)


@dataclass
class InteriorBlocks:
    """Index maps from an assembled tangent K (fixed CSR pattern) to the blocks of one contact
    set, and the K_ff solves of a shared :class:`TangentFactor`.

    Parameters
    ----------
    pattern : scipy.sparse.csr_matrix
        A tangent of the mesh (only its pattern is used).
    free, cdofs : (f,), (c,) ndarray of int
        Interior and contact DOFs.
    shared : TangentFactor
        The object's factorisation (one per mesh, shared by its contact sets).
    """

    pattern: sp.csr_matrix
    free: np.ndarray
    cdofs: np.ndarray
    shared: TangentFactor = field(default_factory=TangentFactor)

    def __post_init__(self) -> None:
        self.held = tuple(int(k) for k in self.cdofs)
        self._fc = _gather(self.pattern, self.free, self.cdofs)
        self._cc = _gather(self.pattern, self.cdofs, self.cdofs)

    def _solve(self, r: np.ndarray) -> np.ndarray:
        b = np.zeros(self.pattern.shape[0])
        b[self.free] = r
        return self.shared.solve(b)[self.free]

    def factor(self, K: sp.csr_matrix, owner: object = None) -> Callable[[np.ndarray],
                                                                          np.ndarray]:
        """Factorise K_ff of the tangent ``K`` (same pattern) and return its solve; ``owner``
        names the state the factorisation now belongs to.
        """
        self.shared.factor(K, self.held, owner)
        return self._solve

    @property
    def owner(self) -> object:
        """The state whose factorisation of this set's K_ff is held, None if none is."""
        return self.shared.owner if self.shared.held == self.held else None

    @owner.setter
    def owner(self, token: object) -> None:
        self.shared.owner = token

    @property
    def factored(self) -> sp.csr_matrix | None:
        """The tangent whose K_ff of this set is factorised now, None if none is."""
        return self.shared.tangent if self.shared.held == self.held else None

    @property
    def solve(self) -> Callable[[np.ndarray], np.ndarray] | None:
        """The solve of the factorisation of this set's K_ff held now (of whichever state
        :attr:`owner` names), None if the object's factorisation is of another set.
        """
        return self._solve if self.shared.held == self.held else None

    def contact_stiffness(self, K: sp.csr_matrix, solve: Callable[[np.ndarray], np.ndarray],
                          owner: object = None) -> "ContactStiffness":
        """S of the tangent ``K`` whose K_ff ``solve`` factorises (see :meth:`factor`)."""
        return ContactStiffness(_values(*self._cc, K).toarray(), _values(*self._fc, K), solve,
                                owner, K)


@dataclass
class ContactStiffness:
    """dF/d delta = K_cc - K_cf K_ff^-1 K_fc of one state, applied to vectors (``S @ v``).

    Attributes
    ----------
    cc : (c, c) ndarray
        K_cc.
    fc : scipy.sparse.csc_matrix
        K_fc.
    solve : callable
        r -> K_ff^-1 r for this state (the caller keeps it valid: see
        :meth:`~squeeze_grasp_ros.mechanics.elastic.contact_response.ContactResponse`).
    owner : object
        The token of this state in :attr:`InteriorBlocks.owner`.
    tangent : scipy.sparse.csr_matrix
        The whole tangent K of the state.
    """

    cc: np.ndarray
    fc: sp.csc_matrix
    solve: Callable[[np.ndarray], np.ndarray]
    owner: object = None
    tangent: sp.csr_matrix | None = field(default=None, repr=False)
    _memo: dict = field(default_factory=dict, repr=False)

    @property
    def scale(self) -> float:
        """Largest |entry| of K_cc: the stiffness scale of tolerances."""
        return float(np.abs(self.cc).max())

    def _known(self, d: np.ndarray) -> np.ndarray | None:
        """K_ff^-1 K_fc d if d is a memoised vector or a multiple of one, else None."""
        hit = self._memo.get(d.tobytes())
        if hit is not None:
            return hit[1]
        scale = np.abs(d).max()
        for v, x in self._memo.values():
            vv = float(v @ v)
            if vv > 0:
                alpha = float(d @ v) / vv
                if np.abs(d - alpha * v).max() <= 1e-14 * scale:
                    return alpha * x
        return None

    def knows(self, d: np.ndarray) -> bool:
        """Whether :meth:`interior_response` of ``d`` needs no solve."""
        return self._known(np.ascontiguousarray(d, float)) is not None

    def interior_response(self, d: np.ndarray) -> np.ndarray:
        """K_ff^-1 K_fc d: minus the interior's displacement for contact displacements d.

        Memoised, and a multiple of a memoised d is answered by the same multiple (the stepper
        asks for the finger motion, then for multiples of it as Newton predictors).
        """
        d = np.ascontiguousarray(d, float)
        x = self._known(d)
        if x is None:
            x = self.solve(self.fc @ d)
            self._memo[d.tobytes()] = (d, x)
        return x

    def __matmul__(self, V: np.ndarray) -> np.ndarray:
        V = np.asarray(V, float)
        if V.ndim == 1:
            return self.cc @ V - self.fc.T @ self.interior_response(V)
        return np.column_stack([self @ V[:, j] for j in range(V.shape[1])]).reshape(
            len(self.cc), V.shape[1])

    def toarray(self) -> np.ndarray:
        """S as a dense matrix (one interior solve per contact DOF)."""
        return self @ np.eye(len(self.cc))
