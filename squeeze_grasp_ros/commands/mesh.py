# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp mesh``: the scene's triangulation."""
from __future__ import annotations

import argparse

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.common import add_plot_argument, add_scene_argument, load_setup


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE and --plot."""
    add_scene_argument(parser)
    add_plot_argument(parser)


def run(args: argparse.Namespace) -> dict:
    """Mesh the scene; JSON keys: nodes, triangles, boundary (0-based, CCW), material."""
    setup = load_setup(args.scene)
    scene, obj = setup.scene, setup.solid
    mesh, mat = obj.mesh, obj.material
    if args.plot:
        fig, (ax,) = plots.figure(size=5.0)
        ax.triplot(mesh.nodes[:, 0], mesh.nodes[:, 1], mesh.triangles, lw=0.4, color="0.6")
        plots.draw_outline(ax, mesh)
        ax.set_title(f"{scene.name or args.scene}: {mesh.n} nodes, {len(mesh.triangles)} elements")
        plots.save(fig, args.plot)
    return {
        "nodes": mesh.nodes.tolist(),
        "triangles": mesh.triangles.tolist(),
        "boundary": mesh.boundary.tolist(),
        "material": {"E": mat.E, "nu": mat.nu, "thickness": mat.thickness},
        "min_angle_deg": mesh.min_angle_deg(),
    }


def summary(result: dict) -> str:
    """Counts and quality."""
    return (
        f"{len(result['nodes'])} nodes, {len(result['triangles'])} triangles, "
        f"{len(result['boundary'])} boundary nodes, min angle {result['min_angle_deg']:.1f} deg"
    )
