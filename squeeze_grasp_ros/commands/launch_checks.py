# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""What the launch files check before they start a node, and what they make of a process that
ends: plain functions, so that they are tested without ``launch`` installed.

A launch argument of ``sim_pipeline.launch.py`` for the run is checked by ``squeeze-grasp run``'s
own parser before any node starts, and a yes/no argument by :func:`flag` (a bad one ends the
launch with exit status 1 and the parser's words). Once the nodes run, a node of any of the
launch files that exits before the launch shuts down (:func:`required`), or a run that exits
with a status other than 0, ends the launch with exit status 1 and a line saying which process
and why; ``ros2 launch`` exits 0 only when the run did.

>>> run_arguments(on_slip_alarm="resqueeze", max_attempts="3", resqueeze_margin="")
['--on-slip-alarm=resqueeze', '--max-attempts=3']
>>> run_arguments(max_attempts="0")
Traceback (most recent call last):
    ...
ValueError: max_attempts:=0: must be in [1, 100], got 0
>>> print(run_ended(1))
the run exited 1 (OUTCOME: the grasp did not hold in the simulated world; its summary is above)
"""
from __future__ import annotations

import argparse

from squeeze_grasp_ros.exit_codes import ExitCode

__all__ = ["FLAG_WORDS", "RUN_ARGUMENTS", "LaunchEnded", "flag", "node_ended", "required",
           "run_arguments", "run_ended"]

FLAG_WORDS = {"true": True, "1": True, "yes": True, "on": True,
              "false": False, "0": False, "no": False, "off": False}
"""The words a yes/no launch argument takes (any case)."""

RUN_ARGUMENTS = ("on_slip_alarm", "max_attempts", "resqueeze_margin")
"""Launch arguments handed to ``squeeze-grasp run`` as the options of the same names."""

MEANINGS = {
    ExitCode.OUTCOME: "the grasp did not hold in the simulated world; its summary is above",
    ExitCode.USAGE: "invalid input; its message is above",
    ExitCode.NUMERICAL: "a solver failed; its residuals are above",
    ExitCode.INTERNAL: "not the user's fault; its message is above",
    ExitCode.INTERRUPTED: "stopped by SIGINT",
    ExitCode.TERMINATED: "stopped by SIGTERM",
}
"""What a run's exit status says, as the launch reports it."""


def flag(name: str, text: str) -> bool:
    """The yes/no launch argument ``name`` given as ``text`` (one of :data:`FLAG_WORDS`).

    Raises
    ------
    ValueError
        For any other word, naming the argument (``run:=ture`` would otherwise start the nodes
        without a run, waiting for a goal nobody sends).

    Examples
    --------
    >>> flag("run", "True"), flag("rviz", "off")
    (True, False)
    """
    try:
        return FLAG_WORDS[text.lower()]
    except KeyError:
        raise ValueError(f"{name}:={text[:40]}: must be true or false (or "
                         f"{', '.join(w for w in FLAG_WORDS if w not in ('true', 'false'))})"
                         ) from None


def run_arguments(**given: str) -> list[str]:
    """The ``squeeze-grasp run`` options of the launch arguments ``given`` (name: text; an empty
    text gives no option, i.e. run's default), checked by run's own parser.

    Raises
    ------
    ValueError
        Naming the launch argument, its value and what the parser says of it.
    """
    from squeeze_grasp_ros.commands import run

    parser = argparse.ArgumentParser(prog="sim_pipeline.launch.py", exit_on_error=False)
    run.add_arguments(parser)
    options = []
    for name, text in given.items():
        if name not in RUN_ARGUMENTS:
            raise ValueError(f"{name} is not a launch argument of the run (one of "
                             f"{', '.join(RUN_ARGUMENTS)})")
        if not text:
            continue
        option = f"--{name.replace('_', '-')}={text}"
        try:
            parser.parse_args(["scene.yaml", option])
        except argparse.ArgumentError as exc:
            raise ValueError(f"{name}:={text[:40]}: {exc.message}") from None
        options.append(option)
    return options


def _status(returncode: int) -> str:
    """``CODE (NAME: meaning)`` of a process's exit status (a negative one: killed by a signal)."""
    if returncode < 0:
        return f"{returncode} (killed by signal {-returncode})"
    try:
        code = ExitCode(returncode)
    except ValueError:
        return str(returncode)
    meaning = MEANINGS.get(code)
    return f"{returncode} ({code.name}: {meaning})" if meaning else f"{returncode} ({code.name})"


def run_ended(returncode: int) -> str | None:
    """None if the run's ``returncode`` is 0, else why the launch fails."""
    return None if returncode == 0 else f"the run exited {_status(returncode)}"


def node_ended(name: str, returncode: int) -> str:
    """Why the launch fails when the node ``name`` exits with ``returncode`` while the launch
    runs (its own message is in the log above).
    """
    return f"the {name} node exited {_status(returncode)} while the launch ran"


class LaunchEnded(RuntimeError):
    """A process of the launch ended as it should not have: launch logs this and exits 1."""


def required(name: str):
    """The ``on_exit`` of a launch's node ``name``: a node that ends before the launch shuts
    down (a recorder that cannot write its folder, a monitor refusing its parameters, a crash)
    ends the launch with exit status 1; the others would wait for it for ever, or go on without
    it.

    Returns
    -------
    callable
        ``on_exit(event, context)`` of launch's ``ExecuteProcess``: raises :class:`LaunchEnded`
        (:func:`node_ended`) unless ``context.is_shutdown``.
    """
    def on_exit(event, context) -> None:
        if not context.is_shutdown:
            raise LaunchEnded(node_ended(name, event.returncode))
    return on_exit
