# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp sweep``: a grasp dataset on Dask, resumable and deterministic
(docs/sweep.md).
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import sys

from squeeze_grasp_ros.exit_codes import ExitCode
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import (
    COMPILE_CPU_S,
    COMPILED_FROM_EVALUATIONS,
    selected,
    sweep_route,
)
from squeeze_grasp_ros.sweep.engine import dry_run, run_sweep
from squeeze_grasp_ros.sweep.spec import SweepError, load_sweep_spec

WORKERS_PER_CORE = 4
"""Most local workers per core: each is a process of its own (over 90 MB once it has
evaluated a task of the example sweep) evaluating on one core, so more only share the cores and
fill the memory."""

EPILOG = ("exit status: 0 every task written (an evaluation that raised is a row with its error "
          "and leaves the status 0; the summary counts them); 1 some tasks failed as a whole "
          "(listed with their error in DIR/manifest.json; the other tasks are written, and "
          "re-running the same command retries only the failed ones); 2 invalid spec or option, "
          "a spec over the size limits, unreachable --scheduler or one whose workers lack this "
          "version of the package, an --out that another sweep "
          "is writing or that refuses writes, or a bad manifest; 4 the sweep extra missing (the "
          "install line is printed), or the disk filled up (the parts written are kept; re-run "
          "to resume); 130 stopped by "
          "Ctrl-C (SIGINT), 143 by SIGTERM, at any point from start-up on: finished parts are "
          "kept, re-run to resume. Route: with the fast extra (numba), the local workers of a "
          f"sweep of at least {COMPILED_FROM_EVALUATIONS:,} evaluations run compiled (the "
          f"first run after an install spends about {COMPILE_CPU_S} s of CPU per worker "
          "compiling), smaller "
          "sweeps by numpy; SQUEEZE_GRASP_KERNEL=numba or numpy decides instead; --json "
          "reports it as kernel")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SPEC, --out, --scheduler, --workers, --dry-run, --no-progress; the exit statuses."""
    parser.epilog = EPILOG
    parser.add_argument("spec", metavar="SPEC.yaml", help="sweep spec (keys: squeeze-grasp "
                                                          "sweep-help)")
    parser.add_argument("--out", metavar="DIR",
                        help="output directory: parts/*.parquet and manifest.json (required "
                             "unless --dry-run); re-running into it resumes")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786 "
                             "(default: a local cluster, one worker process per core)")
    parser.add_argument("--workers", type=int, metavar="N",
                        help=f"local cluster size (default: one per core; at most "
                             f"{WORKERS_PER_CORE} per core)")
    parser.add_argument("--dry-run", action="store_true",
                        help="print task and evaluation counts and an estimated time from a "
                             "small timed sample; run nothing on Dask")
    parser.add_argument("--no-progress", action="store_true", help="no progress line on stderr")


def run(args: argparse.Namespace) -> dict | int:
    """Run or resume the sweep; returns its counts, or the exit status after printing them
    (1 if tasks failed) or a stop message (130 on SIGINT, 143 on SIGTERM).
    """
    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    if args.workers is not None and not 1 <= args.workers <= most:
        raise SweepError(f"--workers must be between 1 and {most} ({WORKERS_PER_CORE} per core "
                         f"of the {os.cpu_count() or 1} here: each worker is a process), got "
                         f"{args.workers}")
    if args.workers is not None and args.scheduler:
        raise SweepError("--workers sizes the local cluster; it cannot be used with --scheduler")
    loaded = load_sweep_spec(args.spec)
    if args.dry_run:
        estimate = dry_run(loaded, workers=args.workers, scheduler=args.scheduler)
        return {"dry_run": True, "spec": args.spec, "spec_hash": loaded.hash, **estimate,
                "sample_kernel": selected().value,
                "kernel": None if args.scheduler else sweep_route(estimate["evaluations"]).value}
    if not args.out:
        raise SweepError("--out DIR is required (or use --dry-run)")
    outcome = run_sweep(loaded, args.out, scheduler=args.scheduler, workers=args.workers,
                        progress=not args.no_progress)
    for line in outcome.repaired:
        print(f"squeeze-grasp sweep: {args.out}/{line}", file=sys.stderr)
    result = {"dry_run": False, "out": args.out, "spec_hash": loaded.hash, **vars(outcome)}
    if outcome.interrupted is not None:
        name = signal.Signals(outcome.interrupted).name
        print(f"squeeze-grasp sweep: stopped by {name}; {outcome.done} task(s) written this run. "
              "Re-run the same command to resume.", file=sys.stderr)
        return int(ExitCode.INTERRUPTED if outcome.interrupted == signal.SIGINT
                   else ExitCode.TERMINATED)
    if outcome.failed:
        print(json.dumps(result) if args.json else summary(result), flush=True)
        print(f"squeeze-grasp sweep: {outcome.failed} of {outcome.tasks} task(s) failed (errors "
              f"in {args.out}/manifest.json). Re-run the same command to retry them.",
              file=sys.stderr)
        return int(ExitCode.OUTCOME)
    return result


def summary(result: dict) -> str:
    """Human-readable counts."""
    if result["dry_run"]:
        s = result["sample"]
        lines = [f"{result['spec']}: {result['objects']} objects, {result['groups']} groups "
                 f"(object x material), {result['tasks']} tasks, {result['evaluations']} "
                 f"evaluations ({result['parameters']} parameter sets per placement)",
                 f"sample ({s['group']}): prepare {s['prepare_s']:.2f} s, "
                 f"{s['evaluations']} evaluations at {s['mean_evaluation_s']:.3f} s each"]
        if "estimate_s" in result:
            lines.append(f"estimated time on {result['workers']} worker(s): "
                         f"{result['estimate_s'] / 60:.1f} min")
        if result["kernel"] not in (None, result["sample_kernel"]):
            lines.append(f"the sample ran by {result['sample_kernel']}; the local workers will "
                         f"run by {result['kernel']} (the first run after an install compiles "
                         f"for about {COMPILE_CPU_S} s of CPU per worker, then each evaluation "
                         "is faster)")
        return "\n".join(lines)
    if result["skipped"] == result["tasks"]:
        return (
            f"{result['out']}: all {result['tasks']} tasks already done "
            f"({result['seconds']:.2f} s); summary: squeeze-grasp sweep-report {result['out']}"
        )
    lines = [f"{result['out']}: {result['tasks']} tasks, {result['skipped']} already done, "
             f"{result['done']} written now ({result['evaluations']} evaluations, "
             f"{result['errors']} with an error), {result['failed']} failed",
             f"time {result['seconds']:.1f} s on {result['workers']} worker(s)"]
    if result["evaluations"]:
        lines[-1] += (
            f"; "
            f"{result['evaluations'] / result['seconds'] / max(result['workers'], 1):.2f}"
            " evaluations/s per worker"
        )
    if result["errors"] and not result["failed"]:
        lines.append(f"every task written; {result['errors']} evaluation(s) raised and are rows "
                     "with their error (exit status 0; a re-run does not redo them)")
    lines.append(f"summary: squeeze-grasp sweep-report {result['out']}")
    return "\n".join(lines)
