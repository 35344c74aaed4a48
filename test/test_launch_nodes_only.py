# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``sim_pipeline.launch.py run:=false``: the nodes alone, waiting for a goal a ROS user types.

The launch file gives its nodes the parameters of ``squeeze-grasp run`` (``node_parameters``),
which make the monitor and the executor await the prediction that run latches on
``planner/predicted_events``. Without a run nobody publishes it: before, the monitor and the
executor never answered the lockstep handshake, ``sim_hardware`` never started tick 0, and the
documented ``ros2 action send_goal /executor/execute_grasp ...`` was accepted and then waited
for ever (no feedback, no result; seen with ros2launch on the colcon route). Now the launch
file hands nodes without a run :func:`without_run`'s parameters.
"""
from __future__ import annotations

import ast
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from geometry_msgs.msg import Vector3
from rclpy.action import ActionClient
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.run.options import RunOptions, node_parameters, without_run
from squeeze_grasp_ros.scene import GraspSetup, load_scene

LAUNCH = Path(__file__).resolve().parents[1] / "launch" / "sim_pipeline.launch.py"
NAMESPACE = "/nodes_only"


def launch_parameters(run: bool) -> dict[str, dict]:
    """The parameters ``sim_pipeline.launch.py`` gives the foam square's loop nodes."""
    path = str(scene_file("foam_square"))
    setup = GraspSetup.build(load_scene(path))
    params = node_parameters(setup.scene, path, RunOptions(path),
                             setup.motion.relative_per_depth)
    del params["recorder"]
    return params if run else without_run(params)


def test_the_launch_file_gives_nodes_without_a_run_parameters_that_await_no_prediction():
    source = LAUNCH.read_text(encoding="utf-8")
    calls = {getattr(n.func, "id", "") for n in ast.walk(ast.parse(source))
             if isinstance(n, ast.Call)}
    assert "without_run" in calls
    assert launch_parameters(run=True)["monitor"]["await_prediction"] is True
    nodes_only = launch_parameters(run=False)
    assert nodes_only["monitor"]["await_prediction"] is False
    assert nodes_only["executor"]["await_prediction"] is False


@contextmanager
def loop_nodes(ros_context) -> Iterator[tuple[dict, Callable, ActionClient, Executor]]:
    """The loop nodes of ``run:=false`` and a client node on one executor: (the nodes by name,
    ``until(done, seconds)`` spinning them, an action client of the executor's goal, the
    executor).
    """
    from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
    from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode
    from squeeze_grasp_ros.ros.nodes.sim_hardware import SimHardwareNode

    args = ["--ros-args", "-r", f"__ns:={NAMESPACE}", "-r", f"/clock:={NAMESPACE}/clock"]
    classes = {"sim_hardware": SimHardwareNode, "monitor": MonitorNode,
               "executor": ExecutorNode}
    spinner = SingleThreadedExecutor(context=ros_context)
    nodes = {}
    try:
        for name, values in launch_parameters(run=False).items():
            nodes[name] = classes[name](context=ros_context, cli_args=args, parameter_overrides=[
                Parameter(k, value=v) for k, v in values.items()])
        nodes["typist"] = Node("typist", namespace=NAMESPACE, context=ros_context)
        for node in nodes.values():
            spinner.add_node(node)

        def until(done, seconds=60.0) -> bool:
            deadline = time.monotonic() + seconds
            while not done() and time.monotonic() < deadline:
                spinner.spin_once(timeout_sec=0.05)
            return done()

        yield nodes, until, ActionClient(nodes["typist"], ExecuteGrasp, pipeline.ACTION), spinner
    finally:
        for node in nodes.values():
            spinner.remove_node(node)
            node.destroy_node()
        spinner.shutdown()


def typed_goal(depth: float) -> ExecuteGrasp.Goal:
    """The goal docs/pipeline.md has a user type, to ``depth`` m."""
    return ExecuteGrasp.Goal(fingers=["F1", "F2"],
                             directions=[Vector3(x=0.70711), Vector3(x=-0.70711)],
                             depth=depth, relative_per_depth=14.1421, on_slip_alarm="hold")


def test_nodes_started_without_a_run_start_the_loop_and_execute_a_typed_goal(ros_context):
    """The loop nodes of ``run:=false`` on real rclpy: tick 0 starts without a prediction,
    and the goal docs/pipeline.md has a user type (shallower here) ends ``depth_reached``.
    """
    with loop_nodes(ros_context) as (nodes, until, client, _):
        assert until(lambda: nodes["sim_hardware"].now_ns >= 0), \
            "sim_hardware never started tick 0"
        assert until(client.server_is_ready)
        sent = client.send_goal_async(typed_goal(0.002))
        assert until(sent.done) and sent.result().accepted
        result = sent.result().get_result_async()
        assert until(result.done), "the goal never ended"
        assert result.result().result.termination == ExecuteGrasp.Result.DEPTH_REACHED


def test_an_executor_that_stops_ends_its_goal(ros_context):
    """SIGINT or SIGTERM makes a node's ``main`` drain it before it ends: the executor ends a
    running goal ABORTED (termination ``canceled``, "the executor is shutting down"), and its
    client gets that result. Before, the goal was left running and its client waited for ever.
    """
    from action_msgs.msg import GoalStatus

    with loop_nodes(ros_context) as (nodes, until, client, spinner):
        assert until(client.server_is_ready)
        feedback = []
        sent = client.send_goal_async(typed_goal(0.02), feedback_callback=feedback.append)
        assert until(sent.done) and sent.result().accepted
        assert until(lambda: feedback), "no feedback: the goal did not start"
        result = sent.result().get_result_async()
        nodes["executor"].drain(spinner)
        assert until(result.done, 5.0), "the goal never ended"
        assert result.result().status == GoalStatus.STATUS_ABORTED
        ended = result.result().result
        assert ended.termination == ExecuteGrasp.Result.CANCELED and not ended.success
        assert "the executor is shutting down" in ended.message
