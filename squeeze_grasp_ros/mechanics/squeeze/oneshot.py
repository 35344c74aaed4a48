# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""One-shot solve of a final contact configuration on the full FEM problem (paper Sec. 5.3).

Uniqueness of the deformation for given contacts and contact displacements means the final
shape of an incremental squeeze can be regenerated "in one shot". This module does so
independently of the stepper's route (no compliance, no reduced stiffness C): it solves the
saddle-point system of the full stiffness K with sparse LU,

    K u - sum_{k in T} E_k f_k - sum_{k in P} E_k lambda_k e(nu(theta_k) - slip_k phi) = 0
    u_k = o_f + x_f(theta_k) - p_k                              (k in T: theta_k given;
                                                                 k in P: theta_k unknown)

by Newton on (u, f_T, theta_P, lambda_P): sticking nodes are Dirichlet conditions with
reaction forces f_k, sliding nodes lie on their tip (x_f(theta) = r_f e(theta) for a circle,
a pad's face in :mod:`.tip_shapes`, contact normal e(nu)) with the force on the friction-cone
edge. Dimensionless inside (lengths by L, forces by E h L); SI out.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.errors import NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, tip_geometry
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import tangent, unit
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode

ONE_SHOT_MAX_ITERATIONS = 30


@dataclass(frozen=True)
class OneShot:
    """Result of :func:`one_shot_solve`.

    Attributes
    ----------
    displacement : (n, 2) ndarray
        Displacement of every node, m.
    forces : (m, 2) ndarray
        Contact forces in the state's contact order, N.
    theta : (m,) ndarray
        Contact coordinates (a circle's polar angles) of the contact nodes, rad (solved for
        sliding nodes).
    iterations : int
        Newton iterations.
    residual : float
        Relative residual ||r|| / ||K|| ||u|| of the final iterate.
    """

    displacement: np.ndarray
    forces: np.ndarray
    theta: np.ndarray
    iterations: int
    residual: float


def one_shot_solve(obj: ElasticObject, state: ContactState, mu: float,
                   theta_perturbation: float = 1e-3) -> OneShot:
    """Solve the full FEM problem for the contact set and modes of ``state``.

    Sticking nodes keep the state's contact coordinates; sliding nodes start Newton from the
    state's coordinates shifted by ``theta_perturbation`` (rad) so the solve cannot simply
    return its input.

    Raises
    ------
    InvalidInputError
        If Newton does not converge.
    """
    L, fu = obj.scale, obj.material.force_scale * obj.scale
    K = obj.stiffness.tocsr()
    n2 = K.shape[0]
    phi = float(np.arctan(mu))
    contacts = state.contacts
    nodes = np.array([c.node for c in contacts], int)
    stick = np.array([c.mode == ContactMode.STICK for c in contacts], bool)
    slip = np.array([c.slip for c in contacts], float)
    fingers = {f.name: k for k, f in enumerate(state.fingers)}
    owner = np.array([fingers[c.finger] for c in contacts], int)
    centers = np.array([state.fingers[k].center for k in owner]) / L
    tip = tip_geometry(state.fingers).scaled(L).take(owner)
    radius = tip.radius
    p0 = obj.mesh.nodes[nodes] / L
    theta = np.array([c.theta for c in contacts], float)
    T, P = np.flatnonzero(stick), np.flatnonzero(~stick)
    theta[P] += theta_perturbation
    nT, nP = len(T), len(P)

    def selector(idx: np.ndarray) -> sp.csr_matrix:
        rows = np.stack([2 * nodes[idx], 2 * nodes[idx] + 1], axis=1).reshape(-1)
        return sp.csr_matrix((np.ones(len(rows)), (rows, np.arange(len(rows)))),
                             shape=(n2, len(rows)))

    ET, EP = selector(T), selector(P)
    u = np.zeros(n2)
    fT = np.zeros(2 * nT)
    lam = np.zeros(nP)
    residual = np.inf
    for it in range(ONE_SHOT_MAX_ITERATIONS):
        nu, kappa = tip.normal_angle(theta), tip.curvature(theta)
        alpha = nu[P] - slip[P] * phi
        ea, ta = unit(alpha), tangent(alpha)
        target = centers + tip.offset(theta) - p0
        r_u = K @ u - ET @ fT - EP @ (lam[:, None] * ea).reshape(-1)
        r_T = (ET.T @ u) - target[T].reshape(-1)
        r_P = (EP.T @ u) - target[P].reshape(-1)
        r = np.concatenate([r_u, r_T, r_P])
        residual = float(np.linalg.norm(r) / max(np.linalg.norm(u), 1e-300))
        if it > 0 and residual < 1e-12:
            break
        # d r_u / d theta_P = -E_P lambda kappa t(alpha); d r_P / d theta_P = -r t(nu)
        cols = np.arange(nP)

        def blk(v: np.ndarray) -> sp.csr_matrix:
            return sp.csr_matrix((v.reshape(-1), (np.arange(2 * nP), np.repeat(cols, 2))),
                                 shape=(2 * nP, nP))
        J = sp.bmat([
            [K, -ET, -EP @ blk((lam * kappa[P])[:, None] * ta), -EP @ blk(ea)],
            [ET.T, None, None, None],
            [EP.T, None, -blk(radius[P, None] * tangent(nu[P])), None],
        ], format="csc")
        dx = spla.spsolve(J, -r)
        if not np.all(np.isfinite(dx)):
            raise NumericalError("one-shot solve: singular saddle-point system (too few "
                                 "sticking contacts to fix the rigid motion?)",
                                 residuals={"newton": residual})
        u += dx[:n2]
        fT += dx[n2:n2 + 2 * nT]
        theta[P] += dx[n2 + 2 * nT:n2 + 2 * nT + nP]
        lam += dx[n2 + 2 * nT + nP:]
    else:
        raise NumericalError("one-shot Newton did not converge", residuals={"newton": residual})
    forces = np.zeros((len(nodes), 2))
    forces[T] = fT.reshape(-1, 2)
    forces[P] = lam[:, None] * unit(tip.normal_angle(theta)[P] - slip[P] * phi)
    return OneShot(u.reshape(-1, 2) * L, forces * fu, theta, it, residual)
