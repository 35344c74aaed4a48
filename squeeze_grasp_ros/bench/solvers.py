# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Solver routes vs mesh size: precompute and per-squeeze time, spectral vs factorised."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from squeeze_grasp_ros.bench.table import Table, best_time, timed
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.elastic.reduced import boundary_displacement, reduced_stiffness
from squeeze_grasp_ros.mechanics.squeeze.graspmap import grasp_map
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import SqueezeKind

TITLE = "Solver routes: precompute and squeeze time vs mesh size"
MATERIAL = Material(5e4, 0.3, 0.0254)
OUTLINE = shapes.fourier_blob(0.06, cos=[0.0, 0.15, 0.05], sin=[0.05])


def _squeeze(obj: ElasticObject, contacts) -> np.ndarray:
    """One two-contact stable squeeze: reduced stiffness, plan, boundary displacement."""
    red = reduced_stiffness(obj, contacts)
    sq = plan_squeeze(obj, contacts, kind=SqueezeKind.STABLE, red=red)
    return boundary_displacement(obj, red, 1e-3 * sq.displacement)


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """Time both routes at several mesh sizes (spectral only where it fits in time)."""
    sizes = (500, 1000, 3000, 10000) if quick else (500, 1000, 2000, 3000, 5000, 10000, 20000)
    spectral_max = 1000 if quick else 3000
    rows, gm_rows = [], []
    for target in sizes:
        progress(f"solvers: n ~ {target}")
        mesh, t_mesh = timed(lambda: generate_mesh(OUTLINE, target_max_area(OUTLINE, target)))
        b = mesh.boundary
        contacts = [b[0], b[len(b) // 2]]
        fact = ElasticObject(mesh, MATERIAL)
        _, t_fact = timed(fact.precompute)
        t_sq = best_time(lambda: _squeeze(fact, contacts))
        if mesh.n <= spectral_max * 1.1:
            spec = ElasticObject(mesh, MATERIAL, "spectral")
            _, t_spec = timed(spec.precompute)
            t_sq_spec = best_time(lambda: _squeeze(spec, contacts), repeat=2)
            ratio = t_spec / t_fact
        else:
            t_spec = t_sq_spec = ratio = "-"
        rows.append([mesh.n, len(b), t_mesh, t_fact, 1e3 * t_sq, t_spec,
                     1e3 * t_sq_spec if t_sq_spec != "-" else "-", ratio])
        _, t_map = timed(lambda: grasp_map(fact, 0.4))
        gm_rows.append([mesh.n, len(b), len(b) * (len(b) - 1) // 2, t_map])
    table = Table(
        TITLE,
        [
            "nodes n",
            "boundary b",
            "mesh [s]",
            "factorised precompute [s]",
            "factorised squeeze [ms]",
            "spectral precompute [s]",
            "spectral squeeze [ms]",
            "precompute ratio spectral/factorised",
        ],
        rows,
        "Precompute = assembly + factorisation (+ eigendecomposition for the spectral route) + "
        "boundary compliance. Squeeze = reduced stiffness + stable squeeze + boundary "
        "displacement "
        "for two contacts. Both routes on the same mesh in the same run.",
    )
    gm = Table("All-pairs grasp map (after precompute)",
               ["nodes n", "boundary b", "placements", "time [s]"], gm_rows,
               "Stiffness, inwardness and force closure of every boundary-node pair, vectorised.")
    return [table, gm]
