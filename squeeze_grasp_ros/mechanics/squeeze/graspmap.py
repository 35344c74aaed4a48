# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""All-pairs grasp map of a solid object under point contacts (Sec. 4, Theorem 10).

For every pair of outer-boundary nodes (i, j): the stable-squeeze stiffness 1/(u^T A u),
whether the stable squeeze u is inward, and whether the placement is force closure for a
friction coefficient mu. Vectorised over all b^2 pairs from the cached boundary compliance:
no solve per pair.

Point-contact stiffnesses depend on the mesh (a 2-D point load has unbounded displacement
under it; docs/design.md §2): compare placements on one mesh, never across meshes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import force_closure_pairs


@dataclass(frozen=True)
class GraspMap:
    """Stable-squeeze quality of every placement pair.

    Attributes
    ----------
    boundary : (b,) ndarray of int
        Mesh node indices of the outer boundary, counter-clockwise; rows/columns follow it.
    stiffness : (b, b) ndarray
        1/(u^T A u), N/m, symmetric; 0 on the diagonal (no placement).
    inward : (b, b) ndarray of bool
        Both nodes move into the object under u (fingers approach).
    force_closure : (b, b) ndarray of bool
        Segment p_i p_j inside both friction cones (rigid-body precondition).
    mu : float
        Friction coefficient used for ``force_closure``.
    """

    boundary: np.ndarray
    stiffness: np.ndarray
    inward: np.ndarray
    force_closure: np.ndarray
    mu: float

    @property
    def feasible(self) -> np.ndarray:
        """Placements that are inward and force closure (b, b) bool, diagonal excluded."""
        ok = self.inward & self.force_closure
        np.fill_diagonal(ok, False)
        return ok

    def best(self, count: int = 5) -> list[tuple[int, int, float]]:
        """The ``count`` stiffest feasible placements as (node_i, node_j, stiffness N/m), i < j."""
        score = np.where(np.triu(self.feasible, 1), self.stiffness, -np.inf)
        flat = np.argsort(score, axis=None)[::-1][:count]
        rows, cols = np.unravel_index(flat, score.shape)
        return [
            (int(self.boundary[r]), int(self.boundary[c]), float(self.stiffness[r, c]))
            for r, c in zip(rows, cols)
            if np.isfinite(score[r, c])
        ]

    def to_json(self, pairs: bool = False) -> dict:
        """Summary (and, with ``pairs``, the full matrices as nested lists)."""
        feasible = self.feasible
        iu = np.triu_indices(len(self.boundary), 1)
        out = {
            "boundary": self.boundary.tolist(),
            "mu": self.mu,
            "pairs": int(len(iu[0])),
            "feasible_pairs": int(np.count_nonzero(feasible[iu])),
            "inward_pairs": int(np.count_nonzero(self.inward[iu])),
            "force_closure_pairs": int(np.count_nonzero(self.force_closure[iu])),
            "stiffness_range": [float(self.stiffness[iu].min()), float(self.stiffness[iu].max())],
            "best": [{"contacts": [i, j], "stiffness": k} for i, j, k in self.best()],
        }
        if pairs:
            out["stiffness"] = self.stiffness.tolist()
            out["inward"] = self.inward.tolist()
            out["force_closure"] = self.force_closure.tolist()
        return out


def grasp_map(obj: ElasticObject, mu: float) -> GraspMap:
    """Stable-squeeze stiffness, inwardness and force closure of all boundary-node pairs.

    ``mu`` is the friction coefficient (>= 0) of the force-closure test; an
    :class:`InvalidInputError` says so otherwise.

    Examples
    --------
    >>> from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
    >>> obj = scene_solid(load_scene(scene_file("disk")))
    >>> mesh = obj.mesh
    >>> i, j = (int(mesh.boundary[k]) for k in (0, len(mesh.boundary) // 2))
    >>> gmap = grasp_map(obj, mu=0.4)
    >>> b = len(mesh.boundary)
    >>> symmetric = np.allclose(gmap.stiffness, gmap.stiffness.T, equal_nan=True)
    >>> gmap.stiffness.shape == (b, b), bool(symmetric)
    (True, True)
    """
    mesh = obj.mesh
    p = mesh.nodes[mesh.boundary] / obj.scale
    n = mesh.normals
    b = len(p)
    A = obj.boundary_compliance.reshape(b, 2, b, 2)
    diag = A[np.arange(b), :, np.arange(b), :]
    d = p[None, :, :] - p[:, None, :]
    dist = np.linalg.norm(d, axis=2)
    np.fill_diagonal(dist, 1.0)
    d = d / dist[..., None]
    q_ii = np.einsum("abi,aij,abj->ab", d, diag, d)
    q_jj = np.einsum("abi,bij,abj->ab", d, diag, d)
    q_ij = np.einsum("abi,aibj,abj->ab", d, A, d)
    q = 0.5 * (q_ii + q_jj - 2.0 * q_ij)
    np.fill_diagonal(q, np.inf)
    stiffness = obj.material.force_scale / q
    inward = (np.einsum("abi,ai->ab", d, n) < 0) & (np.einsum("abi,bi->ab", d, n) > 0)
    pts = mesh.nodes[mesh.boundary]
    closure = force_closure_pairs(
        pts[:, None, :], n[:, None, :], pts[None, :, :], n[None, :, :], mu
    )
    np.fill_diagonal(inward, False)
    return GraspMap(mesh.boundary.copy(), stiffness, inward, closure, float(mu))
