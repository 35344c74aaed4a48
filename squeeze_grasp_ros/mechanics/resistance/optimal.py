# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Optimal resistance to a translating adversary finger at fixed contacts (paper Sec. 6.1-6.2).

Three fingers F1, F2 (grasping) and A (adversary) touch the object at fixed contact node sets
I, J, K: one node each for point contacts (Sec. 6.1), segments for Sec. 6.2. Every node of a set
moves with its finger (eq. 64), so the contact displacement is Delta = P x with x = (d1, d2, a)
and the 2m x 6 expansion P of App. D. The grasping fingers' work (eqs. 53, 94) is

    W_F = 1/2 (d1, d2, 0)^T G (d1, d2, a),   G = P^T C P   (6 x 6),

minimised over (d1, d2) for a given adversary translation a, under one of two constraints:

* **stable** (Delta in col(C)): eqs. (54)-(55), or (66) for segments. Eliminating d2 by (54)
  gives W_F = 1/2 d1^T H d1 + c^T d1 + omega (eq. 57; App. D eqs. 86-88, 92-93). With
  d1 = tau t + eta n, t the unit vector of p - q (contact centroids of F1, F2), (55)/(66) fixes
  eta (eq. 59) and W_F = 1/2 b2 tau^2 + b1 tau + b0 (eq. 60). b2 = t^T H t > 0 always
  (Theorem 11, Proposition 12), so tau* = -b1/b2 is the unique optimum for every p_k, including
  the midpoint of p_i p_j (docs/design.md §2: the null space of H matters only without (55)).
* **pure** (Delta in col(AC) = null(E^T), Theorem 7): x = U tau with U an orthonormal basis of
  null(E^T P) (App. D; for point contacts U spans col(AC)) and a = Q tau, Q = (0, I2) U
  (eq. 62). If a is outside col(Q) (possible only when rank Q < 2) the adversary cannot be
  resisted purely. Otherwise the feasible tau form the affine set Q^+ a + null(Q), on which W_F
  has a positive definite Hessian (a pure Delta with a = 0 is never rigid, since E^T B = I), so
  the minimiser is unique: eq. (63) with tau*_1 of App. D eq. (91) when rank Q = 2. For
  rank Q = 1 the paper sets tau2 = tau3 = 0, which is feasible but not minimal in general; here
  the minimum over the whole feasible plane is taken.

The optimum is linear in a: d* = ||a|| psi(a / ||a||) (eq. 61) and W*_F = ||a||^2 W*_F(a_hat), so
a sweep of adversary directions is one vectorised evaluation. Internals are dimensionless
(lengths by the object size L, forces by E h L, work by E h L^2); the API is SI. The closed
forms themselves are in :mod:`.resistance_forms`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Mapping, Sequence

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh
from squeeze_grasp_ros.mechanics.elastic.reduced import (
    ReducedStiffness,
    reduced_stiffness,
    rotation_angle,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, node_indices, require_finite
from squeeze_grasp_ros.mechanics.resistance.forms import (
    PureForm,
    StableForm,
    expansion_matrix,
    null_basis,
    perp,
    pure_form,
    stable_form,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_state import event_counts
from squeeze_grasp_ros.mechanics.ties import first_max, first_min
from squeeze_grasp_ros.mechanics.vocabulary import ContactKind, ContactMode, Finger, SqueezeKind

FEASIBILITY_TOL = 1e-7
"""Relative constraint residual above which a resistance is reported as infeasible."""


@dataclass(frozen=True)
class ResistanceGrasp:
    """The fixed-contact resistance problem of one placement of F1, F2 and A.

    Build it with :func:`resistance_grasp`. It caches everything that does not depend on the
    adversary translation a, so each direction then costs a few 2x2 and 6x6 products.

    Attributes
    ----------
    obj : ElasticObject
        The object (its cached compliance is reused, never recomputed).
    segments : mapping
        Finger (F1, F2, A) -> mesh node indices (k,) of its contact set I, J, K; the first node
        of each set is the finger's initial contact node.
    red : ReducedStiffness
        Reduced stiffness (SI) of the nodes of I, J, K concatenated in that order.
    G : (6, 6) ndarray
        Dimensionless P^T C_hat P: the fingers' resultant forces for x = (d1, d2, a).
    points : (m, 2) ndarray
        Dimensionless contact node positions (object frame / L), in the order of ``red.contacts``.
    scale : float
        The object size L, m.
    """

    obj: ElasticObject
    segments: Mapping[Finger, np.ndarray]
    red: ReducedStiffness
    G: np.ndarray
    points: np.ndarray
    scale: float

    @property
    def counts(self) -> np.ndarray:
        """|I|, |J|, |K| (3,) int."""
        return np.array([len(self.segments[f]) for f in tuple(Finger)])

    @property
    def kind(self) -> ContactKind:
        """Contact kind: point if every finger touches one node, else segment."""
        return ContactKind.POINT if np.all(self.counts == 1) else ContactKind.SEGMENT

    @property
    def contacts(self) -> list[int]:
        """Initial contact nodes [i, j, k] of F1, F2, A."""
        return [int(self.segments[f][0]) for f in tuple(Finger)]

    @property
    def centroids(self) -> np.ndarray:
        """Dimensionless contact centroids p, q, r (3, 2) of F1, F2, A (Sec. 6.2)."""
        finger = np.repeat(np.arange(3), self.counts)
        return np.array([self.points[finger == f].mean(axis=0) for f in range(3)])

    @cached_property
    def stable(self) -> StableForm:
        """The quadratic form (57) and the line (59) of the stable resistances."""
        return stable_form(self.G, self.counts, self.centroids)

    @cached_property
    def pure(self) -> PureForm:
        """The pure resistances and their minimiser."""
        E_fingers = expansion_matrix(self.counts).T @ self.red.E
        return pure_form(self.G, null_basis(E_fingers.T))

    def form(self, mode: SqueezeKind) -> StableForm | PureForm:
        """The :class:`StableForm` or :class:`PureForm` of ``mode``."""
        if mode not in SqueezeKind.planned():
            raise InvalidInputError(
                f"resistance mode must be one of {list(SqueezeKind.planned())}, got {mode!r}"
            )
        return self.stable if mode == SqueezeKind.STABLE else self.pure


def resistance_grasp(obj: ElasticObject,
                     segments: Mapping[Finger, Sequence[int]]) -> ResistanceGrasp:
    """The resistance problem for contact sets ``segments`` = {"F1": I, "F2": J, "A": K}.

    Parameters
    ----------
    obj : ElasticObject
        The meshed object; its cached boundary compliance gives the contact block.
    segments : mapping of str to sequence of int
        Non-empty, pairwise disjoint sets of outer-boundary mesh nodes of F1, F2 and A; the first
        node of each is reported as the finger's initial contact node.

    Raises
    ------
    InvalidInputError
        For missing or unknown fingers, empty or overlapping sets, or nodes off the boundary.
    """
    if set(segments) != set(tuple(Finger)):
        raise InvalidInputError(
            f"segments must have exactly the keys {list(tuple(Finger))}, got {sorted(segments)}"
        )
    sets = {f: node_indices(f"segments[{f}]", segments[f]) for f in tuple(Finger)}
    empty = [f for f in tuple(Finger) if len(sets[f]) == 0]
    if empty:
        raise InvalidInputError(f"contact set of {empty[0]} is empty")
    nodes = np.concatenate([sets[f] for f in tuple(Finger)])
    if len(np.unique(nodes)) != len(nodes):
        listed = {f: sets[f].tolist() for f in tuple(Finger)}
        raise InvalidInputError(f"contact sets of F1, F2 and A must be disjoint, got {listed}")
    node_indices("contact nodes", nodes, obj.mesh.n)
    off = nodes[obj.boundary_positions(nodes) < 0]
    if len(off):
        raise InvalidInputError(
            f"contact nodes must lie on the outer boundary, got {off.tolist()}"
        )
    red = reduced_stiffness(obj, nodes)
    P = expansion_matrix([len(sets[f]) for f in tuple(Finger)])
    G = P.T @ (red.C / obj.material.force_scale) @ P
    L = obj.scale
    return ResistanceGrasp(obj, sets, red, 0.5 * (G + G.T), obj.mesh.nodes[nodes] / L, L)


def contact_segments(
    mesh: Mesh, contacts: Sequence[int], half_width: float | None = None
) -> list[np.ndarray]:
    """Fixed contact segments around initial contact nodes (Sec. 6.2).

    Parameters
    ----------
    mesh : Mesh
        The object mesh.
    contacts : sequence of int
        Initial contact nodes on the outer boundary, one per finger.
    half_width : float, optional
        Arc length, m, along the undeformed boundary on each side of a contact node whose nodes
        join its segment. None: the node and its two boundary neighbours.

    Returns
    -------
    list of (k,) ndarray of int
        One segment per contact, the contact node first, then by arc distance.

    Raises
    ------
    InvalidInputError
        For a ``half_width`` that is negative or not finite, or so wide that two segments
        share a node (named with the contacts' arc distance, the field's bound).
    """
    loop = mesh.boundary
    edge = np.linalg.norm(np.roll(mesh.nodes[loop], -1, axis=0) - mesh.nodes[loop], axis=1)
    s = np.concatenate([[0.0], np.cumsum(edge)[:-1]])
    perimeter = float(edge.sum())
    if half_width is not None and not (np.isfinite(half_width) and half_width >= 0):
        raise InvalidInputError(f"segment half width must be finite and >= 0 m, got {half_width}")
    out = []
    for c in contacts:
        k = mesh.boundary_position(int(c))
        gap = np.abs(s - s[k])
        dist = np.minimum(gap, perimeter - gap)
        if half_width is None:
            near = np.argsort(dist, kind="mergesort")[:3]
        else:
            near = np.flatnonzero(dist <= half_width * (1 + 1e-12))
            near = near[np.argsort(dist[near], kind="mergesort")]
        out.append(loop[near])
    if half_width is not None:
        _require_apart(out, [s[mesh.boundary_position(int(c))] for c in contacts], perimeter,
                       half_width)
    return out


def _require_apart(segments: list[np.ndarray], arc: list[float], perimeter: float,
                   half_width: float) -> None:
    """Refuse segments of F1, F2, A (in that order) that share a node, naming the two
    contacts, their distance along the boundary and the half width that keeps them apart.

    Parameters
    ----------
    segments : list of (k,) ndarray of int
        Each finger's segment.
    arc : list of float
        Arc length, m, of each finger's contact node along the outer boundary.
    perimeter : float
        Length of the outer boundary, m.
    half_width : float
        The half width that made the segments, m.
    """
    names = [str(f) for f in tuple(Finger)]
    pairs = list(itertools.combinations(range(len(segments)), 2))
    shared = [(i, j) for i, j in pairs if np.intersect1d(segments[i], segments[j]).size]
    if not shared:
        return
    gaps = {(i, j): min(abs(arc[i] - arc[j]), perimeter - abs(arc[i] - arc[j]))
            for i, j in pairs}
    near = min(pairs, key=gaps.get)
    raise InvalidInputError(
        f"segment half width {half_width:g} m makes the contact segments of "
        f"{names[shared[0][0]]} and {names[shared[0][1]]} overlap; the nearest contacts, "
        f"{names[near[0]]} and {names[near[1]]}, are {gaps[near]:.4g} m apart along the "
        f"boundary, so the half width must be below {gaps[near] / 2:.4g} m")


@dataclass(frozen=True)
class Resistance:
    """A resistance (d1, d2) of F1, F2 to the adversary translation a at fixed contacts.

    Attributes
    ----------
    mode : SqueezeKind
        Stable or pure.
    contact_model : ContactKind
        Point or segment.
    success : bool
        False when the adversary cannot be resisted in this mode, or a user-given resistance
        violates the mode's constraints.
    reason : str
        Why (human-readable).
    contacts : list of int
        Initial contact nodes [i, j, k] of F1, F2, A.
    segments : mapping
        Finger -> contact node set of F1, F2, A.
    a : (2,) ndarray
        Adversary translation, m, object frame.
    d1, d2 : (2,) ndarray or None
        Translations of F1 and F2, m (None if there is no resistance).
    work : mapping
        Finger or "total" -> work, J (None without a resistance); total = F1 + F2 = W_F
        (eq. 53).
    forces : mapping
        Finger -> resultant force (2,) on the object, N (None without a resistance).
    node_forces : (m, 2) ndarray or None
        Force at each contact node, N, in the order of the segments F1, F2, A.
    energy : float or None
        Strain energy 1/2 Delta^T C Delta, J (= W_F + work of A).
    rigid_rotation : float or None
        Rigid-rotation angle of the displacement field, rad (zero for a pure resistance).
    unit_work : float or None
        W_F / ||a||^2, J/m^2: the work to resist a unit push in this direction.
    event_counts : mapping
        Contact events A, B, C, D by letter (all zero at fixed contacts).
    diagnostics : mapping
        Residuals and condition numbers (see :func:`optimal_resistance`).
    """

    mode: SqueezeKind
    contact_model: ContactKind
    success: bool
    reason: str
    contacts: list
    segments: Mapping[Finger, Sequence[int]]
    a: np.ndarray
    d1: np.ndarray | None = None
    d2: np.ndarray | None = None
    work: Mapping[str, float | None] = field(
        default_factory=lambda: {k: None for k in (*Finger, "total")}
    )
    forces: Mapping[Finger, np.ndarray | None] = field(
        default_factory=lambda: {f: None for f in tuple(Finger)})
    node_forces: np.ndarray | None = None
    energy: float | None = None
    rigid_rotation: float | None = None
    unit_work: float | None = None
    event_counts: Mapping[str, int] = field(default_factory=lambda: event_counts(()))
    diagnostics: Mapping[str, object] = field(default_factory=dict)

    def psi(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(psi1, psi2) of eq. (61): d1 / ||a||, d2 / ||a|| (dimensionless), or None."""
        if self.d1 is None:
            return None
        norm = float(np.linalg.norm(self.a))
        return self.d1 / norm, self.d2 / norm

    def to_json(self) -> dict:
        """JSON-able dict (SI); missing quantities are null."""

        def vec(v):
            return None if v is None else [float(x) for x in v]

        per_node = None
        if self.node_forces is not None:
            bounds = np.cumsum([0] + [len(self.segments[f]) for f in tuple(Finger)])
            per_node = {
                f: [
                    {"node": int(n), "mode": ContactMode.STICK, "force": vec(fv)}
                    for n, fv in zip(self.segments[f], self.node_forces[lo:hi])
                ]
                for f, lo, hi in zip(tuple(Finger), bounds[:-1], bounds[1:])
            }
        psi = self.psi()
        return {
            "success": self.success,
            "reason": self.reason,
            "mode": self.mode,
            "contact_model": self.contact_model,
            "contacts": list(self.contacts),
            "segments": per_node
            or {f: [{"node": int(n)} for n in self.segments[f]] for f in tuple(Finger)},
            "a": vec(self.a),
            "d1": vec(self.d1),
            "d2": vec(self.d2),
            "psi": None if psi is None else {Finger.F1: vec(psi[0]), Finger.F2: vec(psi[1])},
            "work": dict(self.work),
            "unit_work": self.unit_work,
            "energy": self.energy,
            "forces": {f: vec(v) for f, v in self.forces.items()},
            "rigid_rotation": self.rigid_rotation,
            "event_counts": dict(self.event_counts),
            "diagnostics": dict(self.diagnostics),
        }


MAX_RELATIVE_PUSH = 0.25
"""Largest adversary translation |a| a resistance accepts, relative to the object size L (the
larger side of its bounding box). Sec. 6 is small-deformation elasticity at fixed (point,
segment) or tracked (Algorithm 2) contacts: the fixed-contact optimum is linear in a, so at
|a| = 9 L (a = 1 m on the 0.11 m blob of Fig. 9) it reported fingers moved by 0.47 m and
126 J as a success, and Algorithm 2 steps A's travel in substeps of L, so an unbounded |a| is
unbounded work. Fig. 9 pushes 0.09 L, Fig. 10 0.05 L."""

MAX_DIRECTIONS = 100_000
"""Most push directions of :func:`sweep_directions` (0.0036 degrees apart; a few MB)."""


MIN_RELATIVE_PUSH = 1e-100
"""Shortest adversary translation |a| a resistance accepts, relative to the object size L, also
as a per-unit-push direction. The work is quadratic in a: at |a| = 1e-160 L the Fig. 9 blob's
work came out as 1.4e-318 J, a subnormal float with 6 significant digits, and below about
1e-154 L of a 0.1 m object |a|^2 left the float range, so a = [1e-200, 0] m was refused as
"must be nonzero"."""


def require_push_range(a: np.ndarray, size: float, *, per_unit_push: bool = False) -> None:
    """Refuse an adversary translation ``a`` (m) shorter than :data:`MIN_RELATIVE_PUSH` or,
    unless ``per_unit_push`` (``a`` is then a direction of any length), longer than
    :data:`MAX_RELATIVE_PUSH` of the object size ``size`` (m).
    """
    length = float(np.hypot(*a))
    if length < MIN_RELATIVE_PUSH * size:
        raise InvalidInputError(
            f"adversary.a is {length:.4g} m long, {length / size:.3g} of the object size "
            f"{size:.4g} m; the resistance model takes |a| >= {MIN_RELATIVE_PUSH:g} of the "
            f"size, {MIN_RELATIVE_PUSH * size:.4g} m (its work, quadratic in a, would leave "
            "the floating-point range)")
    if not per_unit_push and length > MAX_RELATIVE_PUSH * size:
        raise InvalidInputError(
            f"adversary.a is {length:.4g} m long, {length / size:.3g} times the object size "
            f"{size:.4g} m; the resistance model (small deformations) takes |a| <= "
            f"{MAX_RELATIVE_PUSH:g} of the size, {MAX_RELATIVE_PUSH * size:.4g} m")


def _translation(a, name: str = "adversary translation a") -> np.ndarray:
    a = np.asarray(a, dtype=float).reshape(-1)
    if a.shape != (2,):
        raise InvalidInputError(f"{name} must be [x, y] in m, got shape {a.shape}")
    require_finite(name, a)
    if not np.any(a):
        raise InvalidInputError(f"{name} must be nonzero")
    return a


def _unit(v: np.ndarray) -> np.ndarray:
    """``v`` (finite, of a nonzero length) divided by its length.

    ``np.linalg.norm`` squares the entries and overflows beyond about 1e154 (a direction of
    [1e308, 1e308] became [0, 0]): such a ``v`` is first scaled by its largest entry; any
    other is divided as before, bit for bit.
    """
    with np.errstate(over="ignore"):
        norm = float(np.linalg.norm(v))
    if not np.isfinite(norm):
        v = v / np.abs(v).max()
        norm = float(np.linalg.norm(v))
    return v / norm


def _unresisted(
    grasp: ResistanceGrasp, mode: str, a: np.ndarray, reason: str, diagnostics: dict
) -> Resistance:
    segments = {f: grasp.segments[f].tolist() for f in tuple(Finger)}
    return Resistance(
        mode, grasp.kind, False, reason, grasp.contacts, segments, a, diagnostics=diagnostics
    )


def _pure_diagnostics(form: PureForm, a_hat: np.ndarray) -> dict:
    return {
        "rank_Q": form.rank,
        "Q_singular_values": form.singular_values.tolist(),
        "outside_col_Q": float(form.outside(a_hat[None])[0]),
        "hessian_condition": form.hessian_condition,
    }


def _cannot_resist(grasp: ResistanceGrasp, a: np.ndarray) -> Resistance:
    form = grasp.pure
    a_hat = a / grasp.scale
    reason = (
        f"cannot be resisted: rank Q = {form.rank} and a is not in col(Q), so no pure "
        "contact displacement moves A by a (Sec. 6.1.2)"
    )
    return _unresisted(grasp, SqueezeKind.PURE, a, reason, _pure_diagnostics(form, a_hat))


def finger_work(G: np.ndarray, x: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Work (N, 3) of F1, F2, A for rows x = (d1, d2) (N, 4) and a (N, 2): 1/2 d_f . (G x6)_f."""
    x6 = np.hstack([x, a])
    return 0.5 * (x6 * (x6 @ G)).reshape(-1, 3, 2).sum(axis=2)


def optimum_batch(
    grasp: ResistanceGrasp, mode: SqueezeKind, a_hat: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Optimal (d1, d2) for many dimensionless adversary translations at once.

    Parameters
    ----------
    grasp : ResistanceGrasp
    mode : {"stable", "pure"}
    a_hat : (N, 2) ndarray
        Adversary translations divided by the object size L.

    Returns
    -------
    x : (N, 4) ndarray
        Dimensionless (d1, d2) per row (multiply by L for metres); rows that cannot be resisted
        hold the least-squares point and are flagged in ``feasible``.
    work : (N,) ndarray
        Dimensionless W*_F (multiply by E h L^2 for J); for "stable" from the parabola (60).
    feasible : (N,) ndarray of bool
        False where a pure resistance does not exist (a outside col(Q)).
    """
    form = grasp.form(mode)
    if isinstance(form, StableForm):
        x, work = form.optimum(a_hat)
        return x, work, np.ones(len(a_hat), bool)
    x = a_hat @ form.gain.T
    work = finger_work(grasp.G, x, a_hat)[:, :2].sum(axis=1)
    return x, work, form.outside(a_hat) <= FEASIBILITY_TOL


def evaluate_resistance(
    grasp: ResistanceGrasp,
    d1,
    d2,
    a,
    mode: SqueezeKind = SqueezeKind.STABLE,
    reason: str = "user-given resistance",
    *,
    per_unit_push: bool = False,
) -> Resistance:
    """Forces, work and constraint residuals of a given resistance (d1, d2) to a, all in m.

    ``a`` is at most :data:`MAX_RELATIVE_PUSH` of the object size, unless ``per_unit_push``:
    then (d1, d2, a) are rates per metre of A's travel, of any length (the model is linear);
    at least :data:`MIN_RELATIVE_PUSH` of it either way.

    ``success`` is False (the residual is in ``reason``) when (d1, d2, a) violates the mode's
    constraints by more than :data:`FEASIBILITY_TOL`: eqs. (54)-(55) (segments: their Sec. 6.2
    form) for "stable", (d1, d2, a) in null(E^T P) (i.e. E^T Delta = 0) for "pure".

    Diagnostics, all dimensionless: ``sum_delta_residual`` |sum delta_t| / sum |delta_t|
    (eq. 54); ``moment_delta_residual`` |sum p_t x delta_t| / (L sum |delta_t|) (eq. 55);
    ``rigid_residual`` |E^T Delta| / |Delta|; ``force_residual`` |sum f_t| / sum |f_t| and
    ``moment_residual`` |sum p_t x f_t| / (L sum |f_t|) (equilibrium); ``reduced_condition``
    (of Z^T A Z); ``pulling``, the fingers whose resultant force points out of the object at
    their initial contact (fixed contacts act as if glued, Sec. 6.1); plus ``b2`` (N/m,
    eq. 60) for "stable" and the rank of Q, its singular values, the distance of a from col(Q)
    and the Hessian condition for "pure".
    """
    form = grasp.form(mode)
    a = _translation(a)
    require_push_range(a, grasp.scale, per_unit_push=per_unit_push)
    x = np.concatenate([np.asarray(d1, float).reshape(2), np.asarray(d2, float).reshape(2), a])
    require_finite("d1, d2", x)
    red, obj = grasp.red, grasp.obj
    P = expansion_matrix(grasp.counts)
    delta = P @ x
    node_forces = red.forces(delta).reshape(-1, 2)
    resultant = (P.T @ node_forces.reshape(-1)).reshape(3, 2)
    work = {
        f: 0.5 * float(x[2 * k : 2 * k + 2] @ resultant[k]) for k, f in enumerate(tuple(Finger))
    }
    work["total"] = work[Finger.F1] + work[Finger.F2]
    g = red.rigid_coefficients(delta)
    pts = grasp.points - grasp.points.mean(axis=0)
    dl = delta.reshape(-1, 2)
    d_size = max(float(np.linalg.norm(dl, axis=1).sum()), 1e-300)
    f_size = max(float(np.linalg.norm(node_forces, axis=1).sum()), 1e-300)
    diagnostics = {
        "sum_delta_residual": float(np.linalg.norm(dl.sum(axis=0))) / d_size,
        "moment_delta_residual": abs(float(np.sum(perp(pts) * dl))) / d_size,
        "rigid_residual": float(np.linalg.norm(g) / max(float(np.linalg.norm(delta)), 1e-300)),
        "force_residual": float(np.linalg.norm(node_forces.sum(axis=0))) / f_size,
        "moment_residual": abs(float(np.sum(perp(pts) * node_forces))) / f_size,
        "reduced_condition": red.condition,
        "pulling": [
            f
            for k, f in enumerate(tuple(Finger))
            if resultant[k] @ obj.mesh.normal_at(grasp.contacts[k]) > 0
        ],
    }
    if isinstance(form, StableForm):
        violation = max(diagnostics["sum_delta_residual"], diagnostics["moment_delta_residual"])
        diagnostics["b2"] = form.b2 * obj.material.force_scale
    else:
        violation = form.violation(x)
        diagnostics.update(_pure_diagnostics(form, a / grasp.scale))
    success = violation <= FEASIBILITY_TOL
    if not success:
        reason = (
            f"{reason} is not a {mode} resistance: constraint residual {violation:.3g} > "
            f"{FEASIBILITY_TOL:g}"
        )
    return Resistance(
        mode=mode,
        contact_model=grasp.kind,
        success=success,
        reason=reason,
        contacts=grasp.contacts,
        segments={f: grasp.segments[f].tolist() for f in tuple(Finger)},
        a=a,
        d1=x[:2],
        d2=x[2:4],
        work=work,
        forces={f: resultant[k] for k, f in enumerate(tuple(Finger))},
        node_forces=node_forces,
        energy=red.energy(delta),
        rigid_rotation=rotation_angle(obj, g),
        unit_work=work["total"] / float(a @ a),
        diagnostics=diagnostics,
    )


def optimal_resistance(
    grasp: ResistanceGrasp,
    a,
    *,
    mode: SqueezeKind = SqueezeKind.STABLE,
    per_unit_push: bool = False,
) -> Resistance:
    """The resistance (d1, d2) minimising the grasping fingers' work W_F (Sec. 6.1-6.2).

    Parameters
    ----------
    grasp : ResistanceGrasp
        Fixed contact sets of F1, F2, A (:func:`resistance_grasp`).
    a : (2,) array_like
        Adversary translation, m, object frame, from :data:`MIN_RELATIVE_PUSH` to
        :data:`MAX_RELATIVE_PUSH` of the object size.
    mode : {"stable", "pure"}
        Stable: Delta in col(C) (eqs. 54-61, 66); pure: Delta in col(AC) (eqs. 62-63, 91, 94).
    per_unit_push : bool
        ``a`` is a direction of push of any length and the answer is per metre of A's travel
        (the fixed-contact model is linear in a): no size bound. Algorithm 2's stages.

    Returns
    -------
    Resistance
        ``success`` False with a "cannot be resisted" reason when no pure resistance exists.
        Diagnostics as in :func:`evaluate_resistance`, plus ``work_identity_residual``: the
        closed-form W*_F against the work of the assembled forces, relative.

    Examples
    --------
    >>> from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
    >>> obj = scene_solid(load_scene(scene_file("disk")))
    >>> mesh = obj.mesh
    >>> b = [int(k) for k in mesh.boundary]
    >>> sets = {"F1": [b[0]], "F2": [b[len(b) // 2]], "A": [b[len(b) // 4]]}
    >>> grasp = resistance_grasp(obj, sets)
    >>> res = optimal_resistance(grasp, (-0.001, 0.0))
    >>> w = res.work
    >>> print(res.mode, res.success, bool(np.isclose(w["total"], w["F1"] + w["F2"])))
    stable True True
    """
    a = _translation(a)
    require_push_range(a, grasp.scale, per_unit_push=per_unit_push)
    form = grasp.form(mode)
    L = grasp.scale
    a_hat = a[None] / L
    if isinstance(form, PureForm) and form.outside(a_hat)[0] > FEASIBILITY_TOL:
        return _cannot_resist(grasp, a)
    x, w, _ = optimum_batch(grasp, mode, a_hat)
    res = evaluate_resistance(
        grasp, x[0, :2] * L, x[0, 2:] * L, a, mode, reason=f"optimal {mode} resistance",
        per_unit_push=per_unit_push,
    )
    closed = float(w[0]) * grasp.obj.material.force_scale * L * L
    scale = max(abs(res.work["total"]), abs(res.energy), 1e-300)
    identity = abs(closed - res.work["total"]) / scale
    return replace(res, diagnostics={**res.diagnostics, "work_identity_residual": identity})


def resistance_along(
    grasp: ResistanceGrasp, a, direction, mode: SqueezeKind = SqueezeKind.STABLE
) -> Resistance:
    """The resistance of ``mode`` to a whose d1 lies on the line of ``direction`` (Table 4).

    The feasible resistances to a form a line (stable; pure with rank Q = 2) or a plane; fixing
    the line of d1 picks one of them, as the paper's "arbitrary" resistance of Table 4 does.

    Parameters
    ----------
    grasp : ResistanceGrasp
    a : (2,) array_like
        Adversary translation, m.
    direction : (2,) array_like
        Direction of F1's translation (any length; d1 may come out antiparallel).
    mode : {"stable", "pure"}

    Returns
    -------
    Resistance
        ``success`` False when no resistance of this mode moves F1 along that line.
    """
    a = _translation(a)
    require_push_range(a, grasp.scale)
    e = _translation(direction, "d1 direction")
    form = grasp.form(mode)
    L = grasp.scale
    a_hat = a[None] / L
    if isinstance(form, PureForm) and form.outside(a_hat)[0] > FEASIBILITY_TOL:
        return _cannot_resist(grasp, a)
    x0, Z = form.line(a_hat)
    e = _unit(e)
    coef = perp(e) @ Z[:2]
    rhs = -float(perp(e) @ x0[0, :2])
    if float(np.linalg.norm(coef)) <= 1e-12:
        if abs(rhs) > FEASIBILITY_TOL * max(float(np.linalg.norm(x0)), 1e-300):
            return _unresisted(
                grasp, mode, a, f"no {mode} resistance moves F1 along {e.round(6).tolist()}", {}
            )
        coef = np.zeros_like(coef)
    s = coef * rhs / max(float(coef @ coef), 1e-300)
    x = (x0[0] + Z @ s) * L
    return evaluate_resistance(
        grasp,
        x[:2],
        x[2:],
        a,
        mode,
        reason=f"{mode} resistance with d1 along {e.round(6).tolist()}",
    )


def compare_resistances(optimum: Resistance, other: Resistance) -> dict:
    """Table-4-style comparison of a resistance with the optimum to the same a (J)."""
    base = optimum.work["total"]
    total = other.work["total"]
    return {
        "resistance": other.to_json(),
        "optimal_work": base,
        "excess_work": None if total is None or base is None else total - base,
        "ratio": total / base if total is not None and base is not None and base > 0 else None,
    }


@dataclass(frozen=True)
class ResistanceSweep:
    """Grasp quality over adversary push directions: W*_F of a unit push per direction.

    Attributes
    ----------
    mode : {"stable", "pure"}
    angles : (N,) ndarray
        Push directions, rad from the object-frame x axis.
    unit_work : (N,) ndarray
        W*_F for a 1 m push, J/m^2 (W*_F scales with ||a||^2); NaN where ``feasible`` is False.
    psi : (N, 4) ndarray
        Optimal (d1, d2) per unit push (eq. 61), dimensionless; NaN where not feasible.
    feasible : (N,) ndarray of bool
        The push can be resisted in this mode.
    """

    mode: str
    angles: np.ndarray
    unit_work: np.ndarray
    psi: np.ndarray
    feasible: np.ndarray

    def extremes(self) -> dict:
        """Easiest and hardest feasible push directions with their W*_F (J/m^2), and the mean.

        W*_F of fixed contacts is even in a: each extreme is reached at a direction and its
        opposite, equal to round-off, and the first of them (the smaller angle) is named
        (:mod:`~squeeze_grasp_ros.mechanics.ties`).
        """
        if not np.any(self.feasible):
            return {"min": None, "max": None, "mean": None}
        w = np.where(self.feasible, self.unit_work, np.nan)
        lo = first_min(np.where(self.feasible, self.unit_work, np.inf))
        hi = first_max(np.where(self.feasible, self.unit_work, -np.inf))
        return {
            "min": {"angle_deg": float(np.degrees(self.angles[lo])), "unit_work": float(w[lo])},
            "max": {"angle_deg": float(np.degrees(self.angles[hi])), "unit_work": float(w[hi])},
            "mean": float(np.nanmean(w)),
        }

    def to_json(self) -> dict:
        """JSON-able dict; infeasible directions carry null work and psi."""
        ok = self.feasible
        return {
            "mode": self.mode,
            "angles_deg": np.degrees(self.angles).tolist(),
            "unit_work": [float(w) if f else None for w, f in zip(self.unit_work, ok)],
            "psi": [p.tolist() if f else None for p, f in zip(self.psi, ok)],
            "feasible": ok.tolist(),
            **self.extremes(),
        }


def sweep_directions(
    grasp: ResistanceGrasp, mode: SqueezeKind = SqueezeKind.STABLE, count: int = 360
) -> ResistanceSweep:
    """W*_F of a unit push in ``count`` evenly spaced directions, vectorised (eq. 61); ``count``
    in [1, :data:`MAX_DIRECTIONS`].
    """
    if not 1 <= count <= MAX_DIRECTIONS:
        raise InvalidInputError(
            f"number of directions must be in [1, {MAX_DIRECTIONS:,}], got {count}")
    angles = 2.0 * np.pi * np.arange(count) / count
    units = np.column_stack([np.cos(angles), np.sin(angles)])
    x, w, ok = optimum_batch(grasp, mode, units)
    unit_work = np.where(ok, w * grasp.obj.material.force_scale, np.nan)
    return ResistanceSweep(mode, angles, unit_work, np.where(ok[:, None], x, np.nan), ok)
