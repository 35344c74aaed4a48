# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Rigid fingertips placed on the object: the paper's semicircular tip (Sec. 5, Fig. 5) and the
flat pad of a gripper jaw (:mod:`.tip_shapes` holds their common geometry).

A circular fingertip of radius r touching boundary node p with outward unit normal n has its
centre at o = p + r n. Polar angles are measured at the tip centre in the object frame (x
right, y up, radians, counter-clockwise): a contact node at polar angle theta sits at
o + r e(theta) with

    e(theta) = (cos theta, sin theta)     (from the tip centre into the object)
    t(theta) = (-sin theta, cos theta)    (d e / d theta).

A tip of any shape names its contact points by the coordinate q of :mod:`.tip_shapes` (for a
circle, the polar angle) and its contact normal at q is e(nu(q)). The force a finger applies on
a contact node has normal component f_n = f . e(nu) (> 0 while pressing) and tangential
component f_t = f . t(nu). The friction cone of half-angle phi = atan(mu) is bounded by the
edges e(nu + phi) (f_t > 0) and e(nu - phi) (f_t < 0).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import (
    TipGeometry,
    TipShape,
    cross,
    tangent,
    unit,
)
from squeeze_grasp_ros.mechanics.vocabulary import Finger, TipKind

__all__ = ["TOUCH_TOLERANCE", "Fingertip", "cross", "place_fingertip", "tangent", "unit"]

TOUCH_TOLERANCE = 1e-9
"""Boundary nodes within this gap of a tip placed on the object (relative to the object's
size) touch it from the start: a pad set on a straight side touches every node under its flat
face."""


@dataclass(frozen=True)
class Fingertip:
    """A rigid fingertip at its initial placement.

    Attributes
    ----------
    name : Finger
    node : int
        Mesh node of the initial contact (on the outer boundary).
    center : (2,) ndarray
        Tip reference point o, m, object frame: a circle's centre; rho behind the middle of a
        pad's flat face.
    radius : float
        Tip radius r (a pad's edge radius), m (> 0).
    theta : float
        Contact coordinate of the initial contact node, rad (for a circle, its polar angle
        about the centre: the direction of -n).
    flat : float
        Half the width of the flat face, m (0 for a circle; :mod:`.tip_shapes`).
    facing : float
        Angle of the tip's facing direction, rad (a pad's flat faces e(facing)).
    touching : tuple of (int, float)
        (node, contact coordinate) of the other boundary nodes that touch the tip where it is
        placed (within TOUCH_TOLERANCE).
    """

    name: Finger
    node: int
    center: np.ndarray
    radius: float
    theta: float
    flat: float = 0.0
    facing: float = 0.0
    touching: tuple[tuple[int, float], ...] = ()


def place_fingertip(mesh: Mesh, name: str, node: int, radius: float | TipShape,
                    facing: float | None = None, origin=None) -> Fingertip:
    """Fingertip ``name`` of ``radius`` (m; or any :class:`TipShape`) touching boundary
    ``node``.

    A circle without ``facing`` sits on the outward normal at ``node`` (the paper's
    placement) where it overlaps no other boundary node. A pad (or a tip given ``facing``, the
    angle in rad of the direction it faces, into the object), and a circle whose paper
    placement would overlap the object (a concave stretch of the boundary more tightly curved
    than the tip: the tip cannot reach ``node`` along its normal), faces the inward normal at
    ``node`` (or ``facing``) and approaches the object along that direction until its face
    first touches the outer boundary, at ``node`` when the boundary allows (a pad set square on
    a convex side), else at the node it meets first, which becomes the initial contact; every
    other node then touching is in :attr:`Fingertip.touching`. Either way no boundary node
    starts inside the tip (by more than TOUCH_TOLERANCE of the object size), so the squeeze
    starts from zero force. With ``origin`` (x, y), m, the tip's reference point starts
    there (a gripper jaw on its closing line, clear of the object) instead of on ``node``.

    Raises
    ------
    InvalidInputError
        For an unknown finger name, a non-positive radius or a node not on the outer boundary.
    """
    if name not in Finger.values():
        raise InvalidInputError(f"finger name must be one of {Finger.values()}, got {name!r}")
    shape = radius if isinstance(radius, TipShape) else None
    r = shape.radius if shape is not None else radius
    if not (np.isfinite(r) and r > 0):
        raise InvalidInputError(f"fingers.{name}.tip_radius must be > 0 m for rounded-tip "
                                "contact, "
                             f"got {r}")
    shape = shape or TipShape.circle(float(r))
    n = mesh.normal_at(int(node))
    p = mesh.nodes[int(node)]
    theta0 = float(np.arctan2(-n[1], -n[0])) if facing is None else float(facing)
    if shape.kind == TipKind.CIRCLE and facing is None:
        if not _overlaps(mesh, float(r), p + r * n):
            return Fingertip(name, int(node), p + r * n, float(r), theta0, facing=theta0)
        origin = None
    return _approach(mesh, name, int(node), shape, theta0, origin)


def _overlaps(mesh: Mesh, radius: float, center: np.ndarray) -> bool:
    """Whether a boundary node lies inside the circle of ``radius`` at ``center`` by more than
    TOUCH_TOLERANCE of the object size (squared distances: a few microseconds a placement).
    """
    d = mesh.nodes[mesh.boundary] - center
    inner = radius - TOUCH_TOLERANCE * mesh.size
    return bool(inner > 0 and np.einsum("ij,ij->i", d, d).min() < inner * inner)


def _approach(mesh: Mesh, name: str, node: int, shape: TipShape, theta0: float,
              origin) -> Fingertip:
    """The tip facing e(theta0) moved along it until its face first touches the boundary."""
    r, a = shape.radius, shape.half_flat
    e0 = unit(theta0)
    boundary = mesh.boundary
    # from the origin, advanced until its face touches; or set on the node, then backed off
    # until no boundary node is ahead of its face
    center = mesh.nodes[node] - r * e0 if origin is None else np.asarray(origin, float)
    clear = shape.clearance(mesh.nodes[boundary], center[None], [theta0])[0]
    first = int(np.argmin(clear))
    if not np.isfinite(clear[first]):
        raise InvalidInputError(f"fingers.{name}: the tip's approach from {origin} misses "
                                "the object")
    advance = float(clear[first]) if origin is not None else min(float(clear[first]), 0.0)
    center = center + advance * e0
    tips = TipGeometry.of([shape], [theta0])
    gaps = tips.gaps(mesh.nodes[boundary], center[None])[:, 0]
    touching = boundary[gaps <= TOUCH_TOLERANCE * mesh.size].tolist()
    start = node if node in touching else int(boundary[first])

    def coordinate(k: int) -> float:
        return tips.coordinate(mesh.nodes[k] - center, 0)

    return Fingertip(Finger(name), start, center, float(r), coordinate(start), a, theta0,
                     tuple((k, coordinate(k)) for k in sorted(touching) if k != start))
