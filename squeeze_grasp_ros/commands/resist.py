# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp resist``: optimal resistance to the scene's adversary finger (Sec. 6)."""

from __future__ import annotations

import argparse

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.common import (
    add_plot_argument,
    add_scene_argument,
    add_solver_argument,
    int_in,
    load_setup,
)
from squeeze_grasp_ros.mechanics.elastic.reduced import displacement_field
from squeeze_grasp_ros.mechanics.resistance.forms import expansion_matrix
from squeeze_grasp_ros.mechanics.resistance.frictional import FrictionalResistance
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    MAX_DIRECTIONS,
    Resistance,
    ResistanceGrasp,
    ResistanceSweep,
)
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.events import grasp_health
from squeeze_grasp_ros.mechanics.vocabulary import ContactKind, ContactMode, Finger, SqueezeKind
from squeeze_grasp_ros.scene.studies import resistance_study


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, --mode, --contacts, --directions, --segment-half-width, --compare-direction."""
    add_scene_argument(parser)
    parser.add_argument(
        "--mode", choices=SqueezeKind.planned(), help="resistance type (default: the scene's)"
    )
    parser.add_argument(
        "--contacts",
        choices=ContactKind.values(),
        type=ContactKind,
        help="contact model (default: the scene's adversary.contacts)",
    )
    parser.add_argument(
        "--directions",
        type=int_in(1, MAX_DIRECTIONS),
        metavar="N",
        help="also sweep N adversary push directions (grasp quality, polar plot)",
    )
    parser.add_argument(
        "--segment-half-width",
        type=float,
        metavar="M",
        help="segment contacts: arc length, m, on each side of a contact node (>= 0, below "
             "half the boundary distance of the nearest two contacts)",
    )
    parser.add_argument(
        "--compare-direction",
        type=float,
        nargs=2,
        metavar=("X", "Y"),
        help="compare with the resistance whose d1 lies along (X, Y) (Table 4)",
    )
    add_solver_argument(parser)
    add_plot_argument(parser)


def run(args: argparse.Namespace) -> dict:
    """Optimal resistance (and sweep / comparison when asked); see docs/resistance.md."""
    study = resistance_study(load_setup(args.scene, args.solver), mode=args.mode,
                             contacts=args.contacts, directions=args.directions,
                             half_width=args.segment_half_width,
                             compare_direction=args.compare_direction)
    if args.plot:
        if study.squeeze is not None:
            plot_friction(study.setup.contact_model(terminations=False),
                          study.squeeze.displacement, study.resistance, args.plot)
        else:
            plot(study.grasp, study.resistance, study.sweep, args.plot)
    return study.to_json()


def plot(
    grasp: ResistanceGrasp, res: Resistance, sweep: ResistanceSweep | None, path: str
) -> None:
    """Fig. 9: undeformed shape with the translations; deformed shape with the contact forces;
    with a sweep, the polar plot of W*_F per unit push over the push directions.
    """
    obj = grasp.obj
    mesh, L = obj.mesh, obj.scale
    fig, axes = plots.figure(3 if sweep is not None else 2)
    pts = mesh.nodes[grasp.red.contacts]
    heads = mesh.nodes[res.contacts]
    plots.draw_outline(axes[0], mesh)
    plots.mark_nodes(axes[0], pts, label="contact nodes")
    axes[0].set_title(f"{res.mode} resistance ({res.contact_model} contacts)")
    if res.success:
        moves = np.array([res.d1, res.d2, res.a])
        names = ("d1: F1's optimal translation", "d2: F2's optimal translation",
                 "a: the adversary's push")
        for p, v, color, name in zip(heads, moves, ("C0", "C1", "C3"), names):
            plots.draw_arrows(
                axes[0],
                p[None],
                v[None],
                0.25 * L * np.linalg.norm(v) / np.abs(moves).max(),
                color,
                name,
            )
        plots.legend(axes[0], ncol=1)
        delta = expansion_matrix(grasp.counts) @ np.concatenate([res.d1, res.d2, res.a])
        field = displacement_field(obj, grasp.red, delta)
        plots.draw_outline(axes[1], mesh, color="0.75", lw=0.8, label="undeformed")
        plots.draw_outline(axes[1], mesh, field, label="deformed (to scale)")
        moved = pts + field[grasp.red.contacts]
        longest = float(np.linalg.norm(res.node_forces, axis=1).max())
        plots.draw_arrows(axes[1], moved, res.node_forces, 0.25 * L, "C3",
                          f"contact force on the object (longest {longest:.3g} N)")
        plots.legend(axes[1], ncol=1)
        axes[1].set_title(f"deformed, W*_F = {res.work['total']:.4g} J")
    else:
        axes[1].set_title(res.reason, fontsize=7)
    for ax in axes[:2]:
        ax.margins(0.3)
    if sweep is not None:
        axes[2].remove()
        ax = fig.add_subplot(1, 3, 3, projection="polar")
        ok = sweep.feasible
        ax.plot(
            np.append(sweep.angles[ok], sweep.angles[ok][:1]),
            np.append(sweep.unit_work[ok], sweep.unit_work[ok][:1]),
            "C0.-",
            ms=2,
        )
        ax.set_rlabel_position(202.5)
        ax.tick_params(axis="y", labelsize=7)
        ax.set_title("W*_F per unit push [J/m^2] vs push direction", fontsize=9)
    plots.save(fig, path)


def draw_tips(ax, mesh, res: FrictionalResistance, which: str, displacement) -> None:
    """Deformed outline with the fingertips and contact nodes (solid: stick, hollow: slip)."""
    state = res.start_state if which == "start" else res.state
    plots.draw_outline(ax, mesh, color="0.75", lw=0.8)
    plots.draw_outline(ax, mesh, displacement)
    for color, f in zip(("C0", "C1", "C3"), tuple(Finger)):
        tip = state.finger(f)
        circle = tip.center + tip.radius * np.column_stack(
            [np.cos(np.linspace(0, 2 * np.pi, 121)), np.sin(np.linspace(0, 2 * np.pi, 121))]
        )
        ax.plot(circle[:, 0], circle[:, 1], color=color, lw=1.0)
        nodes = state.segment(f)
        plots.mark_nodes(
            ax,
            np.array([mesh.nodes[c.node] + c.displacement for c in nodes]),
            [c.mode == ContactMode.STICK for c in nodes],
            color,
            14,
            f"{f} ({len(nodes)} nodes)",
        )
    plots.legend(ax, ncol=3, title="contact nodes: filled stick, hollow slip", title_fontsize=8)


def plot_friction(
    model: ContactModel, squeezed: np.ndarray, res: FrictionalResistance, path: str
) -> None:
    """Fig. 10: (a) after the squeeze with A touching; (b) at the end of the resistance;
    (c) the fingers' trajectories from a common origin.
    """
    mesh = model.obj.mesh
    fig, axes = plots.figure(3)
    draw_tips(axes[0], mesh, res, "start", squeezed)
    axes[0].set_title("squeezed, A touching", fontsize=9)
    draw_tips(axes[1], mesh, res, "end", grasp_health(model, res.state)[1])
    axes[1].set_title(f"{res.reason} after {1e3 * res.travelled:.3f} mm", fontsize=9)
    ax = axes[2]
    for color, f in zip(("C0", "C1", "C3"), tuple(Finger)):
        ax.plot(*(1e3 * res.trajectories[f]).T, ".-", color=color, ms=3, label=f)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    plots.legend(ax, ncol=3)
    ax.set_title(f"trajectories, W_F = {res.work['total']:.3g} J", fontsize=9)
    plots.save(fig, path)


def summary(result: dict) -> str:
    """Human-readable resistance report."""
    i, j, k = result["contacts"]
    head = (
        f"{result['mode']} resistance, {result['contact_model']} contacts at nodes "
        f"F1 {i}, F2 {j}, A {k}; a = {np.round(result['a'], 6).tolist()} m"
    )
    if result["contact_model"] == ContactKind.FRICTION:
        return friction_summary(head, result)
    if not result["success"]:
        return f"{head}\n{result['reason']}"
    w = result["work"]
    lines = [
        head,
        f"d1 = {np.round(result['d1'], 6).tolist()} m, d2 = "
        f"{np.round(result['d2'], 6).tolist()} m",
        f"work [J]: F1 {w[Finger.F1]:.5g}, F2 {w[Finger.F2]:.5g}, total W*_F "
        f"{w['total']:.5g} (A {w[Finger.A]:.5g}); per unit push {result['unit_work']:.5g} J/m^2",
    ]
    lines += [f"force {f} [N]: {np.round(result['forces'][f], 4).tolist()}" for f in tuple(Finger)]
    cmp = result.get("comparison")
    if cmp is not None:
        other = cmp["resistance"]
        ratio = f", {cmp['ratio']:.3g} x the optimum" if cmp["ratio"] is not None else ""
        lines.append(
            f"compared: {other['reason']}: W_F {other['work']['total']:.5g} J{ratio}"
            if other["success"]
            else f"compared: {other['reason']}"
        )
    sweep = result.get("sweep")
    if sweep is not None and sweep["min"] is not None:
        lines.append(
            f"sweep of {len(sweep['angles_deg'])} directions: W*_F per unit push "
            f"{sweep['min']['unit_work']:.4g} J/m^2 at {sweep['min']['angle_deg']:.1f} deg "
            f"to {sweep['max']['unit_work']:.4g} J/m^2 at {sweep['max']['angle_deg']:.1f} deg"
        )
    return "\n".join(lines)


def friction_summary(head: str, result: dict) -> str:
    """Human-readable Algorithm 2 report (Table 3 style)."""
    w, along = result["work"], result["force_along"]
    counts = ", ".join(f"{k} {v}" for k, v in result["event_counts"].items())
    lines = [
        head,
        f"{'success' if result['success'] else 'failure'}: {result['reason']} after A "
        f"travelled {1e3 * result['travelled']:.4g} mm in {len(result['stages'])} stages; "
        f"events {counts}",
        f"d1 = {np.round(result['d1'], 6).tolist()} m, d2 = "
        f"{np.round(result['d2'], 6).tolist()} m",
        f"{'':4s}{'force start [N]':>17s}{'force end [N]':>15s}{'work [J]':>12s}",
    ]
    lines += [
        f"{f:4s}{along[f]['start']:17.4g}{along[f]['end']:15.4g}{w[f]:12.4g}"
        for f in tuple(Finger)
    ]
    lines.append(f"W_F = {w['total']:.5g} J (forces along each finger's motion, Table 3)")
    return "\n".join(lines)
