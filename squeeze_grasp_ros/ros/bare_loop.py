# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The floor of a lockstep loop on rclpy: the pipeline's message graph with no work in it.

:func:`bare_loop_rate` runs three nodes and a client on one executor, in the pipeline's shape
(``squeeze-grasp run`` without recording, two devices with every sensor):

- ``sim`` publishes tick t: a clock (to ``monitor`` and ``executor``), three readings per
  device and a tick (to ``monitor``), a state (to the client): 9 messages, 10 deliveries;
- ``monitor``, once it has the tick and all six readings of t, publishes a state (no
  subscriber) and a status (to ``executor``): 2 messages, 1 delivery;
- ``executor``, on the status of t, publishes one setpoint per device (to ``sim``): 2
  messages, 2 deliveries;
- ``sim``, once it has both setpoints, publishes tick t + 1.

Every message is a ``std_msgs/Header`` whose stamp is the tick, on the pipeline's reliable
loop QoS. The same 13 messages per tick as the pipeline, the same executor, and nothing else:
no mechanics, no tracker, no program, no message payload. Its 13 deliveries are two more than
the pipeline's since the monitor and the executor stopped taking ``/clock`` in lockstep; with
``clock_deliveries=False`` the loop drops those two as well (11 deliveries, the pipeline's
count now), with them it stays the yardstick issue 33 set.

The main thread waits as ``squeeze-grasp run``'s loop does (``PipelineRunner.wait``): on
``EventsExecutor`` one ``spin_until_future_complete`` a tick, completed by the client's state
of the tick (or the last tick's setpoints); on ``SingleThreadedExecutor`` one ``spin_once`` an
event. Spinning once an event on ``EventsExecutor`` costs the bare loop about a quarter of its
rate, so a yardstick spun that way would flatter a pipeline spun once a tick.
"""
from __future__ import annotations

import time
from collections.abc import Callable

import rclpy
from rclpy.context import Context
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future
from std_msgs.msg import Header

from squeeze_grasp_ros.ros.nodes.pipeline import loop_qos
from squeeze_grasp_ros.ros.run.runner import WAKE_PERIOD

__all__ = ["DEVICES", "READINGS", "bare_loop_rate"]

DEVICES = ("f1", "f2")
READINGS = ("pose", "wrench", "tactile")


def _header(tick: int) -> Header:
    msg = Header()
    msg.stamp.sec, msg.stamp.nanosec = divmod(tick, 1_000_000_000)
    return msg


def _tick(msg: Header) -> int:
    return msg.stamp.sec * 1_000_000_000 + msg.stamp.nanosec


class _Sim:
    def __init__(self, node: Node, ticks: int, finished: Callable[[], None]) -> None:
        qos = loop_qos(10)
        self.ticks, self.tick, self.pending, self.finished = ticks, 0, set(), finished
        self.pubs = [node.create_publisher(Header, "clock", qos)]
        self.pubs += [node.create_publisher(Header, f"{d}/{r}", qos)
                      for d in DEVICES for r in READINGS]
        self.pubs += [node.create_publisher(Header, "state", qos),
                      node.create_publisher(Header, "tick", qos)]
        for d in DEVICES:
            node.create_subscription(Header, f"{d}/setpoint",
                                     lambda msg, d=d: self._setpoint(d, msg), qos)

    def publish(self) -> None:
        msg = _header(self.tick)
        for pub in self.pubs:
            pub.publish(msg)

    def _setpoint(self, device: str, msg: Header) -> None:
        if _tick(msg) != self.tick + 1:
            return
        self.pending.add(device)
        if len(self.pending) == len(DEVICES):
            self.pending = set()
            self.tick += 1
            if self.tick < self.ticks:
                self.publish()
            else:
                self.finished()


class _Monitor:
    def __init__(self, node: Node, clock: bool) -> None:
        qos = loop_qos(10)
        self.received: dict[int, int] = {}
        if clock:
            node.create_subscription(Header, "clock", lambda _: None, qos)
        for topic in [f"{d}/{r}" for d in DEVICES for r in READINGS] + ["tick"]:
            node.create_subscription(Header, topic, self._reading, qos)
        self.pubs = [node.create_publisher(Header, "contact_state", qos),
                     node.create_publisher(Header, "status", qos)]

    def _reading(self, msg: Header) -> None:
        tick = _tick(msg)
        self.received[tick] = self.received.get(tick, 0) + 1
        if self.received[tick] == len(DEVICES) * len(READINGS) + 1:
            del self.received[tick]
            for pub in self.pubs:
                pub.publish(msg)


class _Executor:
    def __init__(self, node: Node, clock: bool) -> None:
        qos = loop_qos(10)
        if clock:
            node.create_subscription(Header, "clock", lambda _: None, qos)
        node.create_subscription(Header, "status", self._status, qos)
        self.pubs = [node.create_publisher(Header, f"{d}/setpoint", qos) for d in DEVICES]

    def _status(self, msg: Header) -> None:
        out = _header(_tick(msg) + 1)
        for pub in self.pubs:
            pub.publish(out)


def bare_loop_rate(ticks: int, *, executor: str = "events", namespace: str = "/bare_loop",
                   clock_deliveries: bool = True) -> float:
    """Ticks per wall-clock second of the bare loop (module docstring) over ``ticks`` ticks.

    Parameters
    ----------
    ticks : int
        Lockstep ticks to run (after discovery has matched every subscription).
    executor : {"events", "single"}
        rclpy's ``EventsExecutor`` or ``SingleThreadedExecutor``, as ``squeeze-grasp run``.
    namespace : str
        Namespace of the loop's nodes (keep it apart from other loops on the domain).
    clock_deliveries : bool
        Whether ``monitor`` and ``executor`` take the clock (13 deliveries a tick, the loop
        issue 33 measured) or not (11, as the pipeline's nodes in lockstep now: the clock is
        still published, as ``sim_hardware`` does).

    Returns
    -------
    float
        Ticks per second, wall clock, from the first tick's publication to the last tick.
    """
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    spin: Executor = (EventsExecutor(context=context) if executor == "events"
                      else SingleThreadedExecutor(context=context))
    nodes = [Node(name, namespace=namespace, context=context)
             for name in ("sim", "monitor", "executor", "client")]
    wake = Future()

    def tick_done(*_: object) -> None:
        if not wake.done():
            wake.set_result(None)
    try:
        sim = _Sim(nodes[0], ticks, tick_done)
        _Monitor(nodes[1], clock_deliveries), _Executor(nodes[2], clock_deliveries)
        nodes[3].create_subscription(Header, "state", tick_done, loop_qos(10))
        for node in nodes:
            spin.add_node(node)
        subscribed = [(p, (2 if clock_deliveries else 0) if p.topic_name.endswith("/clock")
                       else 1) for p in sim.pubs]
        deadline = time.monotonic() + 30.0
        while not all(p.get_subscription_count() >= n for p, n in subscribed):
            if time.monotonic() > deadline:
                raise TimeoutError("the bare loop's subscriptions did not match within 30 s")
            spin.spin_once(0.01)
        started = time.perf_counter()
        sim.publish()
        while sim.tick < ticks:
            if executor == "events":
                wake = Future()
                spin.spin_until_future_complete(wake, WAKE_PERIOD)
            else:
                spin.spin_once(1.0)
        return ticks / (time.perf_counter() - started)
    finally:
        for node in nodes:
            spin.remove_node(node)
            node.destroy_node()
        spin.shutdown()
        context.try_shutdown()
