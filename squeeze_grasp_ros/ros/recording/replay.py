# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Replay a recording's sensor topics into a fresh monitor, in lockstep on the recorded sim time.

The recording's readings (``devices/<device>/{pose,wrench,tactile}`` and a gripper's
``joint_states``; any writer: ours, ``ros2 bag record``, rosbags; MCAP or SQLite3) are grouped
into ticks: by the recorded ``sim/tick`` messages when there are any (the exact readings of each
tick), else by stamp. For each tick the replayer publishes ``/clock``, the readings' recorded
bytes unchanged and a ``sim/tick`` listing them, and waits for the monitor's status of that tick
before the next, so a run of the monitor sees exactly what it saw live. The monitor's
parameters come from the recording's ``custom_data`` (``monitor_parameters``, written by
``squeeze-grasp run``), else from ``config/monitor.yaml`` with the finger-device mapping read
from the tactile arrays, plus ``overrides``. The replayed events are compared with the recorded
``monitor/events``.
"""
from __future__ import annotations

import re
import time
from collections.abc import Mapping
from typing import Any

import rclpy
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.serialization import deserialize_message
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from squeeze_grasp_interfaces.msg import ContactEventArray, MonitorStatus, TactileArray, Tick
from squeeze_grasp_ros.inputs import InputError, load_yaml, shown
from squeeze_grasp_ros.mechanics.vocabulary import Finger
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.cdr import cdr_stamp_ns
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline
from squeeze_grasp_ros.ros.nodes.monitor import PARAMETERS as MONITOR_PARAMETERS
from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode
from squeeze_grasp_ros.ros.nodes.sim_controllers import JOINT_STATES
from squeeze_grasp_ros.ros.recording.bag import BagContents, BagError, read_bag
from squeeze_grasp_ros.ros.run.options import config_parameters

READING = re.compile(r"^/?(?:devices/([^/]+)/(pose|wrench|tactile)|(joint_states))$")
READING_TYPES: dict[str, tuple[str, type]] = {
    "pose": ("geometry_msgs/msg/PoseStamped", PoseStamped),
    "wrench": ("geometry_msgs/msg/WrenchStamped", WrenchStamped),
    "tactile": ("squeeze_grasp_interfaces/msg/TactileArray", TactileArray),
    JOINT_STATES: ("sensor_msgs/msg/JointState", JointState),
}
"""Stream -> (type name, class) of the readings replay publishes: fixed here, never imported
by a name read from a recording (a crafted recording made replay import any module)."""
TICK_TIMEOUT = 10.0
"""Wall-clock seconds replay waits for the monitor's answer to one tick before giving up."""


def reading_of(topic: str) -> tuple[str, str, str] | None:
    """(device, stream, the key a ``sim/tick`` lists) of a reading's topic, else None: a
    device's ``pose``/``wrench``/``tactile`` ("barrett_f1/pose"), or a simulated controller's
    ``joint_states`` (no device; key "joint_states").
    """
    match = READING.match(topic)
    if match is None:
        return None
    if match.group(3):
        return "", JOINT_STATES, JOINT_STATES
    return match.group(1), match.group(2), f"{match.group(1)}/{match.group(2)}"


def event_tuple(e: Any) -> tuple:
    """(stamp ns, type, finger, node, depth, relative depth) of a ``ContactEvent``."""
    return (messages.stamp_ns(e.header.stamp), e.type, e.finger, int(e.node), float(e.depth),
            float(e.relative_depth))


EVENTS_TYPE = "squeeze_grasp_interfaces/msg/ContactEventArray"
TICK_TYPE = "squeeze_grasp_interfaces/msg/Tick"


def decoded(m: Any, type_name: str, cls: type, verb: str = "reads") -> Any:
    """The recorded message ``m`` decoded as ``cls``, whose type name is ``type_name``.

    Raises
    ------
    BagError
        The recording declares another type for the topic, or the bytes do not decode: one
        line naming the topic and the time.
    """
    if m.type != type_name:
        raise BagError(f"{m.topic} has type {m.type[:80]!r} in the recording; replay {verb} it "
                       f"as {type_name}")
    try:
        return deserialize_message(m.data, cls)
    except Exception as exc:  # noqa: BLE001 (rclpy raises RMWError and others)
        raise BagError(
            f"the message on {m.topic} logged at {m.log_time_ns * 1e-9:.6f} s does not "
            f"decode as {type_name} ({type(exc).__name__}); the recording is corrupt"
        ) from None


def recorded_events(bag: BagContents) -> list[tuple] | None:
    """The monitor events of a recording (None if it has no ``monitor/events`` topic).

    Raises
    ------
    BagError
        A message of the topic is not a ``ContactEventArray`` (:func:`decoded`).
    """
    topic = "/" + pipeline.EVENTS
    if topic not in bag.types:
        return None
    return [event_tuple(e) for m in bag.messages if m.topic == topic
            for e in decoded(m, EVENTS_TYPE, ContactEventArray).events]


def checked_readings(bag: BagContents) -> list:
    """The reading messages of a recording, each checked: its topic's type is the one replay
    publishes for that stream, and it decodes as that type.

    Raises
    ------
    BagError
        Naming the topic, the stamp and what is wrong (a recording is data from elsewhere: one
        corrupt message used to stall replay until its timeout).
    """
    readings = []
    for m in bag.messages:
        reading = reading_of(m.topic)
        if reading is None:
            continue
        decoded(m, *READING_TYPES[reading[1]], verb="publishes")
        readings.append(m)
    return readings


def ticks_of(bag: BagContents) -> list[tuple[int, list]]:
    """[(stamp ns, [reading messages])] in order: by recorded ticks, else by stamp.

    A tick and a reading count once per stamp (and topic): a lost tick is re-sent with its
    stamp and its readings, and a recorder outside the lockstep (``ros2 bag record``) keeps
    both copies, where the pipeline's recorder drops the second.
    """
    readings = checked_readings(bag)
    by_stamp: dict[int, list] = {}
    seen: set[tuple[str, int]] = set()
    for m in readings:
        ns = cdr_stamp_ns(m.data)
        if (m.topic, ns) not in seen:
            seen.add((m.topic, ns))
            by_stamp.setdefault(ns, []).append(m)
    ticks = [m for m in bag.messages if m.topic == "/" + pipeline.TICK]
    if not ticks:
        return sorted(by_stamp.items())
    out = []
    stamps: set[int] = set()
    for m in ticks:
        tick = decoded(m, TICK_TYPE, Tick)
        ns = messages.stamp_ns(tick.header.stamp)
        if ns in stamps:
            continue
        stamps.add(ns)
        keys = set(tick.readings)
        out.append((ns, [r for r in by_stamp.get(ns, [])
                         if reading_of(r.topic)[2] in keys]))
    return out


def monitor_parameters(bag: BagContents) -> dict[str, Any]:
    """The monitor parameters of the recording, or defaults with the recorded devices."""
    if "monitor_parameters" in bag.custom_data:
        try:
            params = load_yaml(str(bag.custom_data["monitor_parameters"]),
                               what="custom_data.monitor_parameters")
        except InputError as exc:
            raise BagError(str(exc)) from None
        if not isinstance(params, dict):
            raise BagError("custom_data.monitor_parameters of the recording is not a mapping")
        return params
    params = config_parameters("monitor")
    fingers: dict[str, str] = {}
    readings = [(m, reading_of(m.topic)) for m in bag.messages]
    readings = [(m, r) for m, r in readings if r is not None and r[0]]
    devices = sorted({r[0] for _, r in readings})
    for m, (device, stream, _) in readings:
        if stream == "tactile":
            fingers.setdefault(device, deserialize_message(m.data, TactileArray).finger)
    free = [f for f in Finger.values() if f not in fingers.values()]
    for device in devices:
        if device not in fingers:
            fingers[device] = free.pop(0)
    params["finger_devices"] = [f"{f}:{d}" for d, f in fingers.items()]
    streams = {r[1] for _, r in readings}
    params["streams"] = sorted(streams - {"pose"}) or [""]
    return params


def monitor_overrides(params: Mapping[str, Any],
                      given: Mapping[str, Any]) -> list[Parameter]:
    """The replay monitor's parameters as ROS parameters, their names and values checked
    before any node exists (the monitor refuses a value of another type than its parameter's
    as it declares it, :func:`~..nodes.pipeline.declare`).

    Parameters
    ----------
    params : mapping
        Every parameter: the recording's (or the defaults), ``given`` and ``lockstep``.
    given : mapping
        The ones given by name (``--param``): each must be one the monitor declares.

    Raises
    ------
    ParameterError
        One line naming the parameter: a given name the monitor does not have, or a value no
        ROS parameter holds.
    """
    for name in given:
        if name not in MONITOR_PARAMETERS and name != "use_sim_time":
            raise ParameterError(f"--param {name[:80]}: the monitor has no such parameter (its "
                                 "parameters: config/monitor.yaml)")
    out = []
    for name, value in params.items():
        try:
            parameter = Parameter(name, value=value)
        except TypeError:
            raise ParameterError(
                f"parameter '{name[:80]}' must be true or false, an integer, a number, a "
                f"string or a list of one of them, got {shown(str(value))}") from None
        out.append(parameter)
    return out


def recorded_prediction(bag: BagContents) -> Any:
    """The last ``planner/predicted_events`` message of a recording, decoded, or None.

    Raises
    ------
    BagError
        It is not a ``ContactEventArray`` (:func:`decoded`).
    """
    prediction = [m for m in bag.messages if m.topic == "/" + pipeline.PREDICTION]
    return decoded(prediction[-1], EVENTS_TYPE, ContactEventArray) if prediction else None


class Replayer(Node):
    """Publishes the recorded ticks one at a time, each after the monitor's previous status."""

    def __init__(self, prediction: Any, ticks: list[tuple[int, list]], **kwargs: Any) -> None:
        """``prediction``: the recording's last ``planner/predicted_events``
        (:func:`recorded_prediction`), latched for the monitor, or None.
        """
        super().__init__("replayer", **kwargs)
        loop = pipeline.loop_qos(1000)
        self.ticks = ticks
        self.clock_pub = self.create_publisher(Clock, pipeline.CLOCK, loop)
        self.tick_pub = self.create_publisher(Tick, pipeline.TICK, loop)
        self.pubs = {topic: self.create_publisher(
                         READING_TYPES[reading_of(topic)[1]][1], topic, loop)
                     for topic in {m.topic for _, group in ticks for m in group}}
        if prediction is not None:
            latched = self.create_publisher(ContactEventArray, pipeline.PREDICTION,
                                            pipeline.LATCHED)
            latched.publish(prediction)
        self.events: list[tuple] = []
        self.alarms: list[tuple] = []
        self.status_ns = -1
        self.next = 0
        self.published = time.monotonic()
        """Wall-clock time the last tick was published."""
        self.create_subscription(MonitorStatus, pipeline.STATUS, self._status, loop)
        self.handshake = pipeline.Handshake(self, ["monitor"], 0.05, self._publish_next)

    def _status(self, msg: MonitorStatus) -> None:
        ns = messages.stamp_ns(msg.header.stamp)
        if ns <= self.status_ns:
            return
        self.status_ns = ns
        self.events += [event_tuple(e) for e in msg.events]
        self.alarms += [(ns, a.type, a.finger) for a in msg.alarms]
        self._publish_next()

    def _publish_next(self) -> None:
        if self.next >= len(self.ticks):
            return
        ns, group = self.ticks[self.next]
        self.clock_pub.publish(messages.clock_msg(ns))
        for m in group:
            self.pubs[m.topic].publish(m.data)
        keys = [reading_of(m.topic)[2] for m in group]
        self.tick_pub.publish(messages.tick_msg(self.next, ns, keys))
        self.next += 1
        self.published = time.monotonic()

    @property
    def finished(self) -> bool:
        """True when the monitor answered the last tick."""
        return bool(self.ticks) and self.status_ns >= self.ticks[-1][0]


def replay(path: str, overrides: Mapping[str, Any] | None = None, timeout: float = 300.0) -> dict:
    """Replay the bag at ``path`` into a fresh monitor; the JSON-able comparison.

    Raises
    ------
    BagError
        If the bag has no readings, or a message replay reads is of another type or does not
        decode (checked before any node starts).
    ParameterError
        A parameter the monitor does not have or refuses (:func:`monitor_overrides`, then the
        monitor as it starts).
    """
    t0 = time.perf_counter()
    bag = read_bag(path)
    ticks = ticks_of(bag)
    if not ticks:
        raise BagError(f"{path} has no devices/<device>/{{pose,wrench,tactile}} readings")
    params = {**monitor_parameters(bag), **dict(overrides or {}), "lockstep": True}
    parameters = monitor_overrides(params, overrides or {})
    recorded, prediction = recorded_events(bag), recorded_prediction(bag)
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    executor = EventsExecutor(context=context)
    nodes: list[Node] = []
    try:
        nodes.append(MonitorNode(context=context, parameter_overrides=parameters))
        replayer = Replayer(prediction, ticks, context=context)
        nodes.append(replayer)
        for node in nodes:
            executor.add_node(node)
        deadline = time.monotonic() + timeout
        while not replayer.finished:
            if time.monotonic() > deadline:
                raise TimeoutError(f"replay timed out after {timeout:.0f} s at tick "
                                   f"{replayer.next} of {len(ticks)}")
            if replayer.next and time.monotonic() > replayer.published + TICK_TIMEOUT:
                raise TimeoutError(f"the monitor did not answer tick {replayer.next - 1} of "
                                   f"{len(ticks)} (t = {ticks[replayer.next - 1][0] * 1e-9:.6f} "
                                   f"s) within {TICK_TIMEOUT:.0f} s")
            executor.spin_once(0.05)
    finally:
        for node in nodes:
            executor.remove_node(node)
            node.destroy_node()
        executor.shutdown()
        context.try_shutdown()
    keys = ("stamp_ns", "type", "finger", "node", "depth", "relative_depth")
    return {
        "bag": str(path),
        "ticks": len(ticks),
        "topics": sorted(bag.types),
        "events": [dict(zip(keys, e)) for e in replayer.events],
        "recorded_events": None if recorded is None else [dict(zip(keys, e)) for e in recorded],
        "reproduced": None if recorded is None else recorded == replayer.events,
        "alarms": len(replayer.alarms),
        "monitor_parameters": params,
        "seconds": time.perf_counter() - t0,
    }
