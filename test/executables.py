# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Where the package's console scripts are installed, on both routes.

The pip route puts them beside the environment's Python (``<venv>/bin``); the colcon route in
``<install prefix>/lib/squeeze_grasp_ros``, where ``ros2 run`` looks, found through the ament
index. And when a started one has begun to run the package's code (:func:`wait_until_caught`).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

PACKAGE = "squeeze_grasp_ros"


def script(name: str) -> str:
    """The path of the installed console script ``name`` (planner, squeeze-grasp, ...)."""
    beside = Path(sys.executable).parent / name
    if beside.is_file():
        return str(beside)
    from ament_index_python.packages import get_package_prefix

    installed = Path(get_package_prefix(PACKAGE)) / "lib" / PACKAGE / name
    assert installed.is_file(), f"console script {name!r} is installed neither beside " \
                                f"{sys.executable} nor in {installed.parent}"
    return str(installed)


def wait_until_caught(pid: int, signum: int, timeout: float = 60.0) -> None:
    """Return once process ``pid`` catches ``signum`` (its handler is installed: Linux's
    ``SigCgt`` mask in ``/proc/PID/status``).

    No program can handle a signal before its first statement has installed a handler; under
    load (11 on the 2-core machine) the interpreter's start-up alone took longer than 0.3 s,
    and a signal sent 0.3 s after the start took the default action.
    """
    deadline = time.monotonic() + timeout
    while True:
        status = Path(f"/proc/{pid}/status").read_text()
        caught = int(next(line.split()[1] for line in status.splitlines()
                          if line.startswith("SigCgt:")), 16)
        if caught >> (int(signum) - 1) & 1:
            return
        assert time.monotonic() < deadline, f"process {pid} installed no {signum!r} handler"
        time.sleep(0.005)  # polling another process's state, not a synchronisation of ours
