# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor under garbage and floods of device readings, on real rclpy and the
``EventsExecutor`` that ``ros2 run`` spins it with: readings the tracker cannot take are refused
(the finger goes stale), readings under stamps no tick closes are bounded, and the monitor
answers the next good tick.
"""
from __future__ import annotations

import math
import time

import pytest
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter

from squeeze_grasp_interfaces.msg import MonitorStatus, TactileArray, Tick
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes.monitor import PENDING_STAMPS, MonitorNode

DEVICES = {"F1": "barrett_f1", "F2": "barrett_f3"}
STREAMS = {"pose": PoseStamped, "wrench": WrenchStamped, "tactile": TactileArray}


class Rig:
    """A monitor (default parameters but ``parameters``) and a peer node publishing its
    readings and ticks and taking its status, on one ``EventsExecutor``: an exception in a
    monitor callback leaves :meth:`until` as it leaves ``ros2 run``'s spin.
    """

    def __init__(self, context, **parameters) -> None:
        self.spinner = EventsExecutor(context=context)
        self.monitor = MonitorNode(context=context, parameter_overrides=[
            Parameter(name, value=value) for name, value in parameters.items()])
        self.peer = Node("abuser", context=context)
        qos = pipeline.loop_qos(100)
        self.pubs = {(finger, stream): self.peer.create_publisher(
            msg_type, pipeline.device_topic(device, stream), qos)
            for finger, device in DEVICES.items() for stream, msg_type in STREAMS.items()}
        self.tick_pub = self.peer.create_publisher(Tick, pipeline.TICK, qos)
        self.statuses: list[MonitorStatus] = []
        self.peer.create_subscription(MonitorStatus, pipeline.STATUS, self.statuses.append,
                                      pipeline.loop_qos(100, kept=True))
        for node in (self.monitor, self.peer):
            self.spinner.add_node(node)
        assert self.until(lambda: all(p.get_subscription_count() for p in self.pubs.values())
                          and self.monitor.count_publishers(pipeline.TICK) > 0)

    def until(self, done, seconds: float = 30.0) -> bool:
        deadline = time.monotonic() + seconds
        while not done() and time.monotonic() < deadline:
            self.spinner.spin_once(timeout_sec=0.05)
        return done()

    def publish(self, finger: str, stream: str, ns: int, **fields) -> None:
        """A reading of ``finger``'s ``stream`` stamped ``ns`` with message ``fields`` (a
        pose's ``x``, a wrench's ``force`` (x, y, z), a tactile array's three lists).
        """
        msg = STREAMS[stream]()
        messages.set_stamp(msg.header.stamp, ns)
        if stream == "pose":
            msg.pose.position.x = fields.get("x", 0.0)
        elif stream == "wrench":
            msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z = fields.get(
                "force", (0.0, 0.0, 0.0))
        else:
            msg.finger = finger
            for name in ("taxel_angles", "normal_forces", "tangential_forces"):
                setattr(msg, name, fields.get(name, [0.0, 0.1, 0.2]))
        self.pubs[finger, stream].publish(msg)

    def publish_good(self, ns: int) -> list[str]:
        """Good readings of every finger and stream stamped ``ns``; return their names."""
        for k, finger in enumerate(DEVICES):
            self.publish(finger, "pose", ns, x=(-0.05, 0.05)[k])
            self.publish(finger, "wrench", ns)
            self.publish(finger, "tactile", ns)
        return [f"{device}/{stream}" for device in DEVICES.values() for stream in STREAMS]

    def tick(self, ns: int, readings: list[str]) -> None:
        msg = Tick(index=ns // 1_000_000, readings=readings)
        messages.set_stamp(msg.header.stamp, ns)
        self.tick_pub.publish(msg)

    def close(self) -> None:
        self.spinner.shutdown()
        self.monitor.destroy_node()
        self.peer.destroy_node()


@pytest.fixture
def rig(ros_context):
    rig = Rig(ros_context)
    yield rig
    rig.close()


BAD = {
    "an empty tactile array": ("tactile", {"taxel_angles": [], "normal_forces": [],
                                           "tangential_forces": []}),
    "a ragged tactile array": ("tactile", {"normal_forces": [1.0] * 5, "tangential_forces": []}),
    "NaN taxel forces": ("tactile", {"normal_forces": [math.nan, 1.0, 1.0]}),
    "an infinite wrench": ("wrench", {"force": (math.nan, math.inf, 0.0)}),
    "a NaN pose": ("pose", {"x": math.nan}),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_reading_the_tracker_cannot_take_is_refused_and_the_tick_answered(rig, case):
    """Tick 1 with a bad reading of one stream (both fingers) and good ones of the others: the
    bad ones are refused, so the tick waits; the good readings of that stream close it, and
    the status holds them. Before, the tick closed on the bad readings: an empty or ragged
    ``TactileArray`` ended the monitor with "ValueError: not enough values to unpack (expected
    2, got 0)" (IndexError when ragged), and NaN readings came out in the status.
    """
    stream, fields = BAD[case]
    ns = 1_000_000
    for k, finger in enumerate(DEVICES):
        for other in STREAMS:
            if other != stream:
                rig.publish(finger, other, ns, x=(-0.05, 0.05)[k])
        rig.publish(finger, stream, ns, **fields)
    rig.tick(ns, [f"{device}/{name}" for device in DEVICES.values() for name in STREAMS])
    assert not rig.until(lambda: bool(rig.statuses), 1.0), \
        f"the tick closed on the bad readings: {rig.statuses[-1]}"
    for k, finger in enumerate(DEVICES):
        rig.publish(finger, stream, ns, x=(-0.05, 0.05)[k])
    assert rig.until(lambda: rig.statuses), "the monitor never answered the good tick"
    status = rig.statuses[-1]
    assert messages.stamp_ns(status.header.stamp) == ns
    assert [p.x for p in status.positions] == [-0.05, 0.05]
    assert all(math.isfinite(v.x) and math.isfinite(v.y) for v in status.forces)


def test_readings_under_stamps_no_tick_closes_are_bounded(rig):
    """5,000 wrench readings under stamps of their own: at most ``PENDING_STAMPS`` of them wait
    (before, every one was kept: 10 kHz of them grew the process by 380 MB in 40 s), the
    ones after tick 1 are dropped when it closes, and tick 1 is answered.
    """
    start = 10**12
    for k in range(5000):
        rig.publish(("F1", "F2")[k % 2], "wrench", start + k)
    rig.until(lambda: len(rig.monitor.buffer) >= PENDING_STAMPS, 10.0)
    rig.until(lambda: False, 1.0)  # the rest of the flood is taken
    assert len(rig.monitor.buffer) <= PENDING_STAMPS
    ns = 1_000_000
    rig.publish("F1", "wrench", ns // 2)  # between ticks: dropped when tick 1 closes
    rig.tick(ns, rig.publish_good(ns))
    assert rig.until(lambda: rig.statuses), "the monitor never answered tick 1"
    assert messages.stamp_ns(rig.statuses[-1].header.stamp) == ns
    assert min(rig.monitor.buffer) > ns


def test_a_hardware_reading_stamped_ahead_of_the_clock_is_refused(ros_context):
    """Hardware mode: readings stamped one hour ahead of the monitor's clock, then silence.
    Before, they counted as fresh until their stamp (``sensor_age`` -3598 s two seconds
    later, no ``stale_sensor``), so a driver with a clock ahead that stopped kept the executor
    squeezing; now they are refused and the fingers are stale.
    """
    rig = Rig(ros_context, lockstep=False, rate=100.0, stale_after=0.1, use_sim_time=False)
    try:
        ahead = rig.peer.get_clock().now().nanoseconds + 3600 * 10**9
        rig.publish_good(ahead)
        rig.until(lambda: False, 0.5)
        assert rig.until(lambda: bool(rig.statuses))
        status = rig.statuses[-1]
        assert all(age >= 0.0 for age in status.sensor_age), list(status.sensor_age)
        assert {(a.type, a.finger) for a in status.alarms} >= {("stale_sensor", "F1"),
                                                               ("stale_sensor", "F2")}
    finally:
        rig.close()
