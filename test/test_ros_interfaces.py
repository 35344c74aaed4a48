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
