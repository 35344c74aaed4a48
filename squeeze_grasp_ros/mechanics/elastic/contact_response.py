# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The nonlinear response of a contact set: contact displacements -> contact forces.

With the displacements delta of the m contact nodes prescribed (they sit on the fingertips), the
other degrees of freedom are in equilibrium: f_int,free(u) = 0. Newton solves them (tangent of
:func:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic.assemble`, backtracking on the residual
norm, never into an inverted element), warm-started from the previous solution of the set with
its interior moved along the last rate map (a first-order predictor: Newton then starts from a
residual of second order in the step); when Newton fails the increment of delta since the last
converged one is halved and marched (load sub-stepping). The contact forces are the internal
forces at the contact DOFs, and the tangent dF/d delta is the Schur complement
K_cc - K_cf K_ff^-1 K_fc of the converged tangent: the trailing block of one sparse LU of the
whole tangent with the contact DOFs ordered last (:class:`~.schur.CondensedLU`), which serves the
interior solves and rates. Line-search trials assemble forces only; the tangent is assembled
where it is factorised.

Factorisations: Newton re-uses the last factorisation of the whole tangent (kept with the last
evaluated state) as long as the residual falls by at least REUSE_CONTRACTION per iteration
(modified Newton), and refactors otherwise; the
converged state is always refactored once for the exact Schur complement. ``stats`` counts both,
and the one factorisation of K_ff per contact set that gives the interior's ordering (a set
grown from another inherits that one's, :meth:`ContactResponse.inherit_order`). The last
KEPT_STATES evaluated states are kept with their factorisations: an evaluation at one of their
deltas, as when the stepper returns to a point it solved while locating an event, is a
look-up.

Everything is dimensionless as in the stepper: coordinates and displacements / L, forces / (E h L),
energies / (E h L^2).
"""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.hyperelastic import (MeshGeometry, area_ratios,
                                                                assemble, mesh_geometry)
from squeeze_grasp_ros.mechanics.elastic.schur import CondensedLU, condense, minimum_degree_order
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

__all__ = ["ContactResponse", "Evaluation", "NEWTON_TOL", "ResponseFailure",
           "factorization_reuse"]

NEWTON_TOL = 1e-10
"""Interior Newton stops when ||f_free|| <= NEWTON_TOL * max(||f_contact||, |K0| ||delta||),
|K0| the largest entry of the undeformed tangent."""
DISPLACEMENT_FLOOR = 1e-6
"""Contact displacements (/ L) below this are measured against it in the tolerance above, so
round-off of an almost undeformed state does not count as a residual."""
MIN_AREA_RATIO = 1e-8
"""States whose smallest element area ratio det F is below this count as inverted, so every
accepted state keeps a margin above det F = 0, where assembly refuses the state."""
MAX_ITERATIONS = 25
MAX_SUBSTEPS = 64
KEPT_STATES = 4
"""Evaluated states a response keeps (with their factorisations): the stepper returns to
points it solved while locating an event, and an evaluation at a kept delta is a look-up."""
REUSE_CONTRACTION = 0.25
BACKTRACKS = 30
_REUSE = [True]


@contextmanager
def factorization_reuse(enabled: bool) -> Iterator[None]:
    """Within the block, interior Newton re-uses factorisations (the default) or refactors the
    tangent at every iteration (full Newton): for measuring what the reuse saves.
    """
    before, _REUSE[0] = _REUSE[0], enabled
    try:
        yield
    finally:
        _REUSE[0] = before


@dataclass(frozen=True)
class Evaluation:
    """The equilibrium of a contact set at one delta (dimensionless).

    Attributes
    ----------
    F : (m, 2) ndarray
        Forces the fingers apply on the contact nodes.
    C : (2m, 2m) ndarray
        Tangent dF / d delta.
    u : (2n,) ndarray
        Displacement of every node.
    energy : float
        Strain energy.
    iterations : int
        Newton iterations of this evaluation (all sub-steps).
    residual : float
        Final relative interior residual.
    """

    F: np.ndarray
    C: np.ndarray
    u: np.ndarray
    energy: float
    iterations: int
    residual: float


@dataclass(frozen=True)
class ResponseFailure:
    """Why no equilibrium was found (a value: callers try smaller steps).

    Attributes
    ----------
    reason : str
    residual : float
        Relative interior residual of the last iterate (inf when none was computed).
    inverted : bool
        Every state tried had an inverted element (det F <= 0): the contact displacement is
        beyond what the object can take, not a solver failure.
    """

    reason: str
    residual: float = float("inf")
    inverted: bool = False


@dataclass
class ContactResponse:
    """Nonlinear response of one contact set of one object (mutable: warm starts, counters).

    Parameters
    ----------
    model : MaterialModel
    nodes : (n, 2) ndarray
        Reference node positions / L.
    triangles : (t, 3) ndarray of int
    contacts : (m,) ndarray of int
        Contact nodes (at least 2 distinct: they fix the rigid motion).
    nu : float
        Poisson's ratio.
    geometry : MeshGeometry, optional
        :func:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic.mesh_geometry` of the mesh, to
        share between the contact sets of one object (built here otherwise).
    """

    model: MaterialModel
    nodes: np.ndarray
    triangles: np.ndarray
    contacts: np.ndarray
    nu: float
    geometry: MeshGeometry | None = field(default=None, repr=False)
    stats: dict = field(default_factory=lambda: {"evaluations": 0, "iterations": 0,
                                                 "factorizations": 0, "substeps": 0,
                                                 "look_ups": 0})
    _u: np.ndarray | None = field(default=None, repr=False)
    _delta: np.ndarray | None = field(default=None, repr=False)
    _lu: CondensedLU | None = field(default=None, repr=False)
    _order: np.ndarray | None = field(default=None, repr=False)
    _energy: float = field(default=0.0, repr=False)
    _reference_stiffness: float | None = field(default=None, repr=False)
    _kept: list = field(default_factory=list, repr=False)

    def __post_init__(self) -> None:
        self.contacts = np.asarray(self.contacts, int)
        if len(set(self.contacts.tolist())) < 2:
            raise InvalidInputError("a contact set needs at least 2 distinct nodes to hold the "
                                    "object")
        n2 = 2 * len(self.nodes)
        self.cdofs = np.stack([2 * self.contacts, 2 * self.contacts + 1], 1).reshape(-1)
        self.free = np.setdiff1d(np.arange(n2), self.cdofs)
        if self.geometry is None:
            self.geometry = mesh_geometry(self.nodes, self.triangles)
        if self._u is None:
            self._u = np.zeros(n2)
            self._delta = np.zeros((len(self.contacts), 2))

    def warm_start(self, u: np.ndarray) -> None:
        """Start the next solve from the displacement field ``u`` (2n,) (e.g. the previous
        contact set's), whose contact displacements become the sub-stepping base.
        """
        self._u = np.array(u, float)
        self._delta = self._u[self.cdofs].reshape(-1, 2)
        self._lu = None

    def inherit_order(self, other: "ContactResponse") -> None:
        """Take the interior's fill-reducing order from ``other``'s (a set of the same object
        with no more contact nodes), without the DOFs that are contact DOFs here: the
        eliminations restricted to a subgraph fill no more than the original did, and the
        new set needs no ordering factorisation of its own.
        """
        if other._order is None or not np.isin(self.free, other.free).all():
            return
        interior = other.free[other._order]
        self._order = np.searchsorted(self.free, interior[np.isin(interior, self.free)])

    def forget(self) -> None:
        """Drop the kept states but the current one (their factorisations hold memory)."""
        self._kept = self._kept[-1:]

    def _recall(self, delta: np.ndarray) -> Evaluation | None:
        """Make the kept state at exactly ``delta`` the current one; its evaluation or None."""
        for kept_delta, out, lu in reversed(self._kept):
            if np.array_equal(kept_delta, delta):
                self._u, self._delta, self._lu, self._energy = out.u, kept_delta, lu, out.energy
                return out
        return None

    def at(self, delta: np.ndarray) -> bool:
        """True if the response is at ``delta`` or keeps the state there (its field can then
        be read); a state was evaluated exactly when its factorisation is kept (none after
        :meth:`warm_start`).
        """
        delta = np.asarray(delta, float).reshape(-1, 2)
        if self._lu is not None and np.array_equal(delta, self._delta):
            return True
        return self._recall(delta) is not None

    def state_u(self) -> np.ndarray:
        """Displacement (2n,) of the last evaluated state."""
        return self._u

    def state_energy(self) -> float:
        """Strain energy of the last evaluated state."""
        return self._energy

    # ------------------------------------------------------------------ helpers
    def _assemble(self, u: np.ndarray, *, tangent: bool):
        return assemble(self.model, self.nodes, self.triangles, u, nu=self.nu,
                        geometry=self.geometry, tangent=tangent)

    def _stiffness(self) -> float:
        """Largest entry of the reference (undeformed) tangent: the scale of NEWTON_TOL."""
        if self._reference_stiffness is None:
            zero = np.zeros(2 * len(self.nodes))
            self._reference_stiffness = float(abs(self._assemble(zero, tangent=True).tangent)
                                              .max())
        return self._reference_stiffness

    def _condense(self, K) -> CondensedLU | None:
        """Factorise the tangent ``K`` (:func:`~.schur.condense`); the interior's
        fill-reducing order is taken once per set from a factorisation of K_ff.
        """
        if self._order is None:
            self._order = minimum_degree_order(K[self.free][:, self.free])
            self.stats["factorizations"] += 1
        self.stats["factorizations"] += 1
        return condense(K, self.free, self.cdofs, self._order)

    def _min_det(self, u: np.ndarray) -> float:
        return float(area_ratios(self.geometry.gradient, u).min())

    def _start(self, u: np.ndarray, delta: np.ndarray) -> np.ndarray | None:
        """Newton's first iterate for contact displacements ``delta`` from the state ``u``:
        the interior moved along the last converged rate map (first-order predictor, when one
        is known and it inverts nothing), else where ``u`` has it; None if the contact
        displacement itself inverts an element.
        """
        plain = u.copy()
        plain[self.cdofs] = delta.reshape(-1)
        if self._lu is not None:
            predicted = plain.copy()
            predicted[self.free] += self._lu.interior_rate(plain[self.cdofs] - u[self.cdofs])
            if self._min_det(predicted) > MIN_AREA_RATIO:
                return predicted
        return plain if self._min_det(plain) > MIN_AREA_RATIO else None

    def _newton(self, u: np.ndarray, delta: np.ndarray):
        """Equilibrium of the free DOFs with the contact DOFs at ``delta``; (u, assembly, its,
        residual) or a ResponseFailure.
        """
        u = self._start(u, delta)
        if u is None:
            return ResponseFailure("the prescribed contact displacement inverts an element",
                                   inverted=True)
        lu, its = (self._lu if _REUSE[0] else None), 0
        asm = self._assemble(u, tangent=lu is None)
        scale = max(np.linalg.norm(asm.force[self.cdofs]),
                    self._stiffness() * max(np.linalg.norm(delta), DISPLACEMENT_FLOOR))
        r = asm.force[self.free]
        norm = np.linalg.norm(r)
        while norm > NEWTON_TOL * scale:
            if its >= MAX_ITERATIONS:
                return ResponseFailure("interior Newton did not converge", norm / scale)
            if lu is None:
                if asm.tangent is None:
                    asm = self._assemble(u, tangent=True)
                lu = self._condense(asm.tangent)
                if lu is None:
                    return ResponseFailure("the interior tangent is singular", norm / scale)
            step = -lu.interior(r)
            its += 1
            inverted = True
            for _ in range(BACKTRACKS):
                trial = u.copy()
                trial[self.free] += step
                if self._min_det(trial) > MIN_AREA_RATIO:
                    inverted = False
                    t_asm = self._assemble(trial, tangent=False)
                    t_norm = np.linalg.norm(t_asm.force[self.free])
                    if t_norm < norm:
                        break
                step *= 0.5
            else:
                if self._lu is not lu or lu is None:
                    return ResponseFailure("interior line search found no descent"
                                           + (" (every trial inverted an element)"
                                              if inverted else ""), norm / scale,
                                           inverted=inverted)
                lu = None
                continue
            contraction = t_norm / norm
            u, asm, r, norm = trial, t_asm, t_asm.force[self.free], t_norm
            if contraction > REUSE_CONTRACTION or not _REUSE[0]:
                lu = None
        return u, asm, its, norm / scale

    # ------------------------------------------------------------------ public
    def evaluate(self, delta: np.ndarray) -> Evaluation | ResponseFailure:
        """The equilibrium at contact displacements ``delta`` (m, 2), or why none was found."""
        delta = np.asarray(delta, float).reshape(-1, 2)
        kept = self._recall(delta)
        if kept is not None:
            self.stats["look_ups"] += 1
            return kept
        self.stats["evaluations"] += 1
        if self._kept and self._lu is not None:
            nearest = min(self._kept, key=lambda state: np.abs(state[0] - delta).max())
            if np.abs(nearest[0] - delta).max() < np.abs(self._delta - delta).max():
                self._recall(nearest[0])
        base_u, base_d = self._u, self._delta
        target, done, its = delta, 0.0, 0
        fraction = 1.0
        result = None
        for _ in range(MAX_SUBSTEPS):
            goal = base_d + (done + fraction) * (target - base_d)
            out = self._newton(base_u if result is None else result[0], goal)
            if isinstance(out, ResponseFailure):
                fraction *= 0.5
                self.stats["substeps"] += 1
                if fraction < 1e-6:
                    return out
                continue
            result = out
            its += out[2]
            done += fraction
            if done >= 1.0 - 1e-12:
                break
        else:
            return ResponseFailure("load sub-stepping did not reach the contact displacement")
        u, asm, _, residual = result
        self.stats["iterations"] += its
        K = asm.tangent if asm.tangent is not None else self._assemble(u, tangent=True).tangent
        lu = self._condense(K)
        if lu is None:
            return ResponseFailure("the interior tangent is singular at equilibrium", residual)
        self._u, self._delta, self._lu = u, delta.copy(), lu
        self._energy = asm.energy
        F = asm.force[self.cdofs].reshape(-1, 2)
        out = Evaluation(F, lu.schur.copy(), u, asm.energy, its, residual)
        self._kept = [*self._kept[1 - KEPT_STATES:], (self._delta, out, lu)]
        return out

    def rate(self, ddelta: np.ndarray) -> np.ndarray:
        """Du / ds (2n,) of every node for a contact-displacement rate (m, 2) at the last
        evaluated state (the interior follows by -K_ff^-1 K_fc).
        """
        du = np.zeros(2 * len(self.nodes))
        d = np.asarray(ddelta, float).reshape(-1)
        du[self.cdofs] = d
        du[self.free] = self._lu.interior_rate(d)
        return du
