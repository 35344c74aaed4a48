# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp graspmap``: stable-squeeze quality of every pair of boundary placements."""

from __future__ import annotations

import argparse

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.common import (
    add_plot_argument,
    add_scene_argument,
    add_solver_argument,
    load_setup,
)
from squeeze_grasp_ros.commands.ring_map import map_summary, plot_map
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap
from squeeze_grasp_ros.mechanics.vocabulary import ObjectModel
from squeeze_grasp_ros.scene.studies import grasp_map_study


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, --pairs, --solver, --plot."""
    add_scene_argument(parser)
    parser.add_argument(
        "--pairs", action="store_true", help="include the full b x b matrices in the JSON"
    )
    add_solver_argument(parser)
    add_plot_argument(parser)


def run(args: argparse.Namespace) -> dict:
    """Map every placement pair of the scene's object (solid or ring model)."""
    study = grasp_map_study(load_setup(args.scene, args.solver))
    if args.plot:
        if study.setup.is_ring:
            plot_map(study.setup.ring, study.map, args.plot)
        else:
            plot(study.setup.solid, study.map, args.plot)
    return study.to_json(pairs=args.pairs)


def plot(obj, gmap: GraspMap, path: str) -> None:
    """Stiffness over (i, j) with infeasible placements greyed, and the best placements."""
    fig, (ax0, ax1) = plots.figure(2, size=5.0)
    k = np.where(gmap.feasible, gmap.stiffness, np.nan)
    im = ax0.imshow(k, origin="lower", cmap="viridis")
    ax0.set_aspect("equal")
    # rows and columns follow the boundary (counter-clockwise); the ticks name the mesh
    # nodes there, the numbers the printed list and the JSON use
    boundary = np.asarray(gmap.boundary)
    ticks = np.unique(np.linspace(0, len(boundary) - 1, 7).round().astype(int))
    for axis in (ax0.xaxis, ax0.yaxis):
        axis.set_ticks(ticks, [str(n) for n in boundary[ticks]])
    ax0.set_xlabel("node of the second contact (along the boundary)")
    ax0.set_ylabel("node of the first contact (along the boundary)")
    ax0.set_title(f"stable stiffness [N/m] (feasible at mu={gmap.mu})", fontsize=10)
    fig.colorbar(im, ax=ax0, shrink=0.8)
    plots.draw_outline(ax1, obj.mesh)
    for rank, (i, j, quality) in enumerate(gmap.best()):
        p = obj.mesh.nodes[[i, j]]
        ax1.plot(p[:, 0], p[:, 1], "-o", color=f"C{rank}", ms=4,
                 label=f"#{rank + 1}: nodes {i}, {j} ({quality:.4g} N/m)")
    plots.legend(ax1, ncol=2)
    ax1.set_title("stiffest feasible placements")
    plots.save(fig, path)


def summary(result: dict) -> str:
    """Counts and the best placements."""
    if result["model"] == ObjectModel.RING:
        return map_summary(result)
    lines = [
        f"{result['pairs']} placements: {result['inward_pairs']} inward, "
        f"{result['force_closure_pairs']} force closure (mu={result['mu']}), "
        f"{result['feasible_pairs']} both",
        "stiffest feasible placements (nodes, N/m):",
    ]
    lines += [
        f"  {b['contacts'][0]:5d} {b['contacts'][1]:5d}  {b['stiffness']:.5g}"
        for b in result["best"]
    ]
    lines.append(result["note"])
    return "\n".join(lines)
