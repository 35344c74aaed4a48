# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp sweep-report``: summary tables (and plots) of a sweep dataset."""
from __future__ import annotations

import argparse

from squeeze_grasp_ros.sweep.engine import require_extra
from squeeze_grasp_ros.sweep.report import plot, summarise, text

HELP = ("summarise a sweep directory: success rate by object and material, quality "
        "distributions, best placements per object; --plot writes pictures")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """DIR, --best, --plot."""
    parser.add_argument("out", metavar="DIR", help="sweep output directory (squeeze-grasp sweep "
                                                   "--out)")
    parser.add_argument("--best", type=int, default=3, metavar="N",
                        help="best placements listed per object (default 3)")
    parser.add_argument("--plot", metavar="DIR",
                        help="write quality_map.png and outcome.png into this directory")


def run(args: argparse.Namespace) -> dict:
    """Read the dataset and summarise it."""
    require_extra()
    from squeeze_grasp_ros.sweep.store import read_dataset, read_manifest, read_outlines
    manifest = read_manifest(args.out)
    rows = read_dataset(args.out).to_pylist()
    out = {"out": args.out, "manifest": {k: manifest[k] for k in
                                         ("name", "spec_hash", "package_version", "counts")},
           **summarise(rows, args.best)}
    if args.plot and rows:
        out["plots"] = plot(rows, args.plot, read_outlines(args.out))
    return out


def summary(result: dict) -> str:
    """The tables."""
    lines = [text(result, result["manifest"])]
    if result.get("plots"):
        lines.append("plots: " + ", ".join(result["plots"]))
    return "\n".join(lines)
