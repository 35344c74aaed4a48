# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Benchmarks: accuracy and time, measured in one run and printed as tables (never asserted).

A section module defines ``TITLE`` and ``run(quick: bool, out_dir: Path, progress) ->
list[Table]``;
``squeeze-grasp bench`` runs the sections listed in ``SECTIONS`` and writes a Markdown report.
A section whose modules are not installed (``REQUIREMENTS``) is skipped with a line saying why,
and the report lists it, so the mechanics sections run on a plain ``pip install .``.
"""
from __future__ import annotations

from squeeze_grasp_ros.extras import EXTRAS, installed

SECTIONS: tuple[str, ...] = (
    "convergence",
    "solvers",
    "resistance",
    "ring",
    "events",
    "evaluation",
    "gripper",
    "material_models",
    "perception",
    "ros_services",
    "pipeline",
    "pareto",
    "sweep",
)
"""Module names of the benchmark sections, in report order."""

REQUIREMENTS: dict[str, tuple[tuple[str, ...], str]] = {
    "ros_services": (("rclpy", "squeeze_grasp_interfaces"), EXTRAS["ros"][1]),
    "pipeline": (("rclpy", "squeeze_grasp_interfaces", "mcap"), EXTRAS["ros"][1]),
    "sweep": EXTRAS["sweep"],
    "perception": EXTRAS["perception"],
}
"""Section -> (modules it imports beyond the mechanics, how to install them)."""


def missing(section: str) -> tuple[list[str], str]:
    """Modules ``section`` needs that are not installed, and how to install them."""
    modules, how = REQUIREMENTS.get(section, ((), ""))
    return [m for m in modules if not installed(m)], how
