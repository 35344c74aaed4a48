# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The lockstep bookkeeping the executor and the monitor share (ros/nodes/pipeline.TickAnswer)."""
from __future__ import annotations

import contextlib
import os
import time

from squeeze_grasp_ros.ros.nodes.pipeline import TickAnswer


class Recorder:
    def __init__(self) -> None:
        self.sent: list = []

    def publish(self, msg) -> None:
        self.sent.append(msg)


def test_each_tick_is_answered_once_and_a_resent_tick_gets_the_same_answer():
    pub = Recorder()
    ticks = TickAnswer()
    assert ticks.is_new(0) and pub.sent == []
    ticks.answer(0, [(pub, "status 0")])
    assert pub.sent == ["status 0"]
    assert not ticks.is_new(0) and pub.sent == ["status 0", "status 0"]  # re-sent tick 0
    assert ticks.is_new(1_000_000)
    ticks.answer(1_000_000, [(pub, "status 1")])
    assert not ticks.is_new(0) and pub.sent[-1] == "status 1"  # an old tick: nothing new
    assert ticks.stamp_ns == 1_000_000


@contextlib.contextmanager
def _lockstep_and_hardware(context, node_class, name: str):
    """A ``node_class`` node with ``use_sim_time`` in lockstep and one on hardware
    (``lockstep: false``), each in a namespace of its own, with a driver node publishing each
    one's ``/clock``, on a ``SingleThreadedExecutor``: yield (nodes by lockstep, driver, clock
    publishers by lockstep, executor, namespace) once the hardware node alone subscribes to
    its ``/clock``.
    """
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rosgraph_msgs.msg import Clock

    from squeeze_grasp_ros.ros.nodes.pipeline import loop_qos
    from squeeze_grasp_ros.ros.run.processes import ros_arguments

    namespace = f"/{name}_{os.getpid()}"
    nodes = {lockstep: node_class(
        context=context, cli_args=ros_arguments(f"{namespace}/{lockstep}"),
        parameter_overrides=[Parameter("use_sim_time", value=True),
                             Parameter("lockstep", value=lockstep)]) for lockstep in (True, False)}
    driver = Node("driver", context=context, namespace=namespace)
    clocks = {lockstep: driver.create_publisher(Clock, f"{namespace}/{lockstep}/clock",
                                                loop_qos(10)) for lockstep in nodes}
    executor = SingleThreadedExecutor(context=context)
    for node in (*nodes.values(), driver):
        executor.add_node(node)
    try:
        subscribed = {lockstep: [s.topic_name for s in node.subscriptions
                                 if s.topic_name.endswith("/clock")]
                      for lockstep, node in nodes.items()}
        assert subscribed == {True: [], False: [f"{namespace}/False/clock"]}
        yield nodes, driver, clocks, executor, namespace
        assert clocks[True].get_subscription_count() == 0
        assert [n.get_parameter("use_sim_time").value for n in nodes.values()] == [False, True]
    finally:
        executor.shutdown()
        for node in (*nodes.values(), driver):
            node.destroy_node()


def _clock_message(sec: int):
    from rosgraph_msgs.msg import Clock

    message = Clock()
    message.clock.sec = sec
    return message


def test_the_lockstep_monitor_takes_no_clock_and_the_hardware_monitor_follows_it(ros_context):
    """In lockstep the monitor's time is each ``sim/tick``'s stamp: with ``use_sim_time`` it
    still does not subscribe to ``/clock`` (one delivery a tick less). On hardware
    (``lockstep: false``) its timer's clock is the one ``use_sim_time`` selects: it follows
    ``/clock``. Real rclpy nodes in a namespace of their own.
    """
    from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode

    with _lockstep_and_hardware(ros_context, MonitorNode, "clock_test") as (
            monitors, _, clocks, executor, _):
        message = _clock_message(5)
        deadline = time.monotonic() + 10.0
        while monitors[False].get_clock().now().nanoseconds != 5_000_000_000:
            assert time.monotonic() < deadline, "the hardware monitor never took /clock"
            for publisher in clocks.values():
                publisher.publish(message)
            executor.spin_once(0.05)
        assert monitors[False].get_clock().ros_time_is_active
        assert not monitors[True].get_clock().ros_time_is_active


def test_the_lockstep_executor_takes_its_time_from_the_statuses_not_the_clock(ros_context):
    """In lockstep with ``use_sim_time`` the executor does not subscribe to ``/clock`` (one
    delivery a tick less); its clock still reads simulated time, each status's stamp (the
    action server stamps accepted goals with it), as ``/clock`` of that tick set it before.
    Without lockstep it follows ``/clock``. Real rclpy nodes in a namespace of their own.
    """
    from squeeze_grasp_interfaces.msg import MonitorStatus
    from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
    from squeeze_grasp_ros.ros.nodes.pipeline import STATUS, loop_qos

    with _lockstep_and_hardware(ros_context, ExecutorNode, "executor_clock_test") as (
            executors, driver, clocks, spin, namespace):
        status = driver.create_publisher(MonitorStatus, f"{namespace}/True/{STATUS}",
                                         loop_qos(10))
        tick, stamped = _clock_message(5), MonitorStatus()
        stamped.header.stamp.sec, stamped.header.stamp.nanosec = 5, 1_000
        deadline = time.monotonic() + 10.0
        while {lockstep: node.get_clock().now().nanoseconds
               for lockstep, node in executors.items()} != {True: 5_000_001_000,
                                                            False: 5_000_000_000}:
            assert time.monotonic() < deadline, "an executor's clock never moved"
            for publisher in clocks.values():
                publisher.publish(tick)
            status.publish(stamped)
            spin.spin_once(0.05)
        assert all(node.get_clock().ros_time_is_active for node in executors.values())
