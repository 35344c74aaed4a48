# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Node parameters as ``ros2 param`` and ``--ros-args -p`` reach them: a value out of its range
is refused at start-up by name and range; a parameter read only at start-up is read-only on the
running node (before, ``ros2 param set`` was accepted and ignored, and ``ros2 param get`` showed
a value the node did not use); the planner's live ``max_pending`` is refused out of range.
"""

from __future__ import annotations

import math
import re
import subprocess
from pathlib import Path

import pytest
import rclpy
from executables import script
from rcl_interfaces.msg import ParameterType
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient

from squeeze_grasp_ros.ros.nodes import (
    ParameterError,
    executor,
    monitor,
    outline,
    recorder,
    sim_hardware,
)
from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode
from squeeze_grasp_ros.ros.nodes.outline import OutlineNode
from squeeze_grasp_ros.ros.nodes.pipeline import READ_AT_START
from squeeze_grasp_ros.ros.nodes.planner import PlannerNode
from squeeze_grasp_ros.ros.nodes.recorder import RecorderNode
from squeeze_grasp_ros.ros.nodes.sim_hardware import SimHardwareNode

TIMEOUT = 30.0


@pytest.mark.parametrize("name, value, message", [
    ("max_pending", -1, "parameter 'max_pending' must be an integer >= 0, got -1"),
    ("worker_threads", 0, "parameter 'worker_threads' must be an integer >= 1, got 0"),
    ("max_nodes", -5, "parameter 'max_nodes' must be an integer >= 1, got -5"),
    ("cache_size", 0, "parameter 'cache_size' must be an integer >= 1, got 0"),
    ("best_count", -3, "parameter 'best_count' must be an integer >= 1, got -3"),
    ("min_step", math.nan, "parameter 'min_step' must be a finite number > 0"),
    ("min_step", 0.0, "parameter 'min_step' must be a finite number > 0"),
])
def test_a_planner_parameter_out_of_range_is_refused_at_start(ros_context: Context, name,
                                                              value, message) -> None:
    """Before, these started a planner that refused every long request (max_pending -1),
    passed a negative best_count on to grasp maps, or failed in ThreadPoolExecutor's own words.
    """
    with pytest.raises(ParameterError, match=message.replace("(", r"\(")):
        PlannerNode(context=ros_context, parameter_overrides=[Parameter(name, value=value)])


MODULES = {"monitor": monitor, "executor": executor, "outline": outline, "recorder": recorder,
           "sim_hardware": sim_hardware}
NODES = {"monitor": MonitorNode, "executor": ExecutorNode, "outline": OutlineNode,
         "recorder": RecorderNode, "sim_hardware": SimHardwareNode}
BOUNDED = [(label, name) for label, module in MODULES.items() for name in module.BOUNDS]


@pytest.mark.parametrize("label, name", BOUNDED)
def test_every_bounded_pipeline_parameter_refuses_a_value_out_of_range(ros_context: Context,
                                                                       label, name) -> None:
    """Before, most of these values started the node: an executor with a NaN or
    negative max_velocity, a monitor whose stale_after was NaN (no reading ever stale), an
    executor whose period of 1e-12 s rounded to a tick of 0 ns...
    """
    module = MODULES[label]
    bound, default = module.BOUNDS[name], module.PARAMETERS[name][0]
    assert bound.why(name, default) is None, "the default is out of its own range"
    hostile = [bound.low - 1] + ([math.nan, math.inf] if isinstance(default, float) else [])
    if bound.above:
        hostile.append(bound.low)
    if bound.low > 0 and isinstance(default, float):
        hostile.append(bound.low / 2)  # below a positive floor (a period of 1e-12 s was 0 ns)
    if bound.high < math.inf:
        hostile.append(bound.high + 1)
    for value in hostile:
        value = float(value) if isinstance(default, float) else int(value)
        with pytest.raises(ParameterError, match=f"parameter '{name}' must be "):
            NODES[label](context=ros_context, parameter_overrides=[Parameter(name, value=value)])


@pytest.mark.parametrize("streams, named", [(["wrench", "force"], "'force'"),
                                             (["pose"], "'pose'"),
                                             (["tactile", "tactile"], "'tactile'")])
def test_the_monitor_refuses_a_stream_that_no_finger_has(ros_context: Context, streams,
                                                         named) -> None:
    """Before: a name that is no sensor stream ('force') started the monitor, whose staleness
    test then waited for that stream's readings for ever (its age inf: every finger stale).
    """
    message = ("parameter 'streams' must list sensor streams among ('wrench', 'tactile') "
               f'(or [""] for none), each once, got {named}')
    with pytest.raises(ParameterError, match=re.escape(message)):
        MonitorNode(context=ros_context, parameter_overrides=[Parameter("streams",
                                                                        value=streams)])
    MonitorNode(context=ros_context, parameter_overrides=[
        Parameter("streams", value=["tactile", ""])]).destroy_node()


def _set(client: AsyncParameterClient, executor, parameter: Parameter):
    """The SetParametersResult of one ``ros2 param set`` through the node's service."""
    future = client.set_parameters([parameter])
    executor.spin_until_future_complete(future, timeout_sec=TIMEOUT)
    assert future.done(), "no answer from the parameter service"
    return future.result().results[0]


def test_ros2_param_set_on_running_nodes(ros_context: Context) -> None:
    planner = PlannerNode(context=ros_context)
    monitor = MonitorNode(context=ros_context)
    user = rclpy.create_node("param_user", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    for node in (planner, monitor, user):
        executor.add_node(node)
    try:
        to_planner = AsyncParameterClient(user, "planner")
        to_monitor = AsyncParameterClient(user, "monitor")
        assert to_planner.wait_for_services(TIMEOUT) and to_monitor.wait_for_services(TIMEOUT)
        refused = _set(to_planner, executor, Parameter("max_pending", value=-1))
        assert not refused.successful
        assert refused.reason == "parameter 'max_pending' must be an integer >= 0, got -1"
        assert planner.get_parameter("max_pending").value == 16
        assert _set(to_planner, executor, Parameter("max_pending", value=3)).successful
        assert planner.get_parameter("max_pending").value == 3
        for client, node, parameter in (
                (to_planner, planner, Parameter("min_step", value=1e-3)),
                (to_planner, planner, Parameter("worker_threads", value=8)),
                (to_monitor, monitor, Parameter("alarm_ratio", value=0.5))):
            before = node.get_parameter(parameter.name).value
            result = _set(client, executor, parameter)
            assert not result.successful
            assert "read-only" in result.reason and parameter.name in result.reason
            assert node.get_parameter(parameter.name).value == before
        future = to_monitor.describe_parameters(["alarm_ratio"])
        executor.spin_until_future_complete(future, timeout_sec=TIMEOUT)
        described = future.result().descriptors[0]
        assert described.read_only
        assert described.additional_constraints == f"a finite number > 0; {READ_AT_START}"
        assert described.type == ParameterType.PARAMETER_DOUBLE
    finally:
        for node in (planner, monitor, user):
            node.destroy_node()
        executor.shutdown()


def test_a_node_process_given_a_value_out_of_range_exits_2_with_one_line() -> None:
    """docs/pipeline.md quotes this line; before, the executor started with max_velocity NaN."""
    out = subprocess.run([script("executor"), "--ros-args", "-p", "max_velocity:=.nan"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 2, out.stderr
    said = "executor: error: parameter 'max_velocity' must be a finite number > 0 m/s, got nan"
    assert out.stderr.strip().splitlines()[-1] == said
    page = (Path(__file__).resolve().parents[1] / "docs" / "pipeline.md").read_text()
    assert f"`{said}`" in " ".join(page.split())


@pytest.mark.parametrize("node, name, value, message", [
    (PlannerNode, "default_solver_route", "bogus",
     "parameter 'default_solver_route': solver_route must be one of ['factorized', 'spectral']"),
    (ExecutorNode, "object_pose", [1.0], "parameter 'object_pose': a pose is 7 finite numbers"),
    (ExecutorNode, "object_pose", [0.0] * 7, "parameter 'object_pose': its orientation qx qy "
                                             "qz qw must be a unit quaternion"),
    (ExecutorNode, "object_pose", [0.0, 0.0, math.nan, 0.0, 0.0, 0.0, 1.0],
     "a pose is 7 finite numbers"),
])
def test_a_parameter_of_the_wrong_shape_is_refused_by_name(ros_context: Context, node, name,
                                                           value, message) -> None:
    """Before: a PlannerError traceback (exit 1) and "not enough values to unpack (expected 7,
    got 1)", which named no parameter; a zero quaternion was published as the object's pose.
    """
    with pytest.raises(ParameterError) as refused:
        node(context=ros_context, parameter_overrides=[Parameter(name, value=value)])
    assert message in str(refused.value)


@pytest.mark.parametrize("program, rule, said", [
    ("planner", "worker_threads:=1.5", "parameter 'worker_threads' must be an integer, got '1.5'"),
    ("executor", "qos_depth:=abc", "parameter 'qos_depth' must be an integer, got 'abc'"),
    ("executor", "object_pose:=[0, 0, 0, 0, 0, 0, 1]",
     "parameter 'object_pose' must be a list of numbers, got '[0, 0, 0, 0, 0, 0, 1]'"),
    ("monitor", "finger_devices:=F1", "parameter 'finger_devices' must be a list of strings, "
                                      "got 'F1'"),
])
def test_a_node_process_given_a_value_of_the_wrong_type_exits_2_with_one_line(program, rule,
                                                                             said) -> None:
    """Before: rclpy's InvalidParameterTypeException traceback, exit 1."""
    out = subprocess.run([script(program), "--ros-args", "-p", rule], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr
    assert out.stderr.strip().splitlines()[-1] == f"{program}: error: {said}"


@pytest.mark.parametrize("node, name, value, message", [
    (PlannerNode, "allowed_roots", "/tmp", "parameter 'allowed_roots' must be a list of strings, "
                                           "got '/tmp'"),
    (MonitorNode, "gripper_pose", "0 0 0", "parameter 'gripper_pose' must be a list of numbers, "
                                           "got '0 0 0'"),
    (MonitorNode, "lockstep", 1, "parameter 'lockstep' must be true or false, got '1'"),
    (MonitorNode, "frame_id", 3, "parameter 'frame_id' must be a string, got '3'"),
    (MonitorNode, "qos_depth", None, "parameter 'qos_depth' must be an integer, got 'None'"),
    (MonitorNode, "mu", "high", "parameter 'mu' must be a number, got 'high'"),
])
def test_every_node_refuses_a_value_of_the_wrong_type_by_name(ros_context: Context, node, name,
                                                              value, message) -> None:
    """One check in ``pipeline.declare`` for every node: an override of another type than the
    parameter's (rclpy's InvalidParameterTypeException before, not a ValueError, so no node
    caught it), and an unset value, which rclpy declares as None without the default.
    """
    with pytest.raises(ParameterError) as refused:
        node(context=ros_context, parameter_overrides=[Parameter(name, value=value)])
    assert str(refused.value) == message


def test_every_parameter_type_has_words_for_its_error() -> None:
    """``pipeline.wrong_type`` names the type of every parameter a node declares."""
    from squeeze_grasp_ros.ros.nodes import planner
    from squeeze_grasp_ros.ros.nodes.pipeline import TYPE_WORDS

    for module in (*MODULES.values(), planner):
        for name, (default, _) in module.PARAMETERS.items():
            expected = (default if isinstance(default, Parameter.Type)
                        else Parameter.Type.from_parameter_value(default))
            assert expected in TYPE_WORDS, (module.__name__, name, expected)
