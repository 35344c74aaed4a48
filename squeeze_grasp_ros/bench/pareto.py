# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Accuracy vs time over all the knobs of the rounded-tip squeeze, and its Pareto front.

Knobs: mesh size (nodes), event tolerance and step of the located engine, and the paper's
fixed-step route. Error: the larger relative error of the final finger force and the strain
energy of the foam-square 12 % squeeze at mu = 0.05 (nodes stick and slip, so the final state
depends on where the events are located), against a much finer mesh with events at 1e-12 L.
Time: mesh + precompute + squeeze (best of two). For each target error the cheapest setting is
the recommendation.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.bench.events import foam_square
from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import Finger

TITLE = "Accuracy vs time: Pareto front of the squeeze settings"
MU, RADIUS, RELATIVE = 0.05, 0.02, 0.12
DEFAULT_TARGET = 3e-3
"""Target error from which the recommended default settings are read."""
TARGETS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3)


def _measure(nodes: int, repeat: int = 2, **kw) -> tuple[float, float, float]:
    """(F1 end force [N], energy [J], best seconds incl. mesh + precompute) of one squeeze."""
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        obj, contacts = foam_square(nodes)
        obj.precompute()
        sq = event_squeeze(obj, contacts, RADIUS, MU, relative_depth=RELATIVE, **kw)
        best = min(best, time.perf_counter() - start)
    return sq.finger_force[Finger.F1][1], sq.energy, best


def pareto_front(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the (time, error) points not dominated by a faster and more accurate one."""
    order = sorted(range(len(points)), key=lambda k: (points[k][0], points[k][1]))
    front, best = [], np.inf
    for k in order:
        if points[k][1] < best:
            front.append(k)
            best = points[k][1]
    return front


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """Grid of settings -> error and time; the front; the cheapest setting per target error."""
    meshes = (500, 1000, 2000, 4000) if quick else (500, 1000, 2000, 4000, 8000, 16000)
    tols = (1e-3, 1e-6, 1e-9)
    steps = (1e-2, 1e-3)
    ref_nodes = 16000 if quick else 48000
    progress(f"pareto: reference, n ~ {ref_nodes}")
    f_ref, e_ref, _ = _measure(ref_nodes, repeat=1, event_tol=1e-12)
    settings = [(n, "located", s, t) for n in meshes for s in steps for t in tols]
    settings += [(n, "fixed step (paper)", h, "-") for n in meshes[:3] for h in (1e-2, 1e-3)]
    rows, points, failed = [], [], []
    for n, route, step, tol in settings:
        progress(f"pareto: n ~ {n}, {route}, step {step:g}, tol {tol}")
        kw = {"step": step, "event_tol": tol} if route == "located" else {"step": step,
                                                                           "reference": True}
        try:
            f, e, seconds = _measure(n, **kw)
        except (InvalidInputError, NumericalError) as exc:
            failed.append(f"n ~ {n}, {route}, step {step:g}: {exc}")
            continue
        err = max(abs(f - f_ref) / abs(f_ref), abs(e - e_ref) / abs(e_ref))
        rows.append([n, route, step, tol, seconds, err])
        points.append((seconds, err))
    front = pareto_front(points)
    for k, row in enumerate(rows):
        row.append("yes" if k in front else "")
    cheapest = []
    for target in TARGETS:
        ok = [k for k in range(len(rows)) if points[k][1] <= target]
        if ok:
            k = min(ok, key=lambda k: points[k][0])
            cheapest.append([target, *rows[k][:5], rows[k][5]])
        else:
            cheapest.append([target, "not reached", "", "", "", "", ""])
    png = "pareto.png"
    fig, (ax,) = plots.figure(size=5.5)
    for route, marker in (("located", "o"), ("fixed step (paper)", "s")):
        ks = [k for k, r in enumerate(rows) if r[1] == route]
        ax.loglog([points[k][0] for k in ks], [points[k][1] for k in ks], marker, alpha=0.6,
                  label=route)
    fx = sorted(front, key=lambda k: points[k][0])
    ax.loglog([points[k][0] for k in fx], [points[k][1] for k in fx], "k-", lw=1.5,
              label="Pareto front")
    labelled: set = set()
    for k in fx:  # one label per mesh size on the front, beside its first (cheapest) point
        if rows[k][0] not in labelled:
            labelled.add(rows[k][0])
            ax.annotate(f"n={rows[k][0]}", points[k], fontsize=7, xytext=(4, 4),
                        textcoords="offset points")
    ax.set_aspect("auto")
    # a log axis spanning about a decade labels its minor ticks, which overlap: label a few
    # round values instead
    from matplotlib.ticker import FixedLocator, NullFormatter, ScalarFormatter

    times = [p[0] for p in points]
    ticks = [t for t in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100)
             if min(times) / 1.5 <= t <= max(times) * 1.5]
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("time: mesh + precompute + squeeze [s]")
    ax.set_ylabel("max rel. error of final force and energy")
    ax.set_title("foam square, 12 % squeeze: accuracy vs time")
    plots.legend(ax, ncol=3)
    plots.save(fig, out_dir / png)
    columns = ["nodes n", "route", "step h [L]", "event tol [L]", "time [s]", "rel. error"]
    on_front = {route: sum(1 for k in front if rows[k][1] == route)
                for route in ("located", "fixed step (paper)")}
    pick = next((c for c in cheapest if c[0] == DEFAULT_TARGET and c[1] != "not reached"), None)
    advice = ("no setting reached the default target" if pick is None else
              f"the cheapest setting within {DEFAULT_TARGET:g} is n ~ {pick[1]}, {pick[2]}, step "
              f"{pick[3]:g} L, event tol {pick[4]} L ({pick[5]:.3g} s)")
    return [
        Table(TITLE, columns + ["on front"], rows,
              f"Reference: n ~ {ref_nodes}, events to 1e-12 L (F1 force {f_ref:.6g} N, energy "
              f"{e_ref:.6g} J), mu = {MU}. Points on the Pareto front: {on_front['located']} "
              f"located-engine settings, {on_front['fixed step (paper)']} fixed-step settings."
              + (" Failed (no result): " + "; ".join(failed) + "." if failed else ""),
              (png,)),
        Table("Cheapest settings for a target error (recommendations)",
              ["target rel. error", *columns[:5], "achieved error"], cheapest,
              f"Measured in this run: {advice}."),
    ]
