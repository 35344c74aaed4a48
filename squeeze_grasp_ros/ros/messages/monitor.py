# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor's outputs: tracked events, alarms, patches, status, the prediction."""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from geometry_msgs.msg import Point, Vector3

from squeeze_grasp_interfaces.msg import (
    Alarm,
    ContactEvent,
    ContactEventArray,
    ContactState,
    MonitorStatus,
)
from squeeze_grasp_ros.control.force_watch import PredictedForces
from squeeze_grasp_ros.control.tracker import (
    PredictedEvent,
    TrackedAlarm,
    TrackedEvent,
    TrackerOutput,
)
from squeeze_grasp_ros.mechanics.vocabulary import EventType, Finger
from squeeze_grasp_ros.ros.messages.cdr import (
    PLANAR_ORIGIN,
    CdrTemplate,
    CdrWriter,
    planar,
    refilled,
    write_contact_arrays,
    write_finger_vectors,
)
from squeeze_grasp_ros.ros.messages.common import float64_array, header, set_stamp
from squeeze_grasp_ros.ros.messages.contacts import CONTACT_MODES, fill_contact_arrays

# --------------------------------------------------------------------------- pipeline: monitor

UNSEEN_AGE = 1e300
"""s: the sensor age a ``MonitorStatus`` gives a finger the monitor has no reading of (the
tracker's infinite age, kept finite for the message)."""


def tracked_event_msg(event: TrackedEvent, ns: int) -> ContactEvent:
    """A monitor event as ``ContactEvent`` (node -1: taxel patches are not mesh nodes)."""
    return ContactEvent(
        header=header(ns),
        type=str(event.type),
        node=-1,
        finger=event.finger,
        depth=float(event.depth),
        relative_depth=float(event.relative_depth),
    )


def tracked_events_msg(out: TrackerOutput) -> ContactEventArray:
    """The events of one monitor tick as one ``ContactEventArray``."""
    return ContactEventArray(
        header=header(out.stamp_ns),
        events=[tracked_event_msg(e, out.stamp_ns) for e in out.events],
    )


def alarm_msg(alarm: TrackedAlarm, ns: int) -> Alarm:
    """A monitor alarm as ``Alarm``."""
    return Alarm(
        header=header(ns),
        type=alarm.type,
        finger=alarm.finger,
        value=float(alarm.value),
        message=alarm.message,
    )


def patches_state_msg(out: TrackerOutput, frame_id: str) -> ContactState:
    """The monitor's reconstructed contact patches as ``ContactState`` (node = -1, polar angle
    = the patch's mean taxel angle, force = the patch force on the object, N).
    """
    return fill_patches_state(ContactState(header=header(out.stamp_ns, frame_id)), out)


def fill_patches_state(msg: ContactState, out: TrackerOutput) -> ContactState:
    """Refill a :func:`patches_state_msg` in place with the patches of a new tick (its frame
    stays).
    """
    patches = out.patches
    trig = [(math.cos(p.angle), math.sin(p.angle)) for p in patches]
    set_stamp(msg.header.stamp, out.stamp_ns)
    return fill_contact_arrays(
        msg,
        [p.finger for p in patches],
        [-1] * len(patches),
        [p.angle for p in patches],
        [CONTACT_MODES[p.mode] for p in patches],
        [p.normal * c - p.tangential * s for p, (c, s) in zip(patches, trig)],
        [p.normal * s + p.tangential * c for p, (c, s) in zip(patches, trig)],
        out.depth,
        out.relative_depth,
    )


def monitor_status_msg(out: TrackerOutput, frame_id: str) -> MonitorStatus:
    """The monitor's per-tick ``MonitorStatus`` (fingers without a pose report the origin)."""
    msg = MonitorStatus(header=header(out.stamp_ns, frame_id), fingers=list(out.fingers),
                        positions=[Point() for _ in out.fingers],
                        forces=[Vector3() for _ in out.fingers],
                        normals=[Vector3() for _ in out.fingers])
    return fill_monitor_status(msg, out)


def fill_monitor_status(msg: MonitorStatus, out: TrackerOutput) -> MonitorStatus:
    """Refill a :func:`monitor_status_msg` in place with a new tick of the same fingers (its
    frame stays).
    """
    set_stamp(msg.header.stamp, out.stamp_ns)
    for f, point, force, normal in zip(out.fingers, msg.positions, msg.forces, msg.normals):
        xy = out.positions.get(f)
        point.x, point.y = (float(xy[0]), float(xy[1])) if xy is not None else (0.0, 0.0)
        force.x, force.y = float(out.forces[f][0]), float(out.forces[f][1])
        normal.x, normal.y = float(out.normals[f][0]), float(out.normals[f][1])
    msg.sensor_age = float64_array([min(out.ages[f], UNSEEN_AGE) for f in out.fingers])
    msg.depth = out.depth
    msg.relative_depth = out.relative_depth
    msg.events = [tracked_event_msg(e, out.stamp_ns) for e in out.events]
    msg.alarms = [alarm_msg(a, out.stamp_ns) for a in out.alarms]
    return msg


def patches_state_cdr(out: TrackerOutput, frame_id: str) -> bytes:
    """:func:`patches_state_msg`'s message, serialised (:mod:`.cdr`)."""
    patches = out.patches
    trig = [(math.cos(p.angle), math.sin(p.angle)) for p in patches]
    values = ([p.angle for p in patches],
              [p.normal * c - p.tangential * s for p, (c, s) in zip(patches, trig)],
              [p.normal * s + p.tangential * c for p, (c, s) in zip(patches, trig)],
              out.depth, out.relative_depth)

    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp, runs = write_contact_arrays(
            writer, out.stamp_ns, frame_id, [p.finger for p in patches], [-1] * len(patches),
            values[0], [CONTACT_MODES[p.mode] for p in patches], *values[1:])
        return CdrTemplate(writer, (stamp,), runs)
    return refilled(("patches", frame_id, *((p.finger, p.mode) for p in patches)), write,
                    out.stamp_ns, values)


def monitor_status_cdr(out: TrackerOutput, frame_id: str) -> bytes:
    """:func:`monitor_status_msg`'s message, serialised (:mod:`.cdr`): what the monitor
    publishes every tick.
    """
    ns, fingers = out.stamp_ns, out.fingers
    positions, forces, normals = out.positions, out.forces, out.normals
    values = (planar([positions.get(f, PLANAR_ORIGIN) for f in fingers]),
              planar([forces[f] for f in fingers]), planar([normals[f] for f in fingers]),
              [min(out.ages[f], UNSEEN_AGE) for f in fingers], out.depth, out.relative_depth)

    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp, runs = write_finger_vectors(writer, ns, frame_id, fingers, values[:3], values[3])
        runs += [(writer.float64(out.depth), 1), (writer.float64(out.relative_depth), 1)]
        writer.uint32(len(out.events))
        for event in out.events:
            writer.header(ns)
            writer.string(str(event.type))
            writer.int32(-1)
            writer.string(event.finger)
            writer.float64(event.depth)
            writer.float64(event.relative_depth)
        writer.uint32(len(out.alarms))
        for alarm in out.alarms:
            writer.header(ns)
            writer.string(alarm.type)
            writer.string(alarm.finger)
            writer.float64(alarm.value)
            writer.string(alarm.message)
        return CdrTemplate(writer, (stamp,), runs)
    if out.events or out.alarms:
        return bytes(write().buffer)
    return refilled(("status", frame_id, *fingers), write, ns, values)


def force_residual_cdr(ns: int, frame_id: str, depth: float, fingers: Sequence[str],
                       measured: Sequence[float], predicted: Sequence[float],
                       relative_error: Sequence[float], tolerance: float) -> bytes:
    """A ``squeeze_grasp_interfaces/ForceResidual`` (depth m, forces N, per finger in
    ``fingers``' order), serialised (:mod:`.cdr`): the force watch's message of a tick.
    """
    values = (depth, measured, predicted, relative_error, tolerance)

    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp = writer.header(ns, frame_id)
        runs = [(writer.float64(depth), 1)]
        writer.strings(fingers)
        runs += [(writer.sequence(v), len(fingers)) for v in values[1:4]]
        runs.append((writer.float64(tolerance), 1))
        return CdrTemplate(writer, (stamp,), runs)
    return refilled(("residual", frame_id, *fingers), write, ns, values)


def prediction_msg(
    events: Sequence[ContactEvent], termination: str, depth: float,
    forces: PredictedForces | None = None,
) -> ContactEventArray:
    """The planner's predicted events as ``ContactEventArray``, with its force curve
    (``forces``) for the monitor's force watch.
    """
    msg = ContactEventArray(events=list(events), termination=termination, depth=float(depth))
    if forces is not None:
        msg.force_depths = float64_array(forces.depths)
        msg.force_f1 = float64_array(forces.forces[Finger.F1])
        msg.force_f2 = float64_array(forces.forces[Finger.F2])
    return msg


def force_curve(depths: Sequence[float], f1: Sequence[float],
                f2: Sequence[float]) -> PredictedForces | None:
    """A force curve from message arrays (m; N, N), None when it has fewer than two points."""
    if len(depths) < 2:
        return None
    return PredictedForces(np.asarray(depths, float), {Finger.F1: np.asarray(f1, float),
                                                       Finger.F2: np.asarray(f2, float)})


def predicted_forces(msg: ContactEventArray) -> PredictedForces | None:
    """The force curve of a prediction (None when it has none)."""
    return force_curve(msg.force_depths, msg.force_f1, msg.force_f2)


def predicted_events(msg: ContactEventArray) -> list[PredictedEvent]:
    """The A-D events of a prediction for the tracker."""
    return [PredictedEvent(EventType(e.type), Finger(e.finger), float(e.depth))
            for e in msg.events]
