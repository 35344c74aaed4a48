# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Blocking calls to the planner from a script, a benchmark or a test, without extra threads.

:class:`PlannerClient` spins the given executor in the calling thread until a response
arrives (a ``spin_once`` loop with a deadline: rclpy 7.1.6's ``spin_until_future_complete``
leaves tasks behind when used in a loop, docs/design.md §5), or with the caller's own wait
(``squeeze-grasp run`` checks for Ctrl-C, dead node processes and foreign traffic while it
waits). Across processes the first request can be lost even after the service is discovered;
``attempts`` re-sends it (the planner's requests are idempotent).
"""
from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from rclpy.client import Client
from rclpy.executors import Executor
from rclpy.node import Node

Wait = Callable[[Callable[[], bool], float], None]
"""``wait(done, timeout)``: spin until ``done()``; raise TimeoutError after ``timeout`` s."""


class PlannerClient:
    """Service clients of one planner, spun by the caller's thread.

    Parameters
    ----------
    node : Node
        The node that owns the clients (already added to ``executor``).
    executor : Executor
        Spun by :meth:`spin_until`; it may also carry the planner itself (one process).
    planner_name : str
        Name of the planner node, e.g. ``/planner`` (a relative name resolves in ``node``'s
        namespace).
    wait : callable, optional
        How to wait (:data:`Wait`); default :meth:`spin_until`.
    """

    def __init__(self, node: Node, executor: Executor, planner_name: str = "/planner", *,
                 wait: Wait | None = None) -> None:
        self.node = node
        self.executor = executor
        self.planner_name = planner_name
        self.wait = wait or self.spin_until
        self._clients: dict[str, Client] = {}

    def client(self, srv_type: Any, name: str, timeout: float = 30.0) -> Client:
        """A (cached) client of service ``<planner>/<name>`` that has found its server.

        Raises
        ------
        TimeoutError
            If the service does not appear within ``timeout`` s.
        """
        if name not in self._clients:
            client = self.node.create_client(srv_type, f"{self.planner_name}/{name}")
            try:
                self.wait(client.service_is_ready, timeout)
            except TimeoutError:
                self.node.destroy_client(client)
                raise TimeoutError(f"service {self.planner_name}/{name} not available") from None
            self._clients[name] = client
        return self._clients[name]

    def call(self, srv_type: Any, name: str, request: Any, timeout: float = 60.0,
             attempts: int = 1) -> Any:
        """Call ``<planner>/<name>`` and return the response.

        Parameters
        ----------
        srv_type : type
            The service type (e.g. ``PlanSqueeze``).
        name : str
            Service name under the planner.
        request : Any
            The request message.
        timeout : float
            Seconds to wait for the service to appear, and for each attempt.
        attempts : int
            Times the request is sent before giving up.

        Raises
        ------
        TimeoutError
            If no attempt is answered.
        """
        client = self.client(srv_type, name, timeout)
        for attempt in range(attempts):
            future = client.call_async(request)
            try:
                self.wait(future.done, timeout)
            except TimeoutError:
                client.remove_pending_request(future)
                if attempt == attempts - 1:
                    raise
                continue
            return future.result()
        raise ValueError(f"attempts must be >= 1, got {attempts}")

    def spin_until(self, done: Callable[[], bool], timeout: float = 60.0) -> None:
        """Spin the executor in this thread until ``done()``; TimeoutError after ``timeout`` s."""
        deadline = time.monotonic() + timeout
        while not done():
            if time.monotonic() > deadline:
                raise TimeoutError(f"not done within {timeout} s")
            self.executor.spin_once(timeout_sec=0.1)
