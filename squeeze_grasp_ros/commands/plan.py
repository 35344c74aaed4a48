# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp plan``: unit stable and pure squeezes at the scene's two contacts (Sec. 4)."""

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
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import Squeeze
from squeeze_grasp_ros.mechanics.vocabulary import SqueezeKind
from squeeze_grasp_ros.scene.studies import point_squeezes


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, depth overrides, --solver, --plot."""
    add_scene_argument(parser)
    depth = parser.add_mutually_exclusive_group()
    depth.add_argument("--depth", type=float, help="squeeze depth rho, m (overrides the scene)")
    depth.add_argument(
        "--relative-depth",
        type=float,
        help="finger approach / initial contact distance (overrides the scene)",
    )
    add_solver_argument(parser)
    add_plot_argument(parser)


def run(args: argparse.Namespace) -> dict:
    """Plan both squeezes; see docs/mechanics.md for the JSON keys."""
    plan = point_squeezes(load_setup(args.scene, args.solver), depth=args.depth,
                          relative_depth=args.relative_depth)
    result = plan.to_json()
    if args.plot:
        plot(plan.setup.solid, plan.stable, plan.pure, plan.depth, plan.boundary_displacement,
             args.plot)
    return result


def plot(obj, stable: Squeeze, pure: Squeeze, rho: float, disp: dict, path: str) -> None:
    """The paper's Fig. 4: squeezes on the undeformed shape; deformed shapes with forces."""
    mesh = obj.mesh
    fig, axes = plots.figure(3)
    pts = mesh.nodes[stable.contacts]
    L = obj.scale
    plots.draw_outline(axes[0], mesh)
    plots.draw_arrows(axes[0], pts, stable.displacement.reshape(-1, 2), 0.2 * L, "C0",
                      "stable u (finger motion)")
    plots.draw_arrows(axes[0], pts, pure.displacement.reshape(-1, 2), 0.2 * L, "C1",
                      "pure v (finger motion)")
    plots.legend(axes[0], ncol=1)
    axes[0].set_title("unit squeezes at the contacts")
    for ax, sq, key in ((axes[1], stable, SqueezeKind.STABLE), (axes[2], pure, SqueezeKind.PURE)):
        full = np.zeros_like(mesh.nodes)
        full[mesh.boundary] = disp[key]
        plots.draw_outline(ax, mesh, color="0.75", lw=0.8, label="undeformed")
        plots.draw_outline(ax, mesh, full, label="deformed (to scale)")
        moved = pts + full[sq.contacts]
        f = np.linalg.norm(rho * sq.forces.reshape(-1, 2), axis=1).max()
        plots.draw_arrows(ax, moved, rho * sq.forces.reshape(-1, 2), 0.2 * L, "C3",
                          f"finger force on the object (longest {f:.3g} N)")
        plots.legend(ax, ncol=1)
        ax.set_title(f"{key}: depth {rho * 1e3:.3f} mm")
    plots.save(fig, path)


def summary(result: dict) -> str:
    """Human-readable comparison of the two squeezes."""
    s, p = result[SqueezeKind.STABLE], result[SqueezeKind.PURE]
    i, j = result["contacts"]
    lines = [
        f"contacts: nodes {i}, {j}; force closure at mu={result['mu']}: {result['force_closure']}",
        f"{'':8s}{'|F|/rho [N/m]':>15s}{'U/rho^2 [J/m^2]':>17s}"
        f"{'rotation [rad/m]':>18s}{'inward':>8s}",
    ]
    for name, b in ((SqueezeKind.STABLE, s), (SqueezeKind.PURE, p)):
        lines.append(
            f"{name:8s}{b['stiffness']:15.5g}{b['energy_per_unit_depth2']:17.5g}"
            f"{b['rigid_rotation']:18.3g}{str(b['inward']):>8s}"
        )
    lines.append(
        f"u.v = {np.dot(s['displacement'], p['displacement']):.5f} "
        f"(= |F(v)|/|F(u)| = {p['stiffness'] / s['stiffness']:.5f}, Theorem 10)"
    )
    lines.append(
        f"{result['squeeze_type']} squeeze to depth {result['depth'] * 1e3:.3f} mm "
        f"= {100 * result['relative_depth']:.2f} % of the finger distance"
    )
    return "\n".join(lines)
