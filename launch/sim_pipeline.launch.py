# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated pipeline under a ROS 2 installation: the nodes ``squeeze-grasp run --processes``
starts, with the same parameters.

    ros2 launch squeeze_grasp_ros sim_pipeline.launch.py            # the shipped foam square
    ros2 launch squeeze_grasp_ros sim_pipeline.launch.py scene:=/path/to/scene.yaml \\
        record:=/tmp/foam_run rviz:=true

The nodes wait for a goal: send the executor its goal with ``ros2 action send_goal
/executor/execute_grasp squeeze_grasp_interfaces/action/ExecuteGrasp '{...}'`` (docs/pipeline.md),
or run the whole scene with ``squeeze-grasp run``. Arguments: ``scene`` (default: the shipped
foam square), ``record`` (bag folder; empty: no recorder), ``include_hidden_topics`` (record the
action's hidden topics too), ``rviz`` (start RViz2 with the shipped configuration).
"""
import shutil

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, LogInfo, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from squeeze_grasp_ros.mechanics.compliance import ElasticObject
from squeeze_grasp_ros.nodes.runner import RunOptions, node_parameters
from squeeze_grasp_ros.resources import config_dir, scene_file, viewer_file
from squeeze_grasp_ros.scene import build_mesh, finger_nodes, load_scene, scene_material
from squeeze_grasp_ros.sim.world import squeeze_geometry

TRUE = ("true", "1", "yes", "on")


def rviz(enabled: str) -> list:
    """RViz2 with the shipped configuration, or a message saying why it does not start."""
    if enabled.lower() not in TRUE:
        return []
    config = str(viewer_file("squeeze_grasp.rviz"))
    if shutil.which("rviz2") is None:
        return [LogInfo(msg=f"rviz:=true, but rviz2 is not installed here (on Ubuntu: sudo apt "
                            f"install ros-jazzy-rviz2); the pipeline runs without it. Its "
                            f"configuration is {config}")]
    return [ExecuteProcess(cmd=["rviz2", "-d", config, "--ros-args", "-p", "use_sim_time:=true"],
                           output="screen")]


def nodes(context, *args, **kwargs):
    """One launch_ros Node per pipeline node, parameters as ``squeeze-grasp run`` sets them."""
    scene_path = LaunchConfiguration("scene").perform(context) or str(scene_file("foam_square"))
    record = LaunchConfiguration("record").perform(context)
    hidden = LaunchConfiguration("include_hidden_topics").perform(context).lower() in TRUE
    scene = load_scene(scene_path)
    obj = ElasticObject(build_mesh(scene), scene_material(scene))
    _, relative_per_depth = squeeze_geometry(scene, obj, finger_nodes(scene, obj.mesh))
    options = RunOptions(scene_path, record=record or None, include_hidden_topics=hidden)
    params = node_parameters(scene, scene_path, options, relative_per_depth)
    if not record:
        del params["recorder"]
    actions = [LogInfo(msg=f"scene {scene_path}"),
               Node(package="squeeze_grasp_ros", executable="planner", name="planner",
                    parameters=[str(config_dir() / "planner.yaml")], output="screen")]
    for name, values in params.items():
        actions.append(Node(package="squeeze_grasp_ros", executable=name, name=name,
                            parameters=[values], output="screen"))
    return actions + rviz(LaunchConfiguration("rviz").perform(context))


def generate_launch_description() -> LaunchDescription:
    """[scene:=FILE] [record:=DIR] [include_hidden_topics:=true] [rviz:=true]."""
    return LaunchDescription([
        DeclareLaunchArgument("scene", default_value="",
                              description="scene YAML file (empty: the shipped foam square)"),
        DeclareLaunchArgument("record", default_value="",
                              description="rosbag2 folder to record into (empty: no recording)"),
        DeclareLaunchArgument("include_hidden_topics", default_value="false",
                              description="also record the action's _action/ topics"),
        DeclareLaunchArgument("rviz", default_value="false",
                              description="start RViz2 with share/squeeze_grasp_ros/config/"
                                          "viewers/squeeze_grasp.rviz"),
        OpaqueFunction(function=nodes),
    ])
