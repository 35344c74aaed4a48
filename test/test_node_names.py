# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Two nodes of one name on a ROS domain: ROS 2 starts both, and both then serve the name's
services, actions and topics (two executors would both command the fingers). A node started
by our executables says so in its log; before, nothing did.
"""

from __future__ import annotations

import os
import time

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from test_planner_shutdown import planner_process

from squeeze_grasp_ros.ros.nodes import twins

TIMEOUT = 30.0


def test_twins_counts_the_other_nodes_of_a_name(ros_context: Context) -> None:
    first = rclpy.create_node("executor", namespace="/lab", context=ros_context)
    other = rclpy.create_node("executor", namespace="/other", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    try:
        assert twins(first) == 0 and twins(other) == 0
        second = rclpy.create_node("executor", namespace="/lab", context=ros_context)
        deadline = time.monotonic() + TIMEOUT
        while twins(first) < 1 and time.monotonic() < deadline:
            executor.spin_once(0.05)
        assert twins(first) == 1 and twins(second) == 1 and twins(other) == 0
        second.destroy_node()
    finally:
        first.destroy_node()
        other.destroy_node()
        executor.shutdown()


def test_a_planner_process_logs_the_other_node_of_its_name(ros_context, tmp_path) -> None:
    name = f"planner_twin_{os.getpid()}"  # no other test's planner on the domain counts
    twin = rclpy.create_node(name, context=ros_context)
    log = tmp_path / "planner.log"
    try:
        with planner_process(tmp_path, "-r", f"__node:={name}"):
            deadline = time.monotonic() + TIMEOUT
            while f"other node(s) named /{name}" not in log.read_text():
                assert time.monotonic() < deadline, log.read_text()
                time.sleep(0.2)
        said = next(line for line in log.read_text().splitlines() if "other node(s)" in line)
        assert (f"1 other node(s) named /{name} are on this ROS domain: each gets the "
                "requests, goals and topics meant for one") in said
        assert "--ros-args -r __node:=NAME" in said
    finally:
        twin.destroy_node()
