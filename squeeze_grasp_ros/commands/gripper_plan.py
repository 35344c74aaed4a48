# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp gripper-plan``: where a parallel-jaw gripper should squeeze the scene's
object, to which aperture, with which effort.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.common import (
    add_plot_argument,
    add_scene_argument,
    add_solver_argument,
    int_in,
    load_setup,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import Termination
from squeeze_grasp_ros.resources import ResourceError, device_file
from squeeze_grasp_ros.scene.gripper import GripperSpec, load_gripper
from squeeze_grasp_ros.scene.gripper_plan import DEFAULT_MARGIN, GripperPlan, scene_gripper_plan


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, --gripper, --count, --evaluate, --yaw-range, --weight, --relative-closing,
    --margin, --solver, --plot.
    """
    add_scene_argument(parser)
    parser.add_argument("--gripper", default="generic_85mm", metavar="NAME|FILE",
                        help="gripper device: a shipped name (config/devices/) or a YAML file "
                             "(default: generic_85mm)")
    parser.add_argument("--count", type=int_in(1, 10000), default=10,
                        help="ranked candidates to list (default 10)")
    parser.add_argument("--evaluate", type=int_in(0, 100), default=3,
                        help="best candidates squeezed with the pads (default 3)")
    parser.add_argument("--yaw-range", type=float, nargs=2, metavar=("MIN", "MAX"),
                        help="allowed closing directions in the object frame, deg (mod 180; "
                             "finite, MIN <= MAX)")
    parser.add_argument("--weight", type=float, metavar="N",
                        help="the object's weight if it is to be lifted (default: the scene's "
                             "pickup.weight)")
    parser.add_argument("--relative-closing", type=float, metavar="F",
                        help="closing beyond first contact / aperture at first contact "
                             "(default: the scene's squeeze.relative_depth)")
    parser.add_argument("--margin", type=float, default=DEFAULT_MARGIN,
                        help=f"commanded / predicted jaw force (default {DEFAULT_MARGIN})")
    add_solver_argument(parser)
    add_plot_argument(parser)


def gripper_device(text: str) -> GripperSpec:
    """A shipped device by name, else a device file path."""
    if Path(text).suffix in (".yaml", ".yml"):
        return load_gripper(text)
    try:
        return load_gripper(device_file(text))
    except ResourceError as exc:
        raise InvalidInputError(f"--gripper: {exc}") from None


def run(args: argparse.Namespace) -> dict:
    """Plan the gripper grasps of the scene's object."""
    gripper = gripper_device(args.gripper)
    if args.yaw_range is not None:
        lo, hi = args.yaw_range
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
            raise InvalidInputError(f"--yaw-range MIN MAX must be finite, in deg, with MIN <= "
                                    f"MAX, got {lo:g} {hi:g}")
    setup = load_setup(args.scene, args.solver)
    yaw = None if args.yaw_range is None else tuple(np.radians(args.yaw_range))
    options = {"count": args.count, "evaluate": min(args.evaluate, args.count),
               "yaw_range": yaw, "margin": args.margin}
    if args.weight is not None:
        options["weight"] = args.weight
    plan = scene_gripper_plan(setup, gripper, relative_closing=args.relative_closing,
                              **options)
    if args.plot:
        plot(setup.solid.mesh, plan, args.plot)
    return {"scene": setup.scene.name, **plan.to_json()}


def plot(mesh, plan: GripperPlan, path: str) -> None:
    """The candidates' closing lines and pads at first contact on the outline; the evaluated
    ones' deformed outline at the planned closing.
    """
    fig, axes = plots.figure(2, size=5.0)
    pad = plan.gripper.pad.shape_of()
    ax = axes[0]
    plots.draw_outline(ax, mesh, color="0.4")
    for c in reversed(plan.candidates):
        d = c.closing_direction
        half = 0.5 * c.aperture + pad.radius
        ends = np.array([c.center - half * d, c.center + half * d])
        color = f"C{c.rank % 10}" if c.rank < 10 else "0.75"
        ax.plot(ends[:, 0], ends[:, 1], "-", color=color, lw=0.8,
                label=f"#{c.rank + 1}: {c.aperture * 1e3:.1f} mm" if c.rank < 5 else None)
        if c.rank < 3:
            for end, facing in ((ends[0], c.yaw), (ends[1], c.yaw + np.pi)):
                face = pad.outline(end, facing)
                ax.plot(face[:, 0], face[:, 1], color=color, lw=1.0)
    ax.set_title(f"{len(plan.candidates)} candidates by work quality (best 5 named: aperture "
                 "at first contact)", fontsize=9)
    plots.legend(ax, ncol=2)
    ax = axes[1]
    plots.draw_outline(ax, mesh, color="0.75")
    for e in plan.evaluations:
        sq = e.squeeze
        plots.draw_outline(ax, mesh, sq.displacement, color=f"C{e.candidate.rank % 10}",
                           label=f"#{e.candidate.rank + 1}: {e.jaw_force:.3g} N at "
                                 f"{e.aperture * 1e3:.1f} mm")
        for name in sq.tips:
            finger = sq.state.finger(name)
            face = sq.tips[name].outline(finger.center, finger.facing)
            ax.plot(face[:, 0], face[:, 1], color=f"C{e.candidate.rank % 10}", lw=1.0)
    ax.set_title(f"evaluated: planned closing {100 * plan.relative_closing:.0f} % of the "
                 "aperture", fontsize=9)
    plots.legend(ax, ncol=1)
    plots.save(fig, path)


def _short(result: dict, c: dict) -> str:
    """What the planned line adds when candidate ``c``'s closing fell short of the header's
    (the jaws' travel to ``opening.min`` caps it, or the squeeze ended first), else nothing.
    """
    asked = result["relative_closing"] * c["aperture_at_contact"]
    if c["closing"] >= asked * (1.0 - 1e-9):
        return ""
    why = ", capped by the jaws' travel to opening.min" \
        if c["termination"] == Termination.DEPTH_REACHED else ""
    return (f", closing {1e3 * c['closing']:.2f} mm "
            f"({100 * c['closing'] / c['aperture_at_contact']:.1f} %) of the {1e3 * asked:.2f} mm "
            f"asked{why}")


def summary(result: dict) -> str:
    """One line per candidate; the evaluated ones with their force, limit and command."""
    lines = [f"{result['scene']}: {result['gripper']}, mu = {result['mu']:g}, closing "
             f"{100 * result['relative_closing']:.1f} % beyond first contact"
             + ("" if result["weight"] is None else f", lift {result['weight']:g} N"),
             " rank  nodes        centre [mm]        yaw [deg]  aperture [mm]  k [N/m]"]
    for c in result["candidates"]:
        x, y = (round(1e3 * v, 2) + 0.0 for v in c["center"])  # no "-0.00"
        lines.append(f"  #{c['rank'] + 1:<3d} {c['nodes'][0]:5d} {c['nodes'][1]:5d}  "
                     f"({x:8.2f}, {y:8.2f})  {np.degrees(c['yaw']):8.2f}  "
                     f"{1e3 * c['aperture_at_contact']:10.2f}  {c['stiffness']:9.4g}")
        if "command" in c:
            cmd, limit = c["command"], c["limit"]
            stop = ("none up to " + f"{1e3 * c['limit_searched_to']:.2f} mm" if limit is None
                    else f"{limit['termination']} at {1e3 * limit['closing']:.2f} mm")
            lines.append(f"        planned: aperture {1e3 * c['aperture_planned']:.2f} mm, jaw "
                         f"force {c['jaw_force']:.4g} N ({c['termination']}){_short(result, c)}; "
                         f"limit closing {stop}")
            joints = ", ".join(f"{j} {p:.4g}" for j, p in zip(cmd["joints"], cmd["positions"]))
            lines.append(f"        command: {joints}, effort {cmd['efforts'][0]:.4g} "
                         f"(jaw force {cmd['jaw_force']:.4g} N = {c['force_margin']:g} x "
                         "predicted" + (", capped at max_force" if c["exceeds_max_force"]
                                        else "") + ")")
            if c["holds_weight"] is not None:
                lines.append(f"        lift: needs {c['lift_force']:.4g} N per jaw: "
                             + ("holds" if c["holds_weight"] else "does NOT hold"))
    return "\n".join(lines)
