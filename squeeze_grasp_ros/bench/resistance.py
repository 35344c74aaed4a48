# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Optimal resistance at fixed contacts: time per adversary direction and per 360-direction
sweep.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from squeeze_grasp_ros.bench.table import Table, best_time, timed
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    contact_segments,
    optimal_resistance,
    resistance_grasp,
    sweep_directions,
)
from squeeze_grasp_ros.mechanics.vocabulary import ContactKind, Finger, SqueezeKind

TITLE = "Optimal resistance (Sec. 6.1-6.2): time per adversary direction"
MATERIAL = Material(5e4, 0.3, 0.0254)
OUTLINE = shapes.fourier_blob(0.055, cos=[0.0118, 0.0211, 0.0423], sin=[-0.0189, 0.027, 0.0007])
"""The Fig. 9-like blob of config/scenes/resist_fig9.yaml."""
PLACEMENT = np.array([[-0.03537, -0.04685], [-0.01256, 0.05212], [0.05900, 0.00502]])
"""Fig. 9's p_i, p_j, p_k, m (nearest boundary nodes are used)."""
PUSH = np.array([-0.01, 0.0])
"""Fig. 9's adversary translation a, m."""
SEGMENT_HALF_WIDTH = 0.004
"""Half width of the fixed contact segments, m."""
DIRECTIONS = 360
COLUMNS = [
    "nodes n",
    "boundary b",
    "contacts",
    "mode",
    "precompute [s]",
    "per direction, grasp cached [ms]",
    "per direction incl. grasp build [ms]",
    f"{DIRECTIONS}-direction sweep incl. build [ms]",
]


def resistance_rows(
    sizes: Sequence[int],
    progress: Callable[[str], None] = lambda _: None,
) -> list[list]:
    """One row per mesh size, contact model and mode (columns: :data:`COLUMNS`).

    Times are best-of wall times after the object's compliance is cached ("precompute" is
    assembly + factorisation + boundary compliance, once per mesh). "per direction" is one
    :func:`optimal_resistance` call (closed form + forces, work, residuals); "incl. grasp build"
    adds :func:`resistance_grasp` (contact compliance gather, reduced stiffness, forms); the
    sweep is :func:`sweep_directions` over 360 directions including the grasp build.
    """
    rows = []
    for target in sizes:
        progress(f"resistance: n ~ {target}")
        mesh = generate_mesh(OUTLINE, target_max_area(OUTLINE, target))
        obj = ElasticObject(mesh, MATERIAL)
        _, t_pre = timed(obj.precompute)
        b = mesh.boundary
        nodes = b[
            np.argmin(np.linalg.norm(mesh.nodes[b][None] - PLACEMENT[:, None], axis=2), axis=1)
        ]
        models = {
            ContactKind.POINT: [[n] for n in nodes],
            ContactKind.SEGMENT: contact_segments(mesh, nodes, SEGMENT_HALF_WIDTH),
        }
        for model, sets in models.items():
            segments = dict(zip(tuple(Finger), sets))
            for mode in SqueezeKind.planned():
                grasp = resistance_grasp(obj, segments)
                t_warm = best_time(lambda: optimal_resistance(grasp, PUSH, mode=mode))
                t_cold = best_time(
                    lambda: optimal_resistance(resistance_grasp(obj, segments), PUSH, mode=mode)
                )
                t_sweep = best_time(
                    lambda: sweep_directions(resistance_grasp(obj, segments), mode, DIRECTIONS)
                )
                rows.append(
                    [mesh.n, len(b), model, mode, t_pre, 1e3 * t_warm, 1e3 * t_cold, 1e3 * t_sweep]
                )
    return rows


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """The resistance timing table (quick: up to 5,000 nodes; full: up to 20,000)."""
    sizes = (517, 2000, 5000) if quick else (517, 2000, 5000, 20000)
    return [
        Table(
            TITLE,
            COLUMNS,
            resistance_rows(sizes, progress),
            "Fig. 9 placement and push on a Fig. 9-like blob. Targets: under 1 ms per "
            "adversary direction after the compliance is cached, and a 360-direction "
            "sweep (grasp-quality polar plot) under 0.5 s.",
        )
    ]
