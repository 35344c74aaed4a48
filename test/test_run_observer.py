# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The run client's subscriptions to the outcome topics, on real rclpy: what a loop node
published before this client's reader matched still reaches it, and a publisher it can never
hear from is named.
"""
from __future__ import annotations

import time

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from squeeze_grasp_interfaces.msg import ContactEvent, ContactEventArray
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.run.graph import run_namespace
from squeeze_grasp_ros.ros.run.observer import Observer
from squeeze_grasp_ros.ros.run.processes import ros_arguments


@pytest.fixture
def ros():
    """A context, an executor and a fresh namespace."""
    context = Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    yield context, executor, run_namespace()
    executor.shutdown()
    rclpy.shutdown(context=context)


def spin(executor, done, seconds):
    """Spin until ``done()`` or ``seconds`` of wall-clock time."""
    deadline = time.monotonic() + seconds
    while not done() and time.monotonic() < deadline:
        executor.spin_once(0.02)


def monitor_node(context, namespace, *, lockstep):
    """A stand-in for the monitor: its events publisher with the monitor's QoS."""
    node = Node("monitor", context=context, cli_args=ros_arguments(namespace))
    pub = node.create_publisher(ContactEventArray, pipeline.EVENTS,
                                pipeline.output_qos(10, lockstep=lockstep))
    return node, pub


@pytest.mark.parametrize("kept", [True, False])
def test_an_event_published_before_the_clients_reader_matched_reaches_only_a_kept_client(
        ros, kept):
    context, executor, namespace = ros
    node, pub = monitor_node(context, namespace, lockstep=True)
    msg = ContactEventArray()
    msg.events = [ContactEvent(type="A", node=7, finger="F1")]
    pub.publish(msg)  # no reader exists yet: what a writer matching late sends "before"
    client = Node("run", context=context, cli_args=ros_arguments(namespace))
    observer = Observer(client, kept=kept)
    for n in (node, client):
        executor.add_node(n)
    # the reader side of discovery (what run waits for), then time for the history to arrive
    spin(executor, lambda: observer.subscriptions[1].get_publisher_count() > 0, 10.0)
    assert observer.subscriptions[1].get_publisher_count() == 1
    spin(executor, lambda: observer.monitor_events, 3.0)
    received = [(e.type, e.node, e.finger) for e in observer.monitor_events]
    assert received == ([("A", 7, "F1")] if kept else [])
    assert observer.incompatible() == []


def test_a_kept_client_names_an_outcome_publisher_it_never_hears(ros):
    context, executor, namespace = ros
    node, _ = monitor_node(context, namespace, lockstep=False)  # volatile: hardware mode
    client = Node("run", context=context, cli_args=ros_arguments(namespace))
    observer = Observer(client, kept=True)
    for n in (node, client):
        executor.add_node(n)
    spin(executor, lambda: observer.subscriptions[1].get_publisher_count() > 0, 10.0)
    assert observer.incompatible() == [f"{namespace}/monitor/events ({namespace}/monitor)"]
    assert Observer(client, kept=False).incompatible() == []
