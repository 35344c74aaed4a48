# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""One event-driven evaluation: where its time goes, and the share of linear-algebra kernels.

The example sweep's evaluations (``config/sweeps/example.yaml``, the quick run its first two
tasks) run once untimed to prepare their groups, once timed (CPU time of this process, BLAS as
the process has it) and once under :mod:`cProfile`. The profile's self times are sorted into
linear-algebra kernels (:data:`KERNEL_PATTERNS`) and everything else; the share is the kernels'
self time over the profile's total. A reader reproduces it with

    python -m squeeze_grasp_ros.bench.evaluation [SPEC] [--tasks N]

which prints the same table and the profile's largest self times.

What cProfile can see decides what the share counts. numpy.linalg runs LAPACK as gufuncs,
which cProfile does not list: their time is in the self time of the numpy.linalg function that
calls them, so those functions count as kernels whole (their own argument handling too: an
upper bound; the helpers they call are listed apart and are not counted). Matrix products
written ``A @ B`` are no function call to cProfile either: they count with the code that calls
them (a lower bound). The profiler's clock is the process's CPU time (the machine is shared:
wall time would count other processes). cProfile's own overhead lengthens every Python call,
so the share under the profiler is below the share of an unprofiled run; the table also
divides the kernels' profiled time by the CPU time of the same evaluations unprofiled (kernel
time is compiled code, hardly lengthened by the profiler: an estimate of the unprofiled share).
"""
from __future__ import annotations

import cProfile
import os
import pstats
import re
import sys
import time
from pathlib import Path

import yaml

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.mechanics.vocabulary import Factorizer
from squeeze_grasp_ros.resources import share_dir
from squeeze_grasp_ros.sweep.evaluate import clear_cache, prepare, run_task
from squeeze_grasp_ros.sweep.plan import plan_tasks
from squeeze_grasp_ros.sweep.spec import parse_sweep_spec

TITLE = "One event-driven evaluation"
KERNEL_PATTERNS: tuple[str, ...] = (
    r"numpy/linalg/_linalg\.py:(solve|inv|cholesky|qr|svd|eig|eigh|eigvals|eigvalsh|lstsq|det"
    r"|slogdet)$",
    r"_flapack|_fblas",
    r"SuperLU|_superlu|gstrf|gstrs",
    *(re.escape(f.value) for f in Factorizer),  # QDLDL, CHOLMOD: module names as the values
)
"""Regular expressions on a profile entry's ``file:function``: a match is a linear-algebra
kernel (LAPACK through numpy.linalg's factorising functions or scipy.linalg, SuperLU, QDLDL,
CHOLMOD). numpy.linalg's helpers and its vector norms (reductions, no LAPACK) are not."""
COMMAND = "python -m squeeze_grasp_ros.bench.evaluation"


def is_kernel(filename: str, function: str) -> bool:
    """Whether a cProfile entry (its file, its function name) is a linear-algebra kernel.

    >>> is_kernel("~", "<method 'solve' of 'SuperLU' objects>")
    True
    >>> is_kernel("/x/numpy/_core/shape_base.py", "stack")
    False
    """
    name = f"{filename}:{function}"
    return any(re.search(p, name) for p in KERNEL_PATTERNS)


def kernel_share(stats: pstats.Stats) -> tuple[float, float, int]:
    """(kernel self time [s], total self time [s], Python-visible calls) of a profile."""
    kernel = total = 0.0
    calls = 0
    for (filename, _, function), (_, ncalls, self_time, _, _) in stats.stats.items():
        total += self_time
        calls += ncalls
        if is_kernel(filename, function):
            kernel += self_time
    return kernel, total, calls


def measure(spec: Path, tasks: int | None) -> dict:
    """Time and profile the evaluations of ``spec``'s first ``tasks`` tasks (all if None)."""
    loaded = parse_sweep_spec(yaml.safe_load(spec.read_text()), spec.parent)
    chosen = list(plan_tasks(loaded))[:tasks]
    clear_cache()
    for task in chosen:
        prepare(task)
    start = time.process_time()
    n = sum(len(run_task(task)["rows"]) for task in chosen)
    cpu = time.process_time() - start
    profile = cProfile.Profile(time.process_time)  # CPU time: the machine is shared
    profile.enable()
    for task in chosen:
        run_task(task)
    profile.disable()
    stats = pstats.Stats(profile)
    kernel, total, calls = kernel_share(stats)
    return {"evaluations": n, "cpu_s": cpu, "kernel_s": kernel, "profiled_s": total,
            "calls": calls, "stats": stats}


def table(m: dict, spec: Path, tasks: int | None) -> Table:
    """The measurement as a table (per evaluation)."""
    n = m["evaluations"]
    load = tuple(round(x, 1) for x in os.getloadavg())
    arg = f" --tasks {tasks}" if tasks else ""
    return Table(
        f"{TITLE}: share of linear-algebra kernels ({spec.name}, cProfile)",
        ["evaluations", "CPU per evaluation [ms]", "profiled per evaluation [ms]",
         "kernels per evaluation (profiled) [ms]", "kernel share of the profile [%]",
         "kernels / unprofiled CPU [%]",
         "Python-visible calls per evaluation"],
        [[n, 1e3 * m["cpu_s"] / n, 1e3 * m["profiled_s"] / n, 1e3 * m["kernel_s"] / n,
          100 * m["kernel_s"] / m["profiled_s"], 100 * m["kernel_s"] / m["cpu_s"],
          round(m["calls"] / n)]],
        f"Kernels: self time of the profile entries matching {' or '.join(KERNEL_PATTERNS)} "
        "(numpy.linalg's factorising functions whole, since their LAPACK gufuncs are invisible "
        "to cProfile; `@` products count with their callers). CPU per evaluation: an "
        "unprofiled run of the same evaluations, groups prepared before. "
        f"Reproduce: `{COMMAND} {spec}{arg}`. "
        f"Load average (1, 5, 15 min) {load} on {os.cpu_count()} cores.",
    )


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """The example sweep's evaluations (its first two tasks when quick)."""
    spec = share_dir() / "config" / "sweeps" / "example.yaml"
    tasks = 2 if quick else None
    progress(f"evaluation: profiling the evaluations of {spec.name}")
    return [table(measure(spec, tasks), spec, tasks)]


if __name__ == "__main__":
    args = sys.argv[1:]
    n_tasks = int(args[args.index("--tasks") + 1]) if "--tasks" in args else None
    path = Path(args[0]) if args and not args[0].startswith("--") else (
        share_dir() / "config" / "sweeps" / "example.yaml")
    result = measure(path, n_tasks)
    print(table(result, path, n_tasks).markdown())
    result["stats"].sort_stats("tottime").print_stats(25)
