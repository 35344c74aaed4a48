# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ring grasp map's picture and summary, shared by ``ring --map`` and ``graspmap`` on a ring
scene (Sec. 7, Table 5).
"""

from __future__ import annotations

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.mechanics.ring.grasp_map import RingGraspMap
from squeeze_grasp_ros.mechanics.ring.model import RingModel
from squeeze_grasp_ros.mechanics.ring.squeeze import LIMITS
from squeeze_grasp_ros.mechanics.vocabulary import StrainMeasure


def closed(points: np.ndarray) -> np.ndarray:
    """A ring's points (n, 2) with the first repeated at the end, for drawing."""
    return np.vstack([points, points[:1]])


def outcome_matrix(gmap: RingGraspMap) -> tuple[np.ndarray, list[str]]:
    """(n, n) outcome codes with the row as F1's node, and their names: the limit codes, then
    "succeeds" (at the requested relative depth) and "outside a cone at start"; -1 on the
    diagonal.
    """
    names = [*(limit.value for limit in LIMITS), "succeeds", "outside a cone at start"]
    code = gmap.limit_code.copy()
    if gmap.requested_relative_depth is not None:
        code[gmap.succeeds(gmap.requested_relative_depth)] = len(LIMITS)
    code[~gmap.initially_feasible] = len(LIMITS) + 1
    swapped = np.choose(np.minimum(code, 2), [1, 0, code]) if len(code) else code
    out = np.full((gmap.n, gmap.n), -1)
    i, j = gmap.pairs.T
    out[i, j], out[j, i] = code, swapped
    return out, names


def plot_map(ring: RingModel, gmap: RingGraspMap, path: str) -> str:
    """Max relative depth over (F1 node, F2 node) (left), outcome (middle), the deepest
    placements on the ring (right).
    """
    from matplotlib.colors import ListedColormap

    fig, (ax0, ax1, ax2) = plots.figure(3, size=4.6)
    im = ax0.imshow(gmap.matrix(gmap.max_relative_depth), origin="lower", cmap="viridis")
    fig.colorbar(im, ax=ax0, shrink=0.75)
    ax0.set_title("max relative depth")
    code, names = outcome_matrix(gmap)
    colors = ["white", "tab:red", "tab:orange", "tab:blue", "tab:gray", "tab:green", "0.85"]
    ax1.imshow(
        code,
        origin="lower",
        cmap=ListedColormap(colors),
        vmin=-1.5,
        vmax=len(names) - 0.5,
        interpolation="nearest",
    )
    for color, name in zip(colors[1:], names):
        ax1.plot([], [], "s", color=color, label=name)
    plots.legend(ax1, ncol=2)
    target = gmap.requested_relative_depth
    ax1.set_title("limit" + (f" / success at relative depth {target:.3g}" if target else ""))
    for ax in (ax0, ax1):
        ax.set_xlabel("F2 node j")
        ax.set_ylabel("F1 node i")
    ax2.plot(*closed(ring.points).T, color="k", lw=1.2)
    for rank, best in enumerate(gmap.best(5)):
        p = ring.points[best["contacts"]]
        ax2.plot(
            p[:, 0],
            p[:, 1],
            "-o",
            ms=4,
            color=f"C{rank}",
            label=f"{best['contacts']}: {best['max_relative_depth']:.3g}",
        )
    ax2.set_aspect("equal")
    plots.legend(ax2, ncol=2, title="F1, F2 nodes: max relative depth", title_fontsize=8)
    ax2.set_title("deepest placements")
    return plots.save(fig, path)


def map_summary(result: dict) -> str:
    """Counts, outcomes and the deepest placements of a ring map's JSON."""
    lines = [
        f"{result['pairs']} placements on {result['elements']} nodes, mu={result['mu']}, "
        f"epsilon={result['epsilon']} (largest fibre strain, "
        f"{StrainMeasure(result['strain_measure']).label} strain); limits: {result['limits']}"
    ]
    if "feasible_pairs" in result:
        lines.append(
            f"{result['feasible_pairs']} succeed at relative depth "
            f"{result['requested_relative_depth']}; {result['initially_infeasible_pairs']} "
            f"start outside a cone; failures during the squeeze: "
            f"{result['failure_modes_during_squeeze']}"
        )
    lines.append("deepest placements (F1, F2, max relative depth, limit):")
    lines += [
        f"  {b['contacts'][0]:5d} {b['contacts'][1]:5d}  {b['max_relative_depth']:.4g}  "
        f"{b['limit']}"
        for b in result["best"]
    ]
    return "\n".join(lines)
