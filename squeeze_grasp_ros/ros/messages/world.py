# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated world's ground truth and its markers."""
from __future__ import annotations

import functools
from collections.abc import Sequence
from operator import attrgetter

import numpy as np
from geometry_msgs.msg import Point, Vector3
from visualization_msgs.msg import Marker, MarkerArray

from squeeze_grasp_interfaces.msg import (
    ContactEvent,
    ContactEventArray,
    ContactState,
    SimState,
)
from squeeze_grasp_ros.mechanics.squeeze import contact_state
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode
from squeeze_grasp_ros.ros.messages.cdr import (
    PLANAR_ORIGIN,
    CdrTemplate,
    CdrWriter,
    planar,
    refilled,
    write_contact_arrays,
    write_finger_vectors,
)
from squeeze_grasp_ros.ros.messages.common import float64_array, header, set_stamp, stamp_ns
from squeeze_grasp_ros.ros.messages.contacts import (
    CONTACT_MODES,
    contact_event_msg,
    fill_contact_state,
)
from squeeze_grasp_ros.sim.world import WorldView

# --------------------------------------------------------------------------- pipeline: ground trut


def sim_state_msg(
    state: contact_state.ContactState,
    fingers: Sequence[str],
    termination: str | None,
    ns: int,
    frame_id: str,
) -> SimState:
    """Ground truth of the simulated world as ``SimState`` (fingers without a tip: zeros)."""
    stamp_header = header(ns, frame_id)
    msg = SimState(header=stamp_header, fingers=list(fingers),
                   positions=[Point() for _ in fingers], forces=[Vector3() for _ in fingers],
                   contacts=ContactState(header=stamp_header))
    return fill_sim_state(msg, state, termination, ns)


def fill_sim_state(
    msg: SimState, state: contact_state.ContactState, termination: str | None, ns: int
) -> SimState:
    """Refill a :func:`sim_state_msg` in place with a new state at sim time ``ns`` (its
    fingers and frame stay).
    """
    present = {f.name: f for f in state.fingers}
    work = []
    for name, point, force in zip(msg.fingers, msg.positions, msg.forces):
        f = present.get(name)
        point.x, point.y = (float(f.center[0]), float(f.center[1])) if f else (0.0, 0.0)
        xy = state.finger_force(name)
        force.x, force.y = float(xy[0]), float(xy[1])
        work.append(f.work if f else 0.0)
    set_stamp(msg.header.stamp, ns)
    set_stamp(msg.contacts.header.stamp, ns)
    msg.work = float64_array(work)
    fill_contact_state(msg.contacts, state)
    msg.termination = termination or ""
    return msg


def sim_state_cdr(
    state: contact_state.ContactState,
    fingers: Sequence[str],
    termination: str | None,
    ns: int,
    frame_id: str,
) -> bytes:
    """:func:`sim_state_msg`'s message, serialised (:mod:`.cdr`): what the simulated hardware
    publishes every tick, without a Python message in between.
    """
    present = {f.name: f for f in state.fingers}
    contacts, arrays = state.contacts, state.arrays
    layout = tuple(map(_LAYOUT, contacts))
    forces, names = arrays.forces, arrays.fingers
    totals = [_SUM(forces[rows], axis=0) if rows is not None else PLANAR_ORIGIN
              for rows in _finger_rows(names, tuple(fingers))]
    values = (planar([present[f].center if f in present else PLANAR_ORIGIN for f in fingers]),
              planar(totals),
              [present[f].work if f in present else 0.0 for f in fingers],
              arrays.thetas, forces[:, 0], forces[:, 1],
              state.depth, state.relative_depth)

    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp, runs = write_finger_vectors(writer, ns, frame_id, fingers, values[:2], values[2])
        nested = write_contact_arrays(writer, ns, frame_id, names, [c.node for c in contacts],
                                      values[3], [CONTACT_MODES[c.mode] for c in contacts],
                                      values[4], values[5], values[6], values[7])
        writer.string(termination or "")
        return CdrTemplate(writer, (stamp, nested[0]), runs + nested[1])
    return refilled(("sim_state", frame_id, tuple(fingers), tuple(present), layout,
                     termination or ""), write, ns, values)


_LAYOUT = attrgetter("finger", "node", "mode")
"""A contact node's (finger, node, mode): the ground truth's layout key."""
_SUM = np.add.reduce
"""``ndarray.sum`` without its Python wrapper."""


@functools.lru_cache(maxsize=64)
def _finger_rows(names: tuple[str, ...], fingers: tuple[str, ...]) -> list[np.ndarray | None]:
    """Each finger's rows among contacts of fingers ``names`` (None: it has none)."""
    return [np.flatnonzero([name == f for name in names]) if f in names else None
            for f in fingers]


def sim_events_msg(
    events: Sequence[contact_state.Event],
    termination: str,
    state: contact_state.ContactState,
    ns: int,
) -> ContactEventArray:
    """The ground-truth events of one tick as ``ContactEventArray``; ``termination`` (e.g.
    "finger_slip", or "") is set at the tick the world ends, with the depth it ended at.
    """
    head = header(ns)
    return ContactEventArray(
        header=head,
        events=[contact_event_msg(e, head) for e in events],
        termination=termination,
        depth=float(state.depth) if termination else 0.0,
    )


def event_record(msg: ContactEvent) -> dict:
    """A ``ContactEvent`` as a JSON-able dict (stamp in ns)."""
    return {
        "stamp_ns": stamp_ns(msg.header.stamp),
        "type": msg.type,
        "node": int(msg.node),
        "finger": msg.finger,
        "depth": float(msg.depth),
        "relative_depth": float(msg.relative_depth),
    }


MARKER_COLOURS: dict[str, tuple[float, float, float]] = {
    "outline": (0.2, 0.4, 0.9),
    "tip": (0.5, 0.5, 0.5),
    ContactMode.STICK: (0.1, 0.75, 0.2),
    ContactMode.SLIP: (0.9, 0.2, 0.1),
    "force": (0.95, 0.7, 0.1),
}
"""RGB of the visualisation markers (contacts: sticking green, sliding red)."""


def _marker(
    ns: int,
    frame_id: str,
    namespace: str,
    ident: int,
    kind: int,
    colour: str,
    points: np.ndarray,
    width: float,
) -> Marker:
    r, g, b = MARKER_COLOURS[colour]
    m = Marker(header=header(ns, frame_id), ns=namespace, id=ident, type=kind, action=Marker.ADD)
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = width
    m.color.r, m.color.g, m.color.b, m.color.a = r, g, b, 1.0
    m.points = [Point(x=float(x), y=float(y)) for x, y in points]
    return m


def world_markers(
    view: WorldView, ns: int, frame_id: str, force_scale: float = 0.002
) -> MarkerArray:
    """``MarkerArray`` of the deformed outline, fingertip circles, contact nodes (sticking green,
    sliding red) and contact force arrows (``force_scale`` m per N), object frame.
    """
    markers = [
        _marker(
            ns,
            frame_id,
            "outline",
            0,
            Marker.LINE_STRIP,
            "outline",
            np.vstack([view.outline, view.outline[:1]]),
            0.0005,
        )
    ]
    circle = np.linspace(0.0, 2.0 * np.pi, 49)
    for k, (_, centre, radius) in enumerate(view.tips):
        pts = centre + radius * np.stack([np.cos(circle), np.sin(circle)], axis=1)
        markers.append(
            _marker(ns, frame_id, "fingertips", k, Marker.LINE_STRIP, "tip", pts, 0.0005)
        )
    for k, (_, point, mode, force) in enumerate(view.contacts):
        markers.append(
            _marker(ns, frame_id, "contacts", k, Marker.SPHERE, mode, np.zeros((0, 2)), 0.002)
        )
        markers[-1].pose.position.x, markers[-1].pose.position.y = float(point[0]), float(point[1])
        arrow = np.array([point - force_scale * np.asarray(force), point])
        markers.append(_marker(ns, frame_id, "forces", k, Marker.ARROW, "force", arrow, 0.0005))
    clear = Marker(header=header(ns, frame_id), action=Marker.DELETEALL)
    return MarkerArray(markers=[clear] + markers)
