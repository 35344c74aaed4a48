# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp ros-setup``: build our ROS 2 interfaces into the active virtual environment."""
from __future__ import annotations

import argparse

from squeeze_grasp_ros.buildtool import interfaces as ros_setup


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """--source, --force, --verbose, --check."""
    parser.description = ros_setup.DESCRIPTION
    ros_setup.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Exit code of the set-up (0 = ready)."""
    return ros_setup.run(args)


def summary(result: dict) -> str:
    """Not used: the verb returns an exit code."""
    return ""
