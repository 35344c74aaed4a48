# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""One event-driven evaluation: where its time goes, and the share of linear-algebra kernels.

The example sweep's evaluations (``config/sweeps/example.yaml``, 288 of them) are timed on
each fixed-set route against the code of the commit before issue 33 §1
(:data:`~.pinned.BASELINE_COMMIT`), taken from this checkout's git history and run in the same
minutes, interleaved (:mod:`~.pinned`; CPU time of child processes, BLAS at one thread, groups
prepared untimed), and so is the 2,020-node foam square's squeeze. They are also profiled
in this process with :mod:`cProfile` (the quick run profiles and times their first two
tasks). The profile's self times are sorted into linear-algebra kernels
(:data:`KERNEL_PATTERNS`) and everything else; the share is the kernels' self time over the
profile's total. A reader reproduces it with

    python -m squeeze_grasp_ros.bench.evaluation [SPEC] [--tasks N]
    python -m squeeze_grasp_ros.bench.evaluation --foam-square

which print the same tables (the first also the profile's largest self times).

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

from squeeze_grasp_ros.bench.pinned import BASELINE_COMMIT, baseline, interleaved, this_tree
from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.bench.timing_driver import prepared_tasks
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
SPEED_UP_PASSES = 4
"""Rounds of the interleaved comparison with the pinned commit (best of them for each code).
Two were too few on this shared machine: runs of the same code minutes apart printed 3.79x
and 4.27x (2026-11-30), a neighbour's load having slowed both rounds of one code."""
FOAM_SQUARE_NODES, FOAM_SQUARE_REPEATS = 2000, 5
"""The foam square of issue 33 §1 (about 2,000 nodes: 2,020) and the squeezes timed per child
(best of them)."""


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
    """:func:`measure` on each fixed-set route this environment has."""
    out = {}
    for kernel in routes():
        with route(kernel):
            out[kernel] = measure(spec, tasks)
    return out


def measure(spec: Path, tasks: int | None) -> dict:
    """Time all of ``spec``'s evaluations (CPU) in this process, and profile those of its first
    ``tasks`` tasks (all if None). The first task runs once untimed (numba's compiled code is
    loaded or compiled on first use); the timed pass and the profiled one start from fresh
    groups (what their objects keep from earlier evaluations, reduced contact sets, would
    shorten the next pass, and a sweep runs each task once), each group prepared outside the
    timing and the profile just before its first task (:func:`~.timing_driver.prepared_tasks`).
    """
    loaded = parse_sweep_spec(yaml.safe_load(spec.read_text()), spec.parent)
    every = list(plan_tasks(loaded))
    run_task(every[0])
    clear_cache()
    per_task = []
    for task in prepared_tasks(every, prepare):
        start = time.process_time()
        rows = len(run_task(task)["rows"])
        per_task.append((rows, time.process_time() - start))
    n, cpu = (sum(x) for x in zip(*per_task))
    chosen = every[:tasks]
    chosen_cpu = sum(t for _, t in per_task[:len(chosen)])
    clear_cache()
    profile = cProfile.Profile(time.process_time)  # CPU time: the machine is shared
    profiled = 0
    for task in prepared_tasks(chosen, prepare):
        profile.enable()
        profiled += len(run_task(task)["rows"])
        profile.disable()
    stats = pstats.Stats(profile)
    kernel, total, calls = kernel_share(stats)
    return {"evaluations": n, "cpu_s": cpu, "profiled": profiled,
            "profiled_cpu_s": chosen_cpu, "kernel_s": kernel, "profiled_s": total,
            "compiled_s": compiled_seconds(stats), "calls": calls, "stats": stats}


def against_baseline(*workload: str, rounds: int = SPEED_UP_PASSES) -> tuple[dict, str | None]:
    """``workload`` (:mod:`~.timing_driver`) timed on each fixed-set route of this code and on
    the pinned commit's code, interleaved; ({label: result}, None) or ({routes only}, why the
    commit's code could not be run).
    """
    mine = [this_tree(k.value, **{KERNEL_VARIABLE: k.value}) for k in routes()]
    with baseline() as pinned:
        if isinstance(pinned, str):
            return interleaved(mine, rounds, *workload), pinned
        return interleaved([pinned, *mine], rounds, *workload), None


def _speed_up(results: dict, label: str) -> float | str:
    base = results.get(BASELINE_COMMIT)
    return base["cpu_s"] / results[label]["cpu_s"] if base else "-"


def table(measured: dict[Kernel, dict], compared: tuple[dict, str | None], spec: Path,
          tasks: int | None) -> Table:
    """The measurements as a table (per evaluation), a row per fixed-set route."""
    load = tuple(round(x, 1) for x in os.getloadavg())
    arg = f" --tasks {tasks}" if tasks else ""
    results, missing = compared
    base = results.get(BASELINE_COMMIT)
    rows = []
    for kernel, m in measured.items():
        n, k = m["evaluations"], m["profiled"]
        mine = results[kernel.value]
        rows.append([kernel.value, mine["count"], 1e3 * mine["cpu_s"] / mine["count"],
                     1e3 * base["cpu_s"] / base["count"] if base else "-",
                     _speed_up(results, kernel.value),
                     results[Kernel.NUMPY.value]["cpu_s"] / mine["cpu_s"],
                     1e3 * m["cpu_s"] / n, k, 1e3 * m["profiled_s"] / k,
                     1e3 * m["kernel_s"] / k, 100 * m["kernel_s"] / m["profiled_s"],
                     100 * m["kernel_s"] / m["profiled_cpu_s"],
                     100 * m["compiled_s"] / m["profiled_s"], round(m["calls"] / k)])
    why = f" The pinned commit's code was not run: {missing}." if missing else ""
    return Table(
        f"{TITLE}: CPU time against {BASELINE_COMMIT}'s code in the same run, and the share "
        f"of linear-algebra kernels ({spec.name})",
        ["fixed-set route", "evaluations timed", "CPU per evaluation [ms]",
         f"{BASELINE_COMMIT}'s code, same run [ms]", f"speed-up over {BASELINE_COMMIT}",
         "speed-up over the numpy route", "in this process [ms]", "profiled evaluations",
         "profiled per evaluation [ms]", "kernels per evaluation (profiled) [ms]",
         "kernel share of the profile [%]", "kernels / unprofiled CPU [%]",
         "compiled kernels (fixed-set solve, substeps, watched values and slopes, location), "
         "share of the profile [%]",
         "Python-visible calls per evaluation"],
        rows,
        "Fixed-set route: the linear model's Newton on the sliding contacts in numpy, or "
        "compiled by numba with the substeps between events and the watched functions at "
        "event points (the `fast` extra; the same floats). CPU per evaluation: the same "
        f"evaluations timed in child processes for each route and for {BASELINE_COMMIT}'s "
        "code (git archive of this checkout's history), taking turns, best of "
        f"{SPEED_UP_PASSES} rounds, groups prepared untimed, BLAS at one thread in every "
        "child; the speed-ups are ratios of those CPU times." + why + " In this process: "
        "all evaluations unprofiled, for the kernels' share of the unprofiled CPU. Kernels: "
        "self time of the cProfile (CPU clock) entries matching "
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


def foam_square_table(compared: tuple[dict, str | None]) -> Table:
    """The foam square's squeeze on each route against the pinned commit's code."""
    load = tuple(round(x, 1) for x in os.getloadavg())
    results, missing = compared
    base = results.get(BASELINE_COMMIT)
    rows = [[label, r["count"], r["events"], 1e3 * r["cpu_s"],
             1e3 * base["cpu_s"] if base else "-", _speed_up(results, label)]
            for label, r in results.items() if label != BASELINE_COMMIT]
    why = f" The pinned commit's code was not run: {missing}." if missing else ""
    return Table(
        f"{TITLE}: the foam square, 12 %, mu = 0.4, linear, against {BASELINE_COMMIT}'s code "
        "in the same run",
        ["fixed-set route", "nodes", "events", "CPU per squeeze [ms]",
         f"{BASELINE_COMMIT}'s code, same run [ms]", f"speed-up over {BASELINE_COMMIT}"],
        rows,
        "The squeeze of the 2,020-node foam square to 12 % (events to 1e-9 L, precomputed "
        f"object, one untimed squeeze first), best of {FOAM_SQUARE_REPEATS} squeezes per child "
        f"process and of {SPEED_UP_PASSES} rounds in which the routes and {BASELINE_COMMIT}'s "
        "code (git archive of this checkout's history) take turns; BLAS at one thread." + why
        + f" Reproduce: `{COMMAND} --foam-square`. Load average (1, 5, 15 min) {load} on "
        f"{os.cpu_count()} cores.",
    )


def speed_ups(spec: Path, tasks: int | None) -> tuple[dict, str | None]:
    """The example sweep's evaluations against the pinned commit (see :func:`table`)."""
    return against_baseline("evaluations", str(spec), "1", str(tasks or 0))


def foam_square_speed_ups() -> tuple[dict, str | None]:
    """The foam square against the pinned commit (see :func:`foam_square_table`)."""
    return against_baseline("foam-square", str(FOAM_SQUARE_NODES), str(FOAM_SQUARE_REPEATS))


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """The example sweep's evaluations (timed and profiled: its first two tasks when quick)
    and the foam square, against the pinned commit's code.
    """
    spec = share_dir() / "config" / "sweeps" / "example.yaml"
    tasks = 2 if quick else None
    progress(f"evaluation: timing and profiling the evaluations of {spec.name} "
             f"({', '.join(k.value for k in routes())}, and {BASELINE_COMMIT}'s code)")
    evaluations = table(measure_routes(spec, tasks), speed_ups(spec, tasks), spec, tasks)
    progress(f"evaluation: the foam square against {BASELINE_COMMIT}'s code")
    return [evaluations, foam_square_table(foam_square_speed_ups())]


if __name__ == "__main__":
    args = sys.argv[1:]
    if "--foam-square" in args:
        print(foam_square_table(foam_square_speed_ups()).markdown())
        sys.exit()
    n_tasks = int(args[args.index("--tasks") + 1]) if "--tasks" in args else None
    path = Path(args[0]) if args and not args[0].startswith("--") else (
        share_dir() / "config" / "sweeps" / "example.yaml")
    results = measure_routes(path, n_tasks)
    print(table(results, speed_ups(path, n_tasks), path, n_tasks).markdown())
    for name, result in results.items():
        print(f"\nfixed-set route {name.value}: the largest self times")
        result["stats"].sort_stats("tottime").print_stats(25)
