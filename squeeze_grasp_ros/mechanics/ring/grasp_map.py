# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Grasp map of a ring: maximum feasible depth and its limit for every pair of nodes (Sec.
7.1-7.2).

Vectorised over all n (n - 1) / 2 unordered placements (F1 at the lower index). For two
contacts null(B^T) is spanned by the squeeze direction u, so Theorem 10 gives everything in
closed form from 2x2 blocks A_ab of the cached compliance, with d the unit vector from p_i to
p_j and q = u^T A u = 1/2 d^T (A_ii - A_ij - A_ji + A_jj) d:

* stable: F_i = -F_j = d / (sqrt(2) q); rigid part g = -(B^T B)^-1 B^T A F;
* pure:   F_i = -F_j = d / (sqrt(2) ||A u||); g = 0;
* node k moves by (A_ki - A_kj) F_i + R_k g per unit depth.

The cone test at rho = 0+ needs only the undeformed normals; roots (batched companion matrices)
and strains (a max over the elements: O(n) per placement, the paper's O(n) search) are computed
only for placements that start inside both cones. :func:`~.ring_squeeze.ring_grasp` computes one
placement through the general Sec. 3 blocks instead; the tests check both agree.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_relative_depth
from squeeze_grasp_ros.mechanics.ring.model import FIBRE_STRAIN_MEASURE, RingModel
from squeeze_grasp_ros.mechanics.ring.squeeze import (
    LIMITS,
    check_limits,
    cone_depths,
    initially_feasible,
    neighbours,
    resolve_limits,
    ring_grasp,
)
from squeeze_grasp_ros.mechanics.vocabulary import RingLimit, SqueezeKind

CHUNK = 512
"""Placements per block in the strain search (bounds the temporary memory to ~CHUNK * 9n
floats)."""


@dataclass(frozen=True)
class RingGraspMap:
    """Maximum feasible depth and limit of every two-finger placement on a ring, SI units.

    Attributes
    ----------
    n : int
        Number of ring nodes.
    kind : SqueezeKind
        Squeeze type (stable or pure).
    mu : float
        Friction coefficient.
    epsilon : float or None
        Strain limit (None: none).
    pairs : (P, 2) ndarray of int
        Placements (i, j), i < j: F1 at node i, F2 at node j.
    max_depth : (P,) ndarray
        Largest feasible depth rho, m.
    max_relative_depth : (P,) ndarray
        The same as a relative depth (finger approach / initial distance).
    limit_code : (P,) ndarray of int
        Index into :data:`~.ring_squeeze.LIMITS` of what bounds each placement.
    initially_feasible : (P,) ndarray of bool
        Both forces start strictly inside their cones (rigid-body force closure).
    requested_relative_depth : float or None
        The relative depth the map is asked about (Table 5), if any.
    """

    n: int
    kind: SqueezeKind
    mu: float
    epsilon: float | None
    pairs: np.ndarray
    max_depth: np.ndarray
    max_relative_depth: np.ndarray
    limit_code: np.ndarray
    initially_feasible: np.ndarray
    requested_relative_depth: float | None = None

    def succeeds(self, relative_depth: float) -> np.ndarray:
        """(P,) bool: placements feasible up to ``relative_depth`` (> 0)."""
        return self.initially_feasible & (self.max_relative_depth >= relative_depth)

    def limit_names(self) -> np.ndarray:
        """(P,) limit names."""
        return np.asarray(RingLimit.values())[self.limit_code]

    def matrix(self, values: np.ndarray, fill: float = np.nan) -> np.ndarray:
        """Symmetric (n, n) matrix of per-placement ``values`` (P,), ``fill`` on the diagonal."""
        out = np.full((self.n, self.n), fill, dtype=float)
        i, j = self.pairs.T
        out[i, j] = out[j, i] = values
        return out

    def lookup(self, i: int, j: int) -> int:
        """Row of placement {i, j} in ``pairs`` (F1 at min(i, j))."""
        a, b = min(i, j), max(i, j)
        if a == b or a < 0 or b >= self.n:
            raise InvalidInputError(f"no placement ({i}, {j}) on a ring of {self.n} nodes")
        return int(a * self.n - a * (a + 1) // 2 + (b - a - 1))

    def failure_modes(self, relative_depth: float, started: bool = False) -> dict[str, int]:
        """Counts, by limit name, of the placements that fail before ``relative_depth``; with
        ``started`` only those that start inside both cones (they fail during the squeeze).
        """
        fail = ~self.succeeds(relative_depth)
        if started:
            fail &= self.initially_feasible
        codes = self.limit_code[fail]
        return {name.value: int(np.sum(codes == k)) for k, name in enumerate(LIMITS)}

    def best(self, count: int = 5) -> list[dict]:
        """The ``count`` (>= 0) placements with the largest maximum relative depth."""
        if count < 0:
            raise InvalidInputError(f"the number of best placements must be >= 0, got {count}")
        order = np.argsort(-self.max_relative_depth, kind="mergesort")[:count]
        return [self._entry(k) for k in order]

    def _entry(self, k: int) -> dict:
        return {"contacts": [int(self.pairs[k, 0]), int(self.pairs[k, 1])],
                "max_depth": float(self.max_depth[k]),
                "max_relative_depth": float(self.max_relative_depth[k]),
                "limit": LIMITS[int(self.limit_code[k])].value}

    def to_json(self, best: int = 10) -> dict:
        """A JSON-able summary: counts, depth statistics, failure modes, best placements."""
        rel = self.max_relative_depth
        out = {
            "elements": self.n, "squeeze": self.kind, "mu": self.mu, "epsilon": self.epsilon,
            "strain_measure": str(FIBRE_STRAIN_MEASURE),
            "pairs": int(len(self.pairs)),
            "initially_feasible_pairs": int(self.initially_feasible.sum()),
            "max_relative_depth": {"min": float(rel.min()), "median": float(np.median(rel)),
                                   "max": float(rel.max())},
            "limits": {name.value: int(np.sum(self.limit_code == k))
                       for k, name in enumerate(LIMITS)},
            "best": self.best(best),
        }
        r = self.requested_relative_depth
        if r is not None:
            ok = self.succeeds(r)
            out.update({"requested_relative_depth": r, "feasible_pairs": int(ok.sum()),
                        "failure_modes": self.failure_modes(r),
                        "initially_infeasible_pairs": int((~self.initially_feasible).sum()),
                        "failure_modes_during_squeeze": self.failure_modes(r, started=True)})
        return out


def _all_pairs(n: int) -> np.ndarray:
    i, j = np.triu_indices(n, k=1)
    return np.column_stack([i, j])


def pair_fields(ring: RingModel, pairs: np.ndarray, kind: SqueezeKind):
    """Closed-form (Theorem 10) squeeze of each placement, dimensionless.

    Returns
    -------
    force : (P, 2, 2) ndarray
        Forces on F1, F2 per unit depth (in units of E w).
    rate : (P, 2, 3, 2) ndarray
        Displacement per unit depth of each finger's (previous, contact, next) node.
    approach : (P,) ndarray
        Finger approach per unit depth.
    """
    n = ring.n
    A4 = ring.compliance.reshape(n, 2, n, 2).transpose(0, 2, 1, 3)
    Rn = ring.rigid[ring.translation_dofs].reshape(n, 2, 3)
    I, J = pairs[:, 0], pairs[:, 1]
    d = ring.points[J] - ring.points[I]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    Ad_i = np.einsum("pab,pb->pa", A4[I, I] - A4[I, J], d)
    Ad_j = np.einsum("pab,pb->pa", A4[J, I] - A4[J, J], d)
    q = 0.5 * np.einsum("pa,pa->p", d, Ad_i - Ad_j)
    Au = np.stack([Ad_i, Ad_j], axis=1) / np.sqrt(2.0)
    if kind == SqueezeKind.STABLE:
        scale = 1.0 / q
        approach = np.full(len(pairs), np.sqrt(2.0))
    else:
        norm_Au = np.linalg.norm(Au.reshape(-1, 4), axis=1)
        scale = 1.0 / norm_Au
        approach = np.linalg.norm(Au[:, 0] - Au[:, 1], axis=1) / norm_Au
    f1 = d * (scale / np.sqrt(2.0))[:, None]
    force = np.stack([f1, -f1], axis=1)
    nb = neighbours(n, pairs)
    rate = np.einsum("pfkab,pb->pfka", A4[nb, I[:, None, None]] - A4[nb, J[:, None, None]], f1)
    if kind == SqueezeKind.STABLE:
        B = np.concatenate([Rn[I], Rn[J]], axis=1)
        BtB = np.einsum("pra,prb->pab", B, B)
        BtAF = np.einsum("pra,pr->pa", B, (Au * scale[:, None, None]).reshape(-1, 4))
        g = -np.linalg.solve(BtB, BtAF[..., None])[..., 0]
        rate += np.einsum("pfkab,pb->pfka", Rn[nb], g)
    return force, rate, approach


def strain_rates(ring: RingModel, pairs: np.ndarray, force: np.ndarray) -> np.ndarray:
    """Largest fibre strain per unit dimensionless depth (P,) of each placement: max over
    elements.
    """
    n = ring.n
    Phi = ring.strain_influence.reshape(n, 2, 3 * n)
    half_h = 0.5 * ring.h_hat
    out = np.empty(len(pairs))
    for start in range(0, len(pairs), CHUNK):
        sl = slice(start, start + CHUNK)
        D = Phi[pairs[sl, 0]]
        D -= Phi[pairs[sl, 1]]
        q = np.matmul(force[sl, 0, None, :], D)[:, 0].reshape(-1, 3, n)
        np.abs(q, out=q)
        bend = np.maximum(q[:, 1], q[:, 2])
        bend *= half_h
        bend += q[:, 0]
        out[sl] = bend.max(axis=1)
    return out


def ring_grasp_map(ring: RingModel, mu: float, *, epsilon: float | None = None,
                   kind: SqueezeKind = SqueezeKind.STABLE,
                   requested_relative_depth: float | None = None) -> RingGraspMap:
    """Maximum feasible depth and limit of every placement (i, j), i < j, on ``ring``.

    Parameters
    ----------
    ring : RingModel
    mu : float
        Friction coefficient, >= 0.
    epsilon : float, optional
        Proportional limit; None for no strain limit.
    kind : {"stable", "pure"}
    requested_relative_depth : float, optional
        Relative depth to report successes and failure modes at (Table 5).

    Examples
    --------
    >>> from squeeze_grasp_ros.api import GraspSetup, load_scene, scene_file
    >>> ring = GraspSetup.build(load_scene(scene_file("ring_ring"))).ring
    >>> gmap = ring_grasp_map(ring, 0.4)
    >>> gmap.n == ring.n, gmap.kind
    (True, 'stable')
    """
    if kind not in (SqueezeKind.STABLE, SqueezeKind.PURE):
        raise InvalidInputError(f"squeeze type must be 'stable' or 'pure', got {kind!r}")
    check_limits(mu, epsilon)
    if requested_relative_depth is not None:
        require_relative_depth(requested_relative_depth)
    L = ring.scale
    pairs = _all_pairs(ring.n)
    force, rate, approach = pair_fields(ring, pairs, kind)
    base = ring.points[neighbours(ring.n, pairs)] / L
    distance = np.linalg.norm(ring.points[pairs[:, 1]] - ring.points[pairs[:, 0]], axis=1) / L
    cap = distance / approach
    ok0 = initially_feasible(base, force, mu)
    start_ok = ok0.all(axis=1)
    strain = np.full(len(pairs), np.inf)
    if epsilon is not None:
        strain[start_ok] = epsilon / strain_rates(ring, pairs[start_ok], force[start_ok])
    cones = np.where(ok0, np.inf, 0.0)
    live = np.flatnonzero(start_ok)
    cones[live] = cone_depths(base[live], rate[live], force[live], mu,
                              np.minimum(cap[live], strain[live]))
    depth, code = resolve_limits(cones, strain, cap)
    return RingGraspMap(n=ring.n, kind=kind, mu=float(mu), epsilon=epsilon, pairs=pairs,
                        max_depth=depth * L, max_relative_depth=depth * approach / distance,
                        limit_code=code, initially_feasible=start_ok,
                        requested_relative_depth=requested_relative_depth)


def bench_ring(ring: RingModel, mu: float, epsilon: float | None = None,
               kind: SqueezeKind = SqueezeKind.STABLE, single: int = 200, seed: int = 0) -> dict:
    """Wall-clock timings of the mechanics on ``ring``, seconds.

    Returns ``precompute`` (stiffness, factor, compliance, strain influence; from a fresh copy of
    the ring), ``map`` (all pairs), ``single_mean`` / ``single_min`` over ``single`` random
    placements (:func:`~.ring_squeeze.ring_grasp`), with ``elements``, ``pairs`` and
    ``initially_feasible_pairs``.
    """
    fresh = RingModel(ring.points, ring.material, ring.wall_thickness)
    t0 = time.perf_counter()
    fresh.precompute()
    t1 = time.perf_counter()
    gmap = ring_grasp_map(fresh, mu, epsilon=epsilon, kind=kind)
    t2 = time.perf_counter()
    rng = np.random.default_rng(seed)
    times = []
    for _ in range(single):
        i, j = rng.choice(fresh.n, size=2, replace=False)
        s = time.perf_counter()
        ring_grasp(fresh, (i, j), mu, epsilon=epsilon, kind=kind)
        times.append(time.perf_counter() - s)
    return {"elements": fresh.n, "pairs": int(len(gmap.pairs)),
            "initially_feasible_pairs": int(gmap.initially_feasible.sum()),
            "precompute": t1 - t0, "map": t2 - t1,
            "single_mean": float(np.mean(times)), "single_min": float(np.min(times))}
