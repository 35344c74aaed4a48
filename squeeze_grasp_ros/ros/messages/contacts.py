# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Contact states and events, and the tactile arrays of the fingertips."""
from __future__ import annotations

import array
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from std_msgs.msg import Header

from squeeze_grasp_interfaces.msg import (
    ContactEvent,
    ContactNode,
    ContactState,
    TactileArray,
)
from squeeze_grasp_ros.mechanics.squeeze import contact_state
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode
from squeeze_grasp_ros.ros.messages.common import float64_array, vector3

CONTACT_MODES: dict[ContactMode, int] = {ContactMode.STICK: ContactNode.STICK,
                                         ContactMode.SLIP: ContactNode.SLIP}
"""Mechanics contact mode -> ``ContactNode.mode`` (= ``ContactState.modes``) constant."""


# --------------------------------------------------------------------------- contact state


def contact_node_msg(node: contact_state.ContactNode) -> ContactNode:
    """A contact node of the stepper as ``ContactNode`` (polar angle rad, force N)."""
    return ContactNode(
        finger=node.finger,
        node=int(node.node),
        polar_angle=float(node.theta),
        mode=CONTACT_MODES[node.mode],
        force=vector3(node.force),
    )


def contact_state_msg(
    state: contact_state.ContactState, header: Header | None = None
) -> ContactState:
    """The contact set of a stepper state as ``ContactState`` (depth rho in m)."""
    return fill_contact_state(ContactState(header=header or Header()), state)


def fill_contact_state(msg: ContactState, state: contact_state.ContactState) -> ContactState:
    """Refill a ``ContactState`` in place with the contact set of a stepper state (its header
    stays).
    """
    contacts = state.contacts
    return fill_contact_arrays(
        msg,
        [c.finger for c in contacts],
        [int(c.node) for c in contacts],
        [float(c.theta) for c in contacts],
        [CONTACT_MODES[c.mode] for c in contacts],
        [float(c.force[0]) for c in contacts],
        [float(c.force[1]) for c in contacts],
        float(state.depth),
        float(state.relative_depth),
    )


def fill_contact_arrays(
    msg: ContactState,
    fingers: list[str],
    nodes: list[int],
    angles: list[float],
    modes: list[int],
    forces_x: list[float],
    forces_y: list[float],
    depth: float,
    relative_depth: float,
) -> ContactState:
    """Refill a ``ContactState`` in place with parallel per-contact lists (angles rad, forces
    N, depth m); its header stays.
    """
    msg.fingers = fingers
    msg.nodes = array.array("i", nodes)
    msg.polar_angles = array.array("d", angles)
    msg.modes = array.array("B", modes)
    msg.forces_x = array.array("d", forces_x)
    msg.forces_y = array.array("d", forces_y)
    msg.depth = depth
    msg.relative_depth = relative_depth
    return msg


def contact_records(msg: ContactState) -> list[dict]:
    """The contacts of a ``ContactState`` as JSON-able dicts (node, finger, mode, force N)."""
    return [
        {
            "node": int(n),
            "finger": f,
            "mode": ContactMode.STICK if m == ContactState.STICK else ContactMode.SLIP,
            "polar_angle": float(a),
            "force": [float(x), float(y)],
        }
        for f, n, a, m, x, y in zip(
            msg.fingers, msg.nodes, msg.polar_angles, msg.modes, msg.forces_x, msg.forces_y
        )
    ]


def contact_event_msg(event: contact_state.Event, header: Header | None = None) -> ContactEvent:
    """A located event (types A-D of Sec. 5.3) as ``ContactEvent`` (depth rho in m)."""
    return ContactEvent(
        header=header or Header(),
        type=event.type.value,
        node=int(event.node),
        finger=event.finger,
        depth=float(event.depth),
        relative_depth=float(event.relative_depth),
    )


# --------------------------------------------------------------------------- tactile arrays


@dataclass(frozen=True)
class TactileReadings:
    """One fingertip's tactile array as numpy arrays.

    Attributes
    ----------
    finger : str
        "F1", "F2" or "A".
    angles : (k,) ndarray
        Polar angle of each taxel on the fingertip, rad (see :mod:`.mechanics.fingertips`).
    normal : (k,) ndarray
        Normal force per taxel, N (> 0 pressing).
    tangential : (k,) ndarray
        Tangential force per taxel, N, positive counter-clockwise.
    """

    finger: str
    angles: np.ndarray
    normal: np.ndarray
    tangential: np.ndarray


def check_taxels(finger: str, *arrays: Sequence[float]) -> None:
    """Raise ValueError unless the tactile arrays of ``finger`` have one entry per taxel."""
    sizes = {len(a) for a in arrays}
    if len(sizes) != 1:
        raise ValueError(f"tactile arrays of {finger} differ in length: {sorted(sizes)}")


def tactile_array_msg(readings: TactileReadings, header: Header | None = None) -> TactileArray:
    """``TactileArray`` of a fingertip's readings; the three arrays must have one entry per taxel.

    Raises
    ------
    ValueError
        If the arrays differ in length.
    """
    check_taxels(readings.finger, readings.angles, readings.normal, readings.tangential)
    return TactileArray(
        header=header or Header(),
        finger=readings.finger,
        taxel_angles=float64_array(readings.angles),
        normal_forces=float64_array(readings.normal),
        tangential_forces=float64_array(readings.tangential),
    )




def tactile_readings(msg: TactileArray) -> TactileReadings:
    """The readings of a ``TactileArray`` as numpy arrays (inverse of
    :func:`tactile_array_msg`).
    """
    return TactileReadings(
        msg.finger,
        np.asarray(msg.taxel_angles, dtype=float),
        np.asarray(msg.normal_forces, dtype=float),
        np.asarray(msg.tangential_forces, dtype=float),
    )
