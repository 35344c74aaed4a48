# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A large grasp dataset on the local Dask cluster, extrapolated to a million evaluations
(``squeeze-grasp bench --only sweep --large [N]``).

The spec is the shipped example sweep's (``config/sweeps/example.yaml``: its base scene,
material, friction, tips, depths, pickup and adversary) with its objects replaced by seeded
Fourier blobs of about 400 nodes, as many as ``N`` evaluations need
(:func:`large_spec`). The sweep runs with the progress line, one worker per core; the table gives
what it did and what 1,000,000 evaluations would take at the same rate and Parquet size per
row, with the machine's cores and load before and after. As ``squeeze-grasp sweep`` does, it runs
the fixed-set solves by the compiled kernel when numba is installed.
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import yaml

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import prefer_compiled
from squeeze_grasp_ros.mechanics.vocabulary import ShapeType
from squeeze_grasp_ros.resources import share_dir

DEFAULT_EVALUATIONS = 100_000
TARGET_EVALUATIONS = 1_000_000
PLACEMENTS = 24
"""Grasp-map placements per object; the example's 3 friction x 2 tips x 2 depths make 12
evaluations of each, so an object is 288 evaluations."""
PER_PLACEMENT = 12


def large_spec(evaluations: int) -> dict:
    """The example sweep with ``ceil(evaluations / (12 x placements))`` Fourier blobs as its
    objects (fewer placements when ``evaluations`` < 288): at least ``evaluations`` rows.
    """
    example = share_dir() / "config" / "sweeps" / "example.yaml"
    data = yaml.safe_load(example.read_text())
    placements = min(PLACEMENTS, math.ceil(evaluations / PER_PLACEMENT))
    objects = math.ceil(evaluations / (PER_PLACEMENT * placements))
    data.update(
        name="large",
        base=str((example.parent / data["base"]).resolve()),
        objects=[{"family": {"type": ShapeType.FOURIER_BLOB.value, "count": objects,
                             "radius": [0.04, 0.06], "harmonics": 4, "amplitude": 0.15}}],
        placements={"mode": "graspmap", "count": placements},
    )
    data.pop("description", None)
    return data


def parquet_bytes(out: Path) -> int:
    """Bytes of the sweep's Parquet parts (``out/parts/*.parquet``)."""
    return sum(p.stat().st_size for p in (out / "parts").glob("*.parquet"))


def run(evaluations: int, progress) -> list[Table]:
    """Run the large sweep in a temporary folder (removed afterwards) and extrapolate."""
    from squeeze_grasp_ros.sweep.engine import run_sweep  # the [sweep] extra: Dask, Arrow
    from squeeze_grasp_ros.sweep.spec import parse_sweep_spec

    prefer_compiled(TARGET_EVALUATIONS)  # the route squeeze-grasp sweep takes for a million

    workers = os.cpu_count() or 1
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="bench_sweep_large_") as tmp:
        out = Path(tmp)
        data = large_spec(evaluations)
        (out / "large.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
        loaded = parse_sweep_spec(data, out)
        progress(f"sweep --large: at least {evaluations:,} evaluations on {workers} workers")
        done = run_sweep(loaded, out / "data", workers=workers, progress=True)
        size = parquet_bytes(out / "data")
    load1 = os.getloadavg()
    n = done.evaluations
    run_s = done.seconds - done.startup_s
    per_row = size / n if n else float("nan")
    hours = (done.startup_s + run_s * TARGET_EVALUATIONS / n) / 3600 if n else float("nan")
    groups = data["objects"][0]["family"]["count"]
    return [
        Table(
            f"Grasp-dataset sweep on Dask: {n:,} evaluations, extrapolated to "
            f"{TARGET_EVALUATIONS:,}",
            ["evaluations", "objects", "error rows", "workers", "wall [s]",
             "of which cluster start-up [s]", "evaluations/s", "evaluations per worker-second",
             "Parquet [bytes per row]", f"{TARGET_EVALUATIONS:,} evaluations [h]",
             f"{TARGET_EVALUATIONS:,} rows of Parquet [MB]"],
            [[n, groups, done.errors, workers, done.seconds, done.startup_s,
              n / run_s if run_s > 0 else float("nan"),
              n / run_s / workers if run_s > 0 else float("nan"), per_row, hours,
              per_row * TARGET_EVALUATIONS / 1e6]],
            f"The example sweep's parameters (config/sweeps/example.yaml) on {groups} seeded "
            f"Fourier blobs of about 400 nodes, {data['placements']['count']} grasp-map "
            "placements each; every object is meshed, factorised and mapped once per worker "
            "(in the time). Extrapolation: cluster start-up once plus the run's wall time after "
            f"start-up scaled by {TARGET_EVALUATIONS:,} / evaluations; Parquet size per row as "
            f"in this run (all parts over all rows). Load average (1, 5, 15 min) before "
            f"{tuple(round(x, 1) for x in load0)}, after {tuple(round(x, 1) for x in load1)} "
            f"on {os.cpu_count()} cores: other processes on the machine slow the rate.",
        )
    ]
