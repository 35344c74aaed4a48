# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The material-models bench's target sentences: each route's neo-Hookean squeeze against the
linear squeeze by the same route, at the scaling table's nominal meshes.
"""
from __future__ import annotations

from squeeze_grasp_ros.bench import material_models as bench
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import Kernel
from squeeze_grasp_ros.mechanics.vocabulary import Factorizer


def _row(nodes, factoriser, route, ratio, cpu_ratio, wall, cpu):
    """A scaling row as the bench builds it (the columns the verdict reads, the rest blank)."""
    return [nodes, factoriser, route, 0.1, wall, ratio, cpu_ratio, cpu, *["-"] * 10]


ROWS = [_row(534, "cholmod", "numpy", 3.8, 3.6, 0.2, 0.1),
        _row(8038, "cholmod", "numpy", 12.5, 12.1, 2.5, 2.3),
        _row(8038, "qdldl", "numpy", 16.0, 16.7, 3.3, 3.2),
        _row(8038, "cholmod", "numba", 9.6, 9.4, 1.8, 1.6),
        _row(20054, "cholmod", "numpy", 31.2, 21.6, 58.1, 13.2),
        _row(20054, "cholmod", "numba", 31.0, 18.8, 61.5, 10.7)]


def test_each_route_is_judged_by_its_own_rows(monkeypatch):
    monkeypatch.setattr(bench, "routes", lambda: [Kernel.NUMPY, Kernel.NUMBA])
    said = bench._scaling_verdict(ROWS, False, Factorizer.CHOLMOD)
    assert ("numpy route: neo-Hookean within 10x linear at 8,038 nodes: 12.5x (not met; "
            "12.1x in CPU time)") in said
    assert "under 60 s at 20,054 nodes: 58.1 s (met; 13.2 s of CPU time)" in said
    assert ("numba route: neo-Hookean within 10x linear at 8,038 nodes: 9.6x (met; 9.4x in "
            "CPU time)") in said
    assert "under 60 s at 20,054 nodes: 61.5 s (not met; 10.7 s of CPU time)" in said
    assert "16.0x" not in said  # the QDLDL row is not the default factoriser's
    # unset variable: the 8,038-node neo-Hookean squeeze assembles compiled (the numba row's
    # 1.8 s, 1.6 s of CPU), its linear squeeze is numpy's (0.1 s, 2.3 / 12.1 s of CPU)
    assert ("default route (variable unset, numba installed: the neo-Hookean assembly compiled "
            "from 6,000 nodes, the linear squeeze by numpy) at 8,038 nodes: 18.0x (not met; "
            "8.4x in CPU time)") in said


def test_without_numba_the_verdict_names_the_extra(monkeypatch):
    monkeypatch.setattr(bench, "routes", lambda: [Kernel.NUMPY])
    rows = [row for row in ROWS if row[2] == "numpy"]
    said = bench._scaling_verdict(rows, False, Factorizer.CHOLMOD)
    assert "numba route" not in said.replace("numba route not measured", "")
    assert "numba route not measured: pip install '.[fast]'" in said
    assert "default route" not in said


def test_the_floor_is_the_profiled_linear_algebra_against_each_routes_linear_cpu():
    """The 8,038-node rows' linear CPU times are 2.3 / 12.1 (numpy) and 1.6 / 9.4 (numba)."""
    profiled = {8000: {"numeric factorisation": 0.95, "solves": 0.85, "assembly": 0.6}}
    said = bench._floor(ROWS, profiled, False, Factorizer.CHOLMOD)
    assert ("Floor at 8,038 nodes: the profiled squeeze's numeric factorisations and solves "
            "alone took 1.80 s of CPU, 9.5x the numpy "
            "route's and 10.6x the numba route's linear squeeze in CPU time") in said
    assert bench._floor(ROWS, profiled, True, Factorizer.CHOLMOD) == ""
    assert bench._floor(ROWS, {500: profiled[8000]}, False, Factorizer.CHOLMOD) == ""
