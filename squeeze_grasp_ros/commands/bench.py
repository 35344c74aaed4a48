# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp bench``: what accuracy costs in time, as tables, a report and plots."""
from __future__ import annotations

import argparse
import importlib
import platform
import sys
from pathlib import Path

from squeeze_grasp_ros.bench import SECTIONS, missing
from squeeze_grasp_ros.bench.sweep_large import DEFAULT_EVALUATIONS, TARGET_EVALUATIONS
from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.commands.common import int_in, make_output_folder, output_folder
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.outputs import write_atomically


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """--quick, --only, --large, --out."""
    parser.add_argument("--quick", action="store_true",
                        help="smaller sizes (every section: about 6 minutes on two quiet "
                             "cores, 7 right after an install while numba compiles, 3 times "
                             "that under load; docs/ci.md)")
    parser.add_argument("--only", nargs="+", choices=SECTIONS, metavar="SECTION",
                        help=f"run only these sections ({', '.join(SECTIONS)})")
    parser.add_argument("--large", nargs="?", const=DEFAULT_EVALUATIONS, default=None,
                        type=int_in(1, 10_000_000), metavar="N",
                        help="the sweep section runs N evaluations (default "
                             f"{DEFAULT_EVALUATIONS:,}) on the local Dask cluster instead of "
                             f"its tables and extrapolates to {TARGET_EVALUATIONS:,} (with "
                             "--only: sweep among its sections)")
    parser.add_argument("--out", default="bench_out", type=output_folder,
                        help="report directory (default: bench_out)")


def _progress(message: str) -> None:
    print(f"[bench] {message}", file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> dict:
    """Run the sections; write OUT/report.md and the plots.

    Raises
    ------
    InvalidInputError
        For ``--large`` with an ``--only`` list without ``sweep``, the one section it changes.
    """
    if args.large and args.only and "sweep" not in args.only:
        raise InvalidInputError(f"--large runs the sweep section, which --only "
                                f"{' '.join(args.only)} leaves out: add sweep to --only")
    out = make_output_folder(args.out)
    tables, skipped = [], []
    for name in args.only or SECTIONS:
        absent, how = missing(name)
        if absent:
            _progress(f"skipped {name}: {', '.join(absent)} not installed ({how})")
            skipped.append([name, ", ".join(absent), how])
            continue
        if name == "sweep" and args.large:
            module = importlib.import_module("..bench.sweep_large", __package__)
            tables += module.run(args.large, _progress)
            continue
        module = importlib.import_module(f"..bench.{name}", __package__)
        tables += module.run(args.quick, out, _progress)
    if skipped:
        tables.append(Table("Skipped sections", ["section", "not installed", "to run it"],
                            skipped, "These sections need modules this environment lacks."))
    header = (f"# squeeze_grasp_ros benchmark ({'quick' if args.quick else 'full'})\n\n"
              f"Python {platform.python_version()}, {platform.machine()}, "
              f"{platform.processor() or 'cpu'}; times are best-of wall times in one run.\n")
    report = out / "report.md"
    text = header + "\n" + "\n".join(t.markdown() for t in tables)
    write_atomically(report, lambda tmp: tmp.write_text(text), "the report")
    return {"report": str(report),
            "tables": [{"title": t.title, "columns": list(t.columns), "rows": t.rows,
                        "notes": t.notes, "plots": list(t.plots)} for t in tables]}


def summary(result: dict) -> str:
    """The tables as Markdown, and where the report is."""
    return Path(result["report"]).read_text() + f"\nreport: {result['report']}"
