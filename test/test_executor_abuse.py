# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor's ``ExecuteGrasp`` action under bursts and abuse, on real rclpy and on the
``EventsExecutor`` that ``ros2 run`` spins it with: goals sent at once from several clients,
goals while one runs, cancels, goals with garbage fields. Every request is answered, one goal
runs at a time, a bad field is named in one short message, and the node serves on.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
from geometry_msgs.msg import Point, Vector3
from rclpy.action import ActionClient
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.msg import Alarm, MonitorStatus
from squeeze_grasp_ros.control.motion import MAX_TRAVEL, GraspGoal, goal_problem
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import SPIN_PERIOD, Spinner, pipeline
from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode

QUEUES = {f"{kind}_service_qos_profile": pipeline.request_queue(0)
          for kind in ("goal", "cancel", "result")}
"""A burst client's own queues: keep-all, or its responses are dropped on its side
(docs/reliability.md, Planner request queues)."""


class Rig:
    """An executor node, a client node with ``clients`` action clients, and a monitor-like
    publisher of ``monitor/status`` that drives the executor's lockstep cycles.
    """

    def __init__(self, context, clients: int, **parameters) -> None:
        self.spinner = EventsExecutor(context=context)
        self.node = ExecutorNode(context=context, parameter_overrides=[
            Parameter(name, value=value) for name, value in parameters.items()])
        self.peer = Node("abuser", context=context)
        self.status = self.peer.create_publisher(MonitorStatus, pipeline.STATUS,
                                                 pipeline.loop_qos(100))
        self.clients = [ActionClient(self.peer, ExecuteGrasp, pipeline.ACTION, **QUEUES)
                        for _ in range(clients)]
        for node in (self.node, self.peer):
            self.spinner.add_node(node)
        self.tick = 0
        self.until(lambda: all(c.server_is_ready() for c in self.clients)
                   and self.node.count_publishers(pipeline.STATUS) > 0)

    def until(self, done, seconds: float = 30.0) -> bool:
        deadline = time.monotonic() + seconds
        while not done() and time.monotonic() < deadline:
            self.spinner.spin_once(timeout_sec=0.05)
        return done()

    def publish_status(self) -> None:
        """The status of the next tick: both fingers seen, still, 5 cm either side."""
        msg = MonitorStatus(fingers=["F1", "F2"],
                            positions=[Point(x=-0.05), Point(x=0.05)],
                            forces=[Vector3(), Vector3()], normals=[Vector3(), Vector3()],
                            sensor_age=[0.0, 0.0])
        messages.set_stamp(msg.header.stamp, self.tick * 1_000_000)
        self.tick += 1
        self.status.publish(msg)

    def result_of(self, handle) -> ExecuteGrasp.Result:
        """Drive cycles until the goal's result is here."""
        future = handle.get_result_async()

        def done() -> bool:
            if not future.done():
                self.publish_status()
            return future.done()
        assert self.until(done), "the goal's result never came"
        return future.result().result

    def close(self) -> None:
        for client in self.clients:
            client.destroy()
        self.spinner.shutdown()
        self.node.destroy_node()
        self.peer.destroy_node()


def squeeze(**fields) -> ExecuteGrasp.Goal:
    """The foam square's squeeze, 1 mm along x, with ``fields`` replaced."""
    goal = ExecuteGrasp.Goal(fingers=["F1", "F2"], directions=[Vector3(x=1.0), Vector3(x=-1.0)],
                             depth=1e-3)
    for name, value in fields.items():
        setattr(goal, name, value)
    return goal


@pytest.fixture
def rig(ros_context):
    rig = Rig(ros_context, clients=3)
    yield rig
    rig.close()


def test_a_burst_of_goals_from_three_clients_is_answered_in_full_and_one_runs(rig):
    """60 goals at once (3 clients x 20) at an idle executor: before, 10 were answered (the
    goal service's queue of 10 dropped the rest, the clients waited for ever) and on
    ``EventsExecutor`` all 10 answered were accepted, each replacing the previous one as the
    running goal (their results never came). Now 60 answers, one accepted; cancelled it ends
    ``canceled``, and the executor takes the next goal.
    """
    futures = [client.send_goal_async(squeeze()) for client in rig.clients for _ in range(20)]
    assert rig.until(lambda: all(f.done() for f in futures)), \
        f"{sum(not f.done() for f in futures)} of 60 goals never answered"
    accepted = [f.result() for f in futures if f.result().accepted]
    assert len(accepted) == 1
    handle = accepted[0]
    rig.publish_status()
    assert rig.until(lambda: rig.node.goal is not None and rig.node.goal.start_ns is not None)
    busy = [rig.clients[1].send_goal_async(squeeze()) for _ in range(5)]
    assert rig.until(lambda: all(f.done() for f in busy))
    assert not any(f.result().accepted for f in busy)
    cancel = handle.cancel_goal_async()
    assert rig.until(cancel.done)
    result = rig.result_of(handle)
    assert result.termination == ExecuteGrasp.Result.CANCELED
    again = rig.clients[2].send_goal_async(squeeze())
    assert rig.until(again.done) and again.result().accepted
    again.result().cancel_goal_async()
    assert rig.result_of(again.result()).termination == ExecuteGrasp.Result.CANCELED


GARBAGE = [
    ("depth", {"depth": math.nan}),
    ("depth", {"depth": math.inf}),
    ("depth", {"depth": -1e-3}),
    ("relative_per_depth", {"relative_per_depth": math.nan}),
    ("relative_per_depth", {"relative_per_depth": -14.1}),
    ("depth", {"depth": 1.0, "relative_per_depth": 14.1421}),
    ("depth", {"depth": 0.0708, "relative_per_depth": 14.1421}),
    ("fingers", {"fingers": []}),
    ("fingers", {"fingers": ["F1", "F1"]}),
    ("finger", {"fingers": ["F1", "F9"]}),
    ("finger", {"fingers": ["F1", "x" * 1_000_000]}),
    ("directions", {"directions": [Vector3(x=math.nan), Vector3(x=-1.0)]}),
    ("directions", {"directions": [Vector3(x=1.0)]}),
    ("directions", {"directions": [Vector3(), Vector3()]}),
    ("on_slip_alarm", {"on_slip_alarm": "explode"}),
    ("on_slip_alarm", {"on_slip_alarm": "y" * 1_000_000}),
    ("pure_directions", {"on_slip_alarm": "pure"}),
    ("resqueeze_margin", {"on_slip_alarm": "resqueeze", "resqueeze_margin": 1.5}),
    ("release_clearance", {"on_slip_alarm": "resqueeze", "release_clearance": -math.inf}),
    # resist without an adversary: before, the squeeze ran alone and ended depth_reached
    ("adversary", {"resist": True}),
    ("adversary", {"resist": True, "adversary": "F2"}),
    ("adversary", {"resist": True, "adversary": "z" * 1_000_000}),
    # finite but beyond MAX_TRAVEL: before, 1e308 was accepted and its first cycle raised
    # OverflowError in the motion profile, ending the executor process
    ("depth", {"depth": 1e308}),
    ("depth", {"depth": 11.0}),
    ("pure_directions", {"on_slip_alarm": "pure",
                         "pure_directions": [Vector3(x=1e300), Vector3(x=-1.0)]}),
    ("release_clearance", {"on_slip_alarm": "resqueeze", "release_clearance": 1e308}),
]


def test_goals_with_garbage_fields_end_invalid_naming_the_field_and_the_node_serves_on(rig):
    """Each goal with one bad field (NaN, inf, negative, empty, unknown, repeated, a 1 MB
    string) is answered: accepted, then aborted ``invalid_goal`` with a message naming the
    field and quoting at most 40 characters of what was sent; afterwards a good goal runs.
    """
    for field, fields in GARBAGE:
        future = rig.clients[0].send_goal_async(squeeze(**fields))
        assert rig.until(future.done), f"{field}: the goal was never answered"
        handle = future.result()
        assert handle.accepted, field
        result = rig.result_of(handle)
        assert (result.termination, result.success) == (ExecuteGrasp.Result.INVALID_GOAL,
                                                        False), (field, result.message)
        assert field in result.message, (field, result.message)
        assert len(result.message) < 200, (field, len(result.message))
    assert_the_next_goal_runs(rig)


@pytest.mark.parametrize("lockstep", [True, False])
def test_a_goal_canceled_before_any_status_ends_at_once(ros_context, lockstep):
    """A goal accepted while no monitor status comes (the loop or the monitor stopped) and
    then canceled: before, the cancel was accepted and the goal never ended (it waited for a
    status to run its cycle). Now it ends ``canceled``, having commanded nothing.
    """
    rig = Rig(ros_context, clients=1, lockstep=lockstep, stale_budget=60.0)
    try:
        future = rig.clients[0].send_goal_async(squeeze())
        assert rig.until(future.done) and future.result().accepted
        assert rig.until(lambda: rig.node.goal is not None)
        result = future.result().get_result_async()
        cancel = future.result().cancel_goal_async()
        assert rig.until(lambda: cancel.done() and result.done(), seconds=10.0), \
            "the canceled goal never ended"
        assert result.result().result.termination == ExecuteGrasp.Result.CANCELED
        assert "nothing was commanded" in result.result().result.message
    finally:
        rig.close()


def test_a_goal_canceled_before_its_execution_starts_ends_at_once(ros_context):
    """The execution of an accepted goal is a later rclpy task, so a cancel can be taken
    before it starts, when the executor has no goal to end yet. Here the execution is held
    back until the cancel was accepted (the action server's accepted callback defers it): in
    lockstep with no monitor status, the goal waited for ever; now it ends ``canceled``.
    """
    rig = Rig(ros_context, clients=1, lockstep=True, stale_budget=60.0)
    held = []
    rig.node.server.register_handle_accepted_callback(held.append)
    try:
        future = rig.clients[0].send_goal_async(squeeze())
        assert rig.until(lambda: future.done() and held) and future.result().accepted
        cancel = future.result().cancel_goal_async()
        assert rig.until(cancel.done) and rig.node.goal is None
        result = future.result().get_result_async()
        held[0].execute()
        assert rig.until(result.done, seconds=10.0), "the canceled goal never ended"
        assert result.result().result.termination == ExecuteGrasp.Result.CANCELED
        assert "nothing was commanded" in result.result().result.message
    finally:
        rig.close()


def test_a_hardware_goal_without_any_monitor_status_ends_after_the_stale_budget(ros_context):
    """Hardware mode (wall-clock cycles), no monitor at all: before, the goal waited for ever;
    now it ends ``stale_data`` after ``stale_budget`` s, naming the topic it waited for.
    """
    rig = Rig(ros_context, clients=1, lockstep=False, stale_budget=0.2)
    try:
        future = rig.clients[0].send_goal_async(squeeze())
        assert rig.until(future.done) and future.result().accepted
        result = future.result().get_result_async()
        assert rig.until(result.done, seconds=10.0), "the goal never ended"
        ended = result.result().result
        assert ended.termination == ExecuteGrasp.Result.STALE_DATA
        assert "no /monitor/status message within stale_budget 0.2 s" in ended.message
    finally:
        rig.close()


BAD_STATUSES = {
    "a finger the monitor does not watch": {"fingers": ["Z9", "F2"]},
    "arrays shorter than its fingers": {"positions": [Point(x=0.05)], "forces": [Vector3()],
                                        "normals": [Vector3()], "fingers": ["F2", "F1"]},
    "a NaN position": {"positions": [Point(x=math.nan), Point(x=0.05)]},
    "an infinite force": {"forces": [Vector3(x=math.inf), Vector3()]},
}


@pytest.mark.parametrize("case", list(BAD_STATUSES))
def test_a_status_without_a_usable_finger_ends_the_goal_and_the_node_serves_on(rig, case):
    """A running goal, then a ``monitor/status`` without a finite position and force of one
    of the executor's fingers (a monitor whose ``finger_devices`` leave one out, or garbage):
    the goal ends ``stale_data`` naming the finger, and the next goal runs. Before, a missing
    finger ended the executor process (KeyError in the control step), a short array was read
    from the bytes after it, and a NaN made the goal's work NaN.
    """
    future = rig.clients[0].send_goal_async(squeeze())
    assert rig.until(future.done) and future.result().accepted
    rig.publish_status()
    assert rig.until(lambda: rig.node.goal is not None and rig.node.goal.start_ns is not None)
    bad = MonitorStatus(fingers=["F1", "F2"], positions=[Point(x=-0.05), Point(x=0.05)],
                        forces=[Vector3(), Vector3()], normals=[Vector3(), Vector3()],
                        sensor_age=[0.0, 0.0])
    for name, value in BAD_STATUSES[case].items():
        setattr(bad, name, value)
    messages.set_stamp(bad.header.stamp, rig.tick * 1_000_000)
    rig.tick += 1
    rig.status.publish(bad)
    result = rig.result_of(future.result())
    assert result.termination == ExecuteGrasp.Result.STALE_DATA, result.message
    assert "has no finite position and force of F1" in result.message, result.message
    assert all(math.isfinite(w) for w in result.work)
    assert_the_next_goal_runs(rig)


def assert_the_next_goal_runs(rig: Rig) -> None:
    """A plain goal after an abuse is accepted, starts on the next status and cancels."""
    future = rig.clients[0].send_goal_async(squeeze())
    assert rig.until(future.done) and future.result().accepted
    rig.publish_status()
    assert rig.until(lambda: rig.node.goal is not None and rig.node.goal.start_ns is not None)
    future.result().cancel_goal_async()
    assert rig.result_of(future.result()).termination == ExecuteGrasp.Result.CANCELED


def _hardware_status(rig: Rig, ns: int, alarm: str = "") -> None:
    """A status stamped ``ns`` (both fingers still, 5 cm either side), with an ``alarm`` of F1."""
    msg = MonitorStatus(fingers=["F1", "F2"], positions=[Point(x=-0.05), Point(x=0.05)],
                        forces=[Vector3(), Vector3()], normals=[Vector3(), Vector3()],
                        sensor_age=[0.0, 0.0])
    if alarm:
        msg.alarms = [Alarm(type=alarm, finger="F1")]
    messages.set_stamp(msg.header.stamp, ns)
    rig.status.publish(msg)


def test_a_hardware_goal_hears_the_monitor_after_its_clock_stepped_back(ros_context):
    """Hardware mode: statuses at 100 s, then the monitor's clock steps back to 1 s and it
    reports ``slip_imminent``. Before, every status after the step was dropped as older than
    the last, and the goal ran on, deaf to the alarm; now it ends ``slip_alarm``.
    """
    rig = Rig(ros_context, clients=1, lockstep=False, stale_budget=1.0)
    try:
        future = rig.clients[0].send_goal_async(squeeze(depth=0.02))
        assert rig.until(future.done) and future.result().accepted
        result = future.result().get_result_async()
        k = 0

        def started() -> bool:
            nonlocal k
            _hardware_status(rig, 100 * 10**9 + k * 1000)
            k += 1
            return rig.node.goal is not None and rig.node.goal.start_ns is not None
        assert rig.until(started)
        rig.until(lambda: False, 0.1)  # it cycles on the statuses of 100 s
        k = 0

        def alarmed() -> bool:
            nonlocal k
            _hardware_status(rig, 10**9 + k * 1000, "slip_imminent")  # 1 us apart: below 100 s
            k += 1
            return result.done()
        assert rig.until(alarmed, 5.0), "the goal never heard the alarm"
        assert result.result().result.termination == ExecuteGrasp.Result.SLIP_ALARM
    finally:
        rig.close()


def test_a_hardware_goal_whose_monitor_stops_ends_after_the_stale_budget(ros_context):
    """Hardware mode: statuses for 0.2 s, then none (the monitor stopped). Before, the goal ran
    on its last status, commanding the squeeze without feedback; now it ends ``stale_data``
    once no status came for ``stale_budget`` s.
    """
    rig = Rig(ros_context, clients=1, lockstep=False, stale_budget=0.3)
    try:
        future = rig.clients[0].send_goal_async(squeeze(depth=0.02))
        assert rig.until(future.done) and future.result().accepted
        result = future.result().get_result_async()
        for k in range(20):
            _hardware_status(rig, 100 * 10**9 + k * 10**7)
            rig.until(lambda: False, 0.01)
        assert not result.done()
        assert rig.until(result.done, 5.0), "the goal ran on without a monitor"
        ended = result.result().result
        assert ended.termination == ExecuteGrasp.Result.STALE_DATA
        assert "no /monitor/status message for" in ended.message
        assert "more than stale_budget 0.3 s" in ended.message
    finally:
        rig.close()


def test_a_resistance_beyond_the_longest_travel_is_refused():
    """The adversary's translation and the resistance waypoints, finite but beyond
    ``MAX_TRAVEL`` (10 m): before, accepted (their profile overflowed as the depth's did).
    """
    base = dict(fingers=("F1", "F2"), directions=np.array([[1.0, 0.0], [-1.0, 0.0]]),
                depth=1e-3, adversary="A", resist_travel=np.array([1e300]),
                adversary_translation=np.array([1e300, 0.0]),
                resist_waypoints=np.zeros((1, 2, 2)))
    far = goal_problem(GraspGoal(**base), ["F1", "F2", "A"])
    assert far == f"adversary_translation must be a nonzero vector of at most {MAX_TRAVEL:g} m"
    waypoints = np.full((1, 2, 2), 1e300)
    far = goal_problem(GraspGoal(**{**base, "adversary_translation": np.array([0.01, 0.0]),
                                    "resist_travel": np.array([0.01]),
                                    "resist_waypoints": waypoints}), ["F1", "F2", "A"])
    assert far == f"resist_waypoints must hold 1 x 2 vectors of at most {MAX_TRAVEL:g} m"


def test_a_waiting_hardware_goal_does_not_make_the_nodes_spin_poll(ros_context):
    """A hardware-mode goal with no monitor status (stale_budget 60 s) waits: the executor's
    execute coroutine is suspended. Spun as ``run_node`` spins it (:class:`Spinner`), the
    ``EventsExecutor`` returns about once a ``SPIN_PERIOD`` while the node's control timer runs
    on and the cancel is served. Before, ``run_node``'s ``spin_once`` loop returned about
    90,000 times a second for as long as a goal ran: each call first resumed the suspended
    coroutine (the executor node's thread at 76 % CPU during a hardware goal).
    """
    rig = Rig(ros_context, clients=1, lockstep=False, stale_budget=60.0)
    try:
        sent = rig.clients[0].send_goal_async(squeeze())
        assert rig.until(sent.done) and sent.result().accepted
        assert rig.until(lambda: rig.node.goal is not None and rig.node.timer_at is not None)
        spin = Spinner(rig.spinner, rig.node)
        spins, start, timer_at = 0, time.monotonic(), rig.node.timer_at
        while time.monotonic() - start < 1.0:
            spin()
            spins += 1
        assert spins <= 1.0 / SPIN_PERIOD + 3, f"{spins} spins in 1 s: the spin polls"
        assert rig.node.goal is not None, "the goal ended: it should still wait"
        assert rig.node.timer_at - timer_at > 0.5, "the control timer stopped running"
        sent.result().cancel_goal_async()
        result = sent.result().get_result_async()
        deadline = time.monotonic() + 10.0
        while not result.done() and time.monotonic() < deadline:
            spin()
        assert result.done(), "the cancel was not served"
        assert result.result().result.termination == ExecuteGrasp.Result.CANCELED
    finally:
        rig.close()
