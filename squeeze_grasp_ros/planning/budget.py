# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The memory a load will need, bounded before the expensive stages start.

A solid's factorisation orders the outer-boundary DOFs last, so its trailing block is dense
(2b x 2b for b boundary nodes), and so are the boundary compliance and the temporaries that
build it; the spectral route is dense in all 2n DOFs. Their memory grows with the square of
that dense size d, and none of it can be interrupted once SuperLU or LAPACK runs. Measured on
this machine (``planning.resident_bytes`` and the peak RSS of a load; thin rectangles of
2,321-4,395 nodes, b = 664-2,550): the object then holds 36-55 bytes per d^2 and the load
peaks at 76-104 bytes per d^2. So a load whose ``PEAK_BYTES_PER_DENSE_ENTRY * d^2`` exceeds the
planner's memory bound is refused right after meshing, before the factorisation.

Before this bound, a thin rectangle (height 1e-5 m, 14,418 nodes, every one on the boundary)
grew the planner's memory by gigabytes inside SuperLU for minutes, beyond any cancel.

>>> check_load(boundary_nodes=377, nodes=19861, route="factorized", max_bytes=2**31)
>>> check_load(boundary_nodes=14418, nodes=14418, route="factorized", max_bytes=2**31)
Traceback (most recent call last):
...
squeeze_grasp_ros.planning.errors.PlannerError: the load needs about 79,299 MiB for its dense \
28836 x 28836 blocks (2 rows per boundary node: 14418 of its 14418 nodes), more than the \
planner's bound of 2,048 MiB (parameter cache_max_megabytes); use fewer nodes (object.mesh), \
or a shape less thin
"""

from __future__ import annotations

from squeeze_grasp_ros.planning.errors import invalid

PEAK_BYTES_PER_DENSE_ENTRY = 100
"""Bytes a load peaks at per entry of its dense d x d blocks (measured 76-104; see above)."""


def check_load(*, boundary_nodes: int, nodes: int, route: str, max_bytes: int | None) -> None:
    """Refuse a load of a meshed solid whose dense blocks would peak above ``max_bytes``.

    Parameters
    ----------
    boundary_nodes, nodes : int
        Outer-boundary nodes b and all nodes n of the mesh.
    route : {"factorized", "spectral"}
        Dense size d = 2b (factorized) or 2n (spectral).
    max_bytes : int or None
        The bound (None: no bound).

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT naming the estimate, the bound and its parameter.
    """
    spectral = route == "spectral"
    dense = 2 * (nodes if spectral else boundary_nodes)
    need = PEAK_BYTES_PER_DENSE_ENTRY * dense * dense
    if max_bytes is not None and need > max_bytes:
        rows = (f"2 rows per node, spectral route: {nodes} nodes" if spectral else
                f"2 rows per boundary node: {boundary_nodes} of its {nodes} nodes")
        raise invalid(
            f"the load needs about {need / 2**20:,.0f} MiB for its dense {dense} x {dense} "
            f"blocks ({rows}), more than the planner's bound of {max_bytes / 2**20:,.0f} MiB "
            "(parameter cache_max_megabytes); use fewer nodes (object.mesh), or a shape less "
            "thin"
        )
