# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner, executor, monitor and (optionally) recorder against real hardware drivers.

    ros2 launch squeeze_grasp_ros hardware.launch.py mu:=0.4 record:=/data/run1

The drivers (Barrett hand, Cobra arm, pusher, fingertip F/T and tactile sensors) provide and
accept the topics of the hardware contract (docs/pipeline.md, "Hardware contract"):
``devices/<device>/pose``, ``wrench``, ``tactile`` with sensor-data QoS and
``devices/<device>/setpoint`` (reliable). The
nodes run on wall-clock timers (``lockstep: false``) on the newest readings; there is no
``/clock`` and no simulated hardware. Finger-device mapping, limits and the object pose in the
robot base frame come from ``config/executor.yaml`` and ``config/monitor.yaml``.

A node that ends while the launch runs (a monitor refusing ``mu:=abc``, a recorder that cannot
write its folder, a crash) ends the launch with exit status 1, naming it: the executor would
otherwise command the fingers without the monitor's alarms, or a run go unrecorded.
"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, NotEqualsSubstitution
from launch_ros.actions import Node

from squeeze_grasp_ros.commands.launch_checks import required
from squeeze_grasp_ros.resources import config_dir

HARDWARE = {"use_sim_time": False, "lockstep": False, "sensor_qos": "sensor_data"}
"""Overrides of the simulation defaults in config/*.yaml."""


def generate_launch_description() -> LaunchDescription:
    """mu:=MU [record:=DIR]."""
    record = LaunchConfiguration("record")
    config = config_dir()
    return LaunchDescription([
        DeclareLaunchArgument("mu", default_value="0.4",
                              description="friction coefficient of the fingertips"),
        DeclareLaunchArgument("record", default_value="",
                              description="rosbag2 folder to record into (empty: no recording)"),
        DeclareLaunchArgument("sigterm_timeout", default_value="10",
                              description="s a node has to end after SIGINT before launch "
                                          "sends SIGTERM (launch's own argument, here longer "
                                          "than its 5 s: a node waits up to 5 s for its "
                                          "readers to acknowledge what it published)"),
        Node(package="squeeze_grasp_ros", executable="planner", name="planner",
             parameters=[str(config / "planner.yaml"), {"use_sim_time": False}], output="screen",
             on_exit=required("planner")),
        Node(package="squeeze_grasp_ros", executable="monitor", name="monitor",
             parameters=[str(config / "monitor.yaml"), HARDWARE,
                         {"mu": LaunchConfiguration("mu")}], output="screen",
             on_exit=required("monitor")),
        Node(package="squeeze_grasp_ros", executable="executor", name="executor",
             parameters=[str(config / "executor.yaml"),
                         {"use_sim_time": False, "lockstep": False}], output="screen",
             on_exit=required("executor")),
        Node(package="squeeze_grasp_ros", executable="recorder", name="recorder",
             parameters=[str(config / "recorder.yaml"), HARDWARE,
                         {"output": record, "simulation": False}],
             condition=IfCondition(NotEqualsSubstitution(record, "")), output="screen",
             on_exit=required("recorder")),
    ])
