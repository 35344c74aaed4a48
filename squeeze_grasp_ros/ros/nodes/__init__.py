# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ROS 2 nodes: thin rclpy wiring around the mechanics, one console script each."""
from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import rclpy
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from squeeze_grasp_ros.exit_codes import ExitCode
from squeeze_grasp_ros.mechanics.errors import InvalidInputError


class ParameterError(InvalidInputError):
    """A node parameter is missing or invalid; the message names it."""


def run_node(factory: Callable[[], Node], args: list[str] | None = None,
             executor_type: Callable[[], Executor] = EventsExecutor) -> int:
    """A node's ``main``: init rclpy, spin the node in the main thread until SIGINT, SIGTERM or
    shutdown, then clean up.

    The executor (default ``rclpy.experimental.EventsExecutor``; the planner, whose worker
    threads hand results back through futures, uses ``SingleThreadedExecutor``) is spun with
    ``spin_once`` in a loop: in rclpy 7.1.6 ``EventsExecutor.spin()`` holds the GIL at 100 % CPU
    once a node has a timer (measured: no callback runs, no other thread gets the GIL) and does
    not return after shutdown. SIGINT (Ctrl-C, also what ``ros2 launch`` sends first) and
    SIGTERM only set a flag, so no callback is interrupted halfway; the loop then ends, a node
    with ``drain(executor)`` processes what has already arrived, its ``close()`` is called, and
    the node is destroyed (the planner joins its workers there).

    Parameters
    ----------
    factory : callable
        Builds the node (after ``rclpy.init``).
    args : list of str, optional
        Command-line arguments for ``rclpy.init`` (``--ros-args ...``); None = ``sys.argv``.
    executor_type : callable
        Builds the executor.

    Returns
    -------
    int
        The exit code: 0, or 2 (:attr:`~.ExitCode.USAGE`) when the node refused its
        parameters (a missing scene, output folder, ...). That error is one line on stderr,
        ``<program>: error: <what>``, not a traceback. Once built, the node logs
        ``<name> ready: <its configuration>``.
    """
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = factory()
    except InvalidInputError as error:
        print(f"{Path(sys.argv[0]).stem}: error: {error}", file=sys.stderr)
        rclpy.try_shutdown()
        return ExitCode.USAGE
    summary = getattr(node, "ready_summary", lambda: "")()
    node.get_logger().info(f"{node.get_name()} ready" + (f": {summary}" if summary else ""))
    executor = executor_type()
    executor.add_node(node)
    try:
        while rclpy.ok() and not stop.is_set():
            executor.spin_once(0.1)
        if stop.is_set() and hasattr(node, "drain"):
            node.drain(executor)
    except ExternalShutdownException:
        pass
    finally:
        if hasattr(node, "close"):
            node.close()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return ExitCode.OK
