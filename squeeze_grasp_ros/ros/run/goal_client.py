# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ``ExecuteGrasp`` action client of a run, robust to responses lost across processes.

The goal ids are the client's, so a goal whose acceptance shows on the action's status topic
counts as accepted even if the response never came; a request unanswered for
``GOAL_RESPONSE_TIMEOUT`` is sent again with a new id, and whichever is accepted first is the
goal (the executor rejects the others while it runs one). A result whose goal the status topic
reports finished but whose response does not come is requested again.
"""
from __future__ import annotations

import time
import uuid
from collections.abc import Callable
from typing import Any

from action_msgs.msg import GoalStatus, GoalStatusArray
from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from rclpy.node import Node
from unique_identifier_msgs.msg import UUID

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.run.options import RunError

__all__ = ["FINISHED", "GOAL_RESPONSE_TIMEOUT", "GoalClient"]

GOAL_RESPONSE_TIMEOUT = 5.0
"""Wall-clock seconds to wait for a goal (or result) response before checking the status."""
FINISHED = (GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_ABORTED, GoalStatus.STATUS_CANCELED)

Spin = Callable[[Callable[[], bool], float, str], None]
"""``spin_until(done, timeout, what)`` of the run: spins until ``done()`` or raises."""


class GoalClient:
    """Send one goal, follow its status, cancel it, collect its result.

    Parameters
    ----------
    node : Node
        The run's client node.
    feedback : callable
        Called with every feedback message.
    """

    def __init__(self, node: Node, feedback: Callable[[Any], None]) -> None:
        self.action = ActionClient(node, ExecuteGrasp, pipeline.ACTION)
        self.feedback = feedback
        self.statuses: dict[bytes, int] = {}
        node.create_subscription(GoalStatusArray, f"{pipeline.ACTION}/_action/status",
                                 self._on_status, pipeline.LATCHED)
        self.handle: ClientGoalHandle | None = None
        self.result_future = None

    def _on_status(self, msg: GoalStatusArray) -> None:
        for status in msg.status_list:
            self.statuses[bytes(status.goal_info.goal_id.uuid)] = status.status

    def status_of(self, goal_id: UUID) -> int | None:
        """The last status the status topic reported for ``goal_id``, or None."""
        return self.statuses.get(bytes(goal_id.uuid))

    def _accepted(self, sent: list) -> ClientGoalHandle | None:
        """The goal handle of the first request known to be accepted (by its response or by
        the status topic), or None.
        """
        for goal_id, future in sent:
            if future.done() and future.result().accepted:
                return future.result()
            if self.status_of(goal_id) is not None:
                return ClientGoalHandle(
                    self.action, goal_id, ExecuteGrasp.Impl.SendGoalService.Response(accepted=True)
                )
        return None

    def send(self, msg: ExecuteGrasp.Goal, spin_until: Spin, timeout: float) -> None:
        """Send ``msg`` and wait until the executor accepted it (raises :class:`RunError`)."""
        deadline = time.monotonic() + timeout
        sent: list = []
        handle = None
        while handle is None:
            goal_id = UUID(uuid=list(uuid.uuid4().bytes))
            sent.append(
                (goal_id, self.action.send_goal_async(msg, self.feedback, goal_uuid=goal_id))
            )
            retry = min(time.monotonic() + GOAL_RESPONSE_TIMEOUT, deadline)
            spin_until(
                lambda: (
                    self._accepted(sent) is not None
                    or all(f.done() for _, f in sent)
                    or time.monotonic() > retry
                ),
                timeout,
                "the goal to be accepted",
            )
            handle = self._accepted(sent)
            if handle is None and all(f.done() for _, f in sent):
                settle = time.monotonic() + GOAL_RESPONSE_TIMEOUT
                spin_until(
                    lambda: self._accepted(sent) is not None or time.monotonic() > settle,
                    timeout,
                    "the status of the goal requests",
                )
                handle = self._accepted(sent) or sent[-1][1].result()
            if handle is None and time.monotonic() > deadline:
                raise RunError("the executor never answered the goal request")
        if not handle.accepted:
            raise RunError("the executor rejected the goal")
        self.handle = handle
        self.result_future = handle.get_result_async()

    def cancel(self) -> None:
        """Ask the executor to cancel the goal (it holds position)."""
        self.handle.cancel_goal_async()

    def result(self, spin_until: Spin, timeout: float,
               cancel_when: Callable[[], bool]) -> ExecuteGrasp.Result:
        """Spin until the goal's result; cancel the goal once ``cancel_when()`` is true."""
        deadline = time.monotonic() + timeout
        cancelled = False
        while not self.result_future.done():
            if not cancelled and cancel_when():
                cancelled = True
                self.cancel()
            ended = [time.monotonic()] if self.status_of(self.handle.goal_id) in FINISHED else []
            spin_until(
                lambda: (
                    self.result_future.done()
                    or (ended and time.monotonic() > ended[0] + GOAL_RESPONSE_TIMEOUT)
                    or (not ended and self.status_of(self.handle.goal_id) in FINISHED)
                    or (not cancelled and cancel_when())
                ),
                max(deadline - time.monotonic(), 0.0),
                "the goal's result",
            )
            if not self.result_future.done() and ended:
                self.result_future = self.handle.get_result_async()
        return self.result_future.result().result
