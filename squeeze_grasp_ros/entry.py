# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Console-script entry points: configure the process, then import and run the target.

Each sets single-threaded BLAS (:func:`squeeze_grasp_ros.threads.single_thread_blas`)
before numpy is loaded, unless the user set the variables; importing the package as a library
changes nothing.
"""
from __future__ import annotations

import importlib
import signal
import sys

from squeeze_grasp_ros.exit_codes import raise_on_signals
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
    except KeyboardInterrupt as exc:
        signum = getattr(exc, "signum", signal.SIGINT)
        print(f"\n{name}: stopped by {signal.Signals(signum).name}", file=sys.stderr)
        return 128 + int(signum)


def cli():
    """``squeeze-grasp``."""
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
