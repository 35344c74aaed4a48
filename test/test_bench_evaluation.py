# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The evaluation bench's kernel share: which profile entries count as linear algebra."""
import cProfile
import pstats
import time

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from squeeze_grasp_ros.bench.evaluation import is_kernel, kernel_share, measure
from squeeze_grasp_ros.resources import share_dir


def _profile(fn) -> pstats.Stats:
    profile = cProfile.Profile(time.process_time)
    profile.enable()
    fn()
    profile.disable()
    return pstats.Stats(profile)


def test_dense_and_sparse_factorisations_count_and_python_and_norms_do_not():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((300, 300)) + 300 * np.eye(300)
    S = sp.csc_matrix(sp.random(400, 400, density=0.01, random_state=3) + sp.eye(400) * 10)

    def work():
        np.linalg.solve(A, np.ones(300))
        spla.splu(S).solve(np.ones(400))
        np.linalg.norm(A, axis=1)
        sum(i * i for i in range(20_000))

    stats = _profile(work)
    counted = {f for (file, _, f) in stats.stats if is_kernel(file, f)}
    assert "solve" in counted  # numpy.linalg.solve: LAPACK gesv inside
    assert any("SuperLU" in f or "gstrf" in f for f in counted)
    assert "norm" not in counted and "<genexpr>" not in counted
    kernel, total, calls = kernel_share(stats)
    assert 0.0 < kernel < total and calls > 20_000


def test_a_pure_python_workload_has_no_kernel_time():
    stats = _profile(lambda: sorted(str(i) for i in range(50_000)))
    assert kernel_share(stats)[0] == 0.0


@pytest.mark.slow
def test_the_example_sweep_evaluations_are_timed_and_profiled_with_their_sparse_solves():
    m = measure(share_dir() / "config" / "sweeps" / "example.yaml", tasks=1)
    names = {f for (_, _, f) in m["stats"].stats}
    assert 0 < m["profiled"] < m["evaluations"]  # one task profiled, all timed
    assert m["cpu_s"] > 0 and m["control_s"] > 0
    assert "<method 'solve' of 'SuperLU' objects>" in names
    assert 0.0 < m["kernel_s"] < m["profiled_s"]
