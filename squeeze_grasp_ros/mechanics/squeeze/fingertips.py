# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Rigid semicircular fingertips (paper Sec. 5, Fig. 5).

A fingertip of radius r touching boundary node p with outward unit normal n has its centre at
o = p + r n. Polar angles are measured at the tip centre in the object frame (x right, y up,
radians, counter-clockwise): a contact node at polar angle theta sits at o + r e(theta) with

    e(theta) = (cos theta, sin theta)     (from the tip centre into the object)
    t(theta) = (-sin theta, cos theta)    (d e / d theta).

The force a finger applies on a contact node has normal component f_n = f . e(theta) (> 0 while
pressing) and tangential component f_t = f . t(theta). The friction cone of half-angle
phi = atan(mu) is bounded by the edges e(theta + phi) (f_t > 0) and e(theta - phi) (f_t < 0).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh
from squeeze_grasp_ros.mechanics.vocabulary import Finger



def unit(theta) -> np.ndarray:
    """e(theta) = (cos, sin) stacked on the last axis, (..., 2).

    >>> unit([0.0, np.pi / 2]).round(12).tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """
    theta = np.asarray(theta, float)
    out = np.empty(theta.shape + (2,))
    np.cos(theta, out=out[..., 0])
    np.sin(theta, out=out[..., 1])
    return out


def tangent(theta) -> np.ndarray:
    """t(theta) = (-sin, cos) stacked on the last axis, (..., 2)."""
    theta = np.asarray(theta, float)
    out = np.empty(theta.shape + (2,))
    np.negative(np.sin(theta), out=out[..., 0])
    np.cos(theta, out=out[..., 1])
    return out


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """2-D cross product a_x b_y - a_y b_x over the last axis."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


@dataclass(frozen=True)
class Fingertip:
    """A rigid semicircular fingertip at its initial placement.

    Attributes
    ----------
    name : Finger
    node : int
        Mesh node of the initial contact (on the outer boundary).
    center : (2,) ndarray
        Tip centre o = p + r n, m, object frame.
    radius : float
        Tip radius r, m (> 0).
    theta : float
        Polar angle of the initial contact node about the centre, rad (the direction of -n).
    """

    name: Finger
    node: int
    center: np.ndarray
    radius: float
    theta: float


def place_fingertip(mesh: Mesh, name: Finger, node: int, radius: float) -> Fingertip:
    """Fingertip ``name`` of radius ``radius`` (m) touching boundary ``node`` on its outward
    normal.

    Raises
    ------
    InvalidInputError
        For an unknown finger name, a non-positive radius or a node not on the outer boundary.
    """
    if name not in Finger.values():
        raise InvalidInputError(f"finger name must be one of {Finger.values()}, got {name!r}")
    if not (np.isfinite(radius) and radius > 0):
        raise InvalidInputError(f"fingers.{name}.tip_radius must be > 0 m for rounded-tip "
                                "contact, "
                             f"got {radius}")
    n = mesh.normal_at(int(node))
    p = mesh.nodes[int(node)]
    center = p + radius * n
    return Fingertip(Finger(name), int(node), center, float(radius),
                     float(np.arctan2(-n[1], -n[0])))


def tip_gaps(points: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Signed distances (k, f) of ``points`` (k, 2) outside fingertips (f centres, f radii).

    Negative values are penetrations. Units follow the inputs.
    """
    d = points[:, None, :] - centers[None, :, :]
    return np.sqrt((d * d).sum(axis=-1)) - radii[None, :]  # np.linalg.norm's arithmetic
