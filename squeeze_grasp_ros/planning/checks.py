# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Checks of request fields: numbers, steps, counts, choices and contact nodes."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from squeeze_grasp_ros.planning.errors import invalid
from squeeze_grasp_ros.planning.object_ids import shown
from squeeze_grasp_ros.planning.objects import MAX_BEST_COUNT, LoadedObject, PlannerLimits

# --------------------------------------------------------------------------- request checks


def check_number(name: str, value: float, low: float = -math.inf, high: float = math.inf) -> float:
    """``value`` if finite and in [low, high], else INVALID_ARGUMENT naming ``name``."""
    if not math.isfinite(value):
        raise invalid(f"{name} must be finite, got {value}")
    if not low <= value <= high:
        bounds = f">= {low}" if high == math.inf else f"in [{low}, {high}]"
        raise invalid(f"{name} must be {bounds}, got {value}")
    return float(value)


def check_step(step: float, limits: PlannerLimits) -> float:
    """An event-squeeze substep no smaller than the node's ``min_step``."""
    if step < limits.min_step:
        raise invalid(
            f"step {step} is below the planner's min_step {limits.min_step} "
            "(parameter): the squeeze would take too long"
        )
    return step


def best_count(requested: int, limits: PlannerLimits, name: str = "best_count") -> int:
    """Placements a map returns: ``requested`` in [1, MAX_BEST_COUNT], or the default for 0;
    ``name`` is the request's field in the error.
    """
    return int(check_number(name, requested, 0, MAX_BEST_COUNT)) or limits.best_count


def choice(name: str, value: str, allowed: Sequence[str], default: str | None = None) -> str:
    """``value`` (or ``default`` when empty and given) if it is one of ``allowed``."""
    if not value and default is not None:
        return default
    if value not in allowed:
        raise invalid(f"{name} must be one of {list(allowed)}, got {shown(value)}")
    return value


def contact_nodes(
    loaded: LoadedObject,
    contacts: Sequence[int],
    count: int | None = None,
    default: Sequence[int] | None = None,
) -> np.ndarray:
    """Validated contact nodes: distinct nodes of the outer boundary (every node of a ring).

    Parameters
    ----------
    loaded : LoadedObject
    contacts : sequence of int
        Requested nodes; empty means ``default``.
    count : int, optional
        Exact number of nodes required (at least 2 when None).
    default : sequence of int, optional
        Nodes used for an empty request (none: an empty request is refused).
    """
    if len(contacts) == 0 and default is not None:
        contacts = default
    nodes = np.asarray(list(contacts), dtype=np.int64).reshape(-1)
    if count is not None and len(nodes) != count:
        raise invalid(f"contacts needs exactly {count} nodes, got {len(nodes)}")
    if len(nodes) < 2:
        raise invalid(f"contacts needs at least 2 nodes, got {len(nodes)}")
    if len(np.unique(nodes)) != len(nodes):
        raise invalid(f"contacts must be distinct nodes, got {nodes.tolist()}")
    off = nodes[~np.isin(nodes, loaded.boundary)]
    if len(off):
        raise invalid(
            f"contact node {int(off[0])} is not on the outer boundary of object "
            f"{loaded.object_id!r} ({len(loaded.boundary)} boundary nodes; "
            "LoadObject with return_model lists them)"
        )
    return nodes
