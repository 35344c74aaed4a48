# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Discovery is asymmetric: a node that has not discovered a publisher yet cannot tell "nobody
publishes it" from "its publisher is on its way", and a client that sees a server cannot know
that the server's writers have matched its readers. Each wait of a lockstep node on a peer is
checked here on real rclpy (docs/reliability.md, Discovery races).
"""
from __future__ import annotations

import importlib.util
import time
from pathlib import Path

import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter

from squeeze_grasp_interfaces.msg import ContactEventArray, MonitorStatus
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.run.graph import run_namespace
from squeeze_grasp_ros.ros.run.processes import ros_arguments

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
NEEDS_CONTROL_MSGS = pytest.mark.skipif(
    importlib.util.find_spec("control_msgs") is None,
    reason="control_msgs is not built: squeeze-grasp ros-setup --control-msgs DIR (DIR a jazzy "
           "checkout of github.com/ros-controls/control_msgs)")


class Spinner:
    """An executor over some nodes, spun until a condition holds (10 s at most)."""

    def __init__(self, context, *nodes: Node) -> None:
        self.executor = SingleThreadedExecutor(context=context)
        self.nodes = list(nodes)
        for node in nodes:
            self.executor.add_node(node)

    def until(self, done, seconds: float = 10.0) -> None:
        deadline = time.monotonic() + seconds
        while not done():
            assert time.monotonic() < deadline, "condition not reached within 10 s"
            self.executor.spin_once(timeout_sec=0.05)

    def close(self) -> None:
        self.executor.shutdown()
        for node in self.nodes:
            node.destroy_node()


def force_curve() -> ContactEventArray:
    """A prediction whose force curve rises from 0 N at 0 m to 4 N at 2 mm on both jaws."""
    return ContactEventArray(force_depths=[0.0, 2e-3], force_f1=[0.0, 4.0],
                             force_f2=[0.0, 4.0])


def executor_node(context, scene: str, awaited: bool, namespace: str):
    from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode

    return ExecutorNode(context=context, cli_args=ros_arguments(namespace), parameter_overrides=[
        Parameter("controller_scene", value=str(SCENES / scene)),
        Parameter("finger_devices", value=["F1:left_jaw", "F2:right_jaw"]),
        Parameter("await_prediction", value=awaited)])


def executor_rig(context, scene: str, awaited: bool):
    """(executor, driver-like peer, spinner) once the peer's ``monitor/status`` publisher and
    its reader of the executor's lockstep output (the jaws' trajectory or ``executor/cycle``)
    have met the executor; in a namespace of their own (an action server or a prediction
    publisher of an earlier test still in the graph would make them ready).
    """
    namespace = run_namespace()
    executor = executor_node(context, scene, awaited, namespace)
    peer = Node("loop_peer", context=context, cli_args=ros_arguments(namespace))
    kept = pipeline.loop_qos(100, kept=True)
    peer.create_publisher(MonitorStatus, pipeline.STATUS, kept)
    output = (executor.jaws or executor.jaw_action).publisher
    peer.create_subscription(output.msg_type, output.topic_name, lambda _: None, kept)
    spin = Spinner(context, executor, peer)
    spin.until(lambda: executor.count_publishers(pipeline.STATUS) > 0
               and output.get_subscription_count() > 0)
    return executor, peer, spin


@pytest.mark.parametrize("awaited", [True, False])
def test_an_executor_awaiting_the_force_curve_is_ready_only_once_it_arrived(ros_context,
                                                                           awaited):
    """The jaws' force curve decides whether the executor refuses a goal beyond the gripper's
    max_force, and the action route's effort. Before, the executor was ready as soon as it
    knew no publisher of ``planner/predicted_events``: across processes, before it had
    discovered the run's latched publisher. With ``await_prediction`` (``run`` sets it) it
    waits for the curve whatever it has discovered; without, it waits only for a publisher it
    knows of.
    """
    executor, peer, spin = executor_rig(ros_context, "sponge_gripper.yaml", awaited)
    try:
        assert executor.count_publishers(pipeline.PREDICTION) == 0
        assert executor.participant.ready() is not awaited
        prediction = peer.create_publisher(ContactEventArray, pipeline.PREDICTION,
                                           pipeline.LATCHED)
        spin.until(lambda: executor.count_publishers(pipeline.PREDICTION) > 0)
        assert not executor.participant.ready()
        prediction.publish(force_curve())
        spin.until(executor.participant.ready)
        assert executor.jaws.plan.at(1e-3) == pytest.approx(2.0)
    finally:
        spin.close()


@NEEDS_CONTROL_MSGS
def test_an_executor_under_a_gripper_action_is_ready_only_with_its_action_server(ros_context):
    """The action route sends one gripper goal at the grasp goal's first cycle; sent before the
    controller's server is there, it is lost and the loop waits for its answer for ever.
    Before, the executor answered the lockstep hello without any action server; now only once
    the server is ready. A goal sent to no server ends at once with the topic named.
    """
    from control_msgs.action import ParallelGripperCommand
    from rclpy.action import ActionServer

    executor, peer, spin = executor_rig(ros_context, "sponge_gripper_parallel.yaml", False)
    try:
        spin.executor.spin_once(timeout_sec=0.5)
        assert not executor.participant.ready()
        answered = []
        executor.jaw_action.send(0.4, 3.0, lambda: answered.append(True), at_ns=0)
        assert answered == [True]
        termination, success, message = executor.jaw_action.outcome
        assert (termination, success) == ("gripper_rejected", False)
        assert (f"no action server on {executor.get_namespace()}/gripper_controller/gripper_cmd"
                " answers") in message
        server = ActionServer(peer, ParallelGripperCommand, "gripper_controller/gripper_cmd",
                              lambda handle: ParallelGripperCommand.Result())
        spin.until(executor.participant.ready)
        server.destroy()
    finally:
        spin.close()


def test_a_publisher_the_recorder_cannot_take_is_named_in_the_recording(ros_context, tmp_path,
                                                                      capfd):
    """In lockstep the recorder reads the loop's topics transient-local; a volatile publisher of
    one (an attached node of another configuration) is never matched, so nothing of it is
    recorded. Before, only rclpy's generic warning said so, and the recording did not; now the
    recorder logs an error naming the topic and the policy and lists it in
    ``metadata.yaml`` (``custom_data.incompatible_publishers``), which ``run`` reports (exit 4).
    A compatible publisher is not listed.
    """
    from squeeze_grasp_interfaces.msg import Tick
    from squeeze_grasp_ros.ros.nodes.recorder import RecorderNode
    from squeeze_grasp_ros.ros.recording.bag import INCOMPATIBLE_KEY, bag_info

    recorder = RecorderNode(context=ros_context, parameter_overrides=[
        Parameter("output", value=str(tmp_path / "bag"))])
    peer = Node("attached_like", context=ros_context)
    peer.create_publisher(MonitorStatus, pipeline.STATUS, pipeline.loop_qos(10))
    peer.create_publisher(Tick, pipeline.TICK, pipeline.loop_qos(10, kept=True))
    spin = Spinner(ros_context, recorder, peer)
    try:
        spin.until(lambda: "/" + pipeline.STATUS in recorder.incompatible)
        spin.executor.spin_once(timeout_sec=0.5)
        assert recorder.incompatible == {"/" + pipeline.STATUS: "durability"}
        recorder.close()
    finally:
        spin.close()
    custom = bag_info(str(tmp_path / "bag"))["custom_data"]
    assert custom[INCOMPATIBLE_KEY] == "{/monitor/status: durability}"
    err = capfd.readouterr().err
    assert ("/monitor/status: a publisher offers a QoS the recorder cannot take (durability; "
            "the recorder asks reliable, transient_local): nothing it publishes is recorded"
            in err)
