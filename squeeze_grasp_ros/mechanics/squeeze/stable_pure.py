# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Stable and pure squeezes under point contacts (paper Sec. 3.4-3.5 and 4, eqs. 38-44).

A *stable* squeeze is the unit contact displacement maximising the strain energy: the top
eigenvector of C (Sec. 3.5); for two contacts it is u of eq. (40) and C = u u^T / (u^T A u)
(Theorem 10). A *pure* squeeze deforms without rigid motion: v = A C u / ||A C u|| (eq. 44;
col(AC) are the pure contact displacements, Theorem 8). Depths follow docs/design.md §2.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.reduced import (
    REDUCED_KEPT,
    ReducedStiffness,
    reduced_stiffness,
    rotation_angle,
)
from squeeze_grasp_ros.mechanics.errors import InfeasibleError, InvalidInputError, require_finite
from squeeze_grasp_ros.mechanics.vocabulary import SQUEEZING_FINGERS, Finger, SqueezeKind


@dataclass(frozen=True)
class Squeeze:
    """A unit squeeze at fixed point contacts.

    Attributes
    ----------
    kind : SqueezeKind
        Stable or pure.
    contacts : (m,) ndarray of int
        Initial contact node indices.
    displacement : (2m,) ndarray
        Unit contact displacement (||.|| = 1), dimensionless direction; depth rho multiplies it
        (m).
    forces : (2m,) ndarray
        Contact forces per unit depth, N/m (forces at depth rho are rho * forces).
    energy_per_unit_depth2 : float
        Strain energy / rho^2, J/m^2.
    rigid_rotation : float
        Rigid-rotation angle per unit depth, rad/m (zero for a pure squeeze).
    inward : bool
        Every contact node moves into the object (the squeeze is admissible).
    approach_per_unit_depth : float
        Finger approach per unit depth (sqrt(2) for a stable two-finger squeeze, ||v_i - v_j||
        for a pure one; for m > 2 the largest pairwise relative displacement).
    initial_distance : float
        Largest distance between the contact nodes, m.
    """

    kind: SqueezeKind
    contacts: np.ndarray
    displacement: np.ndarray
    forces: np.ndarray
    energy_per_unit_depth2: float
    rigid_rotation: float
    inward: bool
    approach_per_unit_depth: float
    initial_distance: float

    @property
    def stiffness(self) -> float:
        """Force-per-depth magnitude ||F|| / rho, N/m (1 / (u^T A u) for a stable squeeze)."""
        return float(np.linalg.norm(self.forces))

    def relative_depth(self, depth: float) -> float:
        """Finger approach over the initial contact distance at squeeze depth ``depth`` (m)."""
        return depth * self.approach_per_unit_depth / self.initial_distance

    def depth_for_relative(self, relative_depth: float) -> float:
        """Squeeze depth rho (m) giving the relative depth ``relative_depth`` (fraction)."""
        return relative_depth * self.initial_distance / self.approach_per_unit_depth


def two_contact_direction(p_i: np.ndarray, p_j: np.ndarray) -> np.ndarray:
    """U of eq. (40): the two nodes move toward each other, ||u|| = 1."""
    d = np.asarray(p_j, float) - np.asarray(p_i, float)
    dist = np.linalg.norm(d)
    if dist == 0:
        raise InvalidInputError("the two contact nodes coincide")
    return np.concatenate([d, -d]) / (np.sqrt(2.0) * dist)


def is_inward(obj: ElasticObject, contacts: np.ndarray, delta: np.ndarray) -> bool:
    """True if every contact node's displacement points into the object (delta_k . n_k < 0)."""
    normals = np.array([obj.mesh.normal_at(int(c)) for c in contacts])
    return bool(np.all(np.einsum("ij,ij->i", delta.reshape(-1, 2), normals) < 0))


def stable_direction(obj: ElasticObject, red: ReducedStiffness) -> np.ndarray:
    """Unit stable squeeze: top eigenvector of C (closed form eq. 40 for m = 2), sign inward."""
    p = obj.mesh.nodes[red.contacts]
    if red.m == 2:
        u = two_contact_direction(p[0], p[1])
    else:
        lam, U = np.linalg.eigh(red.C)
        u = U[:, -1]
        if lam[-1] - lam[-2] <= 1e-9 * lam[-1]:
            raise InfeasibleError("the largest eigenvalue of C is repeated: the stable squeeze "
                                  "is a subspace, not a direction; pick fewer contacts")
    if not is_inward(obj, red.contacts, u) and is_inward(obj, red.contacts, -u):
        u = -u
    return u


def _approach(delta: np.ndarray, points: np.ndarray) -> tuple[float, float]:
    """(largest pairwise relative displacement, largest pairwise distance) of the contacts."""
    d = delta.reshape(-1, 2)
    rel = np.linalg.norm(d[:, None] - d[None], axis=2)
    dist = np.linalg.norm(points[:, None] - points[None], axis=2)
    return float(rel.max()), float(dist.max())


def plan_squeeze(obj: ElasticObject, contacts, *, kind: SqueezeKind = SqueezeKind.STABLE,
                 red: ReducedStiffness | None = None) -> Squeeze:
    """Unit stable or pure squeeze at point ``contacts`` (m >= 2 boundary nodes).

    Raises
    ------
    InvalidInputError
        For bad contacts or an unknown ``kind``.

    Examples
    --------
    >>> from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
    >>> obj = scene_solid(load_scene(scene_file("disk")))
    >>> mesh = obj.mesh
    >>> i, j = (int(mesh.boundary[k]) for k in (0, len(mesh.boundary) // 2))
    >>> stable = plan_squeeze(obj, [i, j])
    >>> print(stable.kind, stable.inward, f"{np.linalg.norm(stable.displacement):.3f}")
    stable True 1.000
    >>> pure = plan_squeeze(obj, [i, j], kind="pure")
    >>> bool(abs(pure.rigid_rotation) < 1e-9)
    True
    """
    if kind not in (SqueezeKind.STABLE, SqueezeKind.PURE):
        raise InvalidInputError(f"squeeze type must be 'stable' or 'pure', got {kind!r}")
    red = red if red is not None else reduced_stiffness(obj, contacts)
    u = stable_direction(obj, red)
    if kind == SqueezeKind.STABLE:
        delta = u
    else:
        w = red.pure_part(u)
        delta = w / np.linalg.norm(w)
    forces = red.forces(delta)
    approach, dist = _approach(delta, obj.mesh.nodes[red.contacts])
    return Squeeze(
        kind=kind,
        contacts=red.contacts,
        displacement=delta,
        forces=forces,
        energy_per_unit_depth2=red.energy(delta),
        rigid_rotation=rotation_angle(obj, red.rigid_coefficients(delta)),
        inward=is_inward(obj, red.contacts, delta),
        approach_per_unit_depth=approach,
        initial_distance=dist,
    )


@dataclass(frozen=True)
class FingerMotion:
    """How the two fingers of a squeeze translate per unit depth (docs/design.md §2).

    Attributes
    ----------
    directions : mapping
        Finger (F1, F2) -> translation (2,) per unit depth, m/m; the stacked vector has norm 1,
        so the depth is rho.
    relative_per_depth : float
        Relative depth per unit depth, 1/m: the fingers' approach along the chord of the
        contacts over the contacts' distance, per metre of depth (may be <= 0 for given
        directions that do not close the fingers).
    kind : SqueezeKind
        The planned squeeze (stable, pure), or custom for user-given directions.
    """

    directions: Mapping[Finger, np.ndarray]
    relative_per_depth: float
    kind: SqueezeKind


def finger_motion(obj: ElasticObject, contacts, *, kind: SqueezeKind = SqueezeKind.STABLE,
                  directions=None) -> FingerMotion:
    """The finger translations of a squeeze from initial contact nodes (F1, F2).

    Parameters
    ----------
    obj : ElasticObject
    contacts : (int, int)
        Initial contact nodes of F1 and F2.
    kind : {"stable", "pure"}
        The planned squeeze (:func:`plan_squeeze`) whose contact displacement the fingers
        follow; ignored when ``directions`` is given.
    directions : mapping, optional
        User-given finger -> translation direction; scaled so the stacked vector has norm 1.

    Raises
    ------
    InvalidInputError
        For bad contacts, an unknown kind, or directions that are not one finite [x, y] per
        finger or are all zero.

    Examples
    --------
    >>> from squeeze_grasp_ros.api import GraspSetup, load_scene, scene_file
    >>> setup = GraspSetup.build(load_scene(scene_file("foam_square")))
    >>> motion = finger_motion(setup.solid, setup.contacts)
    >>> print(motion.kind, f"{motion.relative_per_depth:.3f} 1/m")
    stable 14.142 1/m
    """
    p = obj.mesh.nodes[list(contacts)]
    distance = float(np.linalg.norm(p[1] - p[0]))
    if directions is None:
        plan = _kept_plan(obj, contacts, kind)
        u = plan.displacement.reshape(2, 2)
        return FingerMotion({Finger.F1: u[0].copy(), Finger.F2: u[1].copy()},
                            plan.approach_per_unit_depth / distance, plan.kind)
    missing = [str(n) for n in SQUEEZING_FINGERS if n not in directions]
    if missing:
        raise InvalidInputError(f"squeeze directions give none for {', '.join(missing)}")
    listed = [directions[n] for n in SQUEEZING_FINGERS]
    require_finite("squeeze directions", listed)
    stacked = np.asarray(listed, float)
    if stacked.shape != (len(SQUEEZING_FINGERS), 2):
        raise InvalidInputError(f"squeeze directions must be one [x, y] per finger, got shape "
                                f"{stacked.shape}")
    norm = float(np.linalg.norm(stacked))
    if not norm > 0:
        raise InvalidInputError("squeeze directions must not all be zero")
    dirs = {n: stacked[k] / norm for k, n in enumerate(SQUEEZING_FINGERS)}
    approach = float((dirs[Finger.F1] - dirs[Finger.F2]) @ (p[1] - p[0]) / distance)
    return FingerMotion(dirs, approach / distance, SqueezeKind.CUSTOM)


def _kept_plan(obj: ElasticObject, contacts, kind: SqueezeKind) -> Squeeze:
    """:func:`plan_squeeze` of ``contacts`` and ``kind``, kept on the object (the last
    REDUCED_KEPT, beside the reduced stiffnesses it is planned from): a sweep squeezes every
    placement at several depths, frictions and tips, each with the same plan. Callers copy
    what they hand on; a failed plan is not kept (it raises again).
    """
    kept = obj._shared.setdefault("squeeze_plans", {})
    tag = (str(kind), tuple(int(c) for c in contacts))
    plan = kept.get(tag)
    if plan is None:
        plan = plan_squeeze(obj, list(contacts), kind=kind)
        if len(kept) >= REDUCED_KEPT:
            kept.pop(next(iter(kept)), None)
        kept[tag] = plan
    return plan


def force_closure(p_i, n_i, p_j, n_j, mu: float) -> bool:
    """Two-finger force closure of a rigid body (Nguyen 1988): segment p_i p_j in both cones.

    ``n_i``, ``n_j`` are outward unit normals; the cones have half-angle atan(mu) about the
    inward normals.
    """
    return bool(force_closure_pairs(np.asarray(p_i)[None], np.asarray(n_i)[None],
                                    np.asarray(p_j)[None], np.asarray(n_j)[None], mu)[0])


def force_closure_pairs(p_i, n_i, p_j, n_j, mu: float) -> np.ndarray:
    """Vectorised :func:`force_closure` over arrays of placements (..., 2) -> bool (...)."""
    require_finite("friction coefficient mu", mu)
    if not mu >= 0:
        raise InvalidInputError(f"friction coefficient mu must be >= 0, got {mu}")
    d = p_j - p_i
    dist = np.linalg.norm(d, axis=-1)
    safe = np.where(dist > 0, dist, 1.0)
    cos_i = -np.sum(d * n_i, axis=-1) / safe
    cos_j = np.sum(d * n_j, axis=-1) / safe
    cos_cone = 1.0 / np.sqrt(1.0 + mu * mu)
    return (dist > 0) & (cos_i >= cos_cone - 1e-12) & (cos_j >= cos_cone - 1e-12)
