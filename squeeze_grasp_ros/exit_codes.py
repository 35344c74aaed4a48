# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Process exit codes of the ``squeeze-grasp`` CLI and the node executables.

The codes say who has to act: the user (``USAGE``), nobody because physics said no
(``OUTCOME``), or the maintainers (``NUMERICAL``, ``INTERNAL``).

>>> int(ExitCode.USAGE)
2
>>> ExitCode(130).name
'INTERRUPTED'
"""
from __future__ import annotations

import json
import signal
from collections.abc import Mapping
from enum import IntEnum
from typing import Any

__all__ = ["ExitCode", "Interrupted", "error_json", "raise_on_signals", "raised_signal"]


class ExitCode(IntEnum):
    """Exit status of a command.

    Attributes
    ----------
    OK
        The command did what was asked and the outcome is the one asked for.
    OUTCOME
        The computation completed, but its outcome is negative: the grasp failed in the
        (simulated) world, a replay did not reproduce its recording, a request is infeasible.
    USAGE
        Invalid input: a bad option, scene, file or path; the message names the field.
    NUMERICAL
        A solver failed (no convergence, singular system); the message carries the residuals.
    INTERNAL
        Anything else that is not the user's fault: a node died or hung, ROS is missing, a bug.
    INTERRUPTED
        Stopped by SIGINT (Ctrl-C), 128 + 2; whatever was recorded is finished and readable.
    TERMINATED
        Stopped by SIGTERM, 128 + 15; as for ``INTERRUPTED``.
    """

    OK = 0
    OUTCOME = 1
    USAGE = 2
    NUMERICAL = 3
    INTERNAL = 4
    INTERRUPTED = 130
    TERMINATED = 143


def error_json(message: str, field: str | None, code: ExitCode,
               details: Mapping[str, Any] | None = None) -> str:
    """The one JSON object a command prints on stdout under ``--json`` for an error: its
    message, the field it names (None when it names none), the exit code and the error's
    ``details`` (a solver failure's residuals and where a squeeze failed:
    :func:`~.cli.error_details`).

    >>> error_json("depth must be >= 0 m, got -1", "depth", ExitCode.USAGE)
    '{"error": "depth must be >= 0 m, got -1", "field": "depth", "code": 2, "code_name": "USAGE"}'
    """
    return json.dumps({"error": message, "field": field, "code": int(code),
                       "code_name": code.name, **(details or {})}, allow_nan=False)


class Interrupted(KeyboardInterrupt):
    """A command stopped by a signal; ``signum`` says which (exit status 128 + ``signum``)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)


_RAISED: list[int] = []
"""The signals the handlers of :func:`raise_on_signals` have raised, in order."""


def raised_signal() -> int | None:
    """The last signal a handler of :func:`raise_on_signals` turned into an exception, or None.

    An interrupt that arrives while a C extension imports a module can be swallowed there and
    replaced by an ImportError that does not chain it (numpy's "PyCapsule_Import could not
    import module 'datetime'", seen under load): this says a signal was the cause.
    """
    return _RAISED[-1] if _RAISED else None


def raise_on_signals() -> dict:
    """Make SIGTERM and SIGHUP raise :class:`Interrupted`, as Ctrl-C raises KeyboardInterrupt
    (recorded for :func:`raised_signal` too, when Python's own Ctrl-C handler is in place:
    a process that inherited SIGINT ignored keeps ignoring it).

    Installed first thing by the console scripts (and by ``squeeze-grasp run``), so a signal
    that arrives while the program is still importing or starting ends it with one line and
    128 + the signal number instead of the default action (killed, exit -15, no message).
    Code that must not be cut in half (a run's recording) installs flag-setting handlers of
    its own over these. Returns the handlers it replaced (signal number -> handler).
    """
    def stop(signum: int, _frame: object) -> None:
        _RAISED.append(int(signum))
        raise KeyboardInterrupt if signum == signal.SIGINT else Interrupted(signum)

    signums = [signal.SIGTERM, signal.SIGHUP]
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signums.append(signal.SIGINT)
    return {signum: signal.signal(signum, stop) for signum in signums}


class SignalFlag:
    """A flag that signal handlers set and loops poll, with no lock.

    A handler runs in the main thread between two bytecodes, possibly inside another handler or
    inside a :class:`threading.Event`'s lock; ``Event.set()`` there waits for a lock its own
    thread holds. A node whose run was killed got its parent-death signal several times in a
    row and hung that way, four handlers deep, for good (the slow suite's SIGKILL test). Setting
    an attribute takes no lock, so any number of nested handlers can set it.

    >>> flag = SignalFlag()
    >>> flag.is_set(), flag.set(), flag.is_set()
    (False, None, True)
    """

    __slots__ = ("_set",)

    def __init__(self) -> None:
        self._set = False

    def set(self, *_: object) -> None:
        """Set the flag (with a signal handler's arguments or none)."""
        self._set = True

    def is_set(self) -> bool:
        """Whether the flag is set."""
        return self._set
