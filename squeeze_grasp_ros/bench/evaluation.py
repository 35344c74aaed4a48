# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""One event-driven evaluation: where its time goes, and the share of linear-algebra kernels.

The example sweep's evaluations (``config/sweeps/example.yaml``, 288 of them) are prepared
(mesh, factorisation, grasp map per group, untimed), timed (CPU time of this process) between
two runs of a pure-Python control loop, and profiled with :mod:`cProfile` (the quick run
profiles its first two tasks). The time per evaluation, divided by the control loop's, is
compared with the same figures recorded at the commit before issue 33 §1
(:data:`BASELINE_MS_PER_EVALUATION`). The profile's self times are sorted into linear-algebra
kernels (:data:`KERNEL_PATTERNS`) and everything else; the share is the kernels' self time
over the profile's total. A reader reproduces it with

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

import contextlib
import cProfile
import os
import pstats
import re
import sys
import time
from pathlib import Path

import yaml

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel, compiled
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
COMPILED_PATTERN = (r"fixed_set_numba\.py:\d*\(?solve_linear"
                    r"|substeps_numba\.py:\d*\(?(advance_quiet|watched_values|slope_values)"
                    r"|location_numba\.py:\d*\(?earliest_crossing")
"""The compiled kernels' profile entries: the fixed-set solve, the substeps between events, the
watched functions' values and slopes at event points, and the event location (numba's
dispatchers: their self time is the compiled call, BLAS and LAPACK inside included)."""
CONTROL_ITERATIONS = 5_000_000
BASELINE_COMMIT = "9db5097"
BASELINE_MS_PER_EVALUATION = 12.50
BASELINE_CONTROL_S = 0.199
"""The example sweep's 288 evaluations at commit 9db5097 (before issue 33 §1), single-threaded
BLAS: CPU ms per evaluation, and :func:`control_seconds`'s loop (best of two) just before in
another process, on the project's 2-core machine at load 10-13 (interleaved with this
branch's same runs: 9.83 ms, control 0.203 s). The speed-up column divides both by this run's,
so a machine slower or busier for pure Python by some factor leaves the ratio alone."""


def control_seconds() -> float:
    """CPU seconds of a fixed pure-Python integer loop (:data:`CONTROL_ITERATIONS`): the
    machine's speed for interpreter work, beside the evaluations it normalises.
    """
    start, x = time.process_time(), 0
    for i in range(CONTROL_ITERATIONS):
        x += i * i % 7
    return time.process_time() - start


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


def compiled_seconds(stats: pstats.Stats) -> float:
    """Self time [s] of the compiled kernels' calls in a profile (0 without)."""
    return sum(self_time for (filename, line, function), (_, _, self_time, _, _)
               in stats.stats.items()
               if re.search(COMPILED_PATTERN, f"{filename}:{line}({function}"))


def routes() -> list[Kernel]:
    """The fixed-set routes this environment has: numpy, and numba with the ``fast`` extra."""
    return [Kernel.NUMPY] + ([Kernel.NUMBA] if compiled() is not None else [])


@contextlib.contextmanager
def route(kernel: Kernel):
    """Run the fixed-set solves by ``kernel`` inside (:data:`KERNEL_VARIABLE`)."""
    before = os.environ.get(KERNEL_VARIABLE)
    os.environ[KERNEL_VARIABLE] = kernel.value
    try:
        yield
    finally:
        if before is None:
            del os.environ[KERNEL_VARIABLE]
        else:
            os.environ[KERNEL_VARIABLE] = before


def measure_routes(spec: Path, tasks: int | None) -> dict[Kernel, dict]:
    """:func:`measure` of each fixed-set route (:func:`routes`), one after the other."""
    out = {}
    for kernel in routes():
        with route(kernel):
            out[kernel] = measure(spec, tasks)
    return out


def measure(spec: Path, tasks: int | None) -> dict:
    """Time all of ``spec``'s evaluations (CPU, groups prepared first) between two runs of
    the control loop, and profile those of its first ``tasks`` tasks (all if None). The first
    task runs once untimed (numba's compiled code is loaded or compiled on first use); the
    groups are prepared afresh before the timed pass and before the profiled one.
    """
    loaded = parse_sweep_spec(yaml.safe_load(spec.read_text()), spec.parent)
    every = list(plan_tasks(loaded))

    def prepare_all() -> None:
        """Fresh groups: what their objects keep from earlier evaluations (reduced contact
        sets) would shorten the next pass, and a sweep runs each task once.
        """
        clear_cache()
        for task in every:
            prepare(task)

    prepare_all()
    run_task(every[0])
    prepare_all()
    control, per_task = control_seconds(), []
    for task in every:
        start = time.process_time()
        rows = len(run_task(task)["rows"])
        per_task.append((rows, time.process_time() - start))
    control = min(control, control_seconds())
    n, cpu = (sum(x) for x in zip(*per_task))
    chosen = every[:tasks]
    chosen_cpu = sum(t for _, t in per_task[:len(chosen)])
    prepare_all()
    profile = cProfile.Profile(time.process_time)  # CPU time: the machine is shared
    profile.enable()
    profiled = sum(len(run_task(task)["rows"]) for task in chosen)
    profile.disable()
    stats = pstats.Stats(profile)
    kernel, total, calls = kernel_share(stats)
    return {"evaluations": n, "cpu_s": cpu, "control_s": control, "profiled": profiled,
            "profiled_cpu_s": chosen_cpu, "kernel_s": kernel, "profiled_s": total,
            "compiled_s": compiled_seconds(stats), "calls": calls, "stats": stats}


def table(measured: dict[Kernel, dict], spec: Path, tasks: int | None) -> Table:
    """The measurements as a table (per evaluation), a row per fixed-set route."""
    load = tuple(round(x, 1) for x in os.getloadavg())
    arg = f" --tasks {tasks}" if tasks else ""
    rows, numpy_ratio = [], None
    for kernel, m in measured.items():
        n, k = m["evaluations"], m["profiled"]
        ms = 1e3 * m["cpu_s"] / n
        ratio = ms / m["control_s"]
        numpy_ratio = ratio if numpy_ratio is None else numpy_ratio
        rows.append([kernel.value, n, ms, m["control_s"],
                     (BASELINE_MS_PER_EVALUATION / BASELINE_CONTROL_S) / ratio,
                     numpy_ratio / ratio, k, 1e3 * m["profiled_s"] / k, 1e3 * m["kernel_s"] / k,
                     100 * m["kernel_s"] / m["profiled_s"],
                     100 * m["kernel_s"] / m["profiled_cpu_s"],
                     100 * m["compiled_s"] / m["profiled_s"], round(m["calls"] / k)])
    return Table(
        f"{TITLE}: CPU time and the share of linear-algebra kernels ({spec.name})",
        ["fixed-set route", "evaluations", "CPU per evaluation [ms]", "control loop [s]",
         f"speed-up over {BASELINE_COMMIT} (control-normalised)",
         "speed-up over the numpy route (control-normalised)", "profiled evaluations",
         "profiled per evaluation [ms]", "kernels per evaluation (profiled) [ms]",
         "kernel share of the profile [%]", "kernels / unprofiled CPU [%]",
         "compiled kernels (fixed-set solve, substeps, watched values and slopes, location), "
         "share of the profile [%]",
         "Python-visible calls per evaluation"],
        rows,
        "Fixed-set route: the linear model's Newton on the sliding contacts in numpy, or "
        "compiled by numba with the substeps between events and the watched functions at "
        "event points (the `fast` extra; the same floats); the routes run one after the "
        "other, each with its own control loop. CPU per evaluation: all evaluations "
        "unprofiled, groups prepared before, BLAS at one thread (run_task holds it, as "
        "Dask's workers and the recorded figure had it; before, the process's own two threads "
        f"spun in the CPU time); the control loop ({CONTROL_ITERATIONS:,} pure-Python integer "
        f"iterations, best of one run before and one after) normalises the speed-up against "
        f"the figure recorded at {BASELINE_COMMIT} ({BASELINE_MS_PER_EVALUATION:.2f} ms per "
        f"evaluation, control {BASELINE_CONTROL_S:.3f} s, single-threaded BLAS, this "
        "machine). Kernels: self time of the cProfile (CPU clock) entries matching "
        f"{' or '.join(KERNEL_PATTERNS)} (numpy.linalg's factorising functions whole, since "
        "their LAPACK gufuncs are invisible to cProfile; `@` products count with their "
        "callers); kernels / unprofiled CPU (the profiled evaluations' own unprofiled time) "
        "estimates the share without the profiler's overhead. The compiled kernels' column is "
        "their calls' self time (the fixed-set solve's, and on the numba route the substeps "
        "between events', the watched functions' values and slopes at event points and the "
        "event location's; their "
        "BLAS and LAPACK calls inside, not counted as kernels). "
        f"Reproduce: `{COMMAND} {spec}{arg}`. Load average (1, 5, 15 min) {load} on "
        f"{os.cpu_count()} cores.",
    )


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """The example sweep's evaluations (profiled: its first two tasks when quick)."""
    spec = share_dir() / "config" / "sweeps" / "example.yaml"
    tasks = 2 if quick else None
    progress(f"evaluation: timing and profiling the evaluations of {spec.name} "
             f"({', '.join(k.value for k in routes())})")
    return [table(measure_routes(spec, tasks), spec, tasks)]


if __name__ == "__main__":
    args = sys.argv[1:]
    n_tasks = int(args[args.index("--tasks") + 1]) if "--tasks" in args else None
    path = Path(args[0]) if args and not args[0].startswith("--") else (
        share_dir() / "config" / "sweeps" / "example.yaml")
    results = measure_routes(path, n_tasks)
    print(table(results, path, n_tasks).markdown())
    for name, result in results.items():
        print(f"\nfixed-set route {name.value}: the largest self times")
        result["stats"].sort_stats("tottime").print_stats(25)
