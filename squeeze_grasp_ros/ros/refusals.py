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
from dataclasses import dataclass
from typing import Any

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
        self.line(code, f"refused ({code}): {message}")

    def line(self, code: str, text: str) -> None:
        """Write ``text``, or count it if a line of ``code`` was written within the interval.

        >>> now = [0.0]
        >>> log = RefusalLog(print, clock=lambda: now[0])
        >>> for k in range(3):
        ...     now[0] = 0.01 * k
        ...     log.line("joint_states", f"ignored the joint state of {now[0]:.2f} s: a NaN")
        ignored the joint state of 0.00 s: a NaN
        >>> now[0] = 1.0
        >>> log.line("joint_states", "ignored the joint state of 1.00 s: a NaN")
        ignored the joint state of 1.00 s: a NaN (and 2 more joint_states refusals in the 1.0 s \
before, not logged)
        """
        with self._lock:
            now = self._clock()
            logged, unlogged = self._last.get(code, (-float("inf"), 0))
            if now - logged < self._interval_s:
                self._last[code] = (logged, unlogged + 1)
                return
            self._last[code] = (now, 0)
        note = (f" (and {unlogged} more {code} refusals in the {now - logged:.1f} s before, "
                "not logged)" if unlogged else "")
        self._write(f"{text}{note}")


@dataclass(frozen=True)
class LimitedWarnings:
    """A node logger whose warnings go through a :class:`RefusalLog` under one code (at most
    one line per interval, the rest counted); its info lines are written as they come.

    For readings that a driver may repeat at its full rate: a joint state the monitor cannot
    use, republished at 1 kHz, wrote a warning line per state.
    """

    logger: Any
    refusals: RefusalLog
    code: str

    def warning(self, text: str) -> None:
        """Write ``text`` as a warning, or count it."""
        self.refusals.line(self.code, text)

    def info(self, text: str) -> None:
        """Write ``text`` at INFO."""
        self.logger.info(text)
