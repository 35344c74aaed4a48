# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Where one lockstep tick's time goes, by node and by stage, in a one-process run.

:class:`TickProfile` wraps, after :meth:`.runner.PipelineRunner.start`, every subscription
callback and every publisher's rclpy handle of the run's nodes (the client included) with a
wall-clock timer. rclpy looks both up at every call, so the nodes run unchanged. By node:

- ``deserialise``: what rclpy's conversion of the received messages costs: the number of
  messages each subscription received times the ``deserialize_message`` time of the last one
  (timed after the run; raw subscriptions take bytes and cost nothing here);
- ``logic``: time inside the node's callbacks, minus its publishing, minus (for
  ``sim_hardware``) the mechanics step (reported apart, as ``mechanics``);
- ``publish``: time inside the publisher's rclpy handle (serialisation and the hand-over to
  the middleware), whether a message came through ``Publisher.publish`` or, serialised,
  straight to the handle (:func:`..nodes.pipeline.publish_all`);
- the recorder's logic is the ``record`` stage.

What the loop's wall time holds beyond all of those is the executor itself (waiting, taking
messages, dispatching): :data:`SPIN`.
"""
from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Callable
from typing import Any

from rclpy.node import Node
from rclpy.serialization import deserialize_message, serialize_message

__all__ = ["SPIN", "STAGES", "TickProfile"]

STAGES = ("deserialise", "logic", "publish")
"""The stages measured per node (the recorder's logic is its recording)."""
SPIN = "rclpy executor"
"""The row of the loop's time outside every callback: the executor waiting, taking messages and
dispatching them."""


class TickProfile:
    """Timers on the callbacks and publishers of ``nodes`` (see the module docstring).

    Parameters
    ----------
    nodes : dict of str to Node
        The run's nodes by name (``PipelineRunner.nodes`` plus its client).
    """

    def __init__(self, nodes: dict[str, Node]) -> None:
        self.seconds: dict[tuple[str, str], float] = defaultdict(float)
        """(node, "callbacks" | "publish") -> wall-clock seconds."""
        self.received: dict[tuple[str, Any], list] = {}
        """(node, subscription) -> [count, last message]."""
        for name, node in nodes.items():
            for sub in node.subscriptions:
                sub.callback = self._timed_callback(name, sub, sub.callback)
            for pub in node.publishers:
                pub._Publisher__publisher = _TimedHandle(pub.handle, self.seconds, name)

    def _timed_callback(self, name: str, sub: Any, callback: Callable) -> Callable:
        seconds, received = self.seconds, self.received
        entry = received.setdefault((name, sub), [0, None])

        def timed(msg: Any) -> Any:
            entry[0] += 1
            entry[1] = msg
            t0 = time.perf_counter()
            try:
                return callback(msg)
            finally:
                seconds[name, "callbacks"] += time.perf_counter() - t0
        return timed

    def deserialise_seconds(self) -> dict[str, float]:
        """Node -> estimated seconds rclpy spent converting the messages it received."""
        out: dict[str, float] = defaultdict(float)
        for (name, sub), (count, last) in self.received.items():
            if count == 0 or isinstance(last, bytes) or last is None:
                continue
            data = serialize_message(last)
            repeat, t0 = 200, time.perf_counter()
            for _ in range(repeat):
                deserialize_message(data, sub.msg_type)
            out[name] += count * (time.perf_counter() - t0) / repeat
        return out

    def table(self, ticks: int, loop_seconds: float, mechanics_seconds: float
              ) -> dict[str, dict[str, float]]:
        """Microseconds per tick by node and stage, with :data:`SPIN` and ``mechanics`` rows.

        Parameters
        ----------
        ticks : int
            Ticks of the profiled loop.
        loop_seconds : float
            Wall-clock seconds of the loop (goal sent to result).
        mechanics_seconds : float
            Wall-clock seconds of the world's mechanics step inside ``sim_hardware``.
        """
        deserialise = self.deserialise_seconds()
        names = sorted({name for name, _ in self.seconds} | set(deserialise))
        rows: dict[str, dict[str, float]] = {}
        accounted = 0.0
        for name in names:
            callbacks, publish = self.seconds[name, "callbacks"], self.seconds[name, "publish"]
            logic = callbacks - publish - (mechanics_seconds if name == "sim_hardware" else 0.0)
            rows[name] = {"deserialise": deserialise.get(name, 0.0), "logic": logic,
                          "publish": publish}
            accounted += callbacks + deserialise.get(name, 0.0)
        rows[SPIN] = {"deserialise": 0.0, "logic": loop_seconds - accounted,
                            "publish": 0.0}
        rows["mechanics"] = {"deserialise": 0.0, "logic": mechanics_seconds, "publish": 0.0}
        return {name: {stage: 1e6 * value / ticks for stage, value in row.items()}
                for name, row in rows.items()}


class _TimedHandle:
    """A publisher's rclpy handle whose ``publish`` and ``publish_raw`` add their wall-clock
    seconds to ``seconds[node, "publish"]``; everything else is the handle's.
    """

    def __init__(self, handle: Any, seconds: dict, node: str) -> None:
        self._handle, self._seconds, self._key = handle, seconds, (node, "publish")

    def __getattr__(self, name: str) -> Any:
        return getattr(self._handle, name)

    def __enter__(self) -> Any:
        return self._handle.__enter__()

    def __exit__(self, *exc: Any) -> Any:
        return self._handle.__exit__(*exc)

    def publish(self, msg: Any) -> None:
        self._timed(self._handle.publish, msg)

    def publish_raw(self, data: bytes) -> None:
        self._timed(self._handle.publish_raw, data)

    def _timed(self, publish: Callable, msg: Any) -> None:
        t0 = time.perf_counter()
        try:
            publish(msg)
        finally:
            self._seconds[self._key] += time.perf_counter() - t0
