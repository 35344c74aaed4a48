# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The node processes of a run (``squeeze-grasp run --processes``), as ``ros2 launch`` starts
them: ``python -m squeeze_grasp_ros.ros.nodes.<node> --ros-args -r __ns:=<ns> -r
/clock:=<ns>/clock --params-file <file>``.

The parameters go to one temporary file per run (``squeeze_grasp_run_<pid>_<random>.yaml``,
removed when the run stops). Every process gets single-threaded BLAS and the run's pid and
parameter file in its environment, so it ends, and removes the file, if the run dies without
stopping it (SIGKILL; :func:`..nodes.parent_watch`); a later run removes files whose run no
longer exists (:func:`remove_stale_parameter_files`).
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from squeeze_grasp_ros.ros.nodes import PARAMS_FILE_ENV, PARENT_PID_ENV
from squeeze_grasp_ros.ros.run.options import RunError
from squeeze_grasp_ros.threads import single_thread_blas

__all__ = ["PARAMS_PREFIX", "STOP_SIGNAL", "STOP_TIMEOUT", "NodeProcesses", "process_exists",
           "remove_stale_parameter_files", "ros_arguments"]

PARAMS_PREFIX = "squeeze_grasp_run_"
"""Name prefix of the parameter files a run writes to the temp folder
(``squeeze_grasp_run_<pid>_<random>.yaml``)."""
STOP_SIGNAL = signal.SIGTERM
"""How a run stops its node processes. A started node handles it like SIGINT (it finishes
cleanly, :func:`..nodes.run_node`); a process still importing, before its handlers exist, ends
at once and silently (SIGINT would raise KeyboardInterrupt there and print a traceback)."""
STOP_TIMEOUT = 30.0
"""Wall-clock seconds a node process gets to finish after :data:`STOP_SIGNAL` before it is
killed."""
NODES_PACKAGE = "squeeze_grasp_ros.ros.nodes"


def ros_arguments(namespace: str) -> list[str]:
    """Command-line ROS arguments that put a node into ``namespace`` with ``/clock`` remapped
    into it (the nodes on sim time subscribe to the absolute ``/clock``).

    >>> ros_arguments("/lab/run_1")
    ['--ros-args', '-r', '__ns:=/lab/run_1', '-r', '/clock:=/lab/run_1/clock']
    """
    if not namespace or namespace == "/":
        return ["--ros-args"]
    return ["--ros-args", "-r", f"__ns:={namespace}", "-r", f"/clock:={namespace}/clock"]


def process_exists(pid: int) -> bool:
    """True if a process ``pid`` exists (of any user)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_parameter_files() -> list[Path]:
    """Remove the parameter files of runs whose process no longer exists (a run killed with
    SIGKILL cannot remove its own; its nodes remove it when they notice); returns them.
    """
    stale = []
    for path in Path(tempfile.gettempdir()).glob(f"{PARAMS_PREFIX}*_*.yaml"):
        pid = path.name[len(PARAMS_PREFIX):].split("_", 1)[0]
        if pid.isdigit() and not process_exists(int(pid)):
            path.unlink(missing_ok=True)
            stale.append(path)
    return stale


class NodeProcesses:
    """The node processes of one run, started, watched and stopped together.

    Parameters
    ----------
    namespace : str
        The run's namespace (every process gets it, with ``/clock`` remapped into it).
    """

    def __init__(self, namespace: str) -> None:
        self.namespace = namespace
        self.running: dict[str, subprocess.Popen] = {}
        """Node name -> its process, in start order."""
        self.params_files: list[Path] = []
        """The run's parameter files (one per :meth:`start_nodes`), removed at :meth:`stop_all`."""

    def start_nodes(self, params: Mapping[str, Mapping[str, Any]]) -> None:
        """Write a parameter file and start one process per node of ``params``."""
        from squeeze_grasp_ros.ros.recording.bag import plain_yaml  # loads MCAP: processes only

        remove_stale_parameter_files()
        handle, path = tempfile.mkstemp(prefix=f"{PARAMS_PREFIX}{os.getpid()}_", suffix=".yaml")
        os.close(handle)
        params_file = Path(path)
        self.params_files.append(params_file)
        params_file.write_text(
            plain_yaml({f"{self.namespace}/{name}": {"ros__parameters": dict(values)}
                        for name, values in params.items()})
        )
        for name in params:
            self.start(name, ["--params-file", str(params_file)])

    def start(self, name: str, arguments: Sequence[str]) -> subprocess.Popen:
        """Start node ``name`` (module ``ros.nodes.<name>``) in the run's namespace with more
        ROS ``arguments`` (a parameter file, ``-p`` overrides), in a process group of its own:
        a terminal's Ctrl-C reaches the run only, which stops its nodes (:meth:`stop_all`).
        """
        self.running[name] = subprocess.Popen(
            [sys.executable, "-m", f"{NODES_PACKAGE}.{name}", *ros_arguments(self.namespace),
             *arguments],
            stdin=subprocess.DEVNULL,
            env=self._environment(),
            process_group=0,
        )
        return self.running[name]

    def _environment(self) -> dict[str, str]:
        """The environment of a node process: single-threaded BLAS, and this process's pid and
        parameter file, so that the node ends (and removes the file) if this process dies
        without stopping it (SIGKILL): :func:`..nodes.parent_watch`.
        """
        env = dict(single_thread_blas(dict(os.environ)))
        env[PARENT_PID_ENV] = str(os.getpid())
        if self.params_files:
            env[PARAMS_FILE_ENV] = str(self.params_files[-1])
        return env

    def check(self) -> None:
        """Raise :class:`RunError` if a node process has exited."""
        for name, proc in self.running.items():
            if proc.poll() is not None:
                raise RunError(f"node process {name} exited with code {proc.returncode}")

    def stop(self, name: str) -> None:
        """Stop node ``name`` (:data:`STOP_SIGNAL`: it finishes cleanly) and wait for it."""
        proc = self.running.pop(name)
        if proc.poll() is None:
            proc.send_signal(STOP_SIGNAL)
        _wait(proc)

    def stop_all(self) -> None:
        """Stop every node (:data:`STOP_SIGNAL` to all, then wait for each; kill one that does
        not end within :data:`STOP_TIMEOUT`) and remove the parameter file.

        The simulated hardware is stopped first and on its own, then the other publishing
        nodes, and the recorder last: at its end a node waits for its readers to acknowledge
        every message it published (:func:`..nodes.wait_acknowledged`),
        which they can only do while they still run.
        """
        if "sim_hardware" in self.running:
            self.stop("sim_hardware")
        for last in (False, True):
            group = [self.running.pop(n) for n in list(self.running) if last or n != "recorder"]
            for proc in group:
                if proc.poll() is None:
                    proc.send_signal(STOP_SIGNAL)
            for proc in group:
                _wait(proc)
        for params_file in self.params_files:
            params_file.unlink(missing_ok=True)


def _wait(proc: subprocess.Popen) -> None:
    try:
        proc.wait(STOP_TIMEOUT)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
