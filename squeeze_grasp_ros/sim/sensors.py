# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Fingertip force/torque sensors, tactile arrays, sensor noise and dropout.

Frames and signs (object frame: x right, y up; fingertips only translate, so each fingertip
frame ``<finger>_tip`` is the object frame moved to the tip centre):

- **Wrench** (geometry_msgs/WrenchStamped convention): the force and torque the object applies
  *to the fingertip*, at the tip centre, N and N m: f = -sum_k f_k, tau_z = sum_k
  x(theta_k) x (-f_k), where f_k is the stepper's force of the finger on contact node k at
  contact coordinate theta_k and x(theta_k) the face point there relative to the tip's
  reference point (a circle's centre: r e(theta_k); :mod:`..mechanics.squeeze.tip_shapes`).
- **Tactile array**: taxels at fixed contact coordinates alpha_j (rad, fingertip frame; a
  circle's polar angles, on a pad r_e alpha is the distance along the face) spaced ``delta``
  apart (r delta along the face, on either shape). Each contact node spreads its normal force
  f_n = f_k . e(nu_k) (> 0 while pressing; nu_k its contact normal's angle) and tangential
  force f_t = f_k . t(nu_k) (+ counter-clockwise) over the two
  taxels that bracket it with hat weights max(0, 1 - |theta_k - alpha_j| / delta), which sum to 1
  inside the array: the total force is preserved, but taxels are not mesh nodes (a node between
  two taxels loads both; nodes beyond the array's ends are not sensed).
- **Noise**: independent Gaussian noise of std sigma on every force reading (three wrench force
  components, every taxel's normal and tangential force) and sigma * r on the torques.
- **Dropout**: each wrench and each tactile message of a tick is dropped with probability p.
Noise and dropout draw from two independent streams of one seed, so declaring dropout does not
change the noise values of the messages that are delivered.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactArrays, ContactNode
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry


@dataclass(frozen=True)
class TactileLayout:
    """Taxel angles of one fingertip's tactile array.

    Attributes
    ----------
    angles : (n,) ndarray
        Contact coordinates of the taxel centres, rad, fingertip frame, increasing (a
        circle's polar angles).
    periodic : bool
        The coordinates are angles on a circle (taken modulo 2 pi); a pad's are not (its face
        spans more than 2 pi of coordinate: r_e times it is the length along the face).
    """

    angles: np.ndarray
    periodic: bool = True

    @property
    def spacing(self) -> float:
        """Angle between neighbouring taxels, rad."""
        return float(self.angles[1] - self.angles[0])


def tactile_layout(center: float, taxels: int, span: float,
                   periodic: bool = True) -> TactileLayout:
    """``taxels`` taxels evenly over ``span`` rad centred on contact coordinate ``center``
    rad (``periodic``: a circle's angles).
    """
    return TactileLayout(center + np.linspace(-0.5 * span, 0.5 * span, taxels), periodic)


def taxel_weights(layout: TactileLayout, thetas: np.ndarray) -> np.ndarray:
    """Hat weights (k, n) of contact angles ``thetas`` (k,) rad on the taxels."""
    offset = np.asarray(thetas, float)[:, None] - layout.angles[None, :]
    if layout.periodic:
        offset = (offset + np.pi) % (2.0 * np.pi) - np.pi
    return np.maximum(0.0, 1.0 - np.abs(offset) / layout.spacing)


@dataclass(frozen=True)
class ContactGeometry:
    """What a finger's sensors need of its contact nodes' coordinates: the wrench's lever arms
    and the taxels' projections and weights. They depend on the coordinates only, which stay
    put while the nodes stick, so :class:`FingerSensors` keeps them from tick to tick.

    Attributes
    ----------
    arms : (k, 2) ndarray
        Face point of each node relative to the tip's reference point, m.
    cos, sin : (k,) ndarray
        Cosine and sine of each node's contact normal angle nu.
    weights : (k, n) ndarray or None
        Hat weights of the nodes on the taxels (:func:`taxel_weights`; None without an array).
    """

    arms: np.ndarray
    cos: np.ndarray
    sin: np.ndarray
    weights: np.ndarray | None


def contact_geometry(thetas: np.ndarray, normal_angles: np.ndarray, tip: TipGeometry,
                     layout: TactileLayout | None) -> ContactGeometry:
    """The :class:`ContactGeometry` of nodes at contact coordinates ``thetas`` with contact
    normal angles ``normal_angles`` (k,), rad, on ``tip`` (one, m) and ``layout``.
    """
    return ContactGeometry(tip.offset(thetas, np.zeros(len(thetas), int)), np.cos(normal_angles),
                           np.sin(normal_angles),
                           None if layout is None else taxel_weights(layout, thetas))


def contact_components(contacts: Sequence[ContactNode]) -> tuple[np.ndarray, np.ndarray,
                                                                  np.ndarray]:
    """(thetas, normal forces, tangential forces) (k,) of contact nodes (rad, N, N): the force
    on the object projected on the contact normal e(nu) and t(nu) (nu = theta on a circle).
    """
    arrays = ContactArrays.of(contacts)
    nu = arrays.normal_angles
    return (arrays.thetas, *_components(arrays.forces, np.cos(nu), np.sin(nu)))


def _components(forces: np.ndarray, cos: np.ndarray, sin: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """(normal, tangential) (k,) of forces (k, 2) along e(nu) and t(nu)."""
    return forces[:, 0] * cos + forces[:, 1] * sin, forces[:, 1] * cos - forces[:, 0] * sin


def render_tactile(
    layout: TactileLayout, contacts: Sequence[ContactNode]
) -> tuple[np.ndarray, np.ndarray]:
    """(normal, tangential) taxel forces (n,), N, of one finger's contact nodes."""
    if not contacts:
        return np.zeros(len(layout.angles)), np.zeros(len(layout.angles))
    thetas, fn, ft = contact_components(contacts)
    w = taxel_weights(layout, thetas)
    return fn @ w, ft @ w


def fingertip_wrench(contacts: Sequence[ContactNode],
                     tip: TipGeometry) -> tuple[np.ndarray, np.ndarray]:
    """(force (3,), torque (3,)) the object applies to the fingertip at its reference point (a
    circle's centre), N and N m; ``tip`` is the finger's tip (one, m).
    """
    if not contacts:
        return np.zeros(3), np.zeros(3)
    arrays = ContactArrays.of(contacts)
    return _wrench(arrays.forces, tip.offset(arrays.thetas, np.zeros(len(contacts), int)))


def _wrench(on_object: np.ndarray, arms: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(force (3,), torque (3,)) on the fingertip of forces on the object (k, 2) at ``arms``."""
    forces = -on_object
    torque_z = float(arms[:, 0] @ forces[:, 1] - arms[:, 1] @ forces[:, 0])
    fx, fy = np.add.reduce(forces, axis=0).tolist()  # forces.sum(axis=0) without its wrapper
    return np.array((fx, fy, 0.0)), np.array((0.0, 0.0, torque_z))


class FingerSensors:
    """One fingertip's wrench sensor and tactile array, reading its contact nodes per tick.

    The same numbers as :func:`fingertip_wrench` and :func:`render_tactile`, bit for bit, with
    the nodes' :class:`ContactGeometry` kept from the previous tick while their coordinates
    and normal angles are unchanged (sticking nodes move with the tip): on a tick where they
    are, only the force products remain.

    Parameters
    ----------
    tip : TipGeometry
        The finger's tip (one, m).
    layout : TactileLayout, optional
        Its tactile array (None: none).
    """

    def __init__(self, tip: TipGeometry, layout: TactileLayout | None = None) -> None:
        self.tip, self.layout = tip, layout
        self._key: bytes | None = None
        self._geometry: ContactGeometry | None = None

    def read_arrays(self, thetas: np.ndarray, forces: np.ndarray, nu: np.ndarray
                    ) -> tuple[np.ndarray, ContactGeometry]:
        """(forces on the object (k, 2), N; their :class:`ContactGeometry`) of the finger's
        contact nodes given as arrays (:class:`~.contact_state.ContactArrays`): contact
        coordinates ``thetas`` (k,) rad, forces on the object (k, 2) N and contact normal
        angles ``nu`` (k,) rad.
        """
        key = thetas.tobytes() + nu.tobytes()
        if key != self._key:
            self._key, self._geometry = key, contact_geometry(thetas, nu, self.tip, self.layout)
        return forces, self._geometry

    def wrench(self, forces: np.ndarray, geometry: ContactGeometry
               ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`fingertip_wrench` of nodes read by :meth:`read_arrays`."""
        if not len(forces):
            return np.zeros(3), np.zeros(3)
        return _wrench(forces, geometry.arms)

    def tactile(self, forces: np.ndarray, geometry: ContactGeometry
                ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`render_tactile` of nodes read by :meth:`read_arrays`."""
        if not len(forces):
            return np.zeros(len(self.layout.angles)), np.zeros(len(self.layout.angles))
        fn, ft = _components(forces, geometry.cos, geometry.sin)
        return fn @ geometry.weights, ft @ geometry.weights


class SensorRandomness:
    """Seeded noise and dropout draws, in a fixed order per tick (deterministic).

    Parameters
    ----------
    seed : int
        Seed of both streams.
    noise_std : float or None
        Force noise std, N (None: no noise effect, nothing is drawn).
    dropout : float or None
        Drop probability per message (None: no dropout effect, nothing is drawn).
    draws : collections.Counter
        Work counter; "noise_draws" and "dropout_draws" count the random numbers drawn.
    """

    def __init__(self, seed: int, noise_std: float | None, dropout: float | None, draws) -> None:
        noise_seq, dropout_seq = np.random.SeedSequence(seed).spawn(2)
        self.noise_std = noise_std
        self.dropout = dropout
        self._noise = np.random.default_rng(noise_seq)
        self._dropout = np.random.default_rng(dropout_seq)
        self._draws = draws

    def dropped(self) -> bool:
        """True if the next message is dropped (False without the dropout effect)."""
        if self.dropout is None:
            return False
        self._draws["dropout_draws"] += 1
        return bool(self._dropout.random() < self.dropout)

    def perturb(self, values: np.ndarray, scale: float = 1.0) -> np.ndarray:
        """``values`` plus noise of std ``noise_std * scale`` (unchanged without the noise
        effect).
        """
        if self.noise_std is None:
            return values
        self._draws["noise_draws"] += values.size
        return values + self._noise.normal(0.0, self.noise_std * scale, values.shape)
