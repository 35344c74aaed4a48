# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ``squeeze-grasp`` verbs, one module each, and their one-line help.

A verb module defines ``add_arguments(parser)``, ``run(args) -> dict`` (the JSON-able result)
and ``summary(result) -> str`` (the human-readable report); its one-line help is here, in
:data:`VERBS`, so that the parser lists every verb without importing any: only the verb being
run is imported (``squeeze-grasp --help`` loads no numpy). The CLI adds ``--json`` to every
verb and prints either the JSON or the summary.
"""

VERBS: dict[str, str] = {
    "mesh": "triangulate the scene's object (nodes, triangles, boundary loop, material)",
    "plan": "stable and pure squeezes at the scene's finger placements (point contacts, "
            "Sec. 3-4)",
    "squeeze": "event-driven squeeze with rounded fingertips or flat pads under Coulomb "
               "friction (Sec. 5, Algorithm 1)",
    "match": "least-squares scale/rotation/translation of measured onto simulated points "
             "(App. C)",
    "calibrate": "Young's modulus, Poisson's ratio from cuboid compressions; mu from the slope "
                 "angle (App. B)",
    "graspmap": "all-pairs grasp map: stiffness, inwardness and force closure of every "
                "placement (ring scenes: feasibility and maximum depth, Sec. 7)",
    "gripper_plan": "parallel-jaw gripper grasps: ranked poses, aperture at first contact and "
                    "at the planned closing, jaw force, slip/strain limit, effort to command",
    "resist": "optimal stable/pure resistance of F1, F2 to the scene's adversary finger A "
              "(Sec. 6)",
    "ring": "ring-like object, two point fingers (Sec. 7): max squeeze depth, limit, all-pairs "
            "map",
    "render": "render a scene's object (its top face, anti-aliased; a ring's wall band) into a "
              "mono8 mask and a depth image of a calibrated camera above the plane",
    "outline": "the object's outline (m, holes included) from a top-down mono8 mask or depth "
               "image, as a scene polygon or outline file",
    "run": "run a scene through the planner, executor, simulated hardware, monitor and recorder "
           "nodes (lockstep sim time) and summarise it",
    "replay": "replay a recording's sensor topics on its sim time into a fresh monitor and check "
              "that it reproduces the recorded event sequence",
    "bench": "run the benchmarks; print tables and write a Markdown report with plots",
    "sweep": "evaluate a sweep spec (objects x materials x friction x tips x squeezes x depths "
             "x placements) on Dask into a Parquet dataset; re-run to resume",
    "sweep_report": "summarise a sweep directory: success rate by object and material, quality "
                    "distributions, best placements per object; --plot writes pictures",
    "scene_help": "list every scene key, unit, range, default, shape type and effect",
    "sweep_help": "list every sweep-spec key, unit, range, default and shape family",
    "ros_setup": "build the ROS 2 interface package (msg_defs/) into the active virtual "
                 "environment",
}
"""Module name of each verb -> its one-line help, in the order ``--help`` lists them (CLI
name: '_' -> '-')."""
