# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Console-script entry points: configure the process, then import and run the target.

Each sets single-threaded BLAS (:func:`squeeze_grasp_ros.threads.single_thread_blas`)
before numpy is loaded, unless the user set the variables; importing the package as a library
changes nothing.
"""
from __future__ import annotations

import importlib

from squeeze_grasp_ros.threads import single_thread_blas

__all__ = ["cli", "executor", "monitor", "planner", "recorder", "sim_hardware"]


def _run(module: str):
    single_thread_blas()
    return importlib.import_module(module).main()


def cli():
    """``squeeze-grasp``."""
    return _run("squeeze_grasp_ros.cli")


def planner():
    """``ros2 run squeeze_grasp_ros planner``."""
    return _run("squeeze_grasp_ros.ros.nodes.planner")


def executor():
    """``ros2 run squeeze_grasp_ros executor``."""
    return _run("squeeze_grasp_ros.ros.nodes.executor")


def monitor():
    """``ros2 run squeeze_grasp_ros monitor``."""
    return _run("squeeze_grasp_ros.ros.nodes.monitor")


def sim_hardware():
    """``ros2 run squeeze_grasp_ros sim_hardware``."""
    return _run("squeeze_grasp_ros.ros.nodes.sim_hardware")


def recorder():
    """``ros2 run squeeze_grasp_ros recorder``."""
    return _run("squeeze_grasp_ros.ros.nodes.recorder")
