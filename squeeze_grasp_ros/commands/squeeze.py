# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp squeeze``: event-driven squeeze with rounded fingertips (Sec. 5, Algorithm
1).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.common import (
    add_plot_argument,
    add_scene_argument,
    add_solver_argument,
    load_setup,
    output_file,
)
from squeeze_grasp_ros.commands.csv_io import write_points
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.mechanics.vocabulary import (
    ContactMode,
    EventType,
    Finger,
    MaterialModel,
    StrainMeasure,
    StressMeasure,
    TipKind,
)
from squeeze_grasp_ros.scene.studies import compare_models, squeeze_run

BAR_WIDTH = 30


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, --depth | --relative-depth, --step, --event-tol, --reference, --save-boundary,
    --solver, --plot.
    """
    add_scene_argument(parser)
    depth = parser.add_mutually_exclusive_group()
    depth.add_argument(
        "--depth", type=float, metavar="RHO", help="squeeze depth rho, m (default: the scene's)"
    )
    depth.add_argument(
        "--relative-depth",
        type=float,
        metavar="R",
        help="finger approach / initial contact distance (default: the scene's)",
    )
    parser.add_argument(
        "--step",
        type=float,
        metavar="H",
        help="depth substep relative to the object size; corotational and neo-Hookean objects "
        "adapt theirs between events, from one to four of these (default: the scene's)",
    )
    parser.add_argument(
        "--event-tol",
        type=float,
        metavar="T",
        help="event location tolerance relative to the object size (default: the scene's)",
    )
    parser.add_argument(
        "--reference",
        action="store_true",
        help="the paper's literal route: fixed step H, a full solve per step, "
        "events at step ends (for cross-checks and timing)",
    )
    parser.add_argument(
        "--save-boundary",
        metavar="FILE.csv",
        type=output_file,
        help="write the deformed outer boundary (x,y per node, m, loop order), "
        "e.g. for `squeeze-grasp match`",
    )
    models = parser.add_mutually_exclusive_group()
    models.add_argument(
        "--model",
        choices=MaterialModel.values(),
        help="constitutive model (default: the scene's object.material.model, else linear)",
    )
    models.add_argument(
        "--compare-models",
        action="store_true",
        help="run the scene under every model and print forces, energy, contact widths, max "
        "strain (each model's own measure and the common Biot strain), max von Mises stress, "
        "events and termination side by side with the differences from linear (strains like "
        "for like, in every measure); with --plot, overlay the deformed outlines and the "
        "force-depth curves",
    )
    add_solver_argument(parser)
    add_plot_argument(parser)


class ProgressBar:
    """A one-line progress bar on stderr, drawn only when stderr is a terminal."""

    def __init__(self) -> None:
        self.enabled = sys.stderr.isatty()

    def __call__(self, fraction: float) -> None:
        if self.enabled:
            done = int(round(BAR_WIDTH * fraction))
            sys.stderr.write(
                f"\rsqueeze [{'#' * done}{'.' * (BAR_WIDTH - done)}] {100 * fraction:5.1f} %"
            )
            sys.stderr.flush()

    def close(self) -> None:
        """End the line."""
        if self.enabled:
            sys.stderr.write("\n")


def run(args: argparse.Namespace) -> dict:
    """Run the squeeze; JSON keys per docs/design.md §2 (see docs/events.md)."""
    setup = load_setup(args.scene, args.solver)
    overrides = {"depth": args.depth, "relative_depth": args.relative_depth,
                 "step": args.step, "event_tol": args.event_tol}
    if args.compare_models:
        comparison = compare_models(
            setup, on_model=lambda m: print(f"squeeze: {m} ...", file=sys.stderr, flush=True),
            **overrides)
        out = comparison.to_json()
        if args.plot:
            out["plot"] = plot_models(setup.solid, comparison.results, args.plot)
        return out
    bar = ProgressBar()
    try:
        squeezed = squeeze_run(setup, reference=args.reference, progress=bar,
                               material_model=args.model, **overrides)
    finally:
        bar.close()
    out, res, obj = squeezed.to_json(), squeezed.result, setup.solid
    if args.plot:
        out["plot"] = plot(obj, res, args.plot)
    if args.save_boundary:
        loop = obj.mesh.boundary
        out["boundary_csv"] = write_points(
            args.save_boundary, obj.mesh.nodes[loop] + res.displacement[loop]
        )
    return out


def plot(obj, res: EventSqueeze, path: str) -> str:
    """Deformed shape with sticking (solid) / sliding (hollow) nodes and fingertips (Table 1),
    polar-angle changes vs relative depth (Fig. 6), and the event timeline; one PNG.
    """
    mesh = obj.mesh
    fig, axes = plots.figure(3)
    ax = axes[0]
    plots.draw_outline(ax, mesh, color="0.75", lw=0.8)
    plots.draw_outline(ax, mesh, res.displacement)
    for name, color in ((Finger.F1, "C0"), (Finger.F2, "C1")):
        finger = res.state.finger(name)
        arc = res.tips[name].outline(finger.center, finger.facing)
        ax.plot(arc[:, 0], arc[:, 1], color=color, lw=1.0)
        seg = res.state.segment(name)
        pts = np.array([mesh.nodes[c.node] + c.displacement for c in seg])
        plots.mark_nodes(
            ax,
            pts,
            [c.mode == ContactMode.STICK for c in seg],
            color=color,
            size=14,
            label=f"{name} ({len(seg)} nodes)",
        )
    plots.legend(ax, ncol=2, title="contact nodes: filled stick, hollow slip", title_fontsize=8)
    ax.set_title(
        f"{res.termination} at {100 * res.relative_depth:.2f} % (mu = {res.mu:g})", fontsize=9
    )
    ax = axes[1]
    ax.set_aspect("auto")
    changes = {node: np.array(t)[:, 1] - t[0][1] for node, t in res.trajectories.items()}
    if max((float(np.abs(c).max()) for c in changes.values()), default=0.0) < 1e-9:
        # every node sticks: polar angles stay fixed (Fig. 6 is about sliding nodes)
        for f, curve in res.force_curve.items():
            x, y = np.array(curve).T if curve else ([], [])
            ax.plot(np.asarray(x), y, ls="-" if f == Finger.F1 else "--", label=f)
        plots.legend(ax, ncol=2)
        ax.set_ylabel("force along the finger's motion [N]")
        ax.set_title("every contact node sticks, so no polar angle changes (Fig. 6);\n"
                     "the finger forces instead", fontsize=9)
    else:
        order = sorted(res.trajectories, key=lambda k: (res.trajectories[k][0][0], k))
        for offset, node in enumerate(order):
            traj = np.array(res.trajectories[node])
            scale = max(float(np.abs(changes[node]).max()), 1e-12)
            ax.plot(traj[:, 0], offset + 0.4 * changes[node] / scale, lw=1.0)
            ax.text(traj[-1, 0], offset, f" {node}", fontsize=6, va="center")
        ax.set_ylabel("polar-angle change (each node scaled, offset)")
        ax.set_title("polar angles of the contact nodes (Fig. 6)", fontsize=9)
    ax.set_xlabel("relative squeeze depth")
    ax = axes[2]
    ax.set_aspect("auto")
    for row, kind in enumerate(EventType):
        evs = [e for e in res.events if e.type == kind]
        ax.scatter(
            [e.relative_depth for e in evs],
            [row] * len(evs),
            c=["C0" if e.finger == Finger.F1 else "C1" for e in evs],
            s=18,
            marker="|",
        )
    ax.set_yticks(
        range(len(EventType)),
        [f"{k} ({n})" for k, n in res.event_counts.items()],
    )
    ax.set_xlim(0, max(res.relative_depth, 1e-9) * 1.02)
    ax.set_xlabel("relative squeeze depth")
    ax.set_title("event timeline (F1 blue, F2 orange)", fontsize=9)
    return plots.save(fig, path)


def plot_models(obj, results: dict, path: str) -> str:
    """Deformed outlines and force-depth curves of every model, overlaid."""
    fig, (ax0, ax1) = plots.figure(ncols=2, size=5.2)
    loop = np.append(obj.mesh.boundary, obj.mesh.boundary[0])
    ax0.plot(*obj.mesh.nodes[loop].T, color="0.75", lw=1, label="undeformed")
    for (model, res), color in zip(results.items(), ("C0", "C1", "C2")):
        ax0.plot(*(obj.mesh.nodes + res.displacement)[loop].T, color=color, lw=1.2, label=model)
        for f, curve in res.force_curve.items():
            x, y = np.array(curve).T if curve else ([], [])
            ax1.plot(100 * np.asarray(x), y, color=color,
                     ls="-" if f == Finger.F1 else "--", label=f"{model} {f}")
    ax0.set_aspect("equal")
    ax0.set_title("deformed outlines (m)")
    plots.legend(ax0, ncol=2)
    ax1.set_aspect("auto")
    ax1.set_xlabel("relative depth (%)")
    ax1.set_ylabel("force along the finger's motion (N)")
    ax1.set_title("force-depth")
    plots.legend(ax1, ncol=3)
    return plots.save(fig, path)


def _percent(difference: float) -> str:
    """A relative difference from linear as a signed percentage; one of a quantity that is 0
    for linear (``rel`` gives NaN: a squeeze to depth 0 has no contact width) says so.
    """
    return f"{100 * difference:+.2f} %" if np.isfinite(difference) else "undefined (linear 0)"


def compare_summary(result: dict) -> str:
    """The model comparison as a table."""
    rows, diff = result["models"], result["relative_difference"]
    common = StrainMeasure(result["common_strain_measure"])
    lines = [f"{result['scene']}: the same squeeze under every material model "
             "(differences relative to linear)",
             f"{'model':<14}{'termination':<15}{'rel. depth':>11}{'F1 force N':>12}"
             f"{'energy J':>12}{'F1 half-width m':>17}{'max strain':>12} {'measure':<8}"
             f"{common.label + ' strain':>12}{'von Mises Pa':>14} {'stress':<13}events  time s"]
    for model, r in rows.items():
        counts = " ".join(f"{k}{v}" for k, v in r["event_counts"].items())
        lines.append(f"{model:<14}{r['termination']:<15}{100 * r['relative_depth']:>10.3f}%"
                     f"{r['force'][Finger.F1]:>12.5g}{r['energy']:>12.5g}"
                     f"{r['contact_half_width'][Finger.F1]:>17.4g}{r['max_strain']:>12.4g} "
                     f"{StrainMeasure(r['strain_measure']).label:<8}"
                     f"{r['max_principal_strain'][common]:>12.4g}{r['max_von_mises']:>14.4g} "
                     f"{StressMeasure(r['stress_measure']).label:<13}{counts}  "
                     f"{r['seconds']:.2f}")
    for model, d in diff.items():
        lines.append(f"{model} vs linear: force {_percent(d['force'][Finger.F1])}, energy "
                     f"{_percent(d['energy'])}, max {common.label} strain "
                     f"{_percent(d['max_principal_strain'][common])}, F1 half-width "
                     f"{_percent(d['contact_half_width'][Finger.F1])}, time "
                     f"x{d['seconds_ratio']:.0f}")
    lines.append("max principal strain vs linear, like for like (the same measure of both "
                 "fields):")
    for model, d in diff.items():
        lines.append(f"  {model}: " + ", ".join(
            f"{StrainMeasure(k).label} {_percent(v)}"
            for k, v in d["max_principal_strain"].items()))
    lines.append(f"max strain: in the model's own measure, which its strain limit uses; "
                 f"{common.label} strain: U - I of every field; von Mises of the model's stress "
                 "(small-strain: C : eps; Cauchy: true stress)")
    if "plot" in result:
        lines.append(f"plot: {result['plot']}")
    return "\n".join(lines)


ROUND_OFF = 1e-12
"""Relative size below which a printed value is round-off around an exact zero."""


def at_scale(value: float, scale: float) -> float:
    """``value`` as the summary prints it: 0 if it is round-off against ``scale`` (same unit).

    A squeeze's force along the motion at depth 0, or the slip margin of a sliding node, is zero
    by construction and comes out of the arithmetic as a few 1e-15 N; printed with 4 digits
    next to forces of newtons it read as a value. The JSON keeps the computed floats.

    >>> at_scale(-5.214e-15, 4.906), at_scale(0.06069, 4.906), at_scale(-8.8e-16, 0.0)
    (0.0, 0.06069, -8.8e-16)
    """
    return 0.0 if abs(value) <= ROUND_OFF * abs(scale) else value


def tip_words(tips: dict) -> str:
    """``tip radius 0.02 m`` for circles alike, else each finger's tip (``F1 pad 0.022 m
    wide, edges 0.002 m``).
    """
    words = {name: (f"pad {t['width']:g} m wide, edges {t['edge_radius']:g} m"
                    if t["shape"] == TipKind.PAD else f"tip radius {t['radius']:g} m")
             for name, t in tips.items()}
    if len(set(words.values())) == 1:
        return next(iter(words.values()))
    return ", ".join(f"{name} {text}" for name, text in words.items())


def summary(result: dict) -> str:
    """Human-readable squeeze report."""
    if result.get("compare_models"):
        return compare_summary(result)
    c = result["event_counts"]
    limit = result["strain_limit"]
    lines = [
        f"{result['scene']}: {result['squeeze']} squeeze of a {result['material_model']} "
        f"object, mu = {result['mu']:g}, {tip_words(result['tips'])}, initial "
        f"contacts {result['contacts']}",
        f"termination: {result['termination']} at depth {result['depth']:.6g} m "
        f"(relative {100 * result['relative_depth']:.3f} %)"
        + (f"; strain limit {limit['epsilon']:g} on the "
           f"{StrainMeasure(limit['measure']).label} strain ({limit['criterion']})"
           if limit else ""),
        "events: " + ", ".join(f"{k} {n}" for k, n in c.items()),
    ]
    for name, seg in result["segments"].items():
        modes = " ".join(f"{s['node']}{'' if s['mode'] == ContactMode.STICK else '~'}"
                         for s in seg)
        ff = result["finger_force"][name]
        friction = result["dissipation"][name]
        lines.append(
            f"{name}: {len(seg)} nodes [{modes}] (~ = sliding); force along motion "
            f"{at_scale(ff['start'], ff['end']):.4g} -> {ff['end']:.4g} N, work "
            f"{result['work'][name]:.4g} J"
            + (f" ({friction:.3g} J dissipated by friction)" if friction > 0 else "")
        )
    h = result["health"]
    strain = StrainMeasure(h["strain_measure"]).label
    lines.append(
        f"energy {result['energy']:.5g} J; max strain {h['max_strain']:.4g} "
        f"({strain} strain, {h['criterion']}, element {h['max_strain_element']}); max von "
        f"Mises {h['max_von_mises']:.4g} Pa ({StressMeasure(h['stress_measure']).label} "
        f"stress); max displacement {h['max_displacement']:.4g} m; slip margin "
        + ", ".join(f"{k} {at_scale(v, result['finger_force'].get(k, {}).get('end', 0.0)):.4g} N"
                    for k, v in h["slip_margin"].items())
    )
    if result["chatter"]:
        lines.append(f"chattering bound froze {len(result['chatter'])} node mode(s)")
    t = result["timing"]
    lines.append(f"time: precompute {t['precompute_s']:.3f} s, squeeze {t['squeeze_s']:.3f} s")
    for key in ("plot", "boundary_csv"):
        if key in result:
            lines.append(f"{key.replace('_', ' ')}: {result[key]}")
    return "\n".join(lines)
