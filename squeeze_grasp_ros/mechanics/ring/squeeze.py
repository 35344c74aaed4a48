# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Point-contact squeeze of a ring-like object and its limits in closed form (paper Sec. 7.1).

Two point fingers at ring nodes i (F1) and j (F2) perform a stable or pure squeeze of depth
rho. Everything is linear in rho: the displacement of every node, p_k(rho) = p_k + rho d_k, the
contact forces f = rho F, and every fibre strain. The contact normal at node c is the normal of
the circle through the displaced p_c-1, p_c, p_c+1 (the paper's osculating circle). With
a = p_c-1 - p_c, b = p_c+1 - p_c, the vector

    N = -(|a|^2 b_y - |b|^2 a_y,  |b|^2 a_x - |a|^2 b_x) = 2 (a x b) (p_c - o)

(o the circle's centre) points to the left of the counter-clockwise curve, i.e. into the ring's
hole side, whatever the sign of the curvature (also on straight pieces and at inflections). Its
components are cubic polynomials in rho. The force lies in the friction cone of half-angle
alpha = atan(mu) about N iff both edge functions

    g_-(rho) = N x (Rot(+alpha) F) >= 0,   g_+(rho) = (Rot(-alpha) F) x N >= 0

hold (for alpha < pi/2 they carve out exactly the cone, not its mirror). Each g is a cubic in
rho (the paper's quartic, cross(rho F, N) with the trivial root rho = 0 divided out), so the
depth at which a force reaches a cone edge is the smallest positive real root, found for many
cubics at once from batched companion matrices. The strain depth is epsilon* / (largest fibre
strain per unit depth). The maximum feasible depth is the least of the two cone depths, the
strain depth and the depth cap (relative depth 1: the fingers would meet); ties resolve in the
order F1, F2, strain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import node_dofs
from squeeze_grasp_ros.mechanics.elastic.reduced import reduce_blocks
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, node_indices, require_finite
from squeeze_grasp_ros.mechanics.ring.model import FIBRE_STRAIN_MEASURE, RingModel
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import two_contact_direction
from squeeze_grasp_ros.mechanics.ties import first_max
from squeeze_grasp_ros.mechanics.vocabulary import SQUEEZING_FINGERS, RingLimit, SqueezeKind

LIMITS: tuple[RingLimit, ...] = tuple(RingLimit)
"""What bounds the squeeze depth, indexed by the integer limit codes."""
EDGE_TOL = 1e-9
"""A force within this relative margin (~rad) of a cone edge at rho = 0+ counts as on the edge."""
ROOT_IMAG_TOL = 1e-7
"""A companion eigenvalue with |Im| <= ROOT_IMAG_TOL (1 + |Re|) (scaled variable) is a real
root."""


def poly_mul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Product of polynomials with ascending coefficients along the last axis (broadcasting)."""
    a, b = p.shape[-1], q.shape[-1]
    conv = np.zeros((a * b, a + b - 1))
    conv[np.arange(a * b), np.add.outer(np.arange(a), np.arange(b)).ravel()] = 1.0
    outer = p[..., :, None] * q[..., None, :]
    return outer.reshape(outer.shape[:-2] + (a * b,)) @ conv


def polyval(coeffs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Evaluate ascending ``coeffs`` (..., d+1) at ``x`` (broadcast against ``...``) by Horner."""
    out = np.zeros(np.broadcast_shapes(coeffs.shape[:-1], np.shape(x)))
    for k in range(coeffs.shape[-1] - 1, -1, -1):
        out = out * x + coeffs[..., k]
    return out


def inward_normal(prev: np.ndarray, mid: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    """Unnormalised inward normal N (..., 2) of the circle through three points (..., 2)."""
    a, b = prev - mid, nxt - mid
    aa, bb = np.sum(a * a, axis=-1), np.sum(b * b, axis=-1)
    return -np.stack([aa * b[..., 1] - bb * a[..., 1], bb * a[..., 0] - aa * b[..., 0]], axis=-1)


def normal_polynomial(base: np.ndarray, rate: np.ndarray) -> np.ndarray:
    """Coefficients (..., 2, 4) of N(rho) for points base + rho * rate, both (..., 3, 2)."""
    a = np.stack([base[..., 0, :] - base[..., 1, :], rate[..., 0, :] - rate[..., 1, :]], axis=-1)
    b = np.stack([base[..., 2, :] - base[..., 1, :], rate[..., 2, :] - rate[..., 1, :]], axis=-1)
    aa = poly_mul(a[..., 0, :], a[..., 0, :]) + poly_mul(a[..., 1, :], a[..., 1, :])
    bb = poly_mul(b[..., 0, :], b[..., 0, :]) + poly_mul(b[..., 1, :], b[..., 1, :])
    nx = poly_mul(bb, a[..., 1, :]) - poly_mul(aa, b[..., 1, :])
    ny = poly_mul(aa, b[..., 0, :]) - poly_mul(bb, a[..., 0, :])
    return np.stack([nx, ny], axis=-2)


def _rotate(v: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def cone_polynomials(normal: np.ndarray, force: np.ndarray, mu: float) -> np.ndarray:
    """Edge functions (..., 2, d+1) [g_-, g_+] for N coefficients (..., 2, d+1) and a force (...,
    2).

    The force is inside the cone of half-angle atan(mu) about N(rho) iff both are >= 0.
    """
    alpha = np.arctan(mu)
    fm, fp = _rotate(force, alpha), _rotate(force, -alpha)
    g_minus = normal[..., 0, :] * fm[..., 1, None] - normal[..., 1, :] * fm[..., 0, None]
    g_plus = fp[..., 0, None] * normal[..., 1, :] - fp[..., 1, None] * normal[..., 0, :]
    return np.stack([g_minus, g_plus], axis=-2)


def edge_margins(normal: np.ndarray, force: np.ndarray, mu: float) -> np.ndarray:
    """Relative edge functions (..., 2) of unnormalised normals and forces (..., 2) at one depth.

    Both entries >= 0 iff the force is inside the friction cone; each is the sine of the angle
    to that edge.
    """
    alpha = np.arctan(mu)
    scale = np.linalg.norm(normal, axis=-1) * np.linalg.norm(force, axis=-1)
    g = np.stack(
        [_cross(normal, _rotate(force, alpha)), _cross(_rotate(force, -alpha), normal)], -1
    )
    return g / np.where(scale > 0, scale, 1.0)[..., None]


def positive_on_unit_interval(coeffs: np.ndarray) -> np.ndarray:
    """(k,) True where a cubic (k, 4) in t is certified > 0 on [0, 1]: all Bernstein coefficients
    are positive (the curve lies in their convex hull). False means "may have a root".
    """
    c0, c1, c2, c3 = coeffs.T
    bern = np.stack([c0, c0 + c1 / 3.0, c0 + (2.0 * c1 + c2) / 3.0, c0 + c1 + c2 + c3])
    return np.all(bern > 0, axis=0)


def first_root(coeffs: np.ndarray, cap: np.ndarray) -> np.ndarray:
    """Smallest real root in (0, cap] of each cubic (k, 4) (ascending); inf where there is none.

    The variable is scaled to t = x / cap, the coefficients normalised, the roots taken as the
    eigenvalues of the batched companion matrices and polished by one Newton step. Cubics
    certified positive on the whole interval (:func:`positive_on_unit_interval`) skip the
    eigenvalues.
    """
    coeffs = np.atleast_2d(np.asarray(coeffs, float))
    cap = np.broadcast_to(np.asarray(cap, float), coeffs.shape[:1])
    out = np.full(len(coeffs), np.inf)
    live = np.isfinite(cap) & (cap > 0)
    if not np.any(live):
        return out
    c = coeffs[live] * cap[live, None] ** np.arange(coeffs.shape[1])
    c = c / np.maximum(np.abs(c).max(axis=1, keepdims=True), 1e-300)
    rows = np.flatnonzero(live)
    maybe = ~positive_on_unit_interval(c)
    c, rows = c[maybe], rows[maybe]
    if not len(c):
        return out
    lead = c[:, -1]
    lead = np.where(np.abs(lead) < 1e-14, np.where(lead < 0, -1e-14, 1e-14), lead)
    deg = c.shape[1] - 1
    comp = np.zeros((len(c), deg, deg))
    comp[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
    comp[:, :, -1] = -c[:, :-1] / lead[:, None]
    roots = np.linalg.eigvals(comp)
    real = np.abs(roots.imag) <= ROOT_IMAG_TOL * (1.0 + np.abs(roots.real))
    t = roots.real
    dc = c[:, 1:] * np.arange(1, deg + 1)
    slope = polyval(dc[:, None, :], t)
    step = polyval(c[:, None, :], t) / np.where(slope != 0, slope, 1.0)
    t = np.where(np.abs(step) < 1e-3, t - step, t)
    ok = real & (t > 0) & (t <= 1.0)
    t = np.where(ok, t, np.inf).min(axis=1)
    out[rows] = t * cap[rows]
    return out


def initially_feasible(base: np.ndarray, force: np.ndarray, mu: float) -> np.ndarray:
    """(k, 2) bool: each finger's force direction strictly inside its cone at rho = 0+.

    ``base`` (k, 2, 3, 2) holds each finger's (previous, contact, next) node; ``force`` (k, 2, 2).
    """
    n0 = inward_normal(base[..., 0, :], base[..., 1, :], base[..., 2, :])
    return np.all(edge_margins(n0, force, mu) > EDGE_TOL, axis=-1)


def cone_depths(
    base: np.ndarray, rate: np.ndarray, force: np.ndarray, mu: float, cap: np.ndarray
) -> np.ndarray:
    """(k, 2) depth (scaled like ``base``) at which each finger's force reaches a cone edge.

    ``base``, ``rate`` (k, 2, 3, 2): positions and displacements per unit depth of each finger's
    (previous, contact, next) node; ``force`` (k, 2, 2); ``cap`` (k,): roots beyond it are not
    sought (inf returned). Fingers not inside their cone at rho = 0+ get depth 0.
    """
    inside = initially_feasible(base, force, mu)
    out = np.zeros(inside.shape)
    k, f = np.nonzero(inside)
    g = cone_polynomials(normal_polynomial(base[k, f], rate[k, f]), force[k, f], mu)
    roots = first_root(g.reshape(-1, g.shape[-1]), np.repeat(cap[k], 2))
    out[k, f] = roots.reshape(-1, 2).min(axis=1)
    return out


def resolve_limits(
    cones: np.ndarray, strain: np.ndarray, cap: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Maximum depth (k,) and limit code (k,) (index into :data:`LIMITS`) from the candidate
    depths: cones (k, 2), strain (k,), cap (k,). Ties go to F1, then F2, then strain.
    """
    depths = np.column_stack([cones, strain, cap])
    code = np.argmin(depths, axis=1)
    return depths[np.arange(len(depths)), code], code


def neighbours(n: int, nodes: np.ndarray) -> np.ndarray:
    """(..., 3) indices (previous, node, next) along a closed ring of ``n`` nodes."""
    nodes = np.asarray(nodes, dtype=int)
    return np.stack([(nodes - 1) % n, nodes, (nodes + 1) % n], axis=-1)


@dataclass(frozen=True)
class RingGrasp:
    """A two-finger point-contact squeeze of a ring and its depth limits (Sec. 7.1), SI units.

    Attributes
    ----------
    contacts : (2,) ndarray of int
        Initial contact nodes of F1 and F2.
    kind : SqueezeKind
        Stable or pure.
    mu : float
        Friction coefficient (cone half-angle atan(mu)).
    epsilon : float or None
        Proportional limit (strain), None without a strain limit.
    displacement : (4,) ndarray
        Unit contact displacement (x1, y1, x2, y2); depth rho (m) multiplies it.
    forces : (2, 2) ndarray
        Contact force on the ring at F1, F2 per unit depth, N/m.
    field : (n, 2) ndarray
        Displacement of every node per unit depth, m/m (includes the rigid part of a stable
        squeeze).
    points : (n, 2) ndarray
        Undeformed ring nodes, m.
    strains : (n,) ndarray
        Largest fibre strain |eps| + h/2 |zeta| of every element per unit depth, 1/m.
    approach_per_unit_depth : float
        Finger approach per unit depth (sqrt(2) stable, ||v_i - v_j|| pure).
    initial_distance : float
        ||p_i - p_j||, m.
    cone_depths : (2,) ndarray
        Depth, m, at which F1's / F2's force reaches a cone edge (0: outside its cone from the
        start; inf: never before ``depth_cap``/the strain depth).
    strain_depth : float
        Depth, m, at which the most strained element reaches epsilon (inf without a limit).
    depth_cap : float
        Depth at relative depth 1, m (the fingers would meet).
    max_depth : float
        Largest feasible depth, m.
    limit : RingLimit
        What bounds it.
    condition : float
        Condition number of the reduced compliance (Z^T A Z).
    residual : float
        Relative equilibrium residual ||K x - f|| / ||f|| of the ring's field under the
        contact forces (:func:`equilibrium_residual`).
    """

    contacts: np.ndarray
    kind: SqueezeKind
    mu: float
    epsilon: float | None
    displacement: np.ndarray
    forces: np.ndarray
    field: np.ndarray
    strains: np.ndarray
    points: np.ndarray
    approach_per_unit_depth: float
    initial_distance: float
    cone_depths: np.ndarray
    strain_depth: float
    depth_cap: float
    max_depth: float
    limit: RingLimit
    condition: float
    residual: float

    @property
    def stiffness(self) -> float:
        """Force magnitude per unit depth at each finger, N/m."""
        return float(np.linalg.norm(self.forces[0]))

    @property
    def max_relative_depth(self) -> float:
        """Relative depth at ``max_depth``."""
        return self.relative_depth(self.max_depth)

    def relative_depth(self, depth: float) -> float:
        """Finger approach over the initial contact distance at depth ``depth`` (m)."""
        return depth * self.approach_per_unit_depth / self.initial_distance

    def depth_for_relative(self, relative_depth: float) -> float:
        """Depth rho, m, giving the relative depth ``relative_depth``."""
        return relative_depth * self.initial_distance / self.approach_per_unit_depth

    def forces_at(self, depth: float) -> np.ndarray:
        """Contact forces (2, 2) on the ring at F1, F2 at depth ``depth`` (m), N."""
        return depth * self.forces

    def max_strain_at(self, depth: float) -> float:
        """Largest fibre strain at depth ``depth`` (m)."""
        return float(depth * self.strains.max())

    def displaced(self, depth: float) -> np.ndarray:
        """Node positions (n, 2), m, at depth ``depth``."""
        return self.points + depth * self.field

    def normals_at(self, depth: float) -> np.ndarray:
        """Unit inward contact normals (2, 2) at depth ``depth`` from the displaced nodes."""
        q = self.displaced(depth)[neighbours(len(self.points), self.contacts)]
        nrm = inward_normal(q[:, 0], q[:, 1], q[:, 2])
        return nrm / np.linalg.norm(nrm, axis=1, keepdims=True)

    def cone_margins_at(self, depth: float) -> np.ndarray:
        """(2, 2) sines of the angles from each force to its cone's two edges at ``depth``."""
        return edge_margins(self.normals_at(depth), self.forces, self.mu)

    def feasible_at(self, depth: float) -> bool:
        """O(n) yes/no test at depth ``depth`` (m): forces in their cones and strain <= epsilon.

        Evaluated directly from the displaced nodes, not from the roots.
        """
        require_finite("depth", depth)
        if depth < 0:
            raise InvalidInputError(f"depth must be >= 0 m, got {depth}")
        if depth > self.depth_cap:
            return False
        cones_ok = bool(np.all(self.cone_margins_at(depth) > EDGE_TOL))
        strain_ok = self.epsilon is None or self.max_strain_at(depth) <= self.epsilon
        return cones_ok and strain_ok

    def limit_depths(self) -> dict[RingLimit, float | None]:
        """Candidate depths (m) by limit name; None where the limit is not reached before the
        smaller of the strain depth and ``depth_cap`` (cone roots are not sought beyond).
        """
        vals = [*self.cone_depths, self.strain_depth]
        return {name: (float(v) if np.isfinite(v) else None) for name, v in zip(LIMITS, vals)}

    def force_angles_at(self, depth: float) -> np.ndarray:
        """Angle (2,), deg, between each finger's contact force and its contact normal at
        depth ``depth`` (m); the cone's half-angle is atan(mu).
        """
        N = self.normals_at(depth)
        F = self.forces / np.linalg.norm(self.forces, axis=1, keepdims=True)
        return np.degrees(np.arccos(np.clip(np.sum(N * F, axis=1), -1.0, 1.0)))

    def to_json(self, depth: float) -> dict:
        """JSON-able summary (docs/ring.md) with the yes/no test, forces and strain at the
        requested depth ``depth`` (m).
        """
        forces = self.forces_at(depth)
        at0, at_depth = self.force_angles_at(0.0), self.force_angles_at(depth)
        return {
            "elements": len(self.points),
            "squeeze": self.kind,
            "mu": self.mu,
            "epsilon": self.epsilon,
            "strain_measure": str(FIBRE_STRAIN_MEASURE),
            "contacts": [int(c) for c in self.contacts],
            "points": {f: self.points[c].tolist()
                       for f, c in zip(SQUEEZING_FINGERS, self.contacts)},
            "depth": float(depth),
            "relative_depth": self.relative_depth(depth),
            "max_depth": self.max_depth,
            "max_relative_depth": self.max_relative_depth,
            "limit": self.limit.value,
            "limit_depths": {k.value: v for k, v in self.limit_depths().items()},
            "feasible_at_requested_depth": self.feasible_at(depth),
            "forces": {f: forces[k].tolist() for k, f in enumerate(SQUEEZING_FINGERS)},
            "stiffness": self.stiffness,
            "max_strain": self.max_strain_at(depth),
            "max_strain_element": first_max(self.strains),
            "cone_half_angle_deg": float(np.degrees(np.arctan(self.mu))),
            "force_angle_deg": {f: [float(at0[k]), float(at_depth[k])]
                                for k, f in enumerate(SQUEEZING_FINGERS)},
            "diagnostics": {"reduced_condition": self.condition,
                            "equilibrium_residual": self.residual},
        }


def _check_contacts(ring: RingModel, contacts) -> np.ndarray:
    c = node_indices("contacts", contacts)
    if len(c) != 2:
        raise InvalidInputError(f"a ring grasp needs exactly 2 contact nodes, got {len(c)}")
    if c[0] == c[1]:
        raise InvalidInputError("the two contact nodes coincide")
    if c.min() < 0 or c.max() >= ring.n:
        raise InvalidInputError(f"contact nodes must be in [0, {ring.n - 1}], got {c.tolist()}")
    return c


def check_limits(mu: float, epsilon: float | None) -> None:
    require_finite("mu", mu)
    if mu < 0:
        raise InvalidInputError(f"friction coefficient mu must be >= 0, got {mu}")
    if epsilon is not None:
        require_finite("epsilon", epsilon)
        if not epsilon > 0:
            raise InvalidInputError(f"strain limit epsilon must be > 0, got {epsilon}")


def fibre_strain_rate(ring: RingModel, contacts: np.ndarray, forces_hat: np.ndarray) -> np.ndarray:
    """Largest fibre strain of every element (n,) for dimensionless contact forces (2, 2)."""
    q = np.einsum("cdqe,cd->qe", ring.strain_influence[contacts], forces_hat)
    return np.abs(q[0]) + 0.5 * ring.h_hat * np.maximum(np.abs(q[1]), np.abs(q[2]))


def equilibrium_residual(ring: RingModel, forces_hat: np.ndarray) -> float:
    """Relative residual ||K_hat x - f|| / ||f|| of ``ring``'s field x
    (:meth:`~.model.RingModel.field_from_forces`) under equilibrated dimensionless nodal forces
    ``forces_hat`` (n, 2): how well the banded solve and the loads' balance hold (the node
    clamped in the solve carries what the others do not balance); 1e-10 to 3e-9 on the shipped
    rings (round-off times the clamped stiffness's conditioning), 0 for no load.
    """
    F = np.zeros(3 * ring.n)
    F[ring.translation_dofs] = np.asarray(forces_hat, float).reshape(-1)
    scale = float(np.linalg.norm(F))
    if scale == 0.0:
        return 0.0
    return float(np.linalg.norm(ring.stiffness @ ring.field_from_forces(forces_hat) - F) / scale)


def ring_grasp(
    ring: RingModel,
    contacts,
    mu: float,
    *, epsilon: float | None = None,
    kind: SqueezeKind = SqueezeKind.STABLE,
) -> RingGrasp:
    """Squeeze a ring at two nodes and find its maximum feasible depth in closed form.

    The contact displacement and forces come from the Sec. 3 blocks (C, E by
    :func:`~.reduced.reduce_blocks` on the ring's contact compliance).

    Parameters
    ----------
    ring : RingModel
    contacts : (i, j)
        Contact nodes of F1 and F2.
    mu : float
        Friction coefficient, >= 0.
    epsilon : float, optional
        Proportional limit (strain); None for no strain limit.
    kind : {"stable", "pure"}

    Raises
    ------
    InvalidInputError
        For bad contacts, mu, epsilon or kind.

    Examples
    --------
    >>> from squeeze_grasp_ros.api import GraspSetup, load_scene, scene_file
    >>> ring = GraspSetup.build(load_scene(scene_file("ring_ring"))).ring
    >>> grasp = ring_grasp(ring, [0, ring.n // 2], 0.4)
    >>> print(grasp.kind, bool(grasp.max_depth > 0))
    stable True
    >>> print(grasp.to_json(0.001)["feasible_at_requested_depth"])
    True
    """
    if kind not in (SqueezeKind.STABLE, SqueezeKind.PURE):
        raise InvalidInputError(f"squeeze type must be 'stable' or 'pure', got {kind!r}")
    c = _check_contacts(ring, contacts)
    check_limits(mu, epsilon)
    L = ring.scale
    p = ring.points[c]
    dofs = node_dofs(c)
    A_hat = ring.compliance[np.ix_(dofs, dofs)]
    Rt = ring.rigid[ring.translation_dofs]
    C, E, _, condition = reduce_blocks(A_hat, Rt[dofs])
    u = two_contact_direction(p[0], p[1])
    delta = u if kind == SqueezeKind.STABLE else A_hat @ C @ u
    delta = delta / np.linalg.norm(delta)
    F_hat = C @ delta
    field = ring.compliance[:, dofs] @ F_hat + Rt @ (E.T @ delta)
    field = field.reshape(-1, 2)
    strains = fibre_strain_rate(ring, c, F_hat.reshape(2, 2))
    approach = float(np.linalg.norm(delta[:2] - delta[2:]))
    distance = float(np.linalg.norm(p[1] - p[0]))
    cap_hat = distance / (approach * L)
    strain_hat = np.inf if epsilon is None else epsilon / strains.max()
    nb = neighbours(ring.n, c)
    base = ring.points[nb][None] / L
    cones = cone_depths(
        base, field[nb][None], F_hat.reshape(1, 2, 2), mu, np.array([min(cap_hat, strain_hat)])
    )
    depth, code = resolve_limits(cones, np.array([strain_hat]), np.array([cap_hat]))
    require_finite("ring grasp forces", F_hat)
    loads = np.zeros((ring.n, 2))
    loads[c] = F_hat.reshape(2, 2)
    return RingGrasp(
        contacts=c,
        kind=kind,
        mu=float(mu),
        epsilon=epsilon,
        displacement=delta,
        forces=F_hat.reshape(2, 2) * ring.material.force_scale,
        field=field,
        strains=strains / L,
        points=ring.points,
        approach_per_unit_depth=approach,
        initial_distance=distance,
        cone_depths=cones[0] * L,
        strain_depth=strain_hat * L,
        depth_cap=cap_hat * L,
        max_depth=float(depth[0] * L),
        limit=LIMITS[int(code[0])],
        condition=condition,
        residual=equilibrium_residual(ring, loads),
    )
