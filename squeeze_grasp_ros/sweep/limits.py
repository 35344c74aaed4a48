# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""How large a sweep may be, checked from counts before anything is enumerated.

A spec's size is a product of its axes, so a short spec can ask for more evaluations than any
machine holds (a 106 KB spec with three axes of 3,000 values asks for 2.7e10; ``count: 1e9``
placements or ``repeat: 1e12`` draws likewise), and ``--dry-run`` used to hang building them.
The counts are multiplied first and refused above the limits below, with the count and its
factors in the message; ``--dry-run`` reports them.
"""
from __future__ import annotations

import math

from squeeze_grasp_ros.sweep.spec import SweepError

MAX_EVALUATIONS = 1_000_000
"""Most evaluations (event-driven squeezes) of one sweep: about 28 core-hours at 0.1 s each.
Split larger studies into several specs (each with its own --out)."""

MAX_TASKS = 20_000
"""Most Dask tasks of one sweep (each is a Parquet part and a manifest entry)."""

MAX_TASK_EVALUATIONS = 100_000
"""Most evaluations of one task (one Parquet part; a placement's parameter sets are never split
across tasks)."""

MAX_OBJECTS = 10_000
"""Most objects of one sweep (family ``count`` included)."""


class SweepSizeError(SweepError):
    """A sweep spec asks for more than the limits of :mod:`squeeze_grasp_ros.sweep.limits`."""


def check_objects(count: int) -> None:
    """Refuse more than :data:`MAX_OBJECTS` objects."""
    if count > MAX_OBJECTS:
        raise SweepSizeError(f"the spec has {count:,} objects (families included); at most "
                             f"{MAX_OBJECTS:,} are allowed")


def check_parameter_sets(axes: dict[str, int]) -> int:
    """The number of parameter sets per placement (the product of ``axes``: name -> length);
    refused above :data:`MAX_TASK_EVALUATIONS` (they are one placement's task).
    """
    count = math.prod(axes.values())
    if count > MAX_TASK_EVALUATIONS:
        factors = " x ".join(f"{name} {n:,}" for name, n in axes.items())
        raise SweepSizeError(
            f"the spec asks for {count:,} parameter sets per placement ({factors}); at most "
            f"{MAX_TASK_EVALUATIONS:,} are allowed (and {MAX_EVALUATIONS:,} evaluations in all)")
    return count


def check_evaluations(placements: int, materials: int, parameter_sets: int, tasks: int) -> int:
    """The sweep's evaluations, refused above :data:`MAX_EVALUATIONS` or :data:`MAX_TASKS`
    tasks; the message names the factors.
    """
    count = placements * materials * parameter_sets
    factors = (f"{placements:,} placements (over all objects) x {materials:,} materials x "
               f"{parameter_sets:,} parameter sets")
    if count > MAX_EVALUATIONS:
        raise SweepSizeError(
            f"the spec asks for {count:,} evaluations ({factors}); at most {MAX_EVALUATIONS:,} "
            "are allowed: split it into several specs")
    if tasks > MAX_TASKS:
        raise SweepSizeError(
            f"the spec makes {tasks:,} tasks ({factors}, chunk evaluations per task); at most "
            f"{MAX_TASKS:,} are allowed: raise chunk")
    return count
