# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ``squeeze-grasp`` verbs, one module each.

A verb module defines ``HELP`` (one line), ``add_arguments(parser)``, ``run(args) -> dict``
(the JSON-able result) and ``summary(result) -> str`` (the human-readable report). The CLI adds
``--json`` to every verb and prints either the JSON or the summary.
"""

VERBS: tuple[str, ...] = (
    "mesh",
    "plan",
    "squeeze",
    "match",
    "calibrate",
    "graspmap",
    "gripper_plan",
    "resist",
    "ring",
    "render",
    "outline",
    "run",
    "replay",
    "bench",
    "sweep",
    "sweep_report",
    "scene_help",
    "sweep_help",
    "ros_setup",
)
"""Module names of the verbs, in the order ``--help`` lists them (CLI name: '_' -> '-')."""
