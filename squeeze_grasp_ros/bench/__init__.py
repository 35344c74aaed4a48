# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Benchmarks: accuracy and time, measured in one run and printed as tables (never asserted).

A section module defines ``TITLE`` and ``run(quick: bool, out_dir: Path, progress) -> list[Table]``;
``squeeze-grasp bench`` runs the sections listed in ``SECTIONS`` and writes a Markdown report.
"""

SECTIONS: tuple[str, ...] = (
    "convergence",
    "solvers",
    "resistance",
    "ring",
    "events",
    "ros_services",
    "pipeline",
    "pareto",
    "sweep",
)
"""Module names of the benchmark sections, in report order."""
