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

import signal
from enum import IntEnum

__all__ = ["ExitCode", "Interrupted", "raise_on_signals"]


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


class Interrupted(KeyboardInterrupt):
    """A command stopped by a signal; ``signum`` says which (exit status 128 + ``signum``)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)


def raise_on_signals() -> dict:
    """Make SIGTERM and SIGHUP raise :class:`Interrupted`, as Ctrl-C raises KeyboardInterrupt.

    Installed first thing by the console scripts (and by ``squeeze-grasp run``), so a signal
    that arrives while the program is still importing or starting ends it with one line and
    128 + the signal number instead of the default action (killed, exit -15, no message).
    Code that must not be cut in half (a run's recording) installs flag-setting handlers of
    its own over these. Returns the handlers it replaced (signal number -> handler).
    """
    def stop(signum: int, _frame: object) -> None:
        raise Interrupted(signum)

    return {signum: signal.signal(signum, stop) for signum in (signal.SIGTERM, signal.SIGHUP)}
