# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A node's log of refused requests, at most one line per reason and interval.

Every refused request gets its reason in its response; the log is for the operator. A burst
of 200 requests for an object that is not loaded wrote 200 identical lines (and 420 in
``bench --quick``, which bursts the planner on purpose). :class:`RefusalLog` writes the first
refusal of each error code, counts the ones that follow within ``interval_s``, and names that
count on the next line it writes for the code.
"""
from __future__ import annotations

import threading
import time
from collections.abc import Callable

REFUSAL_LOG_INTERVAL_S = 1.0
"""Seconds after a logged refusal during which refusals of the same error code are counted,
not logged."""


class RefusalLog:
    """Refusals logged through ``write`` (a logger's ``info``), rate-limited per error code.

    Thread-safe: a node's worker threads and its executor refuse requests concurrently.

    Parameters
    ----------
    write : callable
        Writes one line (``node.get_logger().info``).
    interval_s : float, optional
        :data:`REFUSAL_LOG_INTERVAL_S` by default, s.
    clock : callable, optional
        Monotonic seconds (``time.monotonic``).

    Examples
    --------
    >>> now = [0.0]
    >>> log = RefusalLog(print, clock=lambda: now[0])
    >>> for _ in range(3):
    ...     log.refused("UNKNOWN_OBJECT", "unknown object_id 'x'")
    refused (UNKNOWN_OBJECT): unknown object_id 'x'
    >>> log.refused("INVALID_ARGUMENT", "depth must be >= 0 m, got -1")
    refused (INVALID_ARGUMENT): depth must be >= 0 m, got -1
    >>> now[0] = 1.5
    >>> log.refused("UNKNOWN_OBJECT", "unknown object_id 'y'")
    refused (UNKNOWN_OBJECT): unknown object_id 'y' (and 2 more UNKNOWN_OBJECT refusals in the \
1.5 s before, not logged)
    """

    def __init__(self, write: Callable[[str], object], *,
                 interval_s: float = REFUSAL_LOG_INTERVAL_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._write = write
        self._interval_s = interval_s
        self._clock = clock
        self._lock = threading.Lock()
        self._last: dict[str, tuple[float, int]] = {}  # code -> (time logged, not logged since)

    def refused(self, code: str, message: str) -> None:
        """Log the refusal of a request with error ``code`` for ``message``, or count it."""
        with self._lock:
            now = self._clock()
            logged, unlogged = self._last.get(code, (-float("inf"), 0))
            if now - logged < self._interval_s:
                self._last[code] = (logged, unlogged + 1)
                return
            self._last[code] = (now, 0)
        note = (f" (and {unlogged} more {code} refusals in the {now - logged:.1f} s before, "
                "not logged)" if unlogged else "")
        self._write(f"refused ({code}): {message}{note}")
