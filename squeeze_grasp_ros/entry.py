# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Console-script entry points: configure the process, then import and run the target.

Each sets single-threaded BLAS (:func:`squeeze_grasp_ros.threads.single_thread_blas`)
before numpy is loaded, unless the user set the variables; ``squeeze-grasp`` also keeps its
standard output for its results (:func:`squeeze_grasp_ros.stdout.reserve_stdout`: the
middleware's diagnostics go to stderr) and, as the console script (:func:`cli_process`), ends at
once after a verb that used ROS has finished everything (:func:`end_after_ros`). Importing the
package as a library changes nothing.
"""
from __future__ import annotations

import atexit
import importlib
import os
import signal
import sys
import threading

from squeeze_grasp_ros.exit_codes import raise_on_signals, raised_signal
from squeeze_grasp_ros.stdout import reserve_stdout
from squeeze_grasp_ros.threads import single_thread_blas

__all__ = ["cli", "cli_process", "end_after_ros", "executor", "monitor", "outline", "planner",
           "recorder", "sim_hardware"]


def _run(module: str, name: str):
    """Run ``module.main()``; a Ctrl-C, SIGTERM or SIGHUP that nothing inside handled (while the
    program is still importing numpy, ROS or Dask, say) ends with one line naming ``name`` and
    exit 128 + the signal number (130, 143, 129), not a traceback or a silent kill.
    """
    single_thread_blas()
    try:
        raise_on_signals()
        return importlib.import_module(module).main()
    except (KeyboardInterrupt, ImportError) as exc:
        stop = _interruption(exc)
        if stop is not None:
            signum = getattr(stop, "signum", signal.SIGINT)
        elif isinstance(exc, ImportError) and raised_signal() is not None:
            signum = raised_signal()  # the import swallowed the signal's exception
        else:
            raise
        print(f"\n{name}: stopped by {signal.Signals(signum).name}", file=sys.stderr)
        return 128 + int(signum)


def _interruption(exc: BaseException) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt (or :class:`.exit_codes.Interrupted`) behind ``exc``, or None.

    A signal that arrives while a C extension initialises (rclpy's, seen under load) surfaces as
    an ImportError ("initialization failed") caused by the signal's exception.
    """
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def cli():
    """``squeeze-grasp`` in this process: its exit code, returned to the caller."""
    reserve_stdout()
    return _run("squeeze_grasp_ros.cli", "squeeze-grasp")


def cli_process():
    """The ``squeeze-grasp`` console script: :func:`cli`, after which a verb that used ROS ends
    the process with its exit code (:func:`end_after_ros`).
    """
    code = cli()
    end_after_ros(code)
    return code


def end_after_ros(code: int | None) -> None:
    """End the process now with ``code`` if a verb used ROS and has finished everything; return
    (the interpreter's normal exit follows) otherwise.

    The teardown it skips writes nothing and took 0.3-0.5 s after a 2 s ``run`` at load 4-6
    (docs/pipeline.md, start-up): the interpreter's final garbage collections over the 80,000
    objects of a run's 1,300 modules, and Fast DDS's ``DomainParticipantFactory`` destructor (a
    C++ static destructor), which sleeps an unconditional 100 ms before it stops its log thread.
    By the time a verb returns it has destroyed its nodes, closed its recording (the
    recorder's close writes the MCAP footer and ``metadata.yaml``) and stopped its node
    processes; shutting its rclpy contexts down has also finished ROS logging (rcl's log file
    is flushed and closed with the last context that started it).

    Checked first: rclpy was imported, no rclpy context still holds ROS logging (one was left
    running: the normal exit), and no thread but the main one and daemon threads is alive (the
    interpreter would wait for it). Then, as the interpreter would, the exit handlers run and
    the standard streams are flushed; only the finalisation is skipped.
    """
    if "rclpy.context" not in sys.modules:
        return
    from squeeze_grasp_ros.ros.shutdown_state import contexts_shut_down

    if not contexts_shut_down() or any(
            t.is_alive() and not t.daemon and t is not threading.main_thread()
            for t in threading.enumerate()):
        return
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.__stdout__, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):  # a closed pipe or stream: nothing more can be written
            pass
    os._exit(0 if code is None else int(code))


def planner():
    """``ros2 run squeeze_grasp_ros planner``."""
    return _run("squeeze_grasp_ros.ros.nodes.planner", "planner")


def executor():
    """``ros2 run squeeze_grasp_ros executor``."""
    return _run("squeeze_grasp_ros.ros.nodes.executor", "executor")


def monitor():
    """``ros2 run squeeze_grasp_ros monitor``."""
    return _run("squeeze_grasp_ros.ros.nodes.monitor", "monitor")


def sim_hardware():
    """``ros2 run squeeze_grasp_ros sim_hardware``."""
    return _run("squeeze_grasp_ros.ros.nodes.sim_hardware", "sim_hardware")


def recorder():
    """``ros2 run squeeze_grasp_ros recorder``."""
    return _run("squeeze_grasp_ros.ros.nodes.recorder", "recorder")


def outline():
    """``ros2 run squeeze_grasp_ros outline``."""
    return _run("squeeze_grasp_ros.ros.nodes.outline", "outline")
