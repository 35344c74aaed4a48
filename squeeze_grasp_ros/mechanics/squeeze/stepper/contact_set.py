# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The contact set of a stepper call: which nodes touch which finger, in which mode.

A :class:`ContactSet` is a value: every change (new modes, a node added or removed) makes a new
one, and a change of the nodes gathers the new set's data from the contact model
(:meth:`~..contact_model.ContactModel.set_data`, cached per set by the model). Dimensionless.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel, SetData
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode

__all__ = ["ContactSet", "SLIP_RATE_ZERO"]

SLIP_RATE_ZERO = 1e-10
"""Frictionless contacts: polar-angle rates (rad per unit motion) below this have no slip
direction, so round-off in a symmetric contact cannot fake a one-way finger slip."""


@dataclass(frozen=True)
class ContactSet:
    """Contact nodes sorted by index, with their fingers and modes.

    Attributes
    ----------
    nodes : (m,) ndarray of int
        Mesh nodes, ascending.
    finger : (m,) ndarray of int
        Index of each node's finger (in the call's :class:`~.motion.FingerMotion`).
    stick : (m,) ndarray of bool
    slip : (m,) ndarray of int
        Slip direction of sliding nodes (+1/-1), 0 for sticking ones.
    theta : (m,) ndarray
        Polar angles about the tips, rad (the last solution's: the next solve starts there).
    data : SetData
        The contact model's data of the set.
    positions : (m, 2) ndarray
        Undeformed positions / L.
    rows : (m,) ndarray of int
        Positions of the nodes in the outer boundary loop.
    """

    nodes: np.ndarray
    finger: np.ndarray
    stick: np.ndarray
    slip: np.ndarray
    theta: np.ndarray
    data: SetData
    positions: np.ndarray
    rows: np.ndarray

    @classmethod
    def of(cls, model: ContactModel, nodes, finger, stick, slip, theta) -> ContactSet:
        """The set of these nodes (any order; sorted here) and its model data."""
        order = np.argsort(np.asarray(nodes, int), kind="mergesort")
        nodes = np.asarray(nodes, int)[order]
        return cls(nodes, np.asarray(finger, int)[order], np.asarray(stick, bool)[order],
                   np.asarray(slip, int)[order], np.asarray(theta, float)[order],
                   model.set_data(tuple(nodes.tolist())), model.positions(nodes),
                   model.obj.boundary_positions(nodes))

    @classmethod
    def of_state(cls, model: ContactModel, state: ContactState) -> ContactSet:
        """The contacts of ``state`` (fingers indexed in the state's order)."""
        order = {f.name: k for k, f in enumerate(state.fingers)}
        c = state.contacts
        return cls.of(model, [x.node for x in c], [order[x.finger] for x in c],
                      [x.mode == ContactMode.STICK for x in c], [x.slip for x in c],
                      [x.theta for x in c])

    def __len__(self) -> int:
        return len(self.nodes)

    def index(self, node: int) -> int:
        """Position of contact ``node`` in the set."""
        return int(np.searchsorted(self.nodes, node))

    def finger_of(self, node: int) -> int:
        """Finger index of contact ``node``."""
        return int(self.finger[self.index(node)])

    def _with(self, stick: np.ndarray, slip: np.ndarray, theta: np.ndarray) -> ContactSet:
        """The same nodes in modes ``stick``, ``slip`` at polar angles ``theta`` (built
        directly: :func:`dataclasses.replace` reads the fields' metadata at every call, and a
        stepper call makes a set per substep).
        """
        return ContactSet(self.nodes, self.finger, stick, slip, theta, self.data,
                          self.positions, self.rows)

    def with_modes(self, stick: np.ndarray, slip: np.ndarray) -> ContactSet:
        """The same nodes in other modes."""
        return self._with(stick, slip, self.theta)

    def with_mode(self, k: int, stick: bool, slip: int) -> ContactSet:
        """Contact k in another mode."""
        new_stick, new_slip = self.stick.copy(), self.slip.copy()
        new_stick[k], new_slip[k] = stick, slip
        return self._with(new_stick, new_slip, self.theta)

    def with_theta(self, theta: np.ndarray) -> ContactSet:
        """The same contacts at other polar angles."""
        return self._with(self.stick, self.slip, theta)

    def added(self, model: ContactModel, nodes: list[int], fingers: list[int],
              thetas: list[float]) -> ContactSet:
        """The set with new sticking ``nodes`` on ``fingers`` at polar angles ``thetas``."""
        return ContactSet.of(model, np.append(self.nodes, nodes), np.append(self.finger, fingers),
                             np.append(self.stick, [True] * len(nodes)),
                             np.append(self.slip, [0] * len(nodes)),
                             np.append(self.theta, thetas))

    def without(self, model: ContactModel, k: int) -> ContactSet:
        """The set without contact k."""
        keep = np.arange(len(self.nodes)) != k
        return ContactSet.of(model, self.nodes[keep], self.finger[keep], self.stick[keep],
                             self.slip[keep], self.theta[keep])

    def slip_signs(self, dtheta: np.ndarray, frictionless: bool) -> np.ndarray:
        """Slip direction of each contact (from the polar-angle rates ``dtheta`` when
        frictionless, where every contact slides).
        """
        if frictionless:
            rate = np.where(np.abs(dtheta) > SLIP_RATE_ZERO, dtheta, 0.0)
            return np.sign(rate).astype(int)
        return self.slip

    def sliding_finger(self, signs: np.ndarray, masks: tuple[np.ndarray, ...]) -> int | None:
        """Index of a finger whose contacts all slide the same way (finger slip, Sec. 5.1),
        given each contact's slip direction ``signs`` and each finger's contacts ``masks``
        (:attr:`~.motion.ContactTips.masks`); None if no finger does.
        """
        if self.stick.all():
            return None
        for f, mine in enumerate(masks):
            if (mine.any() and not self.stick[mine].any()
                    and (np.all(signs[mine] > 0) or np.all(signs[mine] < 0))):
                return f
        return None
