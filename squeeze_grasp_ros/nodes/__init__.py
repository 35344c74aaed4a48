# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ROS 2 nodes: thin rclpy wiring around the mechanics, one console script each."""
from __future__ import annotations

from collections.abc import Callable

import rclpy
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.node import Node


def run_node(node_type: Callable[[], Node], executor_type: Callable[[], Executor],
             args: list[str] | None = None) -> None:
    """A node's ``main``: init rclpy, spin one node in the main thread until Ctrl-C or
    shutdown, then destroy the node (joining any workers), the executor and the context.

    Parameters
    ----------
    node_type : callable
        Builds the node (after ``rclpy.init``).
    executor_type : callable
        Builds the executor, e.g. ``SingleThreadedExecutor``.
    args : list of str, optional
        Command-line arguments for ``rclpy.init`` (``--ros-args ...``); None = ``sys.argv``.
    """
    rclpy.init(args=args)
    node = node_type()
    executor = executor_type()
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        executor.shutdown()
        rclpy.try_shutdown()
