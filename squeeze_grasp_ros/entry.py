# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Console-script entry points: configure the process, then import and run the target.

Each sets single-threaded BLAS (:func:`squeeze_grasp_ros.threads.single_thread_blas`)
before numpy is loaded, unless the user set the variables; ``squeeze-grasp`` also keeps its
standard output for its results (:func:`squeeze_grasp_ros.stdout.reserve_stdout`: the
middleware's diagnostics go to stderr). Importing the package as a library changes nothing.
"""
from __future__ import annotations

import importlib
import signal
import sys

from squeeze_grasp_ros.exit_codes import raise_on_signals
from squeeze_grasp_ros.stdout import reserve_stdout
from squeeze_grasp_ros.threads import single_thread_blas

__all__ = ["cli", "executor", "monitor", "outline", "planner", "recorder", "sim_hardware"]


def _run(module: str, name: str):
    """Run ``module.main()``; a Ctrl-C, SIGTERM or SIGHUP that nothing inside handled (while the
    program is still importing numpy, ROS or Dask, say) ends with one line naming ``name`` and
    exit 128 + the signal number (130, 143, 129), not a traceback or a silent kill.
    """
    single_thread_blas()
    raise_on_signals()
    try:
        return importlib.import_module(module).main()
    except (KeyboardInterrupt, ImportError) as exc:
        stop = _interruption(exc)
        if stop is None:
            raise
        signum = getattr(stop, "signum", signal.SIGINT)
        print(f"\n{name}: stopped by {signal.Signals(signum).name}", file=sys.stderr)
        return 128 + int(signum)


def _interruption(exc: BaseException) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt (or :class:`.exit_codes.Interrupted`) behind ``exc``, or None.

    A signal that arrives while a C extension initialises (rclpy's, seen under load) surfaces as
    an ImportError ("initialization failed") caused by the signal's exception.
    """
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def cli():
    """``squeeze-grasp`` in this process: its exit code, returned to the caller."""
    reserve_stdout()
    return _run("squeeze_grasp_ros.cli", "squeeze-grasp")


def planner():
    """``ros2 run squeeze_grasp_ros planner``."""
    return _run("squeeze_grasp_ros.ros.nodes.planner", "planner")


def executor():
    """``ros2 run squeeze_grasp_ros executor``."""
    return _run("squeeze_grasp_ros.ros.nodes.executor", "executor")


def monitor():
    """``ros2 run squeeze_grasp_ros monitor``."""
    return _run("squeeze_grasp_ros.ros.nodes.monitor", "monitor")


def sim_hardware():
    """``ros2 run squeeze_grasp_ros sim_hardware``."""
    return _run("squeeze_grasp_ros.ros.nodes.sim_hardware", "sim_hardware")


def recorder():
    """``ros2 run squeeze_grasp_ros recorder``."""
    return _run("squeeze_grasp_ros.ros.nodes.recorder", "recorder")


def outline():
    """``ros2 run squeeze_grasp_ros outline``."""
    return _run("squeeze_grasp_ros.ros.nodes.outline", "outline")
