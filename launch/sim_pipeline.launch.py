# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
r"""The simulated pipeline under a ROS 2 installation: the nodes ``squeeze-grasp run --processes``
starts, with the same parameters.

    ros2 launch squeeze_grasp_ros sim_pipeline.launch.py            # the shipped foam square
    ros2 launch squeeze_grasp_ros sim_pipeline.launch.py scene:=/path/to/scene.yaml \
        record:=/tmp/foam_run rviz:=true

By default a client (``squeeze-grasp run --attach``) plans the scene with the launched planner,
sends the executor its goal, prints the summary and ends the launch with the run.
``run:=false`` only starts the nodes, which then wait for a goal (``ros2 action send_goal
/executor/execute_grasp squeeze_grasp_interfaces/action/ExecuteGrasp '{...}'``, see
docs/pipeline.md). Arguments: ``scene`` (default: the shipped foam square), ``record`` (bag
folder; empty: no recorder), ``include_hidden_topics`` (record the action's hidden topics too),
``rviz`` (start RViz2 with the shipped configuration), ``run``, ``on_slip_alarm``,
``max_attempts`` and ``resqueeze_margin`` (the executor's reaction to a slip alarm, as ``run``'s
options of the same names, checked by run's parser before any node starts; empty: its
defaults), ``namespace`` (empty: the nodes' own names at the root, which the RViz2 configuration
expects, one such launch per ROS domain; ``namespace:=/lab/a``: every node, topic, service and
``/clock`` under ``/lab/a``, so launches in different namespaces share a domain without seeing
each other).

The yes/no arguments (``run``, ``rviz``, ``include_hidden_topics``) take true/false, 1/0, yes/no
or on/off; any other word is refused. The launch exits 0 when its run exits 0 (or, with
``run:=false``, when it is stopped). It exits 1, shutting every node down, when an argument or
the scene is refused, when the run exits otherwise (the grasp did not hold, ...), or when a
pipeline node ends while the pipeline runs (a recorder that cannot write its folder: the others
would wait for it for ever); launch's error line says which and why
(:mod:`squeeze_grasp_ros.commands.launch_checks`).
"""
import shutil
from pathlib import Path

from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    EmitEvent,
    ExecuteProcess,
    LogInfo,
    OpaqueFunction,
    RegisterEventHandler,
)
from launch.event_handlers import OnProcessExit
from launch.events import Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.substitutions import ExecutableInPackage

from squeeze_grasp_ros.commands.launch_checks import (
    RUN_ARGUMENTS,
    LaunchEnded,
    flag,
    required,
    run_arguments,
    run_ended,
)
from squeeze_grasp_ros.resources import config_dir, scene_file, viewer_file
from squeeze_grasp_ros.ros.run.options import RunOptions, node_parameters, without_run
from squeeze_grasp_ros.scene import GraspSetup, load_scene


def rviz(enabled: str) -> list:
    """RViz2 with the shipped configuration, or a message saying why it does not start."""
    if not flag("rviz", enabled):
        return []
    config = str(viewer_file("squeeze_grasp.rviz"))
    if shutil.which("rviz2") is None:
        return [LogInfo(msg=f"rviz:=true, but rviz2 is not installed here (on Ubuntu: sudo apt "
                            f"install ros-jazzy-rviz2); the pipeline runs without it. Its "
                            f"configuration is {config}")]
    return [ExecuteProcess(cmd=["rviz2", "-d", config, "--ros-args", "-p", "use_sim_time:=true"],
                           output="screen")]


def run_exited(event, context):
    """The run's end: shut the pipeline down; exit status 1 unless the run exited 0 (or was
    stopped by a shutdown already under way, whose cause launch has logged).
    """
    if context.is_shutdown:
        return None
    failed = run_ended(event.returncode)
    if failed:
        raise LaunchEnded(failed)
    return [LogInfo(msg="the run has ended; shutting the pipeline down"),
            EmitEvent(event=Shutdown(reason="run finished"))]


def nodes(context, *args, **kwargs):
    """One launch_ros Node per pipeline node, parameters as ``squeeze-grasp run`` sets them."""
    run = flag("run", LaunchConfiguration("run").perform(context))
    reaction = run_arguments(**{name: LaunchConfiguration(name).perform(context)
                                for name in RUN_ARGUMENTS}) if run else []
    scene_path = LaunchConfiguration("scene").perform(context) or str(scene_file("foam_square"))
    record = LaunchConfiguration("record").perform(context)
    hidden = flag("include_hidden_topics",
                  LaunchConfiguration("include_hidden_topics").perform(context))
    setup = GraspSetup.build(load_scene(scene_path))
    options = RunOptions(scene_path, record=record or None, include_hidden_topics=hidden)
    params = node_parameters(setup.scene, scene_path, options, setup.motion.relative_per_depth)
    if not run:  # no run latches the prediction: a node awaiting it would never start the loop
        params = without_run(params)
    if not record:
        del params["recorder"]
    roots = [str(Path(scene_path).resolve().parent), str(config_dir().parent), str(Path.cwd())]
    namespace = LaunchConfiguration("namespace").perform(context).rstrip("/")
    placed = {"namespace": namespace,
              "remappings": [("/clock", f"{namespace}/clock")]} if namespace else {}
    actions = [LogInfo(msg=f"scene {scene_path}"),
               Node(package="squeeze_grasp_ros", executable="planner", name="planner",
                    parameters=[str(config_dir() / "planner.yaml"), {"allowed_roots": roots}],
                    output="screen", on_exit=required("planner"), **placed)]
    for name, values in params.items():
        actions.append(Node(package="squeeze_grasp_ros", executable=name, name=name,
                            parameters=[values], output="screen", on_exit=required(name),
                            **placed))
    if run:
        client = ExecuteProcess(
            cmd=[ExecutableInPackage("squeeze-grasp", "squeeze_grasp_ros"), "run", scene_path,
                 "--attach", *reaction, *(["--namespace", namespace] if namespace else [])],
            output="screen", name="run")
        actions += [client, RegisterEventHandler(OnProcessExit(target_action=client,
                                                               on_exit=run_exited))]
    return actions + rviz(LaunchConfiguration("rviz").perform(context))


def generate_launch_description() -> LaunchDescription:
    """Arguments: scene, record, include_hidden_topics, rviz, run, the slip reaction, namespace."""
    return LaunchDescription([
        DeclareLaunchArgument("scene", default_value="",
                              description="scene YAML file (empty: the shipped foam square)"),
        DeclareLaunchArgument("record", default_value="",
                              description="rosbag2 folder to record into (empty: no recording)"),
        DeclareLaunchArgument("include_hidden_topics", default_value="false",
                              description="also record the action's _action/ topics"),
        DeclareLaunchArgument("run", default_value="true",
                              description="run the scene (plan, send the goal, print the "
                                          "summary, then shut down); false: only start the "
                                          "nodes"),
        DeclareLaunchArgument("on_slip_alarm", default_value="",
                              description="the executor's reaction to a slip alarm: hold, "
                                          "pure, normals or resqueeze (run's --on-slip-alarm; "
                                          "empty: its default, hold)"),
        DeclareLaunchArgument("max_attempts", default_value="",
                              description="with on_slip_alarm:=resqueeze: squeezes in all, the "
                                          "first included (empty: run's default, 2)"),
        DeclareLaunchArgument("resqueeze_margin", default_value="",
                              description="with on_slip_alarm:=resqueeze: a re-squeeze goes to "
                                          "(1 - margin) x the alarm's depth, margin in (0, 1) "
                                          "(empty: run's default, 0.25)"),
        DeclareLaunchArgument("rviz", default_value="false",
                              description="start RViz2 with share/squeeze_grasp_ros/config/"
                                          "viewers/squeeze_grasp.rviz"),
        DeclareLaunchArgument("namespace", default_value="",
                              description="put every node, topic and /clock under this "
                                          "namespace (empty: the root), so that launches in "
                                          "different namespaces share a ROS domain"),
        DeclareLaunchArgument("sigterm_timeout", default_value="10",
                              description="s a node has to end after SIGINT before launch "
                                          "sends SIGTERM (launch's own argument, here longer "
                                          "than its 5 s: a node waits up to 5 s for its "
                                          "readers to acknowledge what it published)"),
        OpaqueFunction(function=nodes),
    ])
