# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Whole-process times of the console script against ``python -c pass`` and ``run`` against
``squeeze`` (part of ``bench --only pipeline``).
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.resources import scene_file

__all__ = ["HELP_TARGET", "RUN_TARGET", "startup_table"]

HELP_TARGET = 3.0
"""Issue 33's target: ``squeeze-grasp --help`` under this many times ``python -c pass``."""
RUN_TARGET = 2.5
"""Issue 33's target: ``squeeze-grasp run`` at most this many times ``squeeze``, whole process."""


def _wall(command: list[str]) -> float:
    """Wall-clock seconds of one process (output discarded); raises if it fails."""
    t0 = time.perf_counter()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   stdin=subprocess.DEVNULL, check=True)
    return time.perf_counter() - t0


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
    for r in range(repeats):
        progress(f"pipeline: start-up, round {r + 1} of {repeats}")
        for name, command in commands.items():
            best[name] = min(best[name], _wall(command))
    base, squeeze = best["python -c pass"], best["squeeze-grasp squeeze foam_square.yaml --json"]
    targets = {"squeeze-grasp --help": f"< {HELP_TARGET:g}x python -c pass",
               "squeeze-grasp run foam_square.yaml --json": f"<= {RUN_TARGET:g}x squeeze"}
    rows = [[name, seconds, seconds / base, seconds / squeeze, targets.get(name, "-")]
            for name, seconds in best.items()]
    load = "/".join(f"{v:.1f}" for v in os.getloadavg())
    return Table(
        "Whole-process time of the console script",
        ["command", "best wall [s]", "/ python -c pass", "/ squeeze", "target"],
        rows,
        f"Best of {repeats} rounds, the commands interleaved; load {load}. Each command is one "
        "process as a user starts it (the console script of this environment); run is one "
        "process on the EventsExecutor without recording, its planner node included.",
    )
