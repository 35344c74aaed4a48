# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Time this code and a pinned older commit's code side by side, in the same minutes.

A speed-up against a figure recorded on another day depends on that day's machine: on this
shared 2-core machine the same code's CPU time has varied 2.5-fold between sessions, in a way a
pure-Python control loop does not track (BLAS and memory-bound work vary with the neighbours,
the interpreter loop much less). So the benches that compare with :data:`BASELINE_COMMIT` take
its code from this checkout's git history (``git archive`` into a temporary folder) and run the
same workload (:mod:`~.timing_driver`) on both trees in child processes, interleaved, with
BLAS at one thread in both. Outside a git checkout that has the commit (an installed wheel, a
shallow clone) the comparison is not made and the table says why.
"""
from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import tarfile
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import squeeze_grasp_ros
from squeeze_grasp_ros.threads import BLAS_THREAD_VARIABLES

BASELINE_COMMIT = "9db5097"
"""The commit before issue 33 §1 (the evaluation's speed-up is measured against its code)."""
DRIVER = Path(__file__).with_name("timing_driver.py")
THIS_TREE = Path(squeeze_grasp_ros.__file__).resolve().parents[1]
"""The folder holding this ``squeeze_grasp_ros`` (a checkout, or site-packages)."""


@dataclass(frozen=True)
class CodeTree:
    """A folder to put first on ``PYTHONPATH``, with the environment variables to set."""

    label: str
    path: Path
    env: Mapping[str, str]


def _git(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["git", "-C", str(THIS_TREE), *args], capture_output=True,
                          check=False)


@contextmanager
def baseline(commit: str = BASELINE_COMMIT) -> Iterator[CodeTree | str]:
    """The code of ``commit`` in a temporary folder, or the reason it is not available.

    >>> with baseline("0" * 40) as tree:
    ...     isinstance(tree, str)
    True
    """
    top = _git("rev-parse", "--show-toplevel")
    if top.returncode != 0 or Path(top.stdout.decode().strip()).resolve() != THIS_TREE:
        yield f"{THIS_TREE} is not a git checkout (clone the repository to compare)"
        return
    if _git("cat-file", "-e", f"{commit}^{{commit}}").returncode != 0:
        yield f"commit {commit} is not in this checkout's history (a shallow clone?)"
        return
    with tempfile.TemporaryDirectory(prefix=f"squeeze-grasp-{commit}-") as folder:
        archive = _git("archive", "--format=tar", commit, "squeeze_grasp_ros", "config")
        with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
            # the "data" filter (Python 3.10.12 / 3.11.4 on) refuses paths out of the folder
            safe = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
            tar.extractall(folder, **safe)
        yield CodeTree(commit, Path(folder), {})


def this_tree(label: str, **env: str) -> CodeTree:
    """This code, with ``env`` set in the child (e.g. the fixed-set route)."""
    return CodeTree(label, THIS_TREE, env)


def timed(tree: CodeTree, *workload: str) -> dict:
    """Run :mod:`~.timing_driver` ``workload`` with ``tree`` first on the path; its JSON.

    The child's BLAS runs one thread; its working folder is a temporary one, so that only
    ``PYTHONPATH`` decides which ``squeeze_grasp_ros`` it imports.
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update({name: "1" for name in BLAS_THREAD_VARIABLES}, PYTHONPATH=str(tree.path))
    env.update(tree.env)
    code = f"import runpy, sys; sys.argv[1:] = {list(workload)!r}; " \
           f"runpy.run_path({str(DRIVER)!r}, run_name='__main__')"
    with tempfile.TemporaryDirectory() as cwd:
        done = subprocess.run([sys.executable, "-c", code], env=env, cwd=cwd,
                              capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"timing {workload} on {tree.label} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def interleaved(trees: list[CodeTree], rounds: int, *workload: str) -> dict[str, dict]:
    """Each tree's best (lowest ``cpu_s``) of ``rounds`` rounds, the trees taking turns."""
    best: dict[str, dict] = {}
    for _ in range(rounds):
        for tree in trees:
            out = timed(tree, *workload)
            if tree.label not in best or out["cpu_s"] < best[tree.label]["cpu_s"]:
                best[tree.label] = out
    return best
