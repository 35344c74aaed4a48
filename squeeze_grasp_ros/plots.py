# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Matplotlib drawing primitives shared by the CLI verbs (Agg backend, PNG output)."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh
from squeeze_grasp_ros.outputs import write_atomically


def figure(ncols: int = 1, nrows: int = 1, size: float = 4.2):
    """A new figure with ``nrows x ncols`` equal-aspect axes (Agg backend, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(nrows, ncols, figsize=(size * ncols, size * nrows), squeeze=False)
    return fig, axes.ravel()


WRITTEN: list[str] = []
"""Every file :func:`save` wrote in this process, in order (the CLI names them)."""


def save(fig, path: str | Path) -> str:
    """Write ``fig`` to ``path`` (PNG, 150 dpi, replaced atomically; the bounding box grows to
    hold legends placed outside the axes), close it and return the path; a failed write raises
    :func:`~squeeze_grasp_ros.outputs.output_error`.
    """
    import matplotlib.pyplot as plt

    fig.tight_layout()
    try:
        write_atomically(path, lambda tmp: fig.savefig(tmp, dpi=150, format="png",
                                                       bbox_inches="tight"), "plot")
    finally:
        plt.close(fig)
    WRITTEN.append(str(path))
    return str(path)


def legend(ax, ncol: int = 3, **options) -> None:
    """A legend below ``ax`` (clear of its tick labels and x label), outside the data, in
    ``ncol`` columns.
    """
    from matplotlib.transforms import offset_copy

    handles, _ = ax.get_legend_handles_labels()
    if handles:
        below = offset_copy(ax.transAxes, fig=ax.figure, y=-34, units="points")
        ax.legend(**({"loc": "upper center", "bbox_to_anchor": (0.5, 0.0),
                      "bbox_transform": below, "ncol": ncol, "fontsize": 8,
                      "frameon": False} | options))


def draw_outline(ax, mesh: Mesh, displacement: np.ndarray | None = None, **style) -> None:
    """Draw the outer and inner boundary loops, displaced by ``displacement`` (n, 2) m if given
    (a ``label`` in ``style`` names the outer loop only).
    """
    pts = mesh.nodes if displacement is None else mesh.nodes + displacement
    for k, loop in enumerate((mesh.boundary, *mesh.inner_boundaries)):
        closed = np.append(loop, loop[0])
        ax.plot(pts[closed, 0], pts[closed, 1],
                **({"color": "k", "lw": 1.2} | style | ({"label": None} if k else {})))
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def draw_arrows(ax, points: np.ndarray, vectors: np.ndarray, length: float, color: str,
                label: str | None = None) -> None:
    """Arrows from ``points`` (k, 2) along ``vectors`` (k, 2), the longest drawn ``length`` m
    long.
    """
    vmax = max(float(np.linalg.norm(vectors, axis=1).max()), 1e-300)
    v = vectors * (length / vmax)
    ax.quiver(points[:, 0], points[:, 1], v[:, 0], v[:, 1], angles="xy", scale_units="xy",
              scale=1.0, color=color, width=0.006, label=label)


def mark_nodes(ax, points: np.ndarray, filled: Sequence[bool] | None = None, color: str = "C3",
               size: float = 28.0, label: str | None = None) -> None:
    """Scatter contact nodes: filled markers where ``filled`` (sticking), hollow elsewhere."""
    filled = np.ones(len(points), bool) if filled is None else np.asarray(filled, bool)
    ax.scatter(points[filled, 0], points[filled, 1], s=size, color=color, zorder=5, label=label)
    ax.scatter(points[~filled, 0], points[~filled, 1], s=size, facecolors="white",
               edgecolors=color, zorder=5)
