# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Summaries of a sweep dataset: success rates, quality distributions, best placements, plots.

Success of an evaluation: no error, and the squeeze held to its depth (termination
``depth_reached``) or, when a weight is given, lifted the object (``picked_up``). Quality of a
placement: W*_F per unit push in the hardest direction (``resist_min``, J/m^2) when the sweep
has an adversary, else the point-contact stiffness (N/m, comparable on one mesh only).
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np

from squeeze_grasp_ros.mechanics.vocabulary import Termination

SUCCESS = (Termination.DEPTH_REACHED, Termination.PICKED_UP)
QUANTILES = (0.0, 0.25, 0.5, 0.75, 1.0)
DISTRIBUTIONS = (
    "stiffness",
    "resist_min",
    "resist_max",
    "energy",
    "max_strain",
    "max_strain_biot",
    "max_von_mises",
    "relative_depth",
    "time_s",
)
MEASURED = {"max_strain": "strain_measure", "max_von_mises": "stress_measure"}
"""Columns whose measure is in another column: their distributions are kept apart per measure
(a sweep over material models mixes small, Biot and log strains in ``max_strain``)."""


def _distribution_values(rows: list[dict], key: str) -> dict[str, list]:
    """Distribution name -> the non-null values of column ``key``: one named ``key``, or one
    named ``key [measure]`` per measure of a :data:`MEASURED` column.
    """
    split: dict[str, list] = defaultdict(list)
    for r in rows:
        if r.get(key) is not None:
            name = f"{key} [{r.get(MEASURED[key]) or 'unnamed'}]" if key in MEASURED else key
            split[name].append(r[key])
    return dict(sorted(split.items()))


def success(row: dict) -> bool:
    """The evaluation succeeded (see module docstring)."""
    if row["error"]:
        return False
    if row[Termination.PICKED_UP] is not None:
        return bool(row[Termination.PICKED_UP])
    return row["termination"] in SUCCESS


QUALITY_UNITS = {"resist_min": "J/m^2", "stiffness": "N/m"}
"""The unit of each quality a report can colour by."""


def quality_key(rows: list[dict]) -> str:
    """``resist_min`` if any row has it, else ``stiffness``."""
    return "resist_min" if any(r["resist_min"] is not None for r in rows) else "stiffness"


def summarise(rows: list[dict], best: int = 3) -> dict:
    """Success by object and material, terminations, quantiles, best placements per object."""
    by = defaultdict(lambda: [0, 0])
    terminations: dict[str, int] = defaultdict(int)
    for r in rows:
        cell = by[(r["object_id"], r["material_id"])]
        cell[0] += success(r)
        cell[1] += 1
        terminations[r["termination"] or "error"] += 1
    dist = {}
    for key in DISTRIBUTIONS:
        for name, values in _distribution_values(rows, key).items():
            dist[name] = {
                "count": len(values),
                "quantiles": dict(zip(("min", "q25", "median", "q75", "max"),
                                      np.quantile(np.array(values, float), QUANTILES).tolist())),
            }
    qkey = quality_key(rows)
    placements: dict = defaultdict(lambda: {"ok": 0, "n": 0})
    for r in rows:
        p = placements[(r["object_id"], r["material_id"], r["placement_id"])]
        p.update(nodes=[r["node_F1"], r["node_F2"]], quality=r[qkey])
        p["ok"] += success(r)
        p["n"] += 1
    ranked = defaultdict(list)
    for (obj, mat, pid), p in sorted(placements.items()):
        if p["quality"] is not None:
            ranked[obj].append(
                {
                    "material": mat,
                    "placement": pid,
                    "nodes": p["nodes"],
                    "quality": p["quality"],
                    "success_rate": p["ok"] / p["n"],
                }
            )
    best_of = {
        obj: sorted(v, key=lambda p: (-p["success_rate"], -p["quality"], p["placement"]))[:best]
        for obj, v in ranked.items()
    }
    return {
        "evaluations": len(rows),
        "errors": sum(1 for r in rows if r["error"]),
        "success_rate": sum(map(success, rows)) / len(rows) if rows else None,
        "by_object_material": [
            {"object": o, "material": m, "success": s, "evaluations": n, "rate": s / n}
            for (o, m), (s, n) in sorted(by.items())
        ],
        "terminations": dict(sorted(terminations.items())),
        "distributions": dist,
        "quality": qkey,
        "best": best_of,
    }


def text(summary: dict, manifest: dict) -> str:
    """The summary as plain-text tables."""
    counts = manifest["counts"]
    lines = [
        f"sweep {manifest.get('name') or ''} (spec {manifest['spec_hash'][:12]}, package "
        f"{manifest['package_version']}): tasks done {counts['done']}, failed "
        f"{counts['failed']}, pending {counts['pending']}; {summary['evaluations']} "
        f"evaluations, {summary['errors']} with an error"
    ]
    if not summary["evaluations"]:
        return "\n".join(lines)
    lines += [
        "",
        f"success rate {100 * summary['success_rate']:.1f} % (held to depth, or picked "
        "up when a weight is given)",
        "",
        f"{'object':28s} {'material':12s} {'success':>9s} {'rate':>7s}",
    ]
    for c in summary["by_object_material"]:
        lines.append(
            f"{c['object']:28s} {c['material']:12s} "
            f"{c['success']:4d}/{c['evaluations']:<4d}"
            f" {100 * c['rate']:6.1f}%"
        )
    lines += [
        "",
        "terminations: " + ", ".join(f"{k} {v}" for k, v in summary["terminations"].items()),
        "",
        f"{'quantity':28s} {'count':>6s} {'min':>10s} {'q25':>10s} {'median':>10s} "
        f"{'q75':>10s} {'max':>10s}",
    ]
    for key, d in summary["distributions"].items():
        q = d["quantiles"]
        lines.append(f"{key:28s} {d['count']:6d} " + " ".join(f"{q[k]:10.4g}" for k in q))
    unit = "J/m^2" if summary["quality"] == "resist_min" else "N/m"
    lines += [
        "",
        f"best placements per object (by success rate, then {summary['quality']} {unit}):",
    ]
    for obj, best in summary["best"].items():
        for p in best:
            lines.append(
                f"  {obj:26s} {p['material']:10s} {p['placement']} nodes "
                f"{p['nodes'][0]:4d},{p['nodes'][1]:4d}  {summary['quality']} "
                f"{p['quality']:.4g}  success {100 * p['success_rate']:.0f} %"
            )
    return "\n".join(lines)


def plot(rows: list[dict], directory: str | Path, outlines: dict | None = None) -> list[str]:
    """Quality map over placements per object (its outline, chords between the contact points
    coloured by quality, failures grey) and success rate against friction and depth; PNG
    paths. ``outlines``: object id -> boundary loop [[x, y], ...], m.
    """
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    from squeeze_grasp_ros import plots

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    qkey = quality_key(rows)
    objects = sorted({r["object_id"] for r in rows})
    fig, axes = plots.figure(min(len(objects), 4), (len(objects) + 3) // 4)
    cmap = colormaps["viridis"]
    for ax, obj in zip(axes, objects):
        mine = [r for r in rows if r["object_id"] == obj]
        if outlines and obj in outlines:
            loop = np.array(outlines[obj] + outlines[obj][:1])
            ax.plot(loop[:, 0], loop[:, 1], color="0.4", lw=0.8)
        ax.set_aspect("equal")
        ax.locator_params(nbins=4)
        good = [r for r in mine if r[qkey] is not None and success(r)]
        for r in mine:
            if not success(r):
                ax.plot([r["x_F1"], r["x_F2"]], [r["y_F1"], r["y_F2"]], color="0.8", lw=0.5)
        if good:
            q = np.array([r[qkey] for r in good])
            scale = Normalize(q.min(), q.max() if np.ptp(q) > 0 else q.min() + 1.0)
            for r, v in zip(good, q):
                ax.plot([r["x_F1"], r["x_F2"]], [r["y_F1"], r["y_F2"]], color=cmap(scale(v)),
                        lw=1.0)
            bar = fig.colorbar(ScalarMappable(scale, cmap), ax=ax, shrink=0.7)
            bar.set_label(f"{qkey} [{QUALITY_UNITS[qkey]}]", fontsize=7)
            bar.ax.tick_params(labelsize=7)
        pts = np.array(
            [[r[k] for k in ("x_F1", "y_F1")] for r in mine]
            + [[r[k] for k in ("x_F2", "y_F2")] for r in mine]
        )
        ax.scatter(pts[:, 0], pts[:, 1], s=6, color="k")
        ax.set_title(f"{obj}\n(grey: placements that failed)", fontsize=8)
    for ax in axes[len(objects) :]:
        ax.set_visible(False)
    paths = [plots.save(fig, directory / "quality_map.png")]
    fig, axes = plots.figure(2)
    for ax, key, label in (
        (axes[0], "mu", "friction coefficient mu"),
        (axes[1], "target", "target depth (relative, or m)"),
    ):
        ax.set_aspect("auto")
        groups = defaultdict(list)
        for r in rows:
            x = (
                r["mu"]
                if key == "mu"
                else (
                    r["target_relative_depth"]
                    if r["target_relative_depth"] is not None
                    else r["target_depth"]
                )
            )
            groups[x].append(success(r))
        xs = sorted(groups)
        ax.plot(xs, [100 * np.mean(groups[x]) for x in xs], "o-")
        ax.set_xlabel(label)
        ax.set_ylabel("success rate [%]")
        ax.set_ylim(-5, 105)
    paths.append(plots.save(fig, directory / "outcome.png"))
    return paths
