# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp sweep-report``: summary tables (and plots) of a sweep dataset."""
from __future__ import annotations

import argparse

from squeeze_grasp_ros.commands.common import int_in, make_output_folder, output_folder
from squeeze_grasp_ros.sweep.engine import require_extra
from squeeze_grasp_ros.sweep.report import plot, summarise, text

MAX_BEST = 10_000
"""Most best placements listed per object."""
NO_PLOTS = "none written: the folder has no finished rows yet (run or resume the sweep)"
"""What ``--plot`` says of a folder whose parts hold no rows (every task pending or failed)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """DIR, --best, --plot."""
    parser.add_argument("out", metavar="DIR", help="sweep output directory (squeeze-grasp sweep "
                                                   "--out)")
    parser.add_argument("--best", type=int_in(1, MAX_BEST), default=3, metavar="N",
                        help=f"best placements listed per object (default 3, at most {MAX_BEST})")
    parser.add_argument("--plot", metavar="DIR", type=output_folder,
                        help="write quality_map.png and outcome.png into this directory")


def run(args: argparse.Namespace) -> dict:
    """Read the verified parts and summarise them; parts left out are listed."""
    require_extra("sweep-report", ("pyarrow",))
    from squeeze_grasp_ros.sweep.store import load_dataset, read_outlines
    data = load_dataset(args.out)
    rows = data.table.to_pylist()
    manifest = {k: data.manifest.get(k) for k in ("name", "spec_hash", "package_version")}
    out = {"out": args.out, "manifest": {**manifest, "counts": data.counts},
           "excluded": list(data.excluded), **summarise(rows, args.best)}
    if args.plot:
        make_output_folder(args.plot)
        out["plots"] = plot(rows, args.plot, read_outlines(args.out)) if rows else []
    return out


def summary(result: dict) -> str:
    """The tables, after the parts left out."""
    lines = []
    if result["excluded"]:
        lines.append(f"{len(result['excluded'])} part(s) left out of this report (re-run the "
                     "sweep to redo their tasks):")
        lines += [f"  {line}" for line in result["excluded"]]
    lines.append(text(result, result["manifest"]))
    if "plots" in result:
        lines.append("plots: " + (", ".join(result["plots"]) or NO_PLOTS))
    return "\n".join(lines)
