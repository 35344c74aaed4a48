# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Whole-process times of the console script against ``python -c pass`` and ``run`` against
``squeeze`` (part of ``bench --only pipeline``).
"""
from __future__ import annotations

import importlib.util
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.resources import scene_file

__all__ = ["HELP_TARGET", "RUN_TARGET", "bytecode_note", "startup_table"]

HELP_TARGET = 3.0
"""Issue 33's target: ``squeeze-grasp --help`` under this many times ``python -c pass``."""
RUN_TARGET = 2.5
"""Issue 33's target: ``squeeze-grasp run`` at most this many times ``squeeze``, whole process."""


def _times(command: list[str]) -> tuple[float, float]:
    """Wall-clock and CPU (user + system) seconds of one process, the CPU of the processes it
    started and waited for included (output discarded); raises if it fails.
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   stdin=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def bytecode_note() -> str:
    """Whether the package's own modules start from cached bytecode (``__pycache__``) or are
    compiled from source in every process (``PYTHONDONTWRITEBYTECODE`` set in an editable
    install): a run compiles about 150 of them, ``squeeze`` about 80 (0.3 s against 0.2 s).
    """
    cli = Path(__file__).resolve().parent.parent / "cli.py"
    cached = Path(importlib.util.cache_from_source(str(cli))).is_file()
    writes = not (sys.dont_write_bytecode or os.environ.get("PYTHONDONTWRITEBYTECODE"))
    if cached:
        return "the package's modules started from cached bytecode"
    return ("the package's modules were compiled from source in every process (no cached "
            "bytecode" + (")" if writes else "; PYTHONDONTWRITEBYTECODE is set)"))


def startup_table(repeats: int, progress) -> Table:
    """Best-of-``repeats`` whole-process times, the commands interleaved."""
    script = str(Path(sys.executable).parent / "squeeze-grasp")
    scene = str(scene_file("foam_square"))
    commands = {
        "python -c pass": [sys.executable, "-c", "pass"],
        "squeeze-grasp --help": [script, "--help"],
        "squeeze-grasp plan --help": [script, "plan", "--help"],
        "squeeze-grasp plan foam_square.yaml --json": [script, "plan", scene, "--json"],
        "squeeze-grasp squeeze foam_square.yaml --json": [script, "squeeze", scene, "--json"],
        "squeeze-grasp run foam_square.yaml --json": [script, "run", scene, "--json"],
    }
    best = dict.fromkeys(commands, float("inf"))
    cpu = dict.fromkeys(commands, float("inf"))
    for r in range(repeats):
        progress(f"pipeline: start-up, round {r + 1} of {repeats}")
        for name, command in commands.items():
            wall, used = _times(command)
            best[name], cpu[name] = min(best[name], wall), min(cpu[name], used)
    squeeze_name = "squeeze-grasp squeeze foam_square.yaml --json"
    base, squeeze = best["python -c pass"], best[squeeze_name]
    targets = {"squeeze-grasp --help": f"< {HELP_TARGET:g}x python -c pass",
               "squeeze-grasp run foam_square.yaml --json": f"<= {RUN_TARGET:g}x squeeze"}
    rows = [[name, seconds, seconds / base, seconds / squeeze, cpu[name],
             cpu[name] / cpu[squeeze_name], targets.get(name, "-")]
            for name, seconds in best.items()]
    load = "/".join(f"{v:.1f}" for v in os.getloadavg())
    return Table(
        "Whole-process time of the console script",
        ["command", "best wall [s]", "/ python -c pass", "/ squeeze", "best CPU [s]",
         "CPU / squeeze's", "target"],
        rows,
        f"Best of {repeats} rounds, the commands interleaved; load {load}; "
        f"{bytecode_note()}. Each command is one process as a user starts it (the console "
        "script of this environment); run is one process on the EventsExecutor without "
        "recording, its planner node included. The targets are on wall time; CPU time (user + "
        "system, the process's threads included) moves less with the machine's load.",
    )
