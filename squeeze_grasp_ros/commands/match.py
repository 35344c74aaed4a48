# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp match``: similarity transform between simulated and measured shapes (App. C)."""
from __future__ import annotations

import argparse

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.common import add_plot_argument
from squeeze_grasp_ros.commands.csv_io import read_points
from squeeze_grasp_ros.mechanics.calibration.matching import Match, match_similarity


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SIM.csv MEASURED.csv, --plot."""
    parser.add_argument("simulated", metavar="SIM.csv",
                        help="simulated points, x,y per line in m (e.g. squeeze --save-boundary)")
    parser.add_argument("measured", metavar="MEASURED.csv",
                        help="measured corresponding points, x,y per line, same count and order")
    add_plot_argument(parser)


def run(args: argparse.Namespace) -> dict:
    """Scale, rotation, translation and the error per node."""
    sim, meas = read_points(args.simulated), read_points(args.measured)
    m = match_similarity(sim, meas)
    out = {"simulated": args.simulated, "measured": args.measured, "points": len(sim),
           **m.to_json()}
    if args.plot:
        out["plot"] = plot(sim, m, args.plot)
    return out


def plot(sim: np.ndarray, m: Match, path: str) -> str:
    """Simulated points and the matched measured points with their error segments."""
    fig, axes = plots.figure(1, size=5.0)
    ax = axes[0]
    closed = np.vstack([sim, sim[:1]])
    moved = np.vstack([m.matched, m.matched[:1]])
    ax.plot(closed[:, 0], closed[:, 1], "C0.-", ms=3, lw=0.8, label="simulated")
    ax.plot(moved[:, 0], moved[:, 1], "C1.-", ms=3, lw=0.8, label="measured, matched")
    for k, (p, q) in enumerate(zip(sim, m.matched)):
        ax.plot([p[0], q[0]], [p[1], q[1]], color="C3", lw=0.6,
                label="error per node" if k == 0 else None)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    plots.legend(ax, ncol=3)
    ax.set_title(f"s = {m.scale:.4g}, rotation {np.degrees(m.rotation):.3g} deg, "
                 f"mean error {1e3 * m.mean_error:.3g} mm", fontsize=9)
    return plots.save(fig, path)


def summary(result: dict) -> str:
    """Human-readable match report."""
    t = result["translation"]
    lines = [f"{result['points']} corresponding points",
             f"scale {result['scale']:.6g}, rotation {result['rotation_deg']:.6g} deg, "
             f"translation ({t[0]:.6g}, {t[1]:.6g}) m",
             f"mean error per node {1e3 * result['mean_error']:.4g} mm (rms "
             f"{1e3 * result['rms_error']:.4g} mm, max {1e3 * result['max_error']:.4g} mm)"]
    if "plot" in result:
        lines.append(f"plot: {result['plot']}")
    return "\n".join(lines)
