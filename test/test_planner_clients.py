# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Several clients of one planner on real rclpy: bursts of requests and goals, shared object
ids, bounded identifiers and abandoned work (issue 34, items 2, 9, 10, 11, 15).
"""
from __future__ import annotations

import time
from collections import Counter
from collections.abc import Iterator

import pytest
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from action_msgs.msg import GoalStatus
from planner_support import BLOB, Harness, planner_threads
from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.srv import LoadObject, PlanSqueeze
from squeeze_grasp_ros.planning import ErrorCode

BURST = 200
"""Requests or goals sent at once (the issue's burst)."""
KEEP_ALL = QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=1,
                      reliability=ReliabilityPolicy.RELIABLE)
"""A burst client's own queue: a client with rclpy's default (keep-last 10) drops responses."""


@pytest.fixture
def planner(ros_context: Context) -> Iterator[Harness]:
    """A planner and a client on one executor spun by the test thread."""
    harness = Harness(ros_context)
    try:
        yield harness
    finally:
        harness.close()
    assert planner_threads() == []


def spin_until_done(harness: Harness, futures: list, timeout: float = 120.0) -> None:
    """Spin the harness until every future is done; fail naming how many were not."""
    deadline = time.monotonic() + timeout
    while not all(f.done() for f in futures):
        assert time.monotonic() < deadline, \
            f"{sum(not f.done() for f in futures)} of {len(futures)} never answered"
        harness.executor.spin_once(0.05)


def burst(harness: Harness, srv_type: type, name: str, requests: list) -> list:
    """Send every request at once from one keep-all client; the responses, in order."""
    client = harness.node.create_client(srv_type, f"{harness.planner_name}/{name}",
                                        qos_profile=KEEP_ALL)
    assert client.wait_for_service(timeout_sec=30.0)
    futures = [client.call_async(r) for r in requests]
    spin_until_done(harness, futures)
    return [f.result() for f in futures]


# --------------------------------------------------------------------------- bursts


def test_a_burst_of_200_plan_squeeze_requests_is_answered_in_full(planner):
    """Before: 105 of 200 answered (a request queue of 100 inside DDS dropped the rest)."""
    planner.load(BLOB, "blob")
    responses = burst(planner, PlanSqueeze, "plan_squeeze", [
        PlanSqueeze.Request(object_id="blob", squeeze_type="stable", depth=1e-3 * (1 + k % 3))
        for k in range(BURST)])
    assert all(r.success for r in responses)
    stiffness = {round(r.stiffness, 9) for r in responses}
    assert len(stiffness) == 1  # one object, one stiffness whatever the depth


def test_a_burst_of_200_loads_gets_200_answers_ok_or_busy(planner):
    """Before: 16 OK, 94 BUSY and 90 never answered. Now every load beyond max_pending (16)
    is answered BUSY at once with the reason, and the others load.
    """
    responses = burst(planner, LoadObject, "load_object", [
        LoadObject.Request(scene_yaml=BLOB, object_id=f"o{k}") for k in range(BURST)])
    codes = Counter(ErrorCode(r.error_code) for r in responses)
    assert set(codes) <= {ErrorCode.OK, ErrorCode.BUSY}, codes
    assert codes[ErrorCode.OK] >= 16 and codes[ErrorCode.BUSY] > 0, codes
    busy = [r.message for r in responses if r.error_code == ErrorCode.BUSY]
    assert all("max_pending" in m and "retry" in m for m in busy)


def test_a_burst_of_200_grasp_map_goals_gets_200_responses_and_results(planner):
    """Before: 20 goal responses and 12 results of 200 (the action server's goal and result
    services kept rclpy's default queue of 10). Every goal is now accepted and ends: SUCCEEDED
    with the map, or ABORTED with error code BUSY and the reason.
    """
    planner.load(BLOB, "blob")
    action = ActionClient(planner.node, GraspMapAction, f"{planner.planner_name}/grasp_map",
                          goal_service_qos_profile=KEEP_ALL,
                          result_service_qos_profile=KEEP_ALL)
    try:
        assert action.wait_for_server(timeout_sec=30.0)
        sent = [action.send_goal_async(GraspMapAction.Goal(object_id="blob", mu=0.4))
                for _ in range(BURST)]
        spin_until_done(planner, sent)
        assert all(f.result().accepted for f in sent)
        results = [f.result().get_result_async() for f in sent]
        spin_until_done(planner, results)
    finally:
        action.destroy()
    outcomes = Counter((r.result().status, ErrorCode(r.result().result.error_code))
                       for r in results)
    assert set(outcomes) <= {(GoalStatus.STATUS_SUCCEEDED, ErrorCode.OK),
                             (GoalStatus.STATUS_ABORTED, ErrorCode.BUSY)}, outcomes
    assert outcomes[(GoalStatus.STATUS_SUCCEEDED, ErrorCode.OK)] >= 16
    maps = {r.result().result.map.pairs for r in results
            if r.result().status == GoalStatus.STATUS_SUCCEEDED}
    assert len(maps) == 1 and maps.pop() > 0
