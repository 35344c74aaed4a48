# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Launch the planner with its parameter file.

``ros2 launch squeeze_grasp_ros planner.launch.py [params_file:=/path/to/planner.yaml]``

A planner that ends before the launch is stopped (a parameter it refuses) ends the launch with
exit status 1, naming it.
"""
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from squeeze_grasp_ros.commands.launch_checks import required


def generate_launch_description() -> LaunchDescription:
    """The planner node, parameters from ``params_file`` (default: the installed config)."""
    default = Path(get_package_share_directory("squeeze_grasp_ros")) / "config" / "planner.yaml"
    return LaunchDescription([
        DeclareLaunchArgument("params_file", default_value=str(default),
                              description="parameter file of the planner node"),
        Node(package="squeeze_grasp_ros", executable="planner", name="planner",
             parameters=[LaunchConfiguration("params_file")], output="screen",
             on_exit=required("planner")),
    ])
