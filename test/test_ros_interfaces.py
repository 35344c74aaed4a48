# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The nodes' interfaces as the ros2 command line shows them, on real rclpy: what a node says
of its names under namespaces and remaps (``ros2 run ... --ros-args -r``), and what
``ros2 param describe`` shows of its parameters.
"""
from __future__ import annotations

from rclpy.action import get_action_names_and_types
from rclpy.context import Context

from squeeze_grasp_ros.ros.run.graph import run_namespace


def test_a_remapped_action_keeps_its_name_and_the_node_says_so(ros_context: Context, capfd):
    """No remap rule applies to an rclpy action name: with ``-r executor/execute_grasp:=/go``
    the server stays ``<ns>/executor/execute_grasp``, but the ready line said ``action /go``,
    where no action was. Now it names the action where it is, and a warning says that the remap
    was not applied.
    """
    from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode

    namespace = run_namespace()
    node = ExecutorNode(context=ros_context, cli_args=[
        "--ros-args", "-r", f"__ns:={namespace}", "-r", "executor/execute_grasp:=/go"])
    try:
        served = [name for name, _ in get_action_names_and_types(node)
                  if name.startswith(namespace) or name == "/go"]
        assert served == [f"{namespace}/executor/execute_grasp"]
        assert node.ready_summary().endswith(f"action {namespace}/executor/execute_grasp")
        err = capfd.readouterr().err
        assert (f"the remap of action executor/execute_grasp to /go is not applied (rclpy remaps "
                f"no action names): the action is {namespace}/executor/execute_grasp") in err
    finally:
        node.destroy_node()


def test_ros2_param_describe_shows_the_range_each_node_enforces(ros_context: Context):
    """``ros2 param describe /executor max_velocity`` showed only "read at start-up: restart
    the node to change it": the range a value must be in (refused at start-up and by
    ``ros2 param set``) was in no description. Now the additional constraints say it, in the
    words of the refusal, for every bounded parameter of every node (``pipeline.declare``).
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter_client import AsyncParameterClient

    from squeeze_grasp_ros.ros.nodes import executor, planner
    from squeeze_grasp_ros.ros.nodes.pipeline import READ_AT_START

    namespace = run_namespace()
    args = ["--ros-args", "-r", f"__ns:={namespace}"]
    nodes = [executor.ExecutorNode(context=ros_context, cli_args=args),
             planner.PlannerNode(context=ros_context, cli_args=args)]
    user = rclpy.create_node("describer", context=ros_context, cli_args=args)
    spin = SingleThreadedExecutor(context=ros_context)
    for node in (*nodes, user):
        spin.add_node(node)

    def described(node_name: str, names: list[str]) -> dict[str, str]:
        client = AsyncParameterClient(user, f"{namespace}/{node_name}")
        assert client.wait_for_services(10.0)
        future = client.describe_parameters(names)
        spin.spin_until_future_complete(future, timeout_sec=10.0)
        return {d.name: d.additional_constraints for d in future.result().descriptors}

    try:
        assert described("executor", ["max_velocity", "base_frame", "feedback_every"]) == {
            "max_velocity": f"a finite number > 0 m/s; {READ_AT_START}",
            "base_frame": READ_AT_START, "feedback_every": f"an integer >= 1; {READ_AT_START}"}
        assert described("planner", ["max_pending", "min_step"]) == {
            "max_pending": "an integer >= 0", "min_step": f"a finite number > 0; {READ_AT_START}"}
    finally:
        spin.shutdown()
        for node in (*nodes, user):
            node.destroy_node()
