# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Curved-beam model of a ring-like (hollow) object (paper Sec. 7.1, eqs. 69-71).

The object is a closed middle curve gamma(s) swept by a rectangular cross-section of in-plane
wall thickness h and out-of-plane width w, E given, nu = 0, under Kirchhoff's assumptions:
strain energy U = 1/2 E w integral (h eps^2 + h^3/12 zeta^2) ds (eq. 71), extension + bending.

Discretisation (and why)
------------------------
The middle curve is sampled at n nodes p_k (counter-clockwise, closed); every chord p_k p_k+1
is a straight Euler-Bernoulli frame element with nodal DOFs (u, v, theta): linear axial and
cubic Hermite transverse displacement in the element frame (t, n). Its energy is eq. (71) with
eps = du/dx and zeta = d^2 w/dx^2 on the chord.

* **Exactly three rigid modes.** Each element's eps and zeta vanish identically on the planar
  rigid motions (u, v, theta) = (a - omega y, b + omega x, omega), so K R = 0 to rounding; the
  closed chain is connected, so null(K) is exactly 3-dimensional and Sec. 3 carries over
  (uniqueness for m >= 2 contacts, C, E, H by :func:`~.reduced.reduce_blocks`).
* **Convergence O(l^2).** The element is exact for a straight beam loaded at its nodes; the only
  error is the chord replacing the arc (offset O(l^2 kappa)), so nodal displacements converge to
  the curved Kirchhoff beam at second order in the element length l. The circular-ring test
  observes order 2 against the closed form of :func:`ring_diameter_changes`.
* **Point contacts at nodes.** A point finger applies a force, no moment: only the contact
  nodes' translational DOFs are prescribed, their rotations stay free.
* **Strains in O(n).** Within an element eps is constant and zeta linear, so the largest fibre
  strain |eps| + h/2 |zeta| is at an element end: the most strained element is a max over n.

A rotation-free discrete-curvature model (translations only) was the alternative; it needs
special stencils at the corners that :func:`~.shapes.resample` keeps (cookie cutters, hearts)
and loses an order on the resulting non-uniform spacing, which frame elements do not.

Compliance
----------
K is factored once with node 0 clamped (its three DOFs removed); the rest of the closed chain
is then a clamped-clamped chain, so the pinned matrix is banded (bandwidth 5) and Cholesky costs
O(n). The generalised inverse used is G = Q X Q^T, X the padded clamped inverse and Q removing
the rigid component orthogonally in the paper's nodal inner product (eq. 16, translations only).
It reproduces the paper's A (eq. 23) and B (eq. 24) for translational contacts: the contact
displacement is A F + B g with B the contact rows of the rigid modes, orthonormal under eq. (16).
(The Moore-Penrose K+ of the 3n DOFs differs from G by rigid motions only; C is the same.)

Units: SI at the API. Inside, lengths are divided by the ring size L, forces by E w L, so
K_hat is dimensionless and A = A_hat / (E w) in m/N, like the solid model with thickness -> w.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp

from squeeze_grasp_ros.mechanics.elastic.fem import rigid_modes, rotation_mode_norm
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.shapes import (
    Outline,
    disk,
    resample,
    resampled_count,
    signed_area,
)
from squeeze_grasp_ros.mechanics.errors import (
    InternalError,
    InvalidInputError,
    NumericalError,
    require_finite,
)
from squeeze_grasp_ros.mechanics.vocabulary import StrainMeasure

FIBRE_STRAIN_MEASURE = StrainMeasure.SMALL
"""The measure of the ring's fibre strains |eps| + h/2 |zeta| and of its strain limit: the
curved beam is linear (small strain)."""

BANDWIDTH = 5
"""Upper bandwidth of the clamped stiffness (two nodes of three DOFs per element)."""


MAX_THINNESS = 3e7
"""Largest n L / h of a ring (n elements, size L, wall thickness h): the bending stiffness
(h^3) is round-off against the extension (h) beyond. Measured on a circle under diametral loads
against :func:`ring_diameter_changes` (16 to 2,000 elements): the round-off part of the error
stayed below 7e-4 up to 3e7; at 1.7e8 it was 6e-3 (256 elements), at 4e8 1.1e-2 (2,000), at
2.7e8 1,000 % (256 elements, h / L = 1.5e-7, returned without a warning), and thinner walls
ended in "clamped ring stiffness is not positive definite"."""


@dataclass(frozen=True)
class RingModel:
    """A ring-like object: middle curve, material and wall thickness, with cached mechanics.

    Parameters
    ----------
    points : (n, 2) ndarray
        Nodes of the middle curve, m, counter-clockwise, closed implicitly (n >= 8).
    material : Material
        E (Pa), nu (must be 0, Sec. 7) and ``thickness`` = the out-of-plane width w (m).
    wall_thickness : float
        In-plane wall thickness h, m (the bending direction), in (0, L/4) with L the larger
        side of the middle curve's bounding box (:attr:`scale`), and at least n L /
        :data:`MAX_THINNESS`.

    Notes
    -----
    ``nodes``, ``n``, ``boundary`` and ``centroid`` mirror :class:`~.mesh.Mesh`, so finger
    placements resolve on a ring as on a mesh: every ring node is a boundary node.
    """

    points: np.ndarray
    material: Material
    wall_thickness: float

    def __post_init__(self) -> None:
        p = np.asarray(self.points, dtype=float)
        if p.ndim != 2 or p.shape[1] != 2 or len(p) < 8:
            raise InvalidInputError(f"ring.points must be (n, 2) with n >= 8, got shape {p.shape}")
        require_finite("ring.points", p)
        if signed_area(p) <= 0:
            raise InvalidInputError("ring.points must be counter-clockwise with positive area")
        if self.material.nu != 0.0:
            raise InvalidInputError(
                f"material.nu must be 0 for the ring model (Sec. 7), got {self.material.nu}"
            )
        require_finite("ring.wall_thickness", self.wall_thickness)
        if not 0.0 < self.wall_thickness < 0.25 * self.scale:
            raise InvalidInputError(
                f"ring.wall_thickness must be in (0, {0.25 * self.scale:.4g}) "
                "m "
                f"(a quarter of the ring size), got {self.wall_thickness}"
            )
        if len(p) * self.scale > MAX_THINNESS * self.wall_thickness:
            raise InvalidInputError(
                f"ring.wall_thickness must be >= {len(p) * self.scale / MAX_THINNESS:.3g} m with "
                f"{len(p)} elements on a ring of size {self.scale:.4g} m, got "
                f"{self.wall_thickness} (n L / h <= {MAX_THINNESS:g}: a thinner wall loses "
                "digits to round-off; fewer ring.elements allow a thinner wall)")
        if np.min(self.element_lengths) <= 1e-9 * self.scale:
            raise InvalidInputError("ring.points has coincident consecutive nodes")
        object.__setattr__(self, "points", p)

    @property
    def nodes(self) -> np.ndarray:
        """Node positions (n, 2), m (alias of ``points``)."""
        return self.points

    @property
    def n(self) -> int:
        """Number of nodes (= number of elements)."""
        return len(self.points)

    @property
    def boundary(self) -> np.ndarray:
        """Every node, in order: the middle curve is the ring's boundary loop."""
        return np.arange(self.n)

    @property
    def centroid(self) -> np.ndarray:
        """Centroid of the area enclosed by the middle curve, m."""
        x, y = self.points[:, 0], self.points[:, 1]
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        cross = x * yn - xn * y
        return np.array([np.sum((x + xn) * cross), np.sum((y + yn) * cross)]) / (
            3.0 * np.sum(cross)
        )

    @cached_property
    def scale(self) -> float:
        """Length scale L, m: the larger side of the bounding box."""
        return float(np.ptp(np.asarray(self.points, float), axis=0).max())

    @property
    def element_lengths(self) -> np.ndarray:
        """Chord length of every element (n,), m; element k joins nodes k and k+1."""
        p = np.asarray(self.points, float)
        return np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)

    @property
    def h_hat(self) -> float:
        """Dimensionless wall thickness h / L."""
        return self.wall_thickness / self.scale

    @cached_property
    def frames(self) -> tuple[np.ndarray, np.ndarray]:
        """(tangent (n, 2), dimensionless length (n,)) of every element."""
        d = (np.roll(self.points, -1, axis=0) - self.points) / self.scale
        length = np.linalg.norm(d, axis=1)
        return d / length[:, None], length

    @cached_property
    def element_dofs(self) -> np.ndarray:
        """(n, 6) global DOF indices (u_a, v_a, theta_a, u_b, v_b, theta_b) of every element."""
        a = np.arange(self.n)
        b = np.roll(a, -1)
        return np.column_stack([3 * a, 3 * a + 1, 3 * a + 2, 3 * b, 3 * b + 1, 3 * b + 2])

    def _rotations(self) -> np.ndarray:
        """(n, 6, 6) global-to-local DOF maps: local (u, w, theta) from global (u, v, theta)."""
        t, _ = self.frames
        T = np.zeros((self.n, 6, 6))
        for o in (0, 3):
            T[:, o, o], T[:, o, o + 1] = t[:, 0], t[:, 1]
            T[:, o + 1, o], T[:, o + 1, o + 1] = -t[:, 1], t[:, 0]
            T[:, o + 2, o + 2] = 1.0
        return T

    @cached_property
    def stiffness(self) -> sp.csr_matrix:
        """Dimensionless stiffness K_hat = K / (E w) (3n x 3n, CSR), translations in units of L.

        U = 1/2 E w L^2 Delta_hat^T K_hat Delta_hat for Delta_hat = (u/L, v/L, theta) per node.
        """
        _, l = self.frames
        h = self.h_hat
        ea, ei = h, h**3 / 12.0
        k = np.zeros((self.n, 6, 6))
        ax = ea / l
        k[:, 0, 0] = k[:, 3, 3] = ax
        k[:, 0, 3] = k[:, 3, 0] = -ax
        bend = np.array(
            [
                [12.0, 6.0, -12.0, 6.0],
                [6.0, 4.0, -6.0, 2.0],
                [-12.0, -6.0, 12.0, -6.0],
                [6.0, 2.0, -6.0, 4.0],
            ]
        )
        powers = np.array([[3, 2, 3, 2], [2, 1, 2, 1], [3, 2, 3, 2], [2, 1, 2, 1]])
        idx = np.array([1, 2, 4, 5])
        k[np.ix_(np.arange(self.n), idx, idx)] = ei * bend / l[:, None, None] ** powers
        T = self._rotations()
        kg = np.einsum("eji,ejk,ekl->eil", T, k, T, optimize=True)
        dofs = self.element_dofs
        rows = np.repeat(dofs, 6, axis=1).ravel()
        cols = np.tile(dofs, (1, 6)).ravel()
        K = sp.csr_matrix((kg.ravel(), (rows, cols)), shape=(3 * self.n, 3 * self.n))
        K.sum_duplicates()
        return K

    @cached_property
    def strain_matrix(self) -> sp.csr_matrix:
        """Sparse (3n, 3n) map from Delta_hat to element strains, rows blocked as
        [eps (n), zeta_hat at start (n), zeta_hat at end (n)]; zeta_hat = zeta L (Hermite w'').
        """
        _, l = self.frames
        S = np.zeros((self.n, 3, 6))
        S[:, 0, 0], S[:, 0, 3] = -1.0 / l, 1.0 / l
        S[:, 1, [1, 2, 4, 5]] = np.column_stack([-6.0 / l**2, -4.0 / l, 6.0 / l**2, -2.0 / l])
        S[:, 2, [1, 2, 4, 5]] = np.column_stack([6.0 / l**2, 2.0 / l, -6.0 / l**2, 4.0 / l])
        Sg = np.einsum("eqj,ejk->eqk", S, self._rotations())
        rows = np.arange(3)[None, :, None] * self.n + np.arange(self.n)[:, None, None]
        rows = np.broadcast_to(rows, Sg.shape).ravel()
        cols = np.broadcast_to(self.element_dofs[:, None, :], Sg.shape).ravel()
        return sp.csr_matrix((Sg.ravel(), (rows, cols)), shape=(3 * self.n, 3 * self.n))

    @cached_property
    def rigid(self) -> np.ndarray:
        """Rigid modes R (3n, 3): translational rows orthonormal under eq. (16), theta rows the
        matching rotation (0, 0, 1/||w_perp||).
        """
        R = np.zeros((3 * self.n, 3))
        tr = self.translation_dofs
        R[tr] = rigid_modes(self.points, self.scale)
        R[2::3, 2] = 1.0 / rotation_mode_norm(self.points, self.scale)
        return R

    @property
    def translation_dofs(self) -> np.ndarray:
        """Global DOF indices (2n,) of the translations, interleaved u_1, v_1, u_2, ..."""
        a = np.arange(self.n)
        return np.column_stack([3 * a, 3 * a + 1]).ravel()

    @cached_property
    def _clamped_factor(self) -> np.ndarray:
        """Banded upper Cholesky factor of K_hat with node 0 clamped (DOFs 0, 1, 2 removed)."""
        K = self.stiffness.tocoo()
        keep = (K.row >= 3) & (K.col >= 3) & (K.row <= K.col)
        r, c, v = K.row[keep] - 3, K.col[keep] - 3, K.data[keep]
        if np.any(c - r > BANDWIDTH):
            raise InternalError("ring stiffness is not banded: nodes out of order")
        ab = np.zeros((BANDWIDTH + 1, 3 * self.n - 3))
        np.add.at(ab, (BANDWIDTH + r - c, c), v)
        try:
            return la.cholesky_banded(ab, lower=False)
        except la.LinAlgError:
            raise NumericalError("clamped ring stiffness is not positive definite") from None

    def clamped_solve(self, rhs: np.ndarray) -> np.ndarray:
        """X rhs: the clamped-at-node-0 solution of K_hat x = rhs (3n,) or (3n, k), zero at
        node 0.
        """
        rhs = np.asarray(rhs, dtype=float)
        x = np.zeros_like(rhs)
        x[3:] = la.cho_solve_banded((self._clamped_factor, False), rhs[3:], check_finite=False)
        return x

    def remove_rigid(self, x: np.ndarray) -> np.ndarray:
        """Q x: subtract the rigid component of field(s) ``x`` (3n[, k]) in the eq. (16) sense."""
        Rt = self.rigid[self.translation_dofs]
        return x - self.rigid @ (Rt.T @ x[self.translation_dofs])

    @cached_property
    def _translational_solutions(self) -> np.ndarray:
        """P_T-projected X T^T: clamped responses (3n, 2n) to unit equilibrated translational
        loads.
        """
        tr = self.translation_dofs
        E = np.zeros((3 * self.n, 2 * self.n))
        E[tr, np.arange(2 * self.n)] = 1.0
        Y = self.clamped_solve(E)
        Rt = self.rigid[tr]
        return Y - (Y @ Rt) @ Rt.T

    @cached_property
    def compliance(self) -> np.ndarray:
        """Dimensionless translational compliance A_hat (2n, 2n) = T G T^T, symmetric PSD.

        The contact block at nodes (i, j) is the paper's A (eq. 23) times E w.
        """
        A = self.remove_rigid(self._translational_solutions)[self.translation_dofs]
        return 0.5 * (A + A.T)

    @cached_property
    def strain_influence(self) -> np.ndarray:
        """(n, 2, 3, n): element strains [eps, zeta_hat start, zeta_hat end] per unit
        dimensionless force on each node's x and y (rigid parts carry no strain).
        """
        S = self.strain_matrix @ self._translational_solutions
        return np.ascontiguousarray(S.T.reshape(self.n, 2, 3, self.n))

    def field_from_forces(self, forces_hat: np.ndarray) -> np.ndarray:
        """Dimensionless deformation Delta_hat (3n,) with no rigid component for equilibrated
        dimensionless nodal forces ``forces_hat`` (n, 2).
        """
        F = np.zeros(3 * self.n)
        F[self.translation_dofs] = np.asarray(forces_hat, float).reshape(-1)
        return self.remove_rigid(self.clamped_solve(F))

    def solve_loads(self, forces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Deformation under equilibrated nodal point loads.

        Parameters
        ----------
        forces : (n, 2) ndarray
            Force on every node, N; must sum to zero with zero net moment.

        Returns
        -------
        displacement : (n, 2) ndarray
            Nodal displacements, m, without rigid component (eq. 16 sense).
        rotation : (n,) ndarray
            Nodal cross-section rotations, rad.
        """
        f = np.asarray(forces, dtype=float)
        require_finite("forces", f)
        if f.shape != (self.n, 2):
            raise InvalidInputError(f"forces must have shape ({self.n}, 2), got {f.shape}")
        Rt = self.rigid[self.translation_dofs]
        imbalance = np.abs(Rt.T @ f.reshape(-1)).max()
        if imbalance > 1e-9 * max(np.abs(f).max(), 1e-300) * np.sqrt(self.n):
            raise InvalidInputError("forces are not equilibrated (net force or moment is nonzero)")
        x = self.field_from_forces(f / (self.material.force_scale * self.scale))
        return x[self.translation_dofs].reshape(-1, 2) * self.scale, x[2::3].copy()

    def fibre_strains(self, field_hat: np.ndarray) -> np.ndarray:
        """Largest fibre strain |eps| + h/2 |zeta| of every element (n,) for a field Delta_hat
        (3n,).
        """
        q = (self.strain_matrix @ field_hat).reshape(3, self.n)
        return np.abs(q[0]) + 0.5 * self.h_hat * np.maximum(np.abs(q[1]), np.abs(q[2]))

    def precompute(self) -> "RingModel":
        """Build the stiffness, factor, compliance and strain influence now; returns self."""
        _ = self.compliance, self.strain_influence
        return self


MAX_RING_ELEMENTS = 2_000
"""Most elements of a ring model. Its compliance, strain influence and grasp map are dense:
measured on this project's 2-core machine (`squeeze-grasp ring config/scenes/ring_ring.yaml`),
one placement took 1.4 s and 0.30 GB at 1,000 elements, 3.5 s and 0.84 GB at 2,000, 19 s and
3.1 GB at 4,000; the all-pairs map 6.6 s and 0.65 GB at 1,000, 48 s and 2.2 GB at 2,000.
``--elements 100000`` asked for a 447 GiB array."""


def ring_from_outline(
    outline: Outline, material: Material, wall_thickness: float, elements: int
) -> RingModel:
    """A :class:`RingModel` whose middle curve is ``outline`` resampled into ~``elements`` nodes.

    Parameters
    ----------
    outline : Outline
        The middle curve (m); its corners are kept as nodes.
    material : Material
        E (Pa), nu = 0, thickness = out-of-plane width w (m).
    wall_thickness : float
        In-plane wall thickness h, m.
    elements : int
        Target number of elements (exact for smooth curves), in [8, :data:`MAX_RING_ELEMENTS`].
    """
    if not 8 <= elements <= MAX_RING_ELEMENTS:
        raise InvalidInputError(
            f"ring.elements must be in [8, {MAX_RING_ELEMENTS}], got {elements} (the ring "
            "model is dense: memory grows with the square of the elements)")
    p = outline.points
    perimeter = float(np.sum(np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)))
    count = resampled_count(p, perimeter / elements, outline.corners)
    if count > MAX_RING_ELEMENTS:
        raise InvalidInputError(
            f"the ring's middle curve keeps {count} nodes (its corners are kept), more than "
            f"{MAX_RING_ELEMENTS}: give fewer ring.elements or a simpler curve")
    nodes = resample(p, perimeter / elements, outline.corners)
    return RingModel(nodes, material, wall_thickness)


def ring_diameter_changes(
    radius: float, E: float, width: float, wall_thickness: float, load: float
) -> tuple[float, float]:
    """Closed-form diameter changes of a thin circular ring under two diametral point loads.

    Kirchhoff curved beam with extension and bending uncoupled (eq. 71, no shear), by
    Castigliano: with I = w h^3 / 12, A = w h, the redundant moment at a load point is P R / pi
    and

    * along the load line:  -(P R^3 / (E I) (pi/4 - 2/pi) + pi P R / (4 E A)),
    * across it:            +(P R^3 / (E I) (2/pi - 1/2) - P R / (2 E A)).

    The bending terms are the classical inextensible results (0.1488, 0.1366 P R^3 / EI); the
    extension terms are smaller by O((h/R)^2).

    Parameters
    ----------
    radius : float
        Middle-curve radius R, m.
    E : float
        Young's modulus, Pa.
    width : float
        Out-of-plane width w, m.
    wall_thickness : float
        In-plane wall thickness h, m.
    load : float
        Each load's magnitude P, N; P > 0 squeezes the ring.

    Returns
    -------
    along, across : float
        Signed changes of the diameter along and across the load line, m (along < 0 < across
        for a squeeze).
    """
    for name, value in (
        ("radius", radius),
        ("E", E),
        ("width", width),
        ("wall_thickness", wall_thickness),
    ):
        require_finite(name, value)
        if not value > 0:
            raise InvalidInputError(f"{name} must be > 0, got {value}")
    require_finite("load", load)
    EI = E * width * wall_thickness**3 / 12.0
    EA = E * width * wall_thickness
    bend = load * radius**3 / EI
    along = -(bend * (np.pi / 4 - 2 / np.pi) + np.pi * load * radius / (4 * EA))
    across = bend * (2 / np.pi - 0.5) - load * radius / (2 * EA)
    return float(along), float(across)


def circle_diametral_response(
    elements: int, radius: float, E: float, width: float, wall_thickness: float, load: float
) -> tuple[float, float, float]:
    """FE counterpart of :func:`ring_diameter_changes` on a circle of ``elements`` elements.

    Returns the changes (m) of the diameter along and across two opposite diametral loads
    ``load`` (N, a squeeze) and the largest fibre strain (dimensionless).
    """
    ring = ring_from_outline(disk(radius), Material(E, 0.0, width), wall_thickness, elements)
    ang = np.arctan2(ring.points[:, 1], ring.points[:, 0])
    top, bottom, left, right = (
        int(np.argmin(np.abs(np.angle(np.exp(1j * (ang - a))))))
        for a in (np.pi / 2, -np.pi / 2, np.pi, 0.0)
    )
    f = np.zeros((ring.n, 2))
    f[top], f[bottom] = (0.0, -load), (0.0, load)
    d, rot = ring.solve_loads(f)
    p, q = ring.points, ring.points + d
    along = np.linalg.norm(q[top] - q[bottom]) - np.linalg.norm(p[top] - p[bottom])
    across = np.linalg.norm(q[left] - q[right]) - np.linalg.norm(p[left] - p[right])
    field = np.zeros(3 * ring.n)
    field[ring.translation_dofs] = d.reshape(-1) / ring.scale
    field[2::3] = rot
    return float(along), float(across), float(ring.fibre_strains(field).max())
