# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``bench --only sweep --large N``: a sweep of at least N evaluations of the example sweep's
parameters on the local Dask cluster, and its extrapolation to a million evaluations.
"""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from squeeze_grasp_ros.bench.sweep_large import large_spec
from squeeze_grasp_ros.resources import share_dir
from squeeze_grasp_ros.sweep.plan import plan_tasks
from squeeze_grasp_ros.sweep.spec import parse_sweep_spec

CLI = str(Path(sys.executable).parent / "squeeze-grasp")


@pytest.mark.parametrize("n", [1, 12, 290, 100_000])
def test_the_large_spec_plans_at_least_n_evaluations_with_the_example_parameters(n, tmp_path):
    data = large_spec(n)
    tasks = list(plan_tasks(parse_sweep_spec(data, tmp_path)))
    total = sum(t.evaluations for t in tasks)
    per_object = 12 * data["placements"]["count"]
    assert n <= total < n + per_object  # one object's evaluations at most beyond n
    example = yaml.safe_load((share_dir() / "config/sweeps/example.yaml").read_text())
    for key in ("friction", "tip_radius", "relative_depth", "weight", "adversary", "mesh"):
        assert data[key] == example[key]


def test_a_large_run_of_zero_evaluations_is_refused_in_one_line(tmp_path):
    done = subprocess.run([CLI, "bench", "--only", "sweep", "--large", "0", "--out",
                           str(tmp_path / "o")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "--large" in done.stderr and "[1, 10000000]" in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.slow
def test_a_small_large_run_writes_its_rows_and_extrapolates(tmp_path):
    pytest.importorskip("distributed", reason="the sweep extra is not installed: "
                                              "pip install '.[sweep]'")
    out = tmp_path / "bench_out"
    done = subprocess.run([CLI, "bench", "--only", "sweep", "--large", "24", "--out", str(out)],
                          capture_output=True, text=True, timeout=900, cwd=tmp_path,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stderr[-3000:]
    assert re.search(r"sweep \[#+\] 24/24 evaluations", done.stderr)  # the progress line
    row = next(line for line in (out / "report.md").read_text().splitlines()
               if line.startswith("| 24 |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    n, objects, errors, workers, wall, startup, rate, per_worker, per_row, hours, mb = cells
    assert (int(objects), int(errors)) == (1, 0)
    assert 0 < float(startup) < float(wall)
    assert float(per_worker) == pytest.approx(float(rate) / int(workers), rel=1e-3)
    assert 100 < float(per_row) < 10_000  # a row of about 40 columns, compressed
    assert float(mb) == pytest.approx(float(per_row), rel=1e-3)  # 1e6 rows, in MB
    expected = (float(startup) + (float(wall) - float(startup)) * 1e6 / 24) / 3600
    assert float(hours) == pytest.approx(expected, rel=1e-2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bench_out"]  # scratch removed
