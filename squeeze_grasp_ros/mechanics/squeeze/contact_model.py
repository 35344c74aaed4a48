# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Mechanics of one fixed contact set under rounded fingertips (paper Sec. 5.2, eqs. 46-47).

Between events the contact set S = T u P (sticking, sliding) is fixed. Every contact node k
lies on its fingertip, x_k = o_f + x_f(q_k) (for a circle x_f(q) = r_f e(q), q the polar angle;
a pad's face in :mod:`.tip_shapes`), so its displacement is delta_k = o_f + x_f(q_k) - p_k
(eq. 46 summed over steps); sticking nodes keep their coordinate q, sliding nodes have the force
on a friction-cone edge about the contact normal e(nu_k), nu_k = nu_f(q_k) (eq. 47):

    f_k x e(nu_k - slip_k phi) = 0,   phi = atan(mu),   F = C delta   (eq. 31)

solved by Newton on the sliding coordinates (a circle's angles). Totals, not increments, are
used: F = C delta holds for the final contact set with total displacements (the one-shot
invariant of Sec. 5.3), so the state between events is a function of the finger positions
alone and does not drift.

Costs (docs/design.md §3): per contact set a gather of the cached boundary compliance (O(m^2)) and
a null-space reduction (O(m^3)), cached by the set; per evaluation O(m^2 |P|) for Newton and
O(b m) for the boundary displacements used by Event A. The element strain map (2m sparse
solves per set) is built only when a strain limit is declared.

The *reference* model follows the paper literally for cross-checks and timing: no boundary
compliance and no per-set cache (C from 2m direct solves whenever the set changes) and a full
displacement solve at every evaluation.

Everything here is dimensionless: lengths by L = obj.scale, forces by E h L.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject, node_dofs
from squeeze_grasp_ros.mechanics.elastic.fem import (
    element_dofs,
    principal_strains,
    strain_displacement,
)
from squeeze_grasp_ros.mechanics.elastic.hyperelastic import area_ratios
from squeeze_grasp_ros.mechanics.elastic.reduced import reduce_blocks
from squeeze_grasp_ros.mechanics.elastic.strain_measures import largest_pair_entry
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import (
    Kernel,
    compiled,
    compiled_substeps,
    selected,
)
from squeeze_grasp_ros.mechanics.squeeze.kept import kept_for, kept_property
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry, cross, tangent, unit
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel, StrainCriterion, StrainMeasure

INVERSION_AREA_RATIO = 0.01
"""A squeeze ends ``element_inverted`` when an element's area ratio det F falls to this: the
element is about to turn inside out (det F <= 0), where no material model means anything and
the finite-deformation solvers cannot converge (the corotational law has no energy barrier at
det F = 0)."""
GRADIENT_BOUND_EXACT = 1.0 - INVERSION_AREA_RATIO**0.5
"""Below this bound on every element's displacement gradient, det F >= (1 - bound)^2 stays above
INVERSION_AREA_RATIO and the linear model's area check needs no solve."""
NEWTON_MAX_ITERATIONS = 50
NEWTON_BACKTRACKS = 30
SINGULAR_SLIDING = (
    "singular Jacobian of the sliding constraints (eq. 47): the sliding contacts "
    "do not fix the object's position (e.g. a frictionless finger touching at one "
    "node lets the object slide along the tip); use mu > 0"
)
NON_FINITE = "non-finite contact forces or angles in the fixed-set solve"
NEWTON_TOL = 1e-14
"""Newton stops when the cone residual is below this times the force scale |C| r, or when the
largest angle update (rad) falls below it."""
BOUNDARY_ROWS_KEPT = 8
"""Row selections of the boundary compliance the fast model keeps for its last contact set
(each 2k x 2m floats for k rows and m contacts)."""
AREA_TABLES_BYTES = 64 * 2**20
"""Memory an object keeps for its contact sets' area tables (:meth:`ContactModel.area_tables`:
9 t floats per contact node for t elements)."""
SHARED_SET_BYTES = 64 * 2**20
"""Memory an object keeps for the reduced data of contact sets its fast contact models share
(:meth:`ContactModel.set_data`; a set of m contacts holds 2m (2b + 2m + 3) floats, and
6 t m more with a strain limit, for b boundary nodes and t elements)."""


@dataclass(frozen=True)
class TerminationLimits:
    """Termination criteria a scene declares (paper Sec. 5.1).

    Attributes
    ----------
    strain : float or None
        Proportional-limit strain epsilon* (eq. 45, dimensionless) in the material model's
        own measure (:attr:`ContactModel.strain_measure`: small for linear, Biot for
        corotational, log for neo_hookean; the measure of ``GraspHealth.max_strain``);
        None = not checked (no strain field).
    criterion : {"principal", "componentwise"}
        "principal": max(|eps_1|, |eps_2|) <= eps* per element (frame invariant, default);
        "componentwise": |eps_x|, |eps_y| <= eps* in the object frame (eq. 45 literally).
    weight : float or None
        Object weight w, N, for the pickup criterion; None = not checked.
    """

    strain: float | None = None
    criterion: str = StrainCriterion.PRINCIPAL
    weight: float | None = None

    def __post_init__(self) -> None:
        if self.criterion not in StrainCriterion.values():
            raise InvalidInputError(
                f"strain_limit.criterion must be one of "
                f"{StrainCriterion.values()}, "
                f"got {self.criterion!r}"
            )
        if self.strain is not None and not (np.isfinite(self.strain) and self.strain > 0):
            raise InvalidInputError(f"strain_limit.epsilon (in the material model's strain "
                                    f"measure) must be finite and > 0, got {self.strain}")
        if self.weight is not None and not (np.isfinite(self.weight) and self.weight > 0):
            raise InvalidInputError(f"pickup.weight must be finite and > 0 N, got {self.weight}")


@dataclass(frozen=True)
class SolveOptions:
    """The two savings of a large-deformation squeeze, as switches for measuring what they save
    (forces and events agree to the Newton tolerance either way; the linear model has neither).

    Attributes
    ----------
    adaptive_substeps : bool
        The stepper adapts its substeps between events (default); False keeps the ``step``
        grid.
    reuse_factorizations : bool
        Interior Newton re-uses the factorisation held while the residual contracts
        (default); False refactors at every iteration (full Newton).
    """

    adaptive_substeps: bool = True
    reuse_factorizations: bool = True


@dataclass(frozen=True)
class SetData:
    """Dimensionless data of one contact set (nodes sorted).

    Attributes
    ----------
    nodes : (m,) ndarray of int
    C : (2m, 2m) ndarray
        Reduced stiffness C_hat (forces / (E h L) per displacement / L).
    E : (2m, 3) ndarray
        Rigid-coefficient map g_hat = E^T delta_hat.
    A_bc : (2b, 2m) ndarray or None
        Boundary compliance columns of the contact DOFs (None in the reference model).
    strain_map : (3t, 2m) ndarray or None
        Element engineering strains per contact force (built only with a strain limit).
    condition : float
        Condition number of Z^T A Z.
    """

    nodes: np.ndarray
    C: np.ndarray
    E: np.ndarray
    A_bc: np.ndarray | None
    strain_map: np.ndarray | None
    condition: float


class SharedSets:
    """The reduced contact sets of one object that its fast contact models share, the least
    recently used dropped beyond SHARED_SET_BYTES (the last one put always stays). Safe for
    the models of several threads (a Dask worker with more than one).
    """

    def __init__(self) -> None:
        self._sets: OrderedDict[tuple, SetData] = OrderedDict()
        self._lock = threading.Lock()
        self.nbytes = 0

    def get(self, tag: tuple) -> SetData | None:
        """The set kept under ``tag`` (now the most recently used), or None."""
        with self._lock:
            data = self._sets.get(tag)
            if data is not None:
                self._sets.move_to_end(tag)
            return data

    def put(self, tag: tuple, data: SetData) -> SetData:
        """Keep ``data`` under ``tag`` (unless a set is kept there already); returns the set
        kept.
        """
        with self._lock:
            if tag in self._sets:
                return self._sets[tag]
            self._sets[tag] = data
            self.nbytes += _set_bytes(data)
            while self.nbytes > SHARED_SET_BYTES and len(self._sets) > 1:
                self.nbytes -= _set_bytes(self._sets.popitem(last=False)[1])
            return data


def _set_bytes(data: SetData) -> int:
    """Memory of a set's arrays, bytes."""
    return sum(0 if a is None else a.nbytes
               for a in (data.C, data.E, data.A_bc, data.strain_map))


@dataclass(frozen=True)
class Solution:
    """The configuration of a contact set at one set of finger positions (dimensionless).

    Attributes
    ----------
    theta : (m,) ndarray
        Contact coordinates q (a circle's polar angles), rad.
    delta : (m, 2) ndarray
        Contact-node displacements / L.
    F : (m, 2) ndarray
        Contact forces / (E h L).
    dtheta : (m,) ndarray
        d theta / ds along the current finger motion (zero for sticking nodes).
    dF : (m, 2) ndarray
        dF / ds.
    ddelta : (m, 2) ndarray
        d delta / ds.
    iterations : int
        Newton iterations used.
    residual : float
        Largest |f_k x e(alpha_k)| over sliding nodes, dimensionless force.
    jacobian_condition : float
        Condition number of the Newton Jacobian (1 without sliding nodes).
    nu : (m,) ndarray or None
        Angles of the contact normals e(nu), rad (None: ``theta``, circular tips).
    kappa : (m,) ndarray or None
        d nu / d theta: 1 on a circle or a pad's rounded edge, 0 on a flat face (None: 1).

    The force components and their rates (:attr:`normal`, :attr:`tangential`, ...) are
    computed on first use and kept: every event function of the point reads them.
    """

    theta: np.ndarray
    delta: np.ndarray
    F: np.ndarray
    dtheta: np.ndarray
    dF: np.ndarray
    ddelta: np.ndarray
    iterations: int
    residual: float
    jacobian_condition: float
    nu: np.ndarray | None = None
    kappa: np.ndarray | None = None

    @property
    def normal_angle(self) -> np.ndarray:
        """The contact normals' angles nu (m,), rad."""
        return self.theta if self.nu is None else self.nu

    @property
    def normal_turn(self) -> np.ndarray:
        """The rates d nu / ds (m,): how fast each contact normal turns (0 on a flat face)."""
        return self.dtheta if self.kappa is None else self.kappa * self.dtheta

    @kept_property
    def unit(self) -> np.ndarray:
        """e(nu) (m, 2) of every contact, computed once per solution."""
        return unit(self.normal_angle)

    @kept_property
    def tangent(self) -> np.ndarray:
        """t(nu) (m, 2) of every contact, computed once per solution."""
        return tangent(self.normal_angle)

    @kept_property
    def normal(self) -> np.ndarray:
        """f_n = F . e(nu) (m,)."""
        return np.einsum("ij,ij->i", self.F, self.unit)

    @kept_property
    def tangential(self) -> np.ndarray:
        """f_t = F . t(nu) (m,)."""
        return np.einsum("ij,ij->i", self.F, self.tangent)

    @kept_property
    def normal_rate(self) -> np.ndarray:
        """D f_n / ds (m,)."""
        return np.einsum("ij,ij->i", self.dF, self.unit) + self.normal_turn * self.tangential

    @kept_property
    def tangential_rate(self) -> np.ndarray:
        """D f_t / ds (m,)."""
        return np.einsum("ij,ij->i", self.dF, self.tangent) - self.normal_turn * self.normal


@dataclass(frozen=True)
class Configuration:
    """Contact modes and finger motion that define the fixed-set problem (dimensionless).

    Attributes
    ----------
    p0 : (m, 2) ndarray
        Undeformed contact-node positions / L.
    stick : (m,) ndarray of bool
    slip : (m,) ndarray of int
        Slip direction of sliding nodes (+1/-1), 0 for sticking ones.
    tip : TipGeometry
        The tip of each node's finger, lengths / L.
    """

    p0: np.ndarray
    stick: np.ndarray
    slip: np.ndarray
    tip: TipGeometry


Response = Callable[[np.ndarray], "tuple[np.ndarray, np.ndarray] | SolveFailure"]
"""An elastic response of a contact set: delta (m, 2) -> (F (m, 2), dF/d delta (2m, 2m))."""


@dataclass(frozen=True)
class SolveFailure:
    """Why a fixed-set solve found no solution: a value, not an exception, because the stepper
    tries mode hypotheses and substeps that may legitimately fail.

    Attributes
    ----------
    reason : str
        What failed.
    residual : float
        The residual ``measure`` names at the last iterate (inf when none was computed).
    indeterminate : bool
        The problem itself has no unique solution (the sliding contacts do not fix the
        object), which the input must change, rather than a solver failure.
    inverted : bool
        No state without an inverted element exists at these finger positions (nonlinear
        models): the squeeze ends ``element_inverted`` rather than failing.
    measure : str
        What ``residual`` is: ``cone``, the largest cone residual |f_k x e(alpha_k)| of the
        Newton on the sliding angles (dimensionless force), or ``interior``, the interior
        force residual of a nonlinear response's equilibrium relative to its contact forces
        (when that equilibrium is what failed).
    """

    reason: str
    residual: float = float("inf")
    indeterminate: bool = False
    inverted: bool = False
    measure: str = "cone"

    def error(self) -> InvalidInputError | NumericalError:
        """The failure as an exception, for callers that cannot go on without a solution."""
        if self.indeterminate:
            return InvalidInputError(self.reason)
        return NumericalError(self.reason, residuals={self.measure: self.residual})


@dataclass(frozen=True, eq=False)
class LinearResponse:
    """The linear model's response F = C delta of a contact set with m nodes: a
    :data:`Response` whose constant stiffness the compiled fixed-set kernel reads.

    Attributes
    ----------
    C : (2m, 2m) ndarray
        The set's reduced stiffness (forces / (E h L) per displacement / L).
    """

    C: np.ndarray

    def __call__(self, delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(F (m, 2), dF/d delta = C) at contact displacements ``delta`` (m, 2)."""
        return (self.C @ delta.reshape(-1)).reshape(delta.shape), self.C


def solve_fixed_set(
    C: np.ndarray,
    cfg: Configuration,
    centers: np.ndarray,
    dirs: np.ndarray,
    theta0: np.ndarray,
    phi: float,
) -> Solution:
    """:func:`attempt_fixed_set`, raising :class:`NumericalError` when it fails."""
    result = attempt_fixed_set(C, cfg, centers, dirs, theta0, phi)
    if isinstance(result, SolveFailure):
        raise result.error()
    return result


def stiffness_scale(C) -> float:
    """Largest |entry| of a contact stiffness: a matrix, or an operator with a ``scale``."""
    scale = getattr(C, "scale", None)
    return float(np.abs(C).max()) if scale is None else float(scale)


def angle_response(C, nu: np.ndarray, r: np.ndarray, P: np.ndarray) -> np.ndarray:
    """dF_k / d q_j = C_kj r_j t(nu_j) for the sliding nodes j in P: (m, 2, |P|) (dx_j / dq_j
    = r_j t(nu_j) on any tip of :mod:`.tip_shapes`).

    ``C`` is the (2m, 2m) contact stiffness or an operator that applies it (``C @ V``).
    """
    m, cols = len(nu), np.arange(len(P))
    V = np.zeros((2 * m, len(P)))
    t = r[P, None] * tangent(nu[P])
    V[2 * P, cols], V[2 * P + 1, cols] = t[:, 0], t[:, 1]
    return (C @ V).reshape(m, 2, len(P))


def attempt_fixed_set(
    response: Response,
    cfg: Configuration,
    centers: np.ndarray,
    dirs: np.ndarray,
    theta0: np.ndarray,
    phi: float,
    *, kernel: Kernel | None = None,
) -> Solution | SolveFailure:
    """Solve the sliding constraints (eq. 47) for one contact set at given tip positions.

    Parameters
    ----------
    response : callable
        The set's elastic response: contact displacements delta (m, 2) -> (forces F (m, 2),
        tangent dF/d delta (2m, 2m)), or a :class:`SolveFailure` (:meth:`ContactModel.response`).
        An attribute ``tolerance`` (relative accuracy of F) loosens the cone tolerance to it;
        an attribute ``stall_halvings`` (a response whose every evaluation is an equilibrium
        solve) ends the solve once a Newton step has been halved that many times: the failure
        of the last trial, or a stall when the trials were solved but none lowered the residual.
    cfg : Configuration
        Modes and geometry.
    centers : (m, 2) ndarray
        Tip reference point (a circle's centre) of each node's finger / L.
    dirs : (m, 2) ndarray
        Translation of each node's finger per unit step parameter s / L (for the rates).
    theta0 : (m,) ndarray
        Contact coordinates (a circle's polar angles): exact for sticking nodes, Newton's
        initial guess for sliding ones.
    phi : float
        Friction angle atan(mu), rad.
    kernel : Kernel, optional
        The route of a linear response (default :func:`~.fixed_set_kernel.selected`: a caller
        that solves many times reads the environment once).

    Returns
    -------
    Solution or SolveFailure
        The failure when Newton does not converge, its Jacobian is singular or it produces
        non-finite values.
    """
    if isinstance(response, LinearResponse) and (
            selected() if kernel is None else kernel) == Kernel.NUMBA:
        return _attempt_compiled(response.C, cfg, centers, dirs, theta0, phi)
    m = len(theta0)
    theta = np.array(theta0, float)
    P = np.flatnonzero(~cfg.stick)
    tip = cfg.tip
    r = tip.radius

    def forces(th: np.ndarray):
        delta = centers + tip.offset(th) - cfg.p0
        out = response(delta)
        return (delta, out, None) if isinstance(out, SolveFailure) else (delta, *out)

    def cone_residual(th: np.ndarray, F: np.ndarray) -> np.ndarray:
        return cross(F[P], unit(tip.normal_angle(th)[P] - cfg.slip[P] * phi))

    delta, F, C = forces(theta)
    if isinstance(F, SolveFailure):
        return F
    force_scale = max(stiffness_scale(C) * float(r.max()), 1e-300)
    tol = max(NEWTON_TOL, getattr(response, "tolerance", 0.0))
    stall = getattr(response, "stall_halvings", NEWTON_BACKTRACKS)
    it, residual, cond = 0, 0.0, 1.0
    J = np.zeros((0, 0))
    R = cone_residual(theta, F)
    while len(P):
        nu = tip.normal_angle(theta)
        ea = unit(nu[P] - cfg.slip[P] * phi)
        G = angle_response(C, nu, r, P)
        J = cross(np.moveaxis(G[P], 2, 1), ea[:, None, :]) + np.diag(
            np.einsum("ij,ij->i", F[P], ea) * tip.curvature(theta)[P]
        )
        residual = float(np.abs(R).max())
        if residual <= tol * force_scale:
            cond = float(np.linalg.cond(J))
            break
        if it >= NEWTON_MAX_ITERATIONS:
            return SolveFailure(
                f"Newton on the sliding angles did not converge in {it} iterations", residual
            )
        try:
            step = np.linalg.solve(J, R)
        except np.linalg.LinAlgError:
            return SolveFailure(SINGULAR_SLIDING, residual, indeterminate=True)
        it += 1
        for halvings in range(NEWTON_BACKTRACKS):
            trial = theta.copy()
            trial[P] -= step
            t_delta, t_F, t_C = forces(trial)
            if isinstance(t_F, SolveFailure):
                if np.abs(step).max() < NEWTON_TOL or halvings >= stall:
                    return t_F
                step = 0.5 * step
                continue
            t_R = cone_residual(trial, t_F)
            if np.abs(t_R).max() < residual or np.abs(step).max() < NEWTON_TOL:
                break
            if halvings >= stall:
                return SolveFailure(f"Newton on the sliding angles stalled: {stall} halvings of "
                                    f"its step did not lower the cone residual", residual)
            step = 0.5 * step
        if isinstance(t_F, SolveFailure):
            return t_F
        theta, delta, F, C, R = trial, t_delta, t_F, t_C, t_R
        if np.abs(step).max() < NEWTON_TOL:
            residual = float(np.abs(R).max())
            cond = float(np.linalg.cond(J))
            break
    dF0 = (C @ dirs.reshape(-1)).reshape(m, 2)
    dtheta = np.zeros(m)
    nu, kappa = tip.normal_angle(theta), tip.curvature(theta)
    if len(P):
        ea = unit(nu[P] - cfg.slip[P] * phi)
        G = angle_response(C, nu, r, P)
        try:
            dtheta[P] = -np.linalg.solve(J, cross(dF0[P], ea))
        except np.linalg.LinAlgError:
            return SolveFailure(SINGULAR_SLIDING, residual, indeterminate=True)
        dF = dF0 + G @ dtheta[P]
    else:
        dF = dF0
    ddelta = dirs + (r * dtheta)[:, None] * tangent(nu)
    return _checked(Solution(theta, delta, F, dtheta, dF, ddelta, it, residual, cond, nu, kappa))


def _checked(sol: Solution) -> Solution | SolveFailure:
    """``sol``, or the failure when its forces, their rates or its angles are not finite."""
    if not (np.all(np.isfinite(sol.F)) and np.all(np.isfinite(sol.dF))
            and np.all(np.isfinite(sol.theta))):
        return SolveFailure(NON_FINITE, sol.residual)
    return sol


def _attempt_compiled(C: np.ndarray, cfg: Configuration, centers: np.ndarray, dirs: np.ndarray,
                      theta0: np.ndarray, phi: float) -> Solution | SolveFailure:
    """:func:`attempt_fixed_set` of a linear response by the compiled kernel
    (:func:`.fixed_set_numba.solve_linear`): the same iteration and the same floats.
    """
    kernel, tip = compiled(), cfg.tip
    status, it, residual, theta, delta, F, dtheta, dF, ddelta, J, nu, kappa = (
        kernel.solve_linear(C, cfg.p0, centers, dirs, np.asarray(theta0, float), cfg.stick,
                            cfg.slip, float(phi), tip.radius, tip.flat, tip.facing, NEWTON_TOL,
                            NEWTON_MAX_ITERATIONS, NEWTON_BACKTRACKS, NEWTON_TOL))
    if status == kernel.NOT_CONVERGED:
        return SolveFailure(
            f"Newton on the sliding angles did not converge in {it} iterations", residual)
    if status == kernel.SINGULAR:
        return SolveFailure(SINGULAR_SLIDING, residual, indeterminate=True)
    if status == kernel.NON_FINITE:
        return SolveFailure(NON_FINITE, residual)
    return Solution(theta, delta, F, dtheta, dF, ddelta, it, residual, jacobian_condition(J), nu,
                    kappa)


def jacobian_condition(J: np.ndarray) -> float:
    """The largest np.linalg.cond of a sliding Jacobian J (k, k) or a stack of them
    (c, k, k); 1 without sliding nodes (k = 0). With one sliding node (k = 1) and finite
    nonzero entries it is exactly 1 (the singular value is |J|), found without the SVD.
    """
    if J.size == 0:
        return 1.0
    if J.shape[-1] == 1:
        a = np.abs(J)
        if np.all((a > 0.0) & (a < np.inf)):
            return 1.0
    return float(np.linalg.cond(J).max())


@dataclass(frozen=True)
class ContactModel:
    """An elastic object under frictional contact with rounded fingertips or pads.

    Parameters
    ----------
    obj : ElasticObject
        The meshed object (its cached boundary compliance is used unless ``reference``).
    mu : float
        Coulomb friction coefficient (>= 0; 0 = frictionless, every contact slides).
    limits : TerminationLimits
        Strain and pickup criteria (only what the scene declares is computed).
    reference : bool
        The paper's literal route: no cached compliance, a full solve per evaluation.
    max_events_per_depth : int
        Chattering bound: a node with more events than this within one depth step is frozen in
        its mode for one depth step (reported).
    options : SolveOptions
        Switches of the large-deformation savings (for measuring them).
    """

    obj: ElasticObject
    mu: float
    limits: TerminationLimits = field(default_factory=TerminationLimits)
    reference: bool = False
    max_events_per_depth: int = 4
    options: SolveOptions = field(default_factory=SolveOptions)
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.mu) and self.mu >= 0):
            raise InvalidInputError(f"friction.mu must be >= 0, got {self.mu}")
        if self.max_events_per_depth < 1:
            raise InvalidInputError(
                f"squeeze.max_events_per_depth must be >= 1, got {self.max_events_per_depth}"
            )

    @property
    def adaptive_steps(self) -> bool:
        """Whether the stepper adapts its substeps between events (a model whose evaluations
        are dear) or keeps the ``step`` grid (this one: an evaluation is a small dense
        product).
        """
        return False

    @property
    def dear_evaluations(self) -> bool:
        """Whether an evaluation of a contact set's response is dear (a nonlinear solve of the
        whole object), so that event location skips the evaluations whose outcome is sure
        (:func:`~.stepper.location.earliest_crossing`); False here: a small dense product.
        """
        return False

    @property
    def constitutive_model(self) -> MaterialModel:
        """The material law of the object: linear (the reduced stiffness of small strain)."""
        return MaterialModel.LINEAR

    @property
    def strain_measure(self) -> StrainMeasure:
        """The measure of :meth:`max_strain`, :meth:`field_strain` and the strain limit."""
        return self.constitutive_model.strain_measure

    @property
    def phi(self) -> float:
        """Friction angle atan(mu), rad."""
        return float(np.arctan(self.mu))

    @property
    def length(self) -> float:
        """L, m (cached: the object's scale is recomputed from the mesh on every access)."""
        if "length" not in self._cache:
            self._cache["length"] = self.obj.scale
        return self._cache["length"]

    @property
    def force_unit(self) -> float:
        """E h L, N: the force unit inside."""
        return self.obj.material.force_scale * self.length

    @property
    def boundary_nodes(self) -> np.ndarray:
        """Outer boundary loop (b,)."""
        return self.obj.mesh.boundary

    def positions(self, nodes) -> np.ndarray:
        """Undeformed positions / L (k, 2)."""
        return self.obj.mesh.nodes[np.asarray(nodes, int)] / self.length

    def response(self, sd: SetData) -> Response:
        """The set's elastic response F = C delta with its constant reduced stiffness."""
        return LinearResponse(sd.C)

    def set_data(self, nodes: tuple[int, ...]) -> SetData:
        """Reduced data of the contact set ``nodes`` (sorted), cached per set (fast model).

        The fast model's sets are shared by every model of the same object (a sweep's
        evaluations of one object with other friction, tips or placements reduce a set once):
        the object keeps them, the least recently used dropped beyond SHARED_SET_BYTES. A
        model counts a set in ``sets_factored`` (and its condition in ``max_condition``) on
        its own first use, whether it reduced the set or took it from the object.
        """
        key = tuple(int(k) for k in nodes)
        sets = self._cache.setdefault("sets", {})
        if key in sets:
            return sets[key]
        if len(key) < 2:
            raise InvalidInputError(
                f"the object lost contact: {len(key)} contact node(s) left; "
                "at "
                "least 2 are needed to hold it (Lemma 2)"
            )
        if self.reference:
            data = self._reduce(key)
        else:
            shared = (self.obj._shared.get("contact_sets")
                      or self.obj._shared.setdefault("contact_sets", SharedSets()))
            tag = (key, self.limits.strain is not None)
            data = shared.get(tag)
            if data is None:
                data = shared.put(tag, self._reduce(key))
        sets[key] = data
        self._cache["max_condition"] = max(self._cache.get("max_condition", 0.0), data.condition)
        self._cache["sets_factored"] = self._cache.get("sets_factored", 0) + 1
        return data

    def _reduce(self, key: tuple[int, ...]) -> SetData:
        """The reduced data of the contact set ``key`` (sorted node indices)."""
        idx = np.array(key)
        dofs = node_dofs(idx)
        if self.reference:
            A_hat = self.unit_responses(dofs)[dofs]
            A_hat = 0.5 * (A_hat + A_hat.T)
            A_bc = None
            self._cache["sets"].clear()
        else:
            pos = self.obj.boundary_positions(idx)
            if np.any(pos < 0):
                raise InvalidInputError(
                    f"contact nodes {idx[pos < 0].tolist()} are not on the outer boundary"
                )
            A_bc = self.obj.boundary_compliance[:, node_dofs(pos)]
            A_hat = A_bc[node_dofs(pos)]
        C, E, _, condition = reduce_blocks(A_hat, self.obj.rigid[dofs])
        strain_map = None
        if self.limits.strain is not None and not self.reference:
            strain_map = self.element_strains(self.unit_responses(dofs))
        return SetData(idx, C, E, A_bc, strain_map, condition)

    def unit_responses(self, dofs: np.ndarray) -> np.ndarray:
        """K+ applied to unit loads at ``dofs``: (2n, len(dofs)), by direct sparse solves."""
        unit_loads = np.zeros((2 * self.obj.mesh.n, len(dofs)))
        unit_loads[dofs, np.arange(len(dofs))] = 1.0
        return self.obj.pinv_apply(unit_loads)

    def element_strains(self, u_hat: np.ndarray) -> np.ndarray:
        """Engineering strains (t*3,) or (t*3, k) of dimensionless nodal displacements (2n[,
        k]).
        """
        B, dofs = strain_tables(self.obj, self.length)
        de = u_hat[dofs]
        return np.einsum("tij,tj...->ti...", B, de).reshape((-1,) + u_hat.shape[1:])

    def full_displacement(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> np.ndarray:
        """Dimensionless displacement of every node (2n,): K+ F + R g (one sparse solve)."""
        rhs = np.zeros(2 * self.obj.mesh.n)
        rhs[node_dofs(sd.nodes)] = F.reshape(-1)
        return self.obj.pinv_apply(rhs) + self.obj.rigid @ (sd.E.T @ delta.reshape(-1))

    def boundary_displacement(
        self, sd: SetData, delta: np.ndarray, F: np.ndarray, rows: np.ndarray | None = None
    ) -> np.ndarray:
        """Dimensionless displacement (k, 2) of boundary loop positions ``rows`` (all if None).

        Fast model: A_bc F + R_b g, O(k m). Reference model: a full solve.
        """
        b = self.boundary_nodes
        rows = np.arange(len(b)) if rows is None else np.asarray(rows, int)
        g = sd.E.T @ delta.reshape(-1)
        if sd.A_bc is None:
            u = self.full_displacement(sd, delta, F).reshape(-1, 2)
            return u[b[rows]]
        A, R = self._boundary_rows(sd, rows)
        u = A @ F.reshape(-1) + R @ g
        return u.reshape(-1, 2)

    def _boundary_rows(self, sd: SetData, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The rows of A_bc and of the rigid modes of boundary positions ``rows`` (integers;
        none: (0, 2m) and (0, 3) arrays), kept for the last contact set (a substep's start and
        end, its events' look-ups ask for the same rows).
        """
        kept = self._cache.get("boundary_rows")
        if kept is None or kept[0] is not sd:
            kept = self._cache["boundary_rows"] = (sd, {})
        tag = (rows.dtype.str, rows.tobytes())
        made = kept[1].get(tag)
        if made is None:
            if len(kept[1]) >= BOUNDARY_ROWS_KEPT:
                kept[1].clear()
            made = kept[1][tag] = (sd.A_bc[node_dofs(rows)],
                                   self.obj.rigid[node_dofs(self.boundary_nodes[rows])])
        return made

    def max_strain(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> tuple[float, int]:
        """(largest strain by the limit's criterion in :attr:`strain_measure`, element index)
        of the configuration (counted in :attr:`strain_evaluations`).
        """
        self._cache["strain_evaluations"] = self.strain_evaluations + 1
        return self._max_strain(sd, delta, F)

    @property
    def strain_evaluations(self) -> int:
        """How many configurations' strain was measured (the strain-limit check's work)."""
        return self._cache.get("strain_evaluations", 0)

    def _max_strain(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> tuple[float, int]:
        if sd.strain_map is not None:
            eps = (sd.strain_map @ F.reshape(-1)).reshape(-1, 3)
        else:
            eps = self.element_strains(self.full_displacement(sd, delta, F)).reshape(-1, 3)
        return strain_criterion(eps, self.limits.criterion)


    def boundary_rate(self, sd: SetData, sol: Solution, rows: np.ndarray) -> np.ndarray:
        """d/ds of the displacement (k, 2) of boundary positions ``rows`` at ``sol``."""
        return self.boundary_displacement(sd, sol.ddelta, sol.dF, rows)

    def strain_energy(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> float:
        """Dimensionless strain energy (/ (E h L^2)) of a configuration: 1/2 delta . F."""
        return 0.5 * float(np.sum(delta * F))

    def field_strain(self, u_hat: np.ndarray) -> tuple[float, int]:
        """(largest strain by the limit's criterion in :attr:`strain_measure`, element) of a
        full displacement / L.
        """
        return strain_criterion(self.element_strains(u_hat).reshape(-1, 3), self.limits.criterion)

    def field_deformation(self, u_hat: np.ndarray) -> np.ndarray:
        """Deformation gradients F = I + grad u (t, 2, 2) of a full displacement / L (2n,)."""
        return np.eye(2) + (self.obj.gradient @ u_hat).reshape(-1, 2, 2)

    def field_area_ratio(self, u_hat: np.ndarray) -> tuple[float, int]:
        """(smallest det F = deformed / reference element area, element) of a full
        displacement / L; <= 0 means the deformed mesh x + u folds over.
        """
        det = area_ratios(self.obj.gradient, u_hat)
        k = int(np.argmin(det))
        return float(det[k]), k

    def area_ratio(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> tuple[float, int]:
        """(smallest det F, element) of the configuration, without solving for the field.

        Every element's displacement gradient obeys ||H_e|| <= B_e = sum_k b_ek ||F_k|| +
        ||H_e of the rigid part|| (b_ek: :meth:`ElasticObject.gradient_bounds`), and
        det(I + H) >= (1 - ||H||)^2: elements with B_e < GRADIENT_BOUND_EXACT are above
        INVERSION_AREA_RATIO whatever they are; the others get their exact H_e = sum_k G_k[e] F_k
        + rigid part (:meth:`ElasticObject.load_gradients`). Returns the smallest exact det F
        and its element, or, if that is larger, the bound (1 - max B_e)^2 of the rest with
        element -1 (no element near the threshold).

        Each node's gradients are read where the object keeps them: stacking a set's as one
        (m, t, 4, 2) array copied 107 MB for each of the 20,091-node foam square's 21 contact
        sets that neared inversion (0.72 of its 2.49 s).
        """
        g = sd.E.T @ delta.reshape(-1)
        rigid = (self.obj.rigid_gradients @ g).reshape(-1, 4)
        bound = (self.area_tables(sd)[0] @ np.sqrt((F * F).sum(axis=1))
                 + np.sqrt((rigid * rigid).sum(axis=1)))
        exact = bound >= GRADIENT_BOUND_EXACT
        near, rest = np.flatnonzero(exact), bound[~exact]
        floor = (1.0 - rest.max()) ** 2 if rest.size else np.inf
        if near.size == 0:
            return float(floor), -1
        if selected() == Kernel.NUMBA:
            self.area_tables(sd, loads=True)  # the kernels' list of them, kept from now
        H = rigid[near] + sum(G[near] @ f for G, f in zip(self.obj.load_gradients(sd.nodes), F))
        det = (1.0 + H[:, 0]) * (1.0 + H[:, 3]) - H[:, 1] * H[:, 2]
        k = int(np.argmin(det))
        return (float(det[k]), int(near[k])) if det[k] <= floor else (float(floor), -1)


    def area_tables(self, sd: SetData, *, loads: bool = False) -> tuple[np.ndarray, object]:
        """:meth:`area_ratio`'s bounds (t, m) and the set's load gradients as the numba route's
        kernels take them (:func:`~.substeps_numba.load_list`; None until an element neared,
        made now if ``loads``), kept by the object for all of its models (they depend on the
        object and the set's nodes only: repeated squeezes and a sweep's evaluations of an
        object share them), at most AREA_TABLES_BYTES of them.
        """
        obj = self.obj
        size = 72 * len(obj.mesh.triangles) * max(len(sd.nodes), 1)  # bounds and loads
        kept = kept_for(obj._shared.setdefault("area_tables", {}), sd, None,
                        lambda: {"bounds": obj.gradient_bounds(tuple(sd.nodes.tolist()))},
                        max(AREA_TABLES_BYTES // size, 2))
        if loads and "loads" not in kept:
            kept["loads"] = compiled_substeps().load_list(obj.load_gradients(sd.nodes))
        return kept["bounds"], kept.get("loads")


def strain_tables(obj: ElasticObject, length: float) -> tuple[np.ndarray, np.ndarray]:
    """The element strain-displacement matrices with coordinates / ``length`` (t, 3, 6) and
    the elements' DOFs (t, 6), kept on ``obj`` (read-only) for all of its contact models,
    whose length is its scale: a sweep computes them once per object, not per evaluation.
    """
    kept = obj._shared.get("strain_b")
    if kept is None or kept[0] != length:
        B, _ = strain_displacement(obj.mesh.nodes / length, obj.mesh.triangles)
        dofs = element_dofs(obj.mesh.triangles)
        B.flags.writeable = dofs.flags.writeable = False
        kept = obj._shared["strain_b"] = (length, B, dofs)
    return kept[1], kept[2]


def strain_criterion(eps: np.ndarray, criterion: str) -> tuple[float, int]:
    """(max strain, element) from engineering strains (t, 3) by ``criterion`` (eq. 45)."""
    pair = eps[:, :2] if criterion == StrainCriterion.COMPONENTWISE else principal_strains(eps)
    return largest_pair_entry(pair)
