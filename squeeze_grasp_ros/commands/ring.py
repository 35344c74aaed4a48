# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp ring``: a ring-like object squeezed by two point fingers (Sec. 7).

One placement (the scene's fingers): the maximum feasible depth, what limits it (a friction
cone at F1/F2, the strain limit, or none before the fingers meet), and forces, strain and the
yes/no test at the requested depth. ``--map``: the same for every pair of ring nodes (Table 5).
``--bench``: timings of the precompute, the map and single placements on the scene's ring.
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.common import add_plot_argument, add_scene_argument, int_in
from squeeze_grasp_ros.commands.ring_map import closed, map_summary, plot_map
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.ring.grasp_map import bench_ring
from squeeze_grasp_ros.mechanics.ring.model import MAX_RING_ELEMENTS, RingModel
from squeeze_grasp_ros.mechanics.ring.squeeze import RingGrasp
from squeeze_grasp_ros.mechanics.vocabulary import (
    SQUEEZING_FINGERS,
    Finger,
    ObjectModel,
    StrainMeasure,
)
from squeeze_grasp_ros.scene import GraspSetup, SceneError, load_scene
from squeeze_grasp_ros.scene.studies import grasp_map_study, ring_placement

MAX_BEST = 10_000
"""Most placements ``--map --best`` lists."""
DEFAULT_BEST = 10
"""Placements ``--map`` lists without ``--best``."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, --map, --depth/--relative-depth, --elements, --best, --bench, --plot."""
    add_scene_argument(parser)
    parser.add_argument(
        "--map",
        action="store_true",
        help="grasp map over every pair of ring nodes instead of the scene's placement",
    )
    depth = parser.add_mutually_exclusive_group()
    depth.add_argument(
        "--depth",
        type=float,
        metavar="M",
        help="requested squeeze depth rho, m (default: the scene's)",
    )
    depth.add_argument(
        "--relative-depth",
        type=float,
        metavar="FRACTION",
        help="requested finger approach / initial contact distance (default: the scene's)",
    )
    parser.add_argument("--elements", type=int_in(8, MAX_RING_ELEMENTS), metavar="N",
                        help=f"override object.ring.elements (8 to {MAX_RING_ELEMENTS})")
    parser.add_argument(
        "--best",
        type=int_in(1, MAX_BEST),
        metavar="K",
        help=f"--map: list the K placements with the largest maximum depth (1 to {MAX_BEST}, "
             f"default {DEFAULT_BEST})",
    )
    parser.add_argument(
        "--bench",
        action="store_true",
        help="time the precompute, the all-pairs map and single placements (takes --elements "
             "and --json only)",
    )
    add_plot_argument(parser)


def load_ring(path: str, elements: int | None = None) -> GraspSetup:
    """The ring scene of file ``path`` made mechanics (``elements`` overrides
    ``object.ring.elements``).
    """
    scene = load_scene(path)
    if scene.object.model != ObjectModel.RING:
        raise SceneError(
            f"{path}: object.model is {scene.object.model!r}; `ring` needs model: ring"
        )
    if elements is not None:
        ring_spec = dataclasses.replace(scene.object.ring, elements=elements)
        scene = dataclasses.replace(
            scene, object=dataclasses.replace(scene.object, ring=ring_spec)
        )
    return GraspSetup.build(scene)


def run(args: argparse.Namespace) -> dict:
    """One placement, the map (``--map``) or timings (``--bench``)."""
    _require_used(args)
    setup = load_ring(args.scene, args.elements)
    scene = setup.scene
    if args.bench:
        bench = bench_ring(setup.ring, scene.mu, setup.limits.strain, scene.squeeze.type)
        return {"model": ObjectModel.RING, "bench": bench}
    if args.map:
        if args.depth is not None or (args.relative_depth is None
                                      and scene.squeeze.depth is not None):
            raise SceneError(
                "the grasp map compares placements at a relative depth: give "
                "squeeze.relative_depth or --relative-depth, not a depth in m"
            )
        study = grasp_map_study(setup, relative_depth=args.relative_depth)
        if args.plot:
            plot_map(setup.ring, study.map, args.plot)
        return study.to_json(best=args.best or DEFAULT_BEST)
    placement = ring_placement(setup, depth=args.depth, relative_depth=args.relative_depth)
    if args.plot:
        plot_grasp(setup.ring, placement.grasp, placement.depth, args.plot)
    return placement.to_json()


def _require_used(args: argparse.Namespace) -> None:
    """Refuse an option the chosen task would ignore: ``--bench`` times the scene's ring and
    draws nothing, and ``--best`` ranks the placements of ``--map`` only.

    Raises
    ------
    InvalidInputError
        Naming the ignored options.
    """
    if args.bench:
        given = [name for name, value in (("--map", args.map), ("--depth", args.depth),
                                          ("--relative-depth", args.relative_depth),
                                          ("--best", args.best), ("--plot", args.plot))
                 if value not in (None, False)]
        if given:
            raise InvalidInputError(f"--bench takes only --elements and --json, got "
                                    f"{', '.join(given)}")
    elif args.best is not None and not args.map:
        raise InvalidInputError("--best ranks the placements of --map: give --map, or leave "
                                "--best out for the scene's placement")


def _cone(ax, apex: np.ndarray, normal: np.ndarray, mu: float, length: float, **style) -> None:
    """A friction cone drawn outside the ring: the edges of the half-angle atan(mu) about
    -normal.
    """
    a = np.arctan(mu)
    edges = [
        np.array([[np.cos(s), -np.sin(s)], [np.sin(s), np.cos(s)]]) @ (-normal) for s in (a, -a)
    ]
    tri = np.array([apex, apex + length * edges[0], apex + length * edges[1]])
    ax.fill(tri[:, 0], tri[:, 1], **style)


def plot_grasp(ring: RingModel, grasp: RingGrasp, depth: float, path: str) -> str:
    """Deformed ring with forces and cones (left); force-to-normal angles vs depth (right)."""
    fig, (ax0, ax1) = plots.figure(2, size=5.0)
    before, after = ring.points, grasp.displaced(depth)
    ax0.plot(*closed(before).T, color="0.6", lw=1.0, ls="--", label="undeformed")
    ax0.plot(
        *closed(after).T,
        color="k",
        lw=1.6,
        label=f"relative depth {grasp.relative_depth(depth):.3g}",
    )
    size = ring.scale
    for k, c in enumerate(grasp.contacts):
        _cone(
            ax0,
            before[c],
            grasp.normals_at(0.0)[k],
            grasp.mu,
            0.18 * size,
            fc="none",
            ec="0.6",
            ls=":",
            label="friction cone, undeformed" if k == 0 else None,
        )
        _cone(
            ax0,
            after[c],
            grasp.normals_at(depth)[k],
            grasp.mu,
            0.18 * size,
            color="0.5",
            alpha=0.4,
            label="friction cone, deformed" if k == 0 else None,
        )
    longest = float(np.linalg.norm(grasp.forces, axis=1).max())
    plots.draw_arrows(ax0, after[grasp.contacts], grasp.forces, 0.25 * size, "purple",
                      f"finger force on the ring (longest {longest:.3g} N)")
    ax0.set_aspect("equal")
    ax0.set_xlabel("x [m]")
    ax0.set_ylabel("y [m]")
    plots.legend(ax0, ncol=2)
    ax0.set_title(
        f"nodes {grasp.contacts.tolist()}: {grasp.limit} at {grasp.max_relative_depth:.3g}"
    )
    top = min(grasp.depth_cap, max(1.5 * depth, 1.2 * grasp.max_depth, 1e-9))
    rhos = np.linspace(0.0, top, 200)
    angles = np.array([grasp.force_angles_at(r) for r in rhos])
    rel = rhos * grasp.approach_per_unit_depth / grasp.initial_distance
    for k, f in enumerate(SQUEEZING_FINGERS):
        ax1.plot(rel, angles[:, k], label=f"{f}: force vs normal")
    ax1.axhline(np.degrees(np.arctan(grasp.mu)), color="0.4", ls="--", label="cone half-angle")
    ax1.axvline(grasp.max_relative_depth, color="C3", lw=1.0, label=f"max depth ({grasp.limit})")
    ax1.axvline(grasp.relative_depth(depth), color="k", lw=0.8, ls=":", label="requested")
    ax1.set_xlabel("relative depth")
    ax1.set_ylabel("angle [deg]")
    plots.legend(ax1, ncol=2)
    ax1.set_title("cone rotation: force-to-normal angle")
    return plots.save(fig, path)


def summary(result: dict) -> str:
    """Human-readable report of one placement, the map, or the timings."""
    if "bench" in result:
        b = result["bench"]
        return (
            f"{b['elements']} elements, {b['pairs']} placements "
            f"({b['initially_feasible_pairs']} start in both cones)\n"
            f"precompute {b['precompute'] * 1e3:.1f} ms, all-pairs map {b['map'] * 1e3:.1f} ms, "
            f"single placement {b['single_mean'] * 1e3:.3f} ms mean / {b['single_min'] * 1e3:.3f} "
            "ms min"
        )
    if "pairs" in result:
        return map_summary(result)
    verdict = "feasible" if result["feasible_at_requested_depth"] else "NOT feasible"
    return "\n".join(
        [
            f"contacts {result['contacts']}: max depth {result['max_depth']:.4g} m "
            f"(relative {result['max_relative_depth']:.4g}), limit {result['limit']}",
            f"requested depth {result['depth']:.4g} m (relative {result['relative_depth']:.4g}): "
            f"{verdict}",
            f"forces F1 {np.round(result['forces'][Finger.F1], 4).tolist()} N, "
            f"F2 {np.round(result['forces'][Finger.F2], 4).tolist()} N; max fibre strain "
            f"{result['max_strain']:.4g} ({StrainMeasure(result['strain_measure']).label} "
            "strain)",
        ]
    )
