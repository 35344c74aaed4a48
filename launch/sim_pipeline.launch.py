# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated pipeline under a ROS 2 installation: the nodes ``squeeze-grasp run --processes``
starts, with the same parameters.

    ros2 launch squeeze_grasp_ros sim_pipeline.launch.py scene:=/path/to/foam_square.yaml \\
        record:=/tmp/foam_run

Then send the executor its goal, e.g. with ``squeeze-grasp run`` logic or ``ros2 action
send_goal /executor/execute_grasp squeeze_grasp_interfaces/action/ExecuteGrasp '{...}'``
(docs/pipeline.md). Arguments: ``scene`` (required), ``record`` (bag folder; empty: no
recorder), ``on_slip_alarm`` is a goal field, not a node parameter.
"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from squeeze_grasp_ros.mechanics.compliance import ElasticObject
from squeeze_grasp_ros.nodes.runner import RunOptions, config_dir, node_parameters
from squeeze_grasp_ros.scene import build_mesh, finger_nodes, load_scene, scene_material
from squeeze_grasp_ros.sim.world import squeeze_geometry


def nodes(context, *args, **kwargs):
    """One launch_ros Node per pipeline node, parameters as ``squeeze-grasp run`` sets them."""
    scene_path = LaunchConfiguration("scene").perform(context)
    record = LaunchConfiguration("record").perform(context)
    scene = load_scene(scene_path)
    obj = ElasticObject(build_mesh(scene), scene_material(scene))
    _, relative_per_depth = squeeze_geometry(scene, obj, finger_nodes(scene, obj.mesh))
    params = node_parameters(scene, scene_path, RunOptions(scene_path, record=record or None),
                             relative_per_depth)
    if not record:
        del params["recorder"]
    actions = [Node(package="squeeze_grasp_ros", executable="planner", name="planner",
                    parameters=[str(config_dir() / "planner.yaml")], output="screen")]
    for name, values in params.items():
        actions.append(Node(package="squeeze_grasp_ros", executable=name, name=name,
                            parameters=[values], output="screen"))
    return actions


def generate_launch_description() -> LaunchDescription:
    """scene:=FILE [record:=DIR]."""
    return LaunchDescription([
        DeclareLaunchArgument("scene", description="scene YAML file"),
        DeclareLaunchArgument("record", default_value="",
                              description="rosbag2 folder to record into (empty: no recording)"),
        OpaqueFunction(function=nodes),
    ])
