# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The nonlinear response of a contact set: contact displacements -> contact forces.

With the displacements delta of the m contact nodes prescribed (they sit on the fingertips), the
other degrees of freedom are in equilibrium: f_int,free(u) = 0. Newton solves them (tangent of
:func:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic.assemble`, backtracking on the residual
norm, never into an inverted element), warm-started from the kept state nearest the new delta
with its interior moved along that state's rate map (a first-order predictor: Newton then
starts from a residual of second order in the step); when Newton fails the increment of delta
since the last converged one is halved and marched (load sub-stepping). The contact forces are
the internal forces at the contact DOFs, and the tangent dF/d delta is the Schur complement
S = K_cc - K_cf K_ff^-1 K_fc of the converged tangent, returned as an operator
(:class:`~.interior.ContactStiffness`: S v costs one interior solve, memoised), because the
stepper applies it to the finger motion and to one vector per sliding contact, never needs all
of it. Line-search trials assemble forces only; the tangent is assembled where it is
factorised.

Factorisations: K_ff is factorised by LDL^T in one :class:`~.interior.TangentFactor` per
object, refactored in place and shared by its contact sets (``factorization``). Newton re-uses
the factorisation held (the last state's) as long as the residual falls by at least
REUSE_CONTRACTION per iteration (modified Newton) and refactors otherwise; the converged state
is always factorised once, for its exact S. ``stats`` counts both. The last KEPT_STATES
evaluated states are kept: an evaluation at one of their deltas, as when the stepper returns to
a point it solved while locating an event, is a look-up, and a kept state whose S is applied
after the factorisation moved on to another state refactors for its own.

Everything is dimensionless as in the stepper: coordinates and displacements / L, forces / (E h L),
energies / (E h L^2).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.hyperelastic import (
    MeshGeometry,
    assemble,
    determinants,
    mesh_geometry,
    with_tangent,
)
from squeeze_grasp_ros.mechanics.elastic.interior import (
    ContactStiffness,
    InteriorBlocks,
    TangentFactor,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

__all__ = ["ContactResponse", "Evaluation", "NEWTON_TOL", "ResponseFailure"]

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
"""Newton solves an evaluation may make, the load sub-stepping's included. A failed solve
halves the increment, which never grows again: once the solves left cannot add up to the rest
of the contact displacement, the evaluation fails with that solve's failure at once (more
halvings would spend Newton solves on a sure failure)."""
KEPT_STATES = 4
"""Evaluated states a response keeps (with their tangents): the stepper returns to
points it solved while locating an event, and an evaluation at a kept delta is a look-up."""
KNOWN_STATE = 5e-8
KNOWN_START = 1e-6
"""A state this close (relative, largest nodal displacement) to the one a contact set was
continued from takes that state's tangent: as its own (KNOWN_STATE: its dF/d delta then differs
from the exact one by about 1e-9 of its largest entry, within RESPONSE_ACCURACY of the contact
model) or for Newton's first factorisation (KNOWN_START). A node that touched a tip within the
event tolerance moves the field by 1e-10 to 3e-8 of it."""
REUSE_CONTRACTION = 0.25
BACKTRACKS = 30
FRESH_BACKTRACKS = 16
"""Halvings of a step from a tangent factorised in this solve before the line search gives up
(BACKTRACKS for the step of a factorisation held from another state). A Newton step of the
state's own tangent whose residual falls only below 2^-16 of its length is stalling at a
minimum of the residual norm that is no equilibrium: its failure then costs 16 force assemblies
instead of 30, and the iterations that would creep on toward it are not spent. No converged
solve of 1,598 random hard squeezes (corotational and neo-Hookean: six shapes, friction to 1.5,
tips of 0.5 % to 30 % of the object, pads, depths to 25 %) took more than 12 halvings of such
a step."""


def _others(n: int, dofs: np.ndarray) -> np.ndarray:
    """The indices 0..n-1 not in ``dofs``, sorted (np.setdiff1d's answer, without its sort)."""
    kept = np.ones(n, dtype=bool)
    kept[dofs] = False
    return np.flatnonzero(kept)


@dataclass(frozen=True)
class Evaluation:
    """The equilibrium of a contact set at one delta (dimensionless).

    Attributes
    ----------
    F : (m, 2) ndarray
        Forces the fingers apply on the contact nodes.
    C : ContactStiffness
        Tangent dF / d delta as an operator (``C @ v``; ``C.toarray()`` for the matrix).
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
    C: ContactStiffness
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
    factorization : TangentFactor, optional
        The object's factorisation, shared between its contact sets (one of its own otherwise).
    reuse : bool
        Newton re-uses the factorisation held while the residual contracts (default; False:
        full Newton, a refactorisation per iteration, to measure what the reuse saves).
    """

    model: MaterialModel
    nodes: np.ndarray
    triangles: np.ndarray
    contacts: np.ndarray
    nu: float
    geometry: MeshGeometry | None = field(default=None, repr=False)
    factorization: TangentFactor = field(default_factory=TangentFactor, repr=False)
    reuse: bool = True
    stats: dict = field(default_factory=lambda: {"evaluations": 0, "iterations": 0,
                                                 "factorizations": 0, "substeps": 0,
                                                 "look_ups": 0})
    _u: np.ndarray | None = field(default=None, repr=False)
    _delta: np.ndarray | None = field(default=None, repr=False)
    _current: Evaluation | None = field(default=None, repr=False)
    _blocks: InteriorBlocks | None = field(default=None, repr=False)
    _reference_stiffness: float | None = field(default=None, repr=False)
    _kept: list = field(default_factory=list, repr=False)
    _known_tangent: tuple | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self.contacts = np.asarray(self.contacts, int)
        if len(set(self.contacts.tolist())) < 2:
            raise InvalidInputError("a contact set needs at least 2 distinct nodes to hold the "
                                    "object")
        n2 = 2 * len(self.nodes)
        self.cdofs = np.stack([2 * self.contacts, 2 * self.contacts + 1], 1).reshape(-1)
        self.free = _others(n2, self.cdofs)
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
        self._current = None
        self._known_tangent = None

    def continue_from(self, other: "ContactResponse") -> None:
        """Start from the current state of ``other`` (another contact set of the same object):
        its field, its tangent (taken for an assembly while that state is in equilibrium here:
        a node just touched a tip) and its factorisation, bordered (:class:`.InteriorBlocks`).
        """
        self.warm_start(other.state_u())
        self._reference_stiffness = other._reference_stiffness
        if other._current is not None:
            self._known_tangent = (other.state_u(), other._current.C.tangent)
            self._blocks = self._blocks or InteriorBlocks(other._current.C.tangent, self.free,
                                                          self.cdofs, self.factorization)

    def forget(self) -> None:
        """Drop the kept states but the current one (their tangents hold memory)."""
        self._kept = self._kept[-1:]

    def _recall(self, delta: np.ndarray) -> Evaluation | None:
        """Make the kept state at exactly ``delta`` the current one; its evaluation or None."""
        for kept_delta, out in reversed(self._kept):
            if np.array_equal(kept_delta, delta):
                self._u, self._delta, self._current = out.u, kept_delta, out
                return out
        return None

    def at(self, delta: np.ndarray) -> bool:
        """True if the response is at ``delta`` or keeps the state there (its field can then
        be read; none is after :meth:`warm_start` until an evaluation).
        """
        delta = np.asarray(delta, float).reshape(-1, 2)
        if self._current is not None and np.array_equal(delta, self._delta):
            return True
        return self._recall(delta) is not None

    def state_u(self) -> np.ndarray:
        """Displacement (2n,) of the last evaluated state."""
        return self._u

    def state_energy(self) -> float:
        """Strain energy of the last evaluated state."""
        return self._current.energy

    # ------------------------------------------------------------------ helpers
    def _assemble(self, u: np.ndarray, *, tangent: bool = False, **known):
        return assemble(self.model, self.nodes, self.triangles, u, nu=self.nu,
                        geometry=self.geometry, tangent=tangent, **known)

    def _stiffness(self) -> float:
        """Largest entry of the reference (undeformed) tangent: the scale of NEWTON_TOL."""
        if self._reference_stiffness is None:
            zero = np.zeros(2 * len(self.nodes))
            self._reference_stiffness = float(abs(self._assemble(zero, tangent=True).tangent)
                                              .max())
        return self._reference_stiffness

    def _factor(self, K, owner: object = None, held: tuple | None = None):
        """Factorise K_ff of the tangent ``K`` (for the state ``owner``; None for a Newton
        iterate; ``held``: :meth:`.InteriorBlocks.factor`); its solve, or None if singular.
        """
        if self._blocks is None:
            self._blocks = InteriorBlocks(K, self.free, self.cdofs, self.factorization)
        self.stats["factorizations"] += 1
        try:
            return self._blocks.factor(K, owner, held)
        except (ValueError, RuntimeError):
            return None

    def _stiffness_of(self, K) -> ContactStiffness | None:
        """dF/d delta of the state whose tangent is ``K`` (:meth:`.InteriorBlocks.owned_stiffness`:
        it owns the factorisation of K_ff, and refactors whenever that has moved on).
        """
        if self._blocks is None and self._factor(K) is None:
            return None
        return self._blocks.owned_stiffness(K, lambda *args: self._factor(K, *args))

    def _known(self, u: np.ndarray, tol: float):
        """The tangent of the state this set was continued from, if ``u`` is that state to
        ``tol`` (relative, largest nodal displacement), else None.
        """
        if self._known_tangent is None:
            return None
        known_u, known_K = self._known_tangent
        close = np.abs(u - known_u).max() <= tol * max(np.abs(known_u).max(),
                                                       DISPLACEMENT_FLOOR)
        return known_K if close else None

    def _upright(self, u: np.ndarray) -> np.ndarray | None:
        """The deformation gradients of ``u`` if every area ratio det F is above
        MIN_AREA_RATIO, else None (an inverted state).
        """
        F = self.geometry.deformation(u)
        return F if float(determinants(F).min()) > MIN_AREA_RATIO else None

    def _start(self, u: np.ndarray, delta: np.ndarray) -> tuple | None:
        """Newton's first iterate for contact displacements ``delta`` from the state ``u``:
        the interior moved along the last converged rate map (first-order predictor, when one
        is known and it inverts nothing), else where ``u`` has it; (iterate, its deformation
        gradients), or None if the contact displacement itself inverts an element.
        """
        plain = u.copy()
        plain[self.cdofs] = delta.reshape(-1)
        if self._current is not None:
            predicted = plain.copy()
            predicted[self.free] -= self._predictor(plain[self.cdofs] - u[self.cdofs])
            F = self._upright(predicted)
            if F is not None:
                return predicted, F
        F = self._upright(plain)
        return None if F is None else (plain, F)

    def _predictor(self, d: np.ndarray) -> np.ndarray:
        """K_ff^-1 K_fc d at the current state: exact when d is a multiple of a direction the
        state has answered (the finger motion) or the factorisation held is the state's, else
        with the factorisation held (a Newton start needs no more), zero if that is of another
        contact set.
        """
        C = self._current.C
        if C.knows(d) or self._blocks.owner is C.owner:
            return C.interior_response(d)
        held = self._blocks.solve
        return np.zeros(len(self.free)) if held is None else held(C.fc @ d)

    def _newton(self, u: np.ndarray, delta: np.ndarray):
        """Equilibrium of the free DOFs with the contact DOFs at ``delta``; (u, assembly, its,
        residual) or a ResponseFailure.
        """
        start = self._start(u, delta)
        if start is None:
            return ResponseFailure("the prescribed contact displacement inverts an element",
                                   inverted=True)
        u, F = start
        held = self._blocks.solve if self._blocks is not None else None
        solve, fresh, its = (held if self.reuse else None), False, 0
        asm = self._assemble(u, tangent=False, deformation=F)
        scale = max(np.linalg.norm(asm.force[self.cdofs]),
                    self._stiffness() * max(np.linalg.norm(delta), DISPLACEMENT_FLOOR))
        r = asm.force[self.free]
        norm = np.linalg.norm(r)
        while norm > NEWTON_TOL * scale:
            if its >= MAX_ITERATIONS:
                return ResponseFailure("interior Newton did not converge", norm / scale)
            if solve is None:
                K = asm.tangent if asm.tangent is not None else self._known(u, KNOWN_START)
                if K is None:
                    asm = with_tangent(self.model, asm, nu=self.nu, geometry=self.geometry)
                    K = asm.tangent
                solve, fresh = self._factor(K), True
                if solve is None:
                    return ResponseFailure("the interior tangent is singular", norm / scale)
            step = -solve(r)
            if not np.all(np.isfinite(step)):
                return ResponseFailure("the interior tangent is singular", norm / scale)
            its += 1
            inverted = True
            for _ in range(FRESH_BACKTRACKS if fresh else BACKTRACKS):
                trial = u.copy()
                trial[self.free] += step
                F = self._upright(trial)
                if F is not None:
                    inverted = False
                    t_asm = self._assemble(trial, deformation=F, stretch=asm.stretch)
                    t_norm = np.linalg.norm(t_asm.force[self.free])
                    if t_norm < norm:
                        break
                step *= 0.5
            else:
                if fresh:
                    return ResponseFailure("interior line search found no descent"
                                           + (" (every trial inverted an element)"
                                              if inverted else ""), norm / scale,
                                           inverted=inverted)
                solve = None
                continue
            contraction = t_norm / norm
            u, asm, r, norm = trial, t_asm, t_asm.force[self.free], t_norm
            if contraction > REUSE_CONTRACTION or not self.reuse:
                solve = None
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
        if self._kept and self._current is not None:
            nearest = min(self._kept, key=lambda state: np.abs(state[0] - delta).max())
            if np.abs(nearest[0] - delta).max() < np.abs(self._delta - delta).max():
                self._recall(nearest[0])
        base_u, base_d = self._u, self._delta
        target, done, its = delta, 0.0, 0
        fraction = 1.0
        result = None
        for k in range(MAX_SUBSTEPS):
            goal = base_d + (done + fraction) * (target - base_d)
            out = self._newton(base_u if result is None else result[0], goal)
            if isinstance(out, ResponseFailure):
                fraction *= 0.5
                self.stats["substeps"] += 1
                if fraction < 1e-6 or done + (MAX_SUBSTEPS - 1 - k) * fraction < 1.0 - 1e-12:
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
        K = asm.tangent if asm.tangent is not None else self._known(u, KNOWN_STATE)
        if K is None:
            K = with_tangent(self.model, asm, nu=self.nu, geometry=self.geometry).tangent
        self._known_tangent = None
        C = self._stiffness_of(K)
        if C is None:
            return ResponseFailure("the interior tangent is singular at equilibrium", residual)
        F = asm.force[self.cdofs].reshape(-1, 2)
        out = Evaluation(F, C, u, asm.energy, its, residual)
        self._u, self._delta, self._current = u, delta.copy(), out
        self._kept = [*self._kept[1 - KEPT_STATES:], (self._delta, out)]
        return out

    def rate(self, ddelta: np.ndarray) -> np.ndarray:
        """Du / ds (2n,) of every node for a contact-displacement rate (m, 2) at the last
        evaluated state (the interior follows by -K_ff^-1 K_fc).
        """
        du = np.zeros(2 * len(self.nodes))
        d = np.asarray(ddelta, float).reshape(-1)
        du[self.cdofs] = d
        du[self.free] = -self._current.C.interior_response(d)
        return du
