# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The evaluation bench's kernel share: which profile entries count as linear algebra."""
import cProfile
import os
import pstats
import time

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from squeeze_grasp_ros.bench.evaluation import (
    compiled_seconds,
    is_kernel,
    kernel_share,
    measure,
    route,
    routes,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_model import attempt_fixed_set
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel
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


def test_the_compiled_kernel_is_found_in_a_profile_of_its_route_only(monkeypatch):
    pytest.importorskip("numba", reason="the fast extra is not installed: pip install '.[fast]'")
    from test_fixed_set_kernel import random_set

    assert routes() == [Kernel.NUMPY, Kernel.NUMBA]
    problems = [random_set(np.random.default_rng(seed), m=4) for seed in range(30)]
    seconds = {}
    monkeypatch.setenv(KERNEL_VARIABLE, "numpy")
    for kernel in Kernel:
        with route(kernel):
            attempt_fixed_set(*problems[0])  # compiled or loaded before the profile
            stats = _profile(lambda: [attempt_fixed_set(*p) for p in problems])
        seconds[kernel] = compiled_seconds(stats)
        assert os.environ[KERNEL_VARIABLE] == "numpy"  # the route is restored after
    assert seconds[Kernel.NUMPY] == 0.0 < seconds[Kernel.NUMBA]


@pytest.mark.slow
def test_the_example_sweep_evaluations_are_timed_and_profiled_with_their_sparse_solves():
    m = measure(share_dir() / "config" / "sweeps" / "example.yaml", tasks=1)
    names = {f for (_, _, f) in m["stats"].stats}
    assert 0 < m["profiled"] < m["evaluations"]  # one task profiled, all timed
    assert m["cpu_s"] > 0
    assert "<method 'solve' of 'SuperLU' objects>" in names
    assert 0.0 < m["kernel_s"] < m["profiled_s"]
    # the groups are prepared outside the profile (before, with more groups than the sweep's
    # cache holds, the profiled task's group had been evicted and was meshed inside it)
    assert not names & {"group_setup", "build_mesh", "grasp_map"}
