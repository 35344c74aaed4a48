# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The start-up bench's measurements (:mod:`squeeze_grasp_ros.bench.startup`): a process's CPU
time is its own, its children's included, and the note says whether the package's modules start
from cached bytecode.
"""
from __future__ import annotations

import importlib.util
import sys

from squeeze_grasp_ros.bench import startup

BURN = ("import time\n"
        "while time.process_time() < {seconds}: pass\n")


def test_cpu_time_counts_the_process_and_the_processes_it_waited_for():
    """A child that burns 0.2 s of its own CPU clock, and one that starts a grandchild burning
    0.3 s and waits for it: at least 0.2 and 0.3 s (the rusage of waited-for descendants).
    """
    _, alone = startup._times([sys.executable, "-c", BURN.format(seconds=0.2)])
    nested = ("import subprocess, sys\n"
              f"subprocess.run([sys.executable, '-c', {BURN.format(seconds=0.3)!r}], "
              "check=True)\n")
    _, both = startup._times([sys.executable, "-c", nested])
    assert alone >= 0.2
    assert both >= 0.3


def test_the_bytecode_note_follows_the_cache_and_the_environment(monkeypatch, tmp_path):
    missing, present = tmp_path / "missing.pyc", tmp_path / "present.pyc"
    present.write_bytes(b"")
    monkeypatch.setattr(importlib.util, "cache_from_source", lambda path: str(missing))
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    monkeypatch.delenv("PYTHONDONTWRITEBYTECODE", raising=False)
    assert startup.bytecode_note().endswith("(no cached bytecode)")
    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")
    assert startup.bytecode_note().endswith("PYTHONDONTWRITEBYTECODE is set)")
    monkeypatch.setattr(importlib.util, "cache_from_source", lambda path: str(present))
    assert startup.bytecode_note() == "the package's modules started from cached bytecode"
