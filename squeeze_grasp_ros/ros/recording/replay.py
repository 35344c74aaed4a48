# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Replay a recording's sensor topics into a fresh monitor, in lockstep on the recorded sim time.

The recording's readings (``devices/<device>/{pose,wrench,tactile}``, any writer: ours, ``ros2
bag record``, rosbags; MCAP or SQLite3) are grouped into ticks: by the recorded ``sim/tick``
messages when there are any (the exact readings of each tick), else by stamp. For each tick the
replayer publishes ``/clock``, the readings' recorded bytes unchanged and a ``sim/tick`` listing
them, and waits for the monitor's status of that tick before the next, so a run of the monitor
sees exactly what it saw live. The monitor's parameters come from the recording's
``custom_data`` (``monitor_parameters``, written by ``squeeze-grasp run``), else from
``config/monitor.yaml`` with the finger-device mapping read from the tactile arrays, plus
``overrides``. The replayed events are compared with the recorded ``monitor/events``.
"""
from __future__ import annotations

import re
import time
from collections.abc import Mapping
from typing import Any

import rclpy
import yaml
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.serialization import deserialize_message
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock

from squeeze_grasp_interfaces.msg import ContactEventArray, MonitorStatus, TactileArray, Tick

from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode
from squeeze_grasp_ros.ros.nodes.recorder import cdr_stamp_ns
from squeeze_grasp_ros.ros.run.options import config_parameters
from squeeze_grasp_ros.ros.recording.bag import BagContents, BagError, read_bag
from squeeze_grasp_ros.mechanics.vocabulary import Finger

READING = re.compile(r"^/?devices/([^/]+)/(pose|wrench|tactile)$")


def event_tuple(e: Any) -> tuple:
    """(stamp ns, type, finger, node, depth, relative depth) of a ``ContactEvent``."""
    return (messages.stamp_ns(e.header.stamp), e.type, e.finger, int(e.node), float(e.depth),
            float(e.relative_depth))


def recorded_events(bag: BagContents) -> list[tuple] | None:
    """The monitor events of a recording (None if it has no ``monitor/events`` topic)."""
    topic = "/" + pipeline.EVENTS
    if topic not in bag.types:
        return None
    return [event_tuple(e) for m in bag.messages if m.topic == topic
            for e in deserialize_message(m.data, ContactEventArray).events]


def ticks_of(bag: BagContents) -> list[tuple[int, list]]:
    """[(stamp ns, [reading messages])] in order: by recorded ticks, else by stamp."""
    readings = [m for m in bag.messages if READING.match(m.topic)]
    by_stamp: dict[int, list] = {}
    for m in readings:
        by_stamp.setdefault(cdr_stamp_ns(m.data), []).append(m)
    ticks = [m for m in bag.messages if m.topic == "/" + pipeline.TICK]
    if not ticks:
        return sorted(by_stamp.items())
    out = []
    for m in ticks:
        tick = deserialize_message(m.data, Tick)
        ns = messages.stamp_ns(tick.header.stamp)
        keys = set(tick.readings)
        out.append((ns, [r for r in by_stamp.get(ns, [])
                         if "/".join(READING.match(r.topic).groups()) in keys]))
    return out


def monitor_parameters(bag: BagContents) -> dict[str, Any]:
    """The monitor parameters of the recording, or defaults with the recorded devices."""
    if "monitor_parameters" in bag.custom_data:
        return yaml.safe_load(bag.custom_data["monitor_parameters"])
    params = config_parameters("monitor")
    fingers: dict[str, str] = {}
    devices = sorted({READING.match(m.topic).group(1) for m in bag.messages
                      if READING.match(m.topic)})
    for m in bag.messages:
        match = READING.match(m.topic)
        if match and match.group(2) == "tactile":
            fingers.setdefault(match.group(1), deserialize_message(m.data, TactileArray).finger)
    free = [f for f in Finger.values() if f not in fingers.values()]
    for device in devices:
        if device not in fingers:
            fingers[device] = free.pop(0)
    params["finger_devices"] = [f"{f}:{d}" for d, f in fingers.items()]
    streams = {READING.match(m.topic).group(2) for m in bag.messages if READING.match(m.topic)}
    params["streams"] = sorted(streams - {"pose"}) or [""]
    return params


class Replayer(Node):
    """Publishes the recorded ticks one at a time, each after the monitor's previous status."""

    def __init__(self, bag: BagContents, ticks: list[tuple[int, list]], **kwargs: Any) -> None:
        super().__init__("replayer", **kwargs)
        loop = pipeline.loop_qos(1000)
        self.ticks = ticks
        self.clock_pub = self.create_publisher(Clock, pipeline.CLOCK, loop)
        self.tick_pub = self.create_publisher(Tick, pipeline.TICK, loop)
        self.pubs = {topic: self.create_publisher(pipeline.message_type(bag.types[topic]),
                                                  topic, loop)
                     for topic in {m.topic for _, group in ticks for m in group}}
        prediction = [m for m in bag.messages if m.topic == "/" + pipeline.PREDICTION]
        if prediction:
            latched = self.create_publisher(ContactEventArray, pipeline.PREDICTION,
                                            pipeline.LATCHED)
            latched.publish(deserialize_message(prediction[-1].data, ContactEventArray))
        self.events: list[tuple] = []
        self.alarms: list[tuple] = []
        self.status_ns = -1
        self.next = 0
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
        keys = ["/".join(READING.match(m.topic).groups()) for m in group]
        self.tick_pub.publish(messages.tick_msg(self.next, ns, keys))
        self.next += 1

    @property
    def finished(self) -> bool:
        """True when the monitor answered the last tick."""
        return bool(self.ticks) and self.status_ns >= self.ticks[-1][0]


def replay(path: str, overrides: Mapping[str, Any] | None = None, timeout: float = 300.0) -> dict:
    """Replay the bag at ``path`` into a fresh monitor; the JSON-able comparison.

    Raises
    ------
    BagError
        If the bag has no readings.
    """
    t0 = time.perf_counter()
    bag = read_bag(path)
    ticks = ticks_of(bag)
    if not ticks:
        raise BagError(f"{path} has no devices/<device>/{{pose,wrench,tactile}} readings")
    params = {**monitor_parameters(bag), **dict(overrides or {}), "lockstep": True}
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    executor = EventsExecutor(context=context)
    monitor = MonitorNode(context=context,
                          parameter_overrides=[Parameter(k, value=v) for k, v in params.items()])
    replayer = Replayer(bag, ticks, context=context)
    try:
        for node in (monitor, replayer):
            executor.add_node(node)
        deadline = time.monotonic() + timeout
        while not replayer.finished:
            if time.monotonic() > deadline:
                raise TimeoutError(f"replay timed out after {timeout:.0f} s at tick "
                                   f"{replayer.next} of {len(ticks)}")
            executor.spin_once(0.05)
    finally:
        for node in (monitor, replayer):
            executor.remove_node(node)
            node.destroy_node()
        executor.shutdown()
        context.try_shutdown()
    recorded = recorded_events(bag)
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
