# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The benches' same-run comparison with a pinned commit's code (bench/pinned.py)."""
import subprocess

import pytest

from squeeze_grasp_ros.bench.pinned import (
    BASELINE_COMMIT,
    THIS_TREE,
    baseline,
    interleaved,
    this_tree,
    timed,
)


def _has_history() -> bool:
    done = subprocess.run(["git", "-C", str(THIS_TREE), "cat-file", "-e",
                           f"{BASELINE_COMMIT}^{{commit}}"], capture_output=True, check=False)
    return done.returncode == 0


def test_an_unknown_commit_is_refused_with_a_reason():
    with baseline("f" * 40) as tree:
        assert isinstance(tree, str) and "f" * 40 in tree


@pytest.mark.skipif(not _has_history(), reason=f"not a git checkout with {BASELINE_COMMIT} "
                    "(the comparison needs a clone: git clone the repository)")
def test_the_pinned_code_runs_the_same_squeeze_in_a_child_process():
    with baseline() as tree:
        assert not isinstance(tree, str), tree
        assert (tree.path / "squeeze_grasp_ros" / "mechanics").is_dir()
        assert not (tree.path / "squeeze_grasp_ros" / "bench" / "pinned.py").exists()
        results = interleaved([tree, this_tree("mine")], 1, "foam-square", "300", "1")
    old, mine = results[BASELINE_COMMIT], results["mine"]
    # the same mesh and the same events from the old code and this code, each timed
    assert old["count"] == mine["count"] and old["events"] == mine["events"] > 0
    assert old["cpu_s"] > 0 and mine["cpu_s"] > 0


def test_a_failing_workload_names_the_tree_and_the_error():
    with pytest.raises(RuntimeError, match="unknown workload 'nothing'"):
        timed(this_tree("mine"), "nothing")
