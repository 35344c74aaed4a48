# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A planner process stopped by SIGINT or SIGTERM answers the long requests it holds.

Before, the node shut its executor down and then stopped its workers: a load running or queued
at Ctrl-C was never answered, and its client waited for ever (measured: 0 of 4 answered
after 40 s).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
import rclpy
from action_msgs.msg import GoalStatus
from planner_support import BLOB, Harness, big_disk
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.srv import LoadObject
from squeeze_grasp_ros.planning import ErrorCode
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.nodes import planner as planner_module

TIMEOUT = 60.0


def _spin_until(executor: SingleThreadedExecutor, done, timeout: float = TIMEOUT) -> None:
    deadline = time.monotonic() + timeout
    while not done():
        assert time.monotonic() < deadline, "timed out"
        executor.spin_once(0.05)


@contextmanager
def planner_process(tmp_path: Path, *ros_args: str) -> Iterator[subprocess.Popen]:
    """A planner process (``python -m``, ``--ros-args`` ``ros_args``) logging to
    ``tmp_path/planner.log``; killed if it still runs at the end.
    """
    with (tmp_path / "planner.log").open("w") as log:
        process = subprocess.Popen(
            [sys.executable, "-m", "squeeze_grasp_ros.ros.nodes.planner",
             *(("--ros-args", *ros_args) if ros_args else ())],
            stdout=log, stderr=subprocess.STDOUT, env=dict(os.environ))
        try:
            yield process
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()


def assert_exits_cleanly(process: subprocess.Popen, tmp_path: Path) -> None:
    """The stopped planner process exits 0 (its log in the message otherwise)."""
    code = process.wait(timeout=TIMEOUT)
    assert code == 0, (tmp_path / "planner.log").read_text()


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_stopped_planner_answers_its_running_and_queued_loads(
    ros_context: Context, tmp_path: Path, signum: int
) -> None:
    """One worker, at most two long requests: a 20,000-node load running, another queued, and
    a third refused BUSY (which shows the first two are held). Then the signal: the queued
    load is refused CANCELLED, "the planner is shutting down", the running one is answered
    too (cancelled at its next stage, or done), and the process exits 0.
    """
    node = rclpy.create_node("shutdown_probe", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    with planner_process(tmp_path, "-p", "worker_threads:=1", "-p", "max_pending:=2") as process:
        client = node.create_client(LoadObject, "/planner/load_object",
                                    qos_profile=pipeline.request_queue(0))
        assert client.wait_for_service(timeout_sec=TIMEOUT)
        # across processes a first request can be lost: a quick refused load first, re-sent
        while True:
            probe = client.call_async(LoadObject.Request(scene_yaml="object: [", object_id="p"))
            deadline = time.monotonic() + 5.0
            while not probe.done() and time.monotonic() < deadline:
                executor.spin_once(0.05)
            if probe.done():
                break
        held = [client.call_async(LoadObject.Request(scene_yaml=big_disk(20000 + k),
                                                     object_id=f"d{k}")) for k in range(2)]
        busy = client.call_async(LoadObject.Request(scene_yaml=BLOB, object_id="blob"))
        _spin_until(executor, busy.done)  # after the two held ones: the same client's order
        assert busy.result().error_code == ErrorCode.BUSY, busy.result().message
        assert not any(f.done() for f in held), "a 20,000-node load ended before the signal"
        process.send_signal(signum)
        _spin_until(executor, lambda: all(f.done() for f in held))
        running, queued = (f.result() for f in held)
        assert running.success or running.error_code == ErrorCode.CANCELLED, running.message
        assert queued.error_code == ErrorCode.CANCELLED, queued.message
        assert "the planner is shutting down" in queued.message
        assert_exits_cleanly(process, tmp_path)
    node.destroy_node()
    executor.shutdown()


def test_a_stopped_planner_ends_its_running_goal(ros_context: Context, tmp_path: Path) -> None:
    """A grasp-map goal running at SIGINT (signalled on its first feedback) ends ABORTED with
    CANCELLED, "the planner is shutting down", and its client gets that result.
    """
    harness = Harness(ros_context, with_planner=False)
    with planner_process(tmp_path) as process:
        def on_feedback(_message) -> None:
            if process.poll() is None and not signalled:
                signalled.append(True)
                process.send_signal(signal.SIGINT)
        signalled: list[bool] = []
        _, outcome = harness.goal(GraspMapAction, "grasp_map",
                                  GraspMapAction.Goal(scene_yaml=big_disk(15_000), mu=0.3),
                                  on_feedback)
        harness.spin_until(outcome.done, timeout=TIMEOUT)
        result = outcome.result()
        assert signalled and result.status == GoalStatus.STATUS_ABORTED
        assert result.result.error_code == ErrorCode.CANCELLED
        assert "the planner is shutting down" in result.result.message
        assert_exits_cleanly(process, tmp_path)
    harness.close()


def test_a_computation_that_outlasts_the_drain_is_answered_without_it(
    ros_context: Context, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A load inside one uninterruptible stage (a call into C, such as meshing a 50,000-node
    disk) when the planner stops: the drain answers it CANCELLED once its time is up, and the
    worker's late result is dropped. Before, its client waited for ever.
    """
    entered, release = threading.Event(), threading.Event()

    def one_long_stage(*_args, **_kwargs):
        entered.set()
        release.wait(TIMEOUT)
        raise AssertionError("the planner answered from a stage after its drain")
    monkeypatch.setattr(planner_module.planning, "load_cached", one_long_stage)
    harness = Harness(ros_context, parameter_overrides=[Parameter("worker_threads", value=1)])
    try:
        client = harness.client(LoadObject, "load_object")
        answer = client.call_async(LoadObject.Request(scene_yaml=BLOB, object_id="blob"))
        harness.spin_until(entered.is_set, timeout=TIMEOUT)
        harness.planner.drain(harness.executor, timeout=0.3)
        assert answer.done(), "the drain ended without answering the request it held"
        assert answer.result().error_code == ErrorCode.CANCELLED
        assert "did not reach a stage boundary within 0.3 s" in answer.result().message
        assert not harness.planner._awaiting
    finally:
        release.set()
        harness.close()
