# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Ring discretisation -> error against the closed-form circle -> time; all-pairs map time."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.bench.convergence import observed_orders
from squeeze_grasp_ros.bench.table import Table, best_time, timed
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.shapes import ellipse
from squeeze_grasp_ros.mechanics.ring.grasp_map import ring_grasp_map
from squeeze_grasp_ros.mechanics.ring.model import (
    circle_diametral_response,
    ring_diameter_changes,
    ring_from_outline,
)
from squeeze_grasp_ros.mechanics.vocabulary import SqueezeKind

TITLE = "Ring discretisation: error against the closed form and time"
RADIUS, E, WIDTH, WALL, LOAD = 0.04, 2e9, 0.01, 0.004, 10.0


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """Circle under diametral loads at increasing element counts; map timing on an ellipse."""
    counts = (16, 32, 64, 128, 256) if quick else (16, 32, 64, 128, 256, 512, 1024)
    exact = np.array(ring_diameter_changes(RADIUS, E, WIDTH, WALL, LOAD))
    rows, errs, times = [], [], []
    for n in counts:
        progress(f"ring: {n} elements")
        t = best_time(lambda: circle_diametral_response(n, RADIUS, E, WIDTH, WALL, LOAD), repeat=2)
        along, across, _ = circle_diametral_response(n, RADIUS, E, WIDTH, WALL, LOAD)
        err = float(np.max(np.abs(np.array([along, across]) / exact - 1.0)))
        errs.append(err)
        times.append(t)
        rows.append([n, 1e3 * t, along, across, err])
    for row, order in zip(rows, observed_orders([1.0 / n for n in counts], errs)):
        row.append(order)
    png = "ring_convergence.png"
    # error and time against the element count: the time per solve is almost flat here (a
    # fixed overhead of a few ms dominates the O(n) banded solve), so error against time
    # folded back on itself wherever the timer's noise reordered two counts
    from matplotlib.ticker import NullFormatter

    fig, (ax0, ax1) = plots.figure(2)
    ax0.loglog(counts, errs, "o-", label="FE against the closed form")
    ax0.loglog(counts, errs[0] * (counts[0] / np.asarray(counts, float)) ** 2, "k:",
               label="second order")
    ax0.set_ylabel("max relative error of diameter changes")
    ax0.set_title("ring: convergence", fontsize=10)
    plots.legend(ax0, ncol=1)
    ax1.semilogx(counts, [1e3 * t for t in times], "o-")
    ax1.set_ylim(0, 1.1e3 * max(times))
    ax1.set_ylabel("time per solve [ms]")
    ax1.set_title("ring: time per solve (best of 2)", fontsize=10)
    for ax in (ax0, ax1):
        ax.set_aspect("auto")
        ax.set_xlabel("elements")
        ax.xaxis.set_ticks(counts, [str(n) for n in counts])
        ax.xaxis.set_minor_formatter(NullFormatter())
    plots.save(fig, out_dir / png)
    map_rows = []
    for n in (100, 200, 400) if quick else (100, 200, 400, 800):
        ring = ring_from_outline(ellipse(0.045, 0.03), Material(3e9, 0.0, 0.01), 0.003, n)
        _, t_pre = timed(ring.precompute)
        gm, t_map = timed(
            lambda: ring_grasp_map(
                ring, 0.5, epsilon=0.03, kind=SqueezeKind.STABLE, requested_relative_depth=0.15
            )
        )
        map_rows.append([ring.n, n * (n - 1) // 2, 1e3 * t_pre, t_map])
    return [
        Table(
            TITLE,
            [
                "elements",
                "time [ms]",
                "along [m]",
                "across [m]",
                "max rel. error",
                "observed order",
            ],
            rows,
            f"Circle R = {RADIUS} m, h = {WALL} m, w = {WIDTH} m, E = {E:g} Pa, diametral loads "
            f"{LOAD} N; closed form with extension and bending (eq. 71). Second order is expected "
            "(straight elements on a curved middle line).",
            (png,),
        ),
        Table(
            "Ring all-pairs grasp map (ellipse, mu 0.5, eps* 0.03, 15 %)",
            ["elements", "placements", "precompute [ms]", "map [s]"],
            map_rows,
            "Feasibility, maximum depth and limit of every placement, vectorised.",
        ),
    ]
