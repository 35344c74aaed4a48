# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The nodes' interfaces as the ros2 command line shows them, on real rclpy: what a node says
of its names under namespaces and remaps (``ros2 run ... --ros-args -r``), and what
``ros2 param describe`` shows of its parameters.
"""
from __future__ import annotations

import pytest
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


def test_the_hardware_recorder_subscribes_no_simulation_topic(ros_context: Context, tmp_path):
    """``ros2 topic list`` during ``ros2 launch squeeze_grasp_ros hardware.launch.py
    record:=DIR`` showed ``/clock``, ``/sim/tick``, ``/sim/state``, ``/sim/events``,
    ``/sim/markers`` and ``/recorder/progress``: the hardware launch's recorder subscribed to the
    simulated hardware's topics (and recorded them, had a simulation run in the domain) and
    advertised the lockstep's flow control. Now the launch gives it ``simulation: false``,
    which leaves those topics out, and a recorder outside lockstep advertises no progress.
    """
    import ast
    import re
    from pathlib import Path

    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.nodes import pipeline
    from squeeze_grasp_ros.ros.nodes.recorder import RecorderNode

    repo = Path(__file__).resolve().parents[1]
    launch = ast.parse((repo / "launch" / "hardware.launch.py").read_text(encoding="utf-8"))
    [recorder_call] = [c for c in ast.walk(launch) if isinstance(c, ast.Call)
                       and getattr(c.func, "id", "") == "Node"
                       and any(k.arg == "name" and getattr(k.value, "value", "") == "recorder"
                               for k in c.keywords)]
    parameters = ast.unparse({k.arg: k.value for k in recorder_call.keywords}["parameters"])
    assert "'simulation': False" in parameters and "HARDWARE" in parameters

    namespace = run_namespace()
    node = RecorderNode(context=ros_context, cli_args=["--ros-args", "-r", f"__ns:={namespace}"],
                        parameter_overrides=[
                            Parameter("output", value=str(tmp_path / "bag")),
                            Parameter("lockstep", value=False),
                            Parameter("sensor_qos", value="sensor_data"),
                            Parameter("simulation", value=False)])
    try:
        subscribed = {name for name, _ in node.get_subscriber_names_and_types_by_node(
            "recorder", namespace)}
        published = {name for name, _ in node.get_publisher_names_and_types_by_node(
            "recorder", namespace)}
        simulated = {f"{namespace}/{name.lstrip('/')}" for name in pipeline.SIMULATION_TOPICS}
        assert f"{namespace}/{pipeline.STATUS}" in subscribed
        assert not subscribed & simulated
        assert f"{namespace}/{pipeline.RECORDER_PROGRESS}" not in published
        # the hardware launch's ready line docs/ros.md shows says the same count
        shown = (repo / "docs" / "ros.md").read_text(encoding="utf-8")
        [count] = re.findall(r"recorder ready: recording (\d+) topics into \S+hw_bag", shown)
        assert node.ready_summary().startswith(f"recording {count} topics into")
        node.close()
    finally:
        node.destroy_node()


def test_every_number_and_vector_field_of_the_interfaces_says_its_unit():
    """``ros2 interface show`` prints a field's trailing comment: a float or vector field
    without one (``relative_depth`` of MonitorStatus, ContactEvent and ExecuteGrasp's result and
    feedback, ``poisson_ratio`` of ObjectModel) left its unit, or that it has none, unsaid.
    """
    import re
    from pathlib import Path

    field = re.compile(r"^(float32|float64|geometry_msgs/(?:Vector3|Point|Pose)\w*)(\[\])? "
                       r"(\w+)\s*(#.*)?$")
    bare = []
    for path in sorted((Path(__file__).resolve().parents[1] / "msg_defs").glob("*/*.*")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            match = field.match(line)
            if match and not (match.group(4) or "").strip("# "):
                bare.append(f"{path.name}:{number} {match.group(3)}")
    assert bare == []


TOPIC_PARAMETERS = [
    ("outline", "OutlineNode", {"image_topic": "cam-mask"},
     "parameter 'image_topic': 'cam-mask' is a topic name ROS refuses: topic name must not "
     "contain characters other than alphanumerics, '_', '~', '{', or '}'"),
    ("executor", "ExecutorNode", {"finger_devices": ["F1:left-jaw", "F2:right_jaw"]},
     "parameter 'finger_devices': device 'left-jaw' gives the topic name "
     "'devices/left-jaw/setpoint', which ROS refuses: topic name must not contain characters"),
    ("monitor", "MonitorNode", {"finger_devices": ["F1:left jaw", "F2:right_jaw"]},
     "parameter 'finger_devices': device 'left jaw' gives the topic name "
     "'devices/left jaw/setpoint', which ROS refuses"),
    ("recorder", "RecorderNode", {"devices": ["2jaw"]},
     "parameter 'devices': device '2jaw' gives the topic name 'devices/2jaw/setpoint', which ROS "
     "refuses: topic name token must not start with a number"),
    ("recorder", "RecorderNode", {"extra_topics": ["joint-states sensor_msgs/msg/JointState"]},
     "parameter 'extra_topics': 'joint-states' is a topic name ROS refuses"),
    ("planner", "PlannerNode", {"frame_pose_topic": "table-pose", "frame_pose_frame": "table"},
     "parameter 'frame_pose_topic': 'table-pose' is a topic name ROS refuses"),
]
"""(module, node class, parameters, the refusal) of a topic name ROS refuses in a parameter."""


@pytest.mark.parametrize("module, node, values, said", TOPIC_PARAMETERS)
def test_a_topic_name_ros_refuses_is_refused_by_parameter(ros_context: Context, tmp_path,
                                                          module, node, values, said):
    """``image_topic:=cam-mask``, a device ``left-jaw`` and the like ended the node with
    rclpy's InvalidTopicNameException traceback (exit 1), naming no parameter, when it created
    the publisher or subscription; now the parameter is refused by name with rcl's reason.
    """
    import importlib

    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.nodes import ParameterError

    factory = getattr(importlib.import_module(f"squeeze_grasp_ros.ros.nodes.{module}"), node)
    overrides = [Parameter(name, value=value) for name, value in values.items()]
    if module == "recorder":
        overrides.append(Parameter("output", value=str(tmp_path / "bag")))
    with pytest.raises(ParameterError) as refused:
        factory(context=ros_context, parameter_overrides=overrides)
    assert said in str(refused.value)


def test_a_node_process_given_a_device_ros_cannot_name_exits_2_with_one_line():
    """``ros2 run squeeze_grasp_ros executor --ros-args -p "finger_devices:=['F1:left-jaw',
    'F2:b']"`` printed a traceback and ``[ros2run]: Process exited with failure 1``.
    """
    import subprocess

    from executables import script

    out = subprocess.run([script("executor"), "--ros-args", "-p",
                          "finger_devices:=['F1:left-jaw', 'F2:b']"], capture_output=True,
                         text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr
    assert out.stderr.strip().splitlines() == [
        "executor: error: parameter 'finger_devices': device 'left-jaw' gives the topic name "
        "'devices/left-jaw/setpoint', which ROS refuses: topic name must not contain characters "
        "other than alphanumerics, '_', '~', '{', or '}'"]


def test_a_hardware_monitor_without_readings_says_so(ros_context: Context):
    """``ros2 topic echo /monitor/status`` of a hardware monitor that has had no reading showed
    the alarm message ``newest F1 reading is inf ms old``; now ``no F1 reading yet`` (the value
    stays inf, the status's sensor age 1e300, as the interface comments now say).
    """
    import time

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    from squeeze_grasp_interfaces.msg import MonitorStatus
    from squeeze_grasp_ros.ros.messages import UNSEEN_AGE
    from squeeze_grasp_ros.ros.nodes import pipeline
    from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode

    args = ["--ros-args", "-r", f"__ns:={run_namespace()}"]
    node = MonitorNode(context=ros_context, cli_args=args, parameter_overrides=[
        Parameter("lockstep", value=False), Parameter("sensor_qos", value="sensor_data")])
    reader = rclpy.create_node("status_reader", context=ros_context, cli_args=args)
    got: list[MonitorStatus] = []
    reader.create_subscription(MonitorStatus, pipeline.STATUS, got.append, 10)
    spin = SingleThreadedExecutor(context=ros_context)
    for n in (node, reader):
        spin.add_node(n)
    try:
        deadline = time.monotonic() + 30
        while not got:
            assert time.monotonic() < deadline, "no monitor status within 30 s"
            spin.spin_once(0.05)
        status = got[0]
        assert list(status.sensor_age) == [UNSEEN_AGE, UNSEEN_AGE]
        assert [(a.type, a.finger, a.message) for a in status.alarms] == [
            ("stale_sensor", "F1", "no F1 reading yet"),
            ("stale_sensor", "F2", "no F2 reading yet")]
    finally:
        spin.shutdown()
        for n in (node, reader):
            n.destroy_node()


def test_a_remapped_lockstep_input_still_makes_the_node_ready(ros_context: Context):
    """``ros2 run squeeze_grasp_ros executor --ros-args -r monitor/status:=...`` (and the
    monitor so remapped) never answered the simulated hardware's hello, so the lockstep never
    started: its readiness counted the publishers of ``monitor/status`` by the name before the
    remap (rclpy's ``count_publishers`` applies no remap rule). Now the executor is ready once
    its remapped input has a publisher.
    """
    import time

    import rclpy
    from geometry_msgs.msg import PoseStamped
    from rclpy.executors import SingleThreadedExecutor

    from squeeze_grasp_interfaces.msg import MonitorStatus
    from squeeze_grasp_ros.ros.nodes import pipeline
    from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode

    namespace = run_namespace()
    status = f"{namespace}/remapped_status"
    node = ExecutorNode(context=ros_context, cli_args=[
        "--ros-args", "-r", f"__ns:={namespace}", "-r", f"{pipeline.STATUS}:={status}"])
    peer = rclpy.create_node("monitor_like", context=ros_context, namespace=namespace)
    peer.create_publisher(MonitorStatus, status, pipeline.loop_qos(10))
    for device in ("barrett_f1", "barrett_f3"):  # the driver side of the executor's outputs
        peer.create_subscription(PoseStamped, pipeline.device_topic(device, "setpoint"),
                                 lambda _: None, pipeline.loop_qos(10))
    spin = SingleThreadedExecutor(context=ros_context)
    for n in (node, peer):
        spin.add_node(n)
    try:
        deadline = time.monotonic() + 20
        while not node.participant.ready():
            assert time.monotonic() < deadline, "the executor never became ready"
            spin.spin_once(0.05)
    finally:
        spin.shutdown()
        for n in (node, peer):
            n.destroy_node()
