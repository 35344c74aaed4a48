# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp plan``: unit stable and pure squeezes at the scene's two contacts (Sec. 4)."""

from __future__ import annotations

import argparse

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.mechanics.errors import require_relative_depth
from squeeze_grasp_ros.mechanics.elastic.reduced import boundary_displacement, reduced_stiffness
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import Squeeze, force_closure, plan_squeeze
from squeeze_grasp_ros.commands.common import (
    add_plot_argument,
    add_scene_argument,
    add_solver_argument,
    load_solid,
)
from squeeze_grasp_ros.mechanics.vocabulary import SqueezeKind

DEFAULT_RELATIVE_DEPTH = 0.05
"""Relative depth used when neither the scene nor the command line gives a depth."""


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


def squeeze_json(sq: Squeeze) -> dict:
    """JSON block of a unit squeeze."""
    return {
        "displacement": sq.displacement.tolist(),
        "forces": sq.forces.tolist(),
        "energy_per_unit_depth2": sq.energy_per_unit_depth2,
        "stiffness": sq.stiffness,
        "rigid_rotation": sq.rigid_rotation,
        "inward": sq.inward,
        "relative_depth_per_unit_depth": sq.relative_depth(1.0),
    }


def requested_depth(args: argparse.Namespace, scene_squeeze, sq: Squeeze) -> float:
    """Depth rho (m) from the command line, else the scene, else DEFAULT_RELATIVE_DEPTH."""
    for depth, rel in (
        (args.depth, args.relative_depth),
        (scene_squeeze.depth, scene_squeeze.relative_depth),
    ):
        if depth is not None:
            require_relative_depth(sq.relative_depth(depth), depth)
            return depth
        if rel is not None:
            require_relative_depth(rel)
            return sq.depth_for_relative(rel)
    return sq.depth_for_relative(DEFAULT_RELATIVE_DEPTH)


def run(args: argparse.Namespace) -> dict:
    """Plan both squeezes; see docs/mechanics.md for the JSON keys."""
    loaded = load_solid(args.scene, args.solver)
    obj, (i, j) = loaded.obj, loaded.contacts
    red = reduced_stiffness(obj, [i, j])
    stable = plan_squeeze(obj, [i, j], kind=SqueezeKind.STABLE, red=red)
    pure = plan_squeeze(obj, [i, j], kind=SqueezeKind.PURE, red=red)
    chosen = stable if loaded.scene.squeeze.type == SqueezeKind.STABLE else pure
    rho = requested_depth(args, loaded.scene.squeeze, chosen)
    disp = {
        k: boundary_displacement(obj, red, rho * sq.displacement)
        for k, sq in ((SqueezeKind.STABLE, stable), (SqueezeKind.PURE, pure))
    }
    mesh = obj.mesh
    result = {
        "contacts": [i, j],
        "contact_points": mesh.nodes[[i, j]].tolist(),
        "stable": squeeze_json(stable),
        "pure": squeeze_json(pure),
        "rigid_rotation": stable.rigid_rotation,
        "squeeze_type": chosen.kind,
        "depth": rho,
        "relative_depth": chosen.relative_depth(rho),
        "rigid_rotation_at_depth": {
            "stable": rho * stable.rigid_rotation,
            "pure": rho * pure.rigid_rotation,
        },
        "boundary_displacement": {k: v.tolist() for k, v in disp.items()},
        "force_closure": force_closure(
            mesh.nodes[i], mesh.normal_at(i), mesh.nodes[j], mesh.normal_at(j), loaded.scene.mu
        ),
        "mu": loaded.scene.mu,
        "diagnostics": {**obj.diagnostics(), "reduced_condition": red.condition},
    }
    if args.plot:
        plot(obj, stable, pure, rho, disp, args.plot)
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
