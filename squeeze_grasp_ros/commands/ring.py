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
from squeeze_grasp_ros.mechanics.ring.grasp_map import RingGraspMap, bench_ring, ring_grasp_map
from squeeze_grasp_ros.mechanics.ring.model import FIBRE_STRAIN_MEASURE, RingModel
from squeeze_grasp_ros.mechanics.ring.squeeze import LIMITS, RingGrasp, ring_grasp
from squeeze_grasp_ros.scene import Scene, SceneError, build_ring, finger_nodes, load_scene
from squeeze_grasp_ros.commands.common import add_plot_argument, add_scene_argument
from squeeze_grasp_ros.mechanics.vocabulary import SQUEEZING_FINGERS, StrainMeasure, Termination

HELP = "ring-like object, two point fingers (Sec. 7): max squeeze depth, limit, all-pairs map"


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
    parser.add_argument("--elements", type=int, metavar="N", help="override object.ring.elements")
    parser.add_argument(
        "--best",
        type=int,
        default=10,
        metavar="K",
        help="--map: list the K placements with the largest maximum depth",
    )
    parser.add_argument(
        "--bench",
        action="store_true",
        help="time the precompute, the all-pairs map and single placements",
    )
    add_plot_argument(parser)


def load_ring(path: str, elements: int | None = None) -> tuple[Scene, RingModel]:
    """The scene and its ring model (``elements`` overrides ``object.ring.elements``)."""
    scene = load_scene(path)
    if scene.object.model != "ring":
        raise SceneError(
            f"{path}: object.model is {scene.object.model!r}; `ring` needs model: ring"
        )
    if elements is not None:
        if elements < 8:
            raise SceneError(f"--elements must be >= 8, got {elements}")
        ring_spec = dataclasses.replace(scene.object.ring, elements=elements)
        scene = dataclasses.replace(
            scene, object=dataclasses.replace(scene.object, ring=ring_spec)
        )
    return scene, build_ring(scene)


def strain_limit(scene: Scene) -> float | None:
    """epsilon* of the scene, None without the strain_limit effect."""
    return scene.strain_limit.epsilon if scene.has(Termination.STRAIN_LIMIT) else None


def requested(scene: Scene, args: argparse.Namespace) -> tuple[float | None, float | None]:
    """(depth m, relative depth): the command line wins over the scene; at most one is set."""
    if args.depth is not None or args.relative_depth is not None:
        return args.depth, args.relative_depth
    return scene.squeeze.depth, scene.squeeze.relative_depth


def run(args: argparse.Namespace) -> dict:
    """One placement, the map (``--map``) or timings (``--bench``)."""
    scene, ring = load_ring(args.scene, args.elements)
    mu, eps, kind = scene.mu, strain_limit(scene), scene.squeeze.type
    if args.bench:
        return {"model": "ring", "bench": bench_ring(ring, mu, eps, kind)}
    depth, relative = requested(scene, args)
    if args.map:
        if depth is not None:
            raise SceneError(
                "the grasp map compares placements at a relative depth: give "
                "squeeze.relative_depth or --relative-depth, not a depth in m"
            )
        return map_result(scene, ring, relative, args.plot, args.best)
    if depth is None and relative is None:
        raise SceneError(
            "give squeeze.depth or squeeze.relative_depth (or --depth/--relative-depth)"
        )
    grasp = ring_grasp(ring, finger_nodes(scene, ring), mu, epsilon=eps, kind=kind)
    rho = depth if depth is not None else grasp.depth_for_relative(relative)
    if args.plot:
        plot_grasp(ring, grasp, rho, args.plot)
    return grasp_json(ring, grasp, rho)


def map_result(
    scene: Scene,
    ring: RingModel,
    relative_depth: float | None,
    plot: str | None = None,
    best: int = 10,
) -> dict:
    """The all-pairs map of a ring scene as JSON (``graspmap`` serves ring scenes with this)."""
    gmap = ring_grasp_map(
        ring,
        scene.mu,
        epsilon=strain_limit(scene),
        kind=scene.squeeze.type,
        requested_relative_depth=relative_depth,
    )
    if plot:
        plot_map(ring, gmap, plot)
    return {"model": "ring", **gmap.to_json(best=best)}


def force_angles(grasp: RingGrasp, depth: float) -> np.ndarray:
    """Angle (deg) between each contact force and its contact normal at ``depth`` (m)."""
    N = grasp.normals_at(depth)
    F = grasp.forces / np.linalg.norm(grasp.forces, axis=1, keepdims=True)
    return np.degrees(np.arccos(np.clip(np.sum(N * F, axis=1), -1.0, 1.0)))


def grasp_json(ring: RingModel, grasp: RingGrasp, depth: float) -> dict:
    """The JSON result of one placement at requested depth ``depth`` (m)."""
    forces = grasp.forces_at(depth)
    at0, at_depth = force_angles(grasp, 0.0), force_angles(grasp, depth)
    return {
        "model": "ring",
        "elements": ring.n,
        "squeeze": grasp.kind,
        "mu": grasp.mu,
        "epsilon": grasp.epsilon,
        "strain_measure": str(FIBRE_STRAIN_MEASURE),
        "contacts": [int(c) for c in grasp.contacts],
        "points": {f: ring.points[c].tolist() for f, c in zip(SQUEEZING_FINGERS, grasp.contacts)},
        "depth": float(depth),
        "relative_depth": grasp.relative_depth(depth),
        "max_depth": grasp.max_depth,
        "max_relative_depth": grasp.max_relative_depth,
        "limit": grasp.limit,
        "limit_depths": grasp.limit_depths(),
        "feasible_at_requested_depth": grasp.feasible_at(depth),
        "forces": {f: forces[k].tolist() for k, f in enumerate(SQUEEZING_FINGERS)},
        "stiffness": grasp.stiffness,
        "max_strain": grasp.max_strain_at(depth),
        "max_strain_element": int(np.argmax(grasp.strains)),
        "cone_half_angle_deg": float(np.degrees(np.arctan(grasp.mu))),
        "force_angle_deg": {
            f: [float(at0[k]), float(at_depth[k])] for k, f in enumerate(SQUEEZING_FINGERS)
        },
    }


def _closed(points: np.ndarray) -> np.ndarray:
    return np.vstack([points, points[:1]])


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
    ax0.plot(*_closed(before).T, color="0.6", lw=1.0, ls="--", label="undeformed")
    ax0.plot(
        *_closed(after).T,
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
        )
        _cone(
            ax0,
            after[c],
            grasp.normals_at(depth)[k],
            grasp.mu,
            0.18 * size,
            color="0.5",
            alpha=0.4,
        )
    plots.draw_arrows(ax0, after[grasp.contacts], grasp.forces, 0.25 * size, "purple", "forces")
    ax0.set_aspect("equal")
    ax0.set_xlabel("x [m]")
    ax0.set_ylabel("y [m]")
    ax0.legend(fontsize=7, loc="upper right")
    ax0.set_title(
        f"nodes {grasp.contacts.tolist()}: {grasp.limit} at {grasp.max_relative_depth:.3g}"
    )
    top = min(grasp.depth_cap, max(1.5 * depth, 1.2 * grasp.max_depth, 1e-9))
    rhos = np.linspace(0.0, top, 200)
    angles = np.array([force_angles(grasp, r) for r in rhos])
    rel = rhos * grasp.approach_per_unit_depth / grasp.initial_distance
    for k, f in enumerate(SQUEEZING_FINGERS):
        ax1.plot(rel, angles[:, k], label=f"{f}: force vs normal")
    ax1.axhline(np.degrees(np.arctan(grasp.mu)), color="0.4", ls="--", label="cone half-angle")
    ax1.axvline(grasp.max_relative_depth, color="C3", lw=1.0, label=f"max depth ({grasp.limit})")
    ax1.axvline(grasp.relative_depth(depth), color="k", lw=0.8, ls=":", label="requested")
    ax1.set_xlabel("relative depth")
    ax1.set_ylabel("angle [deg]")
    ax1.legend(fontsize=7)
    ax1.set_title("cone rotation: force-to-normal angle")
    return plots.save(fig, path)


def outcome_matrix(gmap: RingGraspMap) -> tuple[np.ndarray, list[str]]:
    """(n, n) outcome codes with the row as F1's node, and their names: the limit codes, then
    "succeeds" (at the requested relative depth) and "outside a cone at start"; -1 on the
    diagonal.
    """
    names = [*LIMITS, "succeeds", "outside a cone at start"]
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
    ax1.legend(fontsize=6, loc="upper left")
    target = gmap.requested_relative_depth
    ax1.set_title("limit" + (f" / success at relative depth {target:.3g}" if target else ""))
    for ax in (ax0, ax1):
        ax.set_xlabel("F2 node j")
        ax.set_ylabel("F1 node i")
    ax2.plot(*_closed(ring.points).T, color="k", lw=1.2)
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
    ax2.legend(fontsize=6)
    ax2.set_title("deepest placements")
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
    verdict = "feasible" if result["feasible_at_requested_depth"] else "NOT feasible"
    return "\n".join(
        [
            f"contacts {result['contacts']}: max depth {result['max_depth']:.4g} m "
            f"(relative {result['max_relative_depth']:.4g}), limit {result['limit']}",
            f"requested depth {result['depth']:.4g} m (relative {result['relative_depth']:.4g}): "
            f"{verdict}",
            f"forces F1 {np.round(result['forces']['F1'], 4).tolist()} N, "
            f"F2 {np.round(result['forces']['F2'], 4).tolist()} N; max fibre strain "
            f"{result['max_strain']:.4g} ({StrainMeasure(result['strain_measure']).label} "
            "strain)",
        ]
    )
