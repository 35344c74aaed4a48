# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The interior block of a contact set's tangent: its sparse factorisation and the contact
stiffness dF/d delta as an operator.

With the contact DOFs c prescribed, the interior (free) DOFs f of the tangent K carry the
equilibrium. :class:`TangentFactor` factorises K_ff, holding the contact DOFs as identity rows,
so that one pattern, ordering and symbolic analysis serve every contact set of an object. Two
factorisers (:class:`~squeeze_grasp_ros.mechanics.vocabulary.Factorizer`):

- ``cholmod``: the supernodal Cholesky factorisation LL^T of SuiteSparse CHOLMOD (through
  cvxopt, the ``cholmod`` extra), in METIS's nested-dissection order (pymetis, same extra) or
  CHOLMOD's approximate minimum degree, whichever fills less (its analysis tries both; AMD
  on the 2,054-node foam square, METIS on 8,038 nodes and more): dense BLAS kernels on the
  supernodes, about 5x faster than QDLDL on an 8,000-node object, where the factorisation is
  most of an evaluation's cost. It needs K_ff positive definite (every stable state); a tangent it
  refuses is factorised by QDLDL.
- ``qdldl``: LDL^T without pivoting by QDLDL, with its own AMD order; needs only nonzero pivots.
  The default when cvxopt is not installed.

:class:`InteriorBlocks` gathers a set's K_fc and K_cc out of the assembled tangent through index
maps built once per set. :class:`ContactStiffness` is S = K_cc - K_cf K_ff^-1 K_fc of one state
applied to vectors, one interior solve per vector (memoised): the stepper needs S times the
finger motion (and one more vector per sliding contact), never the whole matrix.

>>> import numpy as np, scipy.sparse as sp
>>> K = sp.csr_matrix(np.array([[4.0, 1, 0], [1, 3, 1], [0, 1, 2]]))
>>> blocks = InteriorBlocks(K, free=np.array([0, 1]), cdofs=np.array([2]))
>>> S = blocks.contact_stiffness(K, blocks.factor(K))
>>> round(float((S @ np.ones(1))[0]), 12)  # 2 - [0 1] [[4 1] [1 3]]^-1 [0 1]^T = 2 - 4/11
1.636363636364
"""
from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from squeeze_grasp_ros.extras import install_hint, installed
from squeeze_grasp_ros.mechanics.vocabulary import Factorizer
from squeeze_grasp_ros.threads import one_blas_thread

__all__ = ["ContactStiffness", "Fill", "InteriorBlocks", "MAX_BORDERED_DOFS", "PatternLayout",
           "TangentFactor", "default_factorizer", "factorizer", "nested_dissection"]

_FACTORIZER: list[Factorizer | None] = [None]

MAX_BORDERED_DOFS = 4
"""A contact set whose DOFs add at most this many to those of the factorisation held (the set
before one or two nodes touched) solves with it bordered (:class:`InteriorBlocks`) instead of a
factorisation of its own: one solve per added DOF against one factorisation, which costs 4-8
solves on the foam square's meshes."""


def default_factorizer() -> Factorizer:
    """The factoriser new :class:`TangentFactor` objects use: the one set by
    :func:`factorizer`, else ``cholmod`` when cvxopt is installed, else ``qdldl``.
    """
    if _FACTORIZER[0] is not None:
        return _FACTORIZER[0]
    return Factorizer.CHOLMOD if installed("cvxopt") else Factorizer.QDLDL


@contextmanager
def factorizer(method: Factorizer | str) -> Iterator[None]:
    """Within the block, new :class:`TangentFactor` objects use ``method`` (for comparing the
    factorisers on one squeeze).

    Raises
    ------
    ImportError
        If ``method`` is ``cholmod`` and cvxopt is not installed.
    """
    method = Factorizer(method)
    if method == Factorizer.CHOLMOD and not installed("cvxopt"):
        raise ImportError(f"the cholmod factoriser needs cvxopt: {install_hint('cvxopt')}")
    before, _FACTORIZER[0] = _FACTORIZER[0], method
    try:
        yield
    finally:
        _FACTORIZER[0] = before


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


def nested_dissection(pattern: sp.spmatrix) -> np.ndarray | None:
    """METIS's nested-dissection order of the DOFs of a tangent with the sparsity ``pattern``
    (two DOFs per node, x and y, kept together: the order is that of the node graph), as the
    permutation p of P K P^T = K[p][:, p]; None if pymetis is not installed.

    On the foam square's interior tangent it needs 19 % (8,038 nodes) and 33 % (20,054) fewer
    flops than approximate minimum degree, and 7-10 % fewer entries of L.

    >>> import scipy.sparse as sp
    >>> order = nested_dissection(sp.eye(6, k=2) + sp.eye(6) + sp.eye(6, k=-2))
    >>> order is None or sorted(order.tolist()) == list(range(6))
    True
    """
    if not installed("pymetis"):
        return None
    import pymetis

    structure = sp.csr_matrix(pattern, dtype=bool).astype(np.int8)
    nodes = sp.csr_matrix((structure + structure.T)[0::2][:, 0::2])
    nodes.setdiag(0)
    nodes.eliminate_zeros()
    perm, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(nodes.indptr, nodes.indices))
    perm = np.asarray(perm, dtype=np.int64)
    order = np.stack([2 * perm, 2 * perm + 1], 1).reshape(-1)
    return order[order < pattern.shape[0]]  # an odd size: the last node has x only


@dataclass(frozen=True)
class Fill:
    """Size and cost of one factorisation of K_ff.

    Attributes
    ----------
    nnz : int
        Entries of the factor L as stored (diagonal included; a supernodal factor stores the
        zeros inside its dense supernodes).
    flops : float
        Multiply-adds of the numeric factorisation, sum over the columns of L of (entries)^2.
    """

    nnz: int
    flops: float


@dataclass
class PatternLayout:
    """What the sparsity pattern of an object's tangents fixes for their factorisations, built
    on first use and then only read: the upper triangle's layout, the held-DOF masks, the
    nested-dissection order and each contact set's block gathers (:class:`InteriorBlocks`).

    Every contact model of one object shares one (kept on the object), so a planner or a sweep
    that squeezes the object many times orders the pattern and gathers a set's blocks once;
    the numeric factorisations stay with each model's :class:`TangentFactor`, so a squeeze's
    floats do not depend on what was squeezed before. Everything here is a function of the
    pattern: sharing it changes no result.
    """

    upper: sp.csc_matrix | None = field(default=None, repr=False)
    upper_at: np.ndarray | None = field(default=None, repr=False)
    rows: np.ndarray | None = field(default=None, repr=False)
    cols: np.ndarray | None = field(default=None, repr=False)
    _orders: dict = field(default_factory=dict, repr=False)
    _masks: dict = field(default_factory=dict, repr=False)
    _blocks: dict = field(default_factory=dict, repr=False)

    def ensure(self, K: sp.csr_matrix) -> None:
        """Lay out the upper triangle of the pattern of ``K`` (once)."""
        if self.upper is None:
            upper, at = _gather(K, np.arange(K.shape[0]), np.arange(K.shape[1]), upper=True)
            coo = upper.tocoo()
            self.upper_at, self.rows, self.cols = at, coo.row, coo.col
            self.upper = upper

    def mask(self, held: tuple) -> tuple[np.ndarray, np.ndarray]:
        """(entries in a held row or column, held diagonal entries) of the upper pattern."""
        if held not in self._masks:
            dofs = np.array(held)
            off = np.isin(self.rows, dofs) | np.isin(self.cols, dofs)
            self._masks[held] = (np.flatnonzero(off),
                                 np.flatnonzero(off & (self.rows == self.cols)))
        return self._masks[held]

    def order(self, upper: sp.csc_matrix, held: tuple) -> np.ndarray | None:
        """:func:`nested_dissection` of ``upper``, the pattern with the DOFs ``held`` held
        (once per held set; None without pymetis).
        """
        if held not in self._orders:
            self._orders[held] = nested_dissection(upper)
        return self._orders[held]

    def blocks(self, K: sp.csr_matrix, free: np.ndarray, cdofs: np.ndarray) -> tuple:
        """(K_fc, K_cc) gathers of :func:`_gather` for the contact DOFs ``cdofs``, kept when
        ``free`` is every other DOF (how contact sets are made).
        """
        held = tuple(int(k) for k in cdofs)
        kept = self._blocks.get(held)
        if kept is not None:
            return kept
        out = (_gather(K, free, cdofs), _gather(K, cdofs, cdofs))
        others = np.ones(K.shape[0], dtype=bool)
        others[cdofs] = False
        if len(free) == int(others.sum()) and bool(others[free].all()):
            self._blocks[held] = out
        return out


@dataclass
class TangentFactor:
    """Factorisation of tangents of one mesh with a set of DOFs held: their rows and columns
    replaced by those of the identity, which leaves K_ff of the other DOFs. Every contact set of
    an object so shares one sparsity pattern, one ordering and one symbolic analysis; the
    numeric factorisation is redone in place (mutable).

    Parameters
    ----------
    method : Factorizer, optional
        ``cholmod`` or ``qdldl`` (default: :func:`default_factorizer`).

    Attributes
    ----------
    owner : object
        Token of the state whose factorisation is held (set by :meth:`factor`).
    held : tuple of int or None
        The held DOFs of that factorisation.
    tangent : scipy.sparse.csr_matrix or None
        Its tangent.
    fallbacks : int
        Tangents the Cholesky factorisation refused (K_ff not positive definite) and QDLDL's
        LDL^T factorised.
    analyses : int
        Orderings and symbolic analyses done (CHOLMOD's, QDLDL's): one per factoriser used,
        however many tangents and contact sets it factorises.
    generation : int
        Numeric factorisations done: what is derived from the one held (the bordered solves of
        :class:`InteriorBlocks`) is valid while this is unchanged.
    bordered : int
        Contact sets that solved with the factorisation held of a subset of their DOFs,
        bordered (:class:`InteriorBlocks`), instead of factorising their own K_ff.
    """

    method: Factorizer = field(default_factory=default_factorizer)
    owner: object = None
    held: tuple | None = None
    tangent: sp.csr_matrix | None = field(default=None, repr=False)
    fallbacks: int = 0
    analyses: int = 0
    generation: int = 0
    bordered: int = 0
    layout: PatternLayout = field(default_factory=PatternLayout, repr=False)
    _upper: sp.csc_matrix | None = field(default=None, repr=False)
    _ldlt: "object | None" = field(default=None, repr=False)  # a qdldl.Solver
    _cholesky: tuple | None = field(default=None, repr=False)
    _solve: Callable[[np.ndarray], np.ndarray] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self.method = Factorizer(self.method)

    def _held_upper(self, K: sp.csr_matrix, held: tuple) -> sp.csc_matrix:
        """The upper triangle of ``K`` with the DOFs ``held`` held (the shared pattern)."""
        layout = self.layout
        layout.ensure(K)
        if self._upper is None:
            self._upper = layout.upper.copy()  # its values are this factoriser's own
        data = K.data[layout.upper_at]
        off, diagonal = layout.mask(held)
        data[off] = 0.0
        data[diagonal] = 1.0
        self._upper.data = data
        return self._upper

    def _symbolic(self, upper: sp.csc_matrix, held: tuple) -> tuple:
        """(cvxopt matrix of the pattern of ``upper``, CHOLMOD's symbolic factorisation of it:
        in the order of :func:`nested_dissection` or CHOLMOD's AMD order, whichever fills less;
        AMD without pymetis).
        """
        import cvxopt
        from cvxopt import cholmod

        matrix = cvxopt.spmatrix(cvxopt.matrix(upper.data), cvxopt.matrix(self.layout.rows),
                                 cvxopt.matrix(self.layout.cols), upper.shape)
        order = self.layout.order(upper, held)
        if order is None:
            return matrix, cholmod.symbolic(matrix, uplo="U")
        return matrix, cholmod.symbolic(matrix, p=cvxopt.matrix(order.tolist(), tc="i"), uplo="U")

    def _cholmod(self, upper: sp.csc_matrix,
                 held: tuple) -> Callable[[np.ndarray], np.ndarray] | None:
        """Supernodal LL^T of ``upper`` by CHOLMOD (symbolic analysis once); its solve, or None
        if the matrix is not positive definite.
        """
        import cvxopt
        from cvxopt import cholmod

        if self._cholesky is None:
            self._cholesky = self._symbolic(upper, held)
            self.analyses += 1
        matrix, factor = self._cholesky
        matrix.V = cvxopt.matrix(upper.data)
        try:
            cholmod.numeric(matrix, factor)
        except ArithmeticError:
            return None

        def solve(b: np.ndarray) -> np.ndarray:
            b = np.asarray(b, float)
            x = cvxopt.matrix(b)  # (n, k): k right-hand sides in one pass over the factor
            cholmod.solve(factor, x)
            return np.asarray(x).reshape(b.shape)

        return solve

    def _qdldl(self, upper: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
        """LDL^T of ``upper`` by QDLDL (ordering once); its solve.

        Raises
        ------
        RuntimeError
            If QDLDL meets a zero pivot.
        """
        if self._ldlt is None:
            import qdldl  # only the large-deformation models need it (``pip install qdldl``)

            self._ldlt = qdldl.Solver(upper, upper=True)
            self.analyses += 1
        else:
            self._ldlt.update(upper, upper=True)
        ldlt = self._ldlt

        def solve(b: np.ndarray) -> np.ndarray:
            b = np.asarray(b, float)
            if b.ndim == 1:
                return ldlt.solve(b)
            return np.column_stack([ldlt.solve(column) for column in b.T])

        return solve

    def factor(self, K: sp.csr_matrix, held: tuple, owner: object = None) -> None:
        """Factorise the tangent ``K`` with the DOFs ``held`` held, for the state ``owner``.

        Raises
        ------
        RuntimeError
            If K_ff is singular (QDLDL meets a zero pivot).
        """
        upper = self._held_upper(K, held)
        self.owner = self.held = self.tangent = self._solve = None
        self.generation += 1
        solve = None
        with one_blas_thread():
            if self.method == Factorizer.CHOLMOD:
                solve = self._cholmod(upper, held)
                if solve is None:
                    self.fallbacks += 1
            self._solve = self._qdldl(upper) if solve is None else solve
        self.owner, self.held, self.tangent = owner, held, K

    def solve(self, b: np.ndarray) -> np.ndarray:
        """The solution of (K with the held DOFs held) x = b, for b (n,) or (n, k) (k
        right-hand sides); a b that is zero on the held DOFs gives an x that is zero there,
        K_ff^-1 b on the others (factorisations and solves run BLAS on one thread:
        :func:`~squeeze_grasp_ros.threads.one_blas_thread`).
        """
        with one_blas_thread():
            return self._solve(b)

    def fill(self, K: sp.csr_matrix, held: tuple) -> Fill:
        """Entries and flops of the factor of ``K`` with ``held`` held, in this factoriser's
        order (a separate factorisation: the one held is kept).
        """
        upper = self._held_upper(K, held)
        if self.method == Factorizer.CHOLMOD:
            from cvxopt import cholmod

            matrix, factor = self._symbolic(upper, held)
            cholmod.numeric(matrix, factor)
            L = cholmod.getfactor(factor)
            counts = np.bincount(np.asarray(L.J).reshape(-1), minlength=upper.shape[0])
        else:
            import qdldl

            L = qdldl.Solver(upper, upper=True).factors()[0]
            counts = np.diff(L.indptr) + 1
        return Fill(int(counts.sum()), float(np.sum(counts.astype(float) ** 2)))


@dataclass
class InteriorBlocks:
    """Index maps from an assembled tangent K (fixed CSR pattern) to the blocks of one contact
    set, and the K_ff solves of a shared :class:`TangentFactor`.

    The shared factorisation serves this set when it holds this set's DOFs, or a subset of them
    missing at most MAX_BORDERED_DOFS (the set before a node touched a tip: the DOFs it adds
    are a low-rank change of the constrained system). A solve then borders the held factor:
    with A the held matrix, D the DOFs this set adds and Z = A^-1 E_D (one solve per added
    DOF, once per factorisation), x = A^-1 b - Z (E_D^T Z)^-1 E_D^T A^-1 b is zero on D and
    solves this set's K_ff x = b on its free DOFs (exact up to round-off, one factorisation
    fewer).

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
    _border: tuple = field(default=(-1, None), repr=False)

    def __post_init__(self) -> None:
        self.held = tuple(int(k) for k in self.cdofs)
        self._fc, self._cc = self.shared.layout.blocks(self.pattern, self.free, self.cdofs)

    def _bordering(self) -> tuple | None:
        """(D, Z, E_D^T Z) bordering the shared factorisation to this set, () when it holds
        exactly this set's DOFs, None when it does not serve this set (see the class).
        """
        generation, border = self._border
        if generation == self.shared.generation:
            return border
        held = self.shared.held
        border = None
        if held == self.held:
            border = ()
        elif held is not None and set(held) <= set(self.held):
            added = np.array(sorted(set(self.held) - set(held)), dtype=np.int64)
            if len(added) <= MAX_BORDERED_DOFS:
                units = np.zeros((self.pattern.shape[0], len(added)))
                units[added, np.arange(len(added))] = 1.0
                Z = self.shared.solve(units)
                border = (added, Z, Z[added])
                self.shared.bordered += 1
        self._border = (self.shared.generation, border)
        return border

    def _solve(self, r: np.ndarray) -> np.ndarray:
        b = np.zeros(self.pattern.shape[0])
        b[self.free] = r
        x = self.shared.solve(b)
        border = self._bordering()
        if border:
            added, Z, G = border
            x -= Z @ np.linalg.solve(G, x[added])
        return x[self.free]

    def factor(self, K: sp.csr_matrix, owner: object = None,
               held: tuple | None = None) -> Callable[[np.ndarray], np.ndarray]:
        """Factorise K_ff of the tangent ``K`` (same pattern) and return its solve; ``owner``
        names the state the factorisation now belongs to; ``held``: a subset of this set's
        DOFs to hold instead of all of them (the solve borders that factorisation).
        """
        self.shared.factor(K, self.held if held is None else held, owner)
        return self._solve

    @property
    def serves(self) -> bool:
        """Whether the shared factorisation held now solves with this set's K_ff (its own, or
        bordered from a subset's: see the class).
        """
        return self._bordering() is not None

    @property
    def owner(self) -> object:
        """The state whose factorisation of this set's K_ff is held, None if none is."""
        return self.shared.owner if self.serves else None

    @owner.setter
    def owner(self, token: object) -> None:
        self.shared.owner = token

    @property
    def factored(self) -> sp.csr_matrix | None:
        """The tangent whose K_ff of this set is factorised now, None if none is."""
        return self.shared.tangent if self.serves else None

    @property
    def solve(self) -> Callable[[np.ndarray], np.ndarray] | None:
        """The solve of the factorisation of this set's K_ff held now (of whichever state
        :attr:`owner` names), None if the object's factorisation is of another set.
        """
        return self._solve if self.serves else None

    def contact_stiffness(self, K: sp.csr_matrix, solve: Callable[[np.ndarray], np.ndarray],
                          owner: object = None) -> "ContactStiffness":
        """S of the tangent ``K`` whose K_ff ``solve`` factorises (see :meth:`factor`)."""
        return ContactStiffness(_values(*self._cc, K).toarray(), _values(*self._fc, K), solve,
                                owner, K)

    def owned_stiffness(self, K: sp.csr_matrix,
                        factor: Callable[[object], object]) -> "ContactStiffness | None":
        """S of the state whose tangent is ``K``, owning the factorisation of K_ff (taken over
        when it is of ``K`` already, bordered or not); its solves take it back whenever the
        shared factorisation has moved on to another state: with no factorisation when that
        holds ``K`` with the same DOFs again, else refactoring ``K`` with the DOFs it held at
        first (a bordered state stays bordered, so its solves keep their bits).
        ``factor(owner[, held])`` factorises ``K`` for ``owner`` (:meth:`factor`; the caller
        counts it) and returns None if it is singular, as then does this.
        """
        token = object()
        if self.factored is K:
            self.owner = token
        elif factor(token) is None:
            return None
        held = self.shared.held

        def solve(r: np.ndarray) -> np.ndarray:
            if self.owner is not token:
                if self.shared.tangent is K and self.shared.held == held:
                    self.owner = token
                else:
                    factor(token, held)
            return self._solve(r)

        return self.contact_stiffness(K, solve, token)


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
