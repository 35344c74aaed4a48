# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Parallel-jaw gripper planning: ranking time against the grasp map's, and the evaluation;
with ROS installed, the executor's first command to the gripper's controller.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from squeeze_grasp_ros.bench.table import Table, best_time, timed
from squeeze_grasp_ros.extras import EXTRAS, installed
from squeeze_grasp_ros.mechanics.squeeze.graspmap import grasp_map
from squeeze_grasp_ros.mechanics.squeeze.gripper_grasp import (
    evaluate_candidate,
    gripper_candidates,
)
from squeeze_grasp_ros.resources import device_file, scene_file
from squeeze_grasp_ros.scene import GraspSetup, load_scene
from squeeze_grasp_ros.scene.gripper import load_gripper

TITLE = "Parallel-jaw gripper: ranking candidates, squeezing the best with the pads"


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """The sponge scene meshed at increasing sizes: grasp map, 100 ranked candidates, one
    evaluation (the event squeeze with pads to the planned closing and on to its limit).
    """
    del out_dir
    jaws = load_gripper(device_file("generic_85mm")).jaws()
    base = load_scene(scene_file("sponge_gripper"))
    rows = []
    for nodes in ((500, 2000) if quick else (500, 2000, 8000)):
        progress(f"gripper: sponge at {nodes} nodes")
        scene = dataclasses.replace(base, object=dataclasses.replace(
            base.object, mesh=dataclasses.replace(base.object.mesh, nodes=nodes)))
        obj = GraspSetup.build(scene).solid
        mu = scene.mu
        gmap, t_map = timed(lambda: grasp_map(obj, mu))
        t_rank = best_time(lambda: gripper_candidates(obj, gmap, jaws, count=100), repeat=3)
        best = gripper_candidates(obj, gmap, jaws, count=100)
        ev, t_eval = timed(lambda: evaluate_candidate(
            obj, best[0], jaws, mu, closing=scene.squeeze.relative_depth * best[0].aperture))
        rows.append([obj.mesh.n, len(obj.mesh.boundary), len(best), 1e3 * t_map,
                     1e3 * t_rank, t_eval, ev.jaw_force, sum(ev.squeeze.event_counts.values())])
    tables = [Table(
        "gripper: plan_gripper_grasp's stages",
        ["nodes", "boundary", "candidates", "grasp map [ms]", "rank 100 [ms]",
         "evaluate best [s]", "jaw force [N]", "events"],
        rows,
        notes=("The sponge scene (config/scenes/sponge_gripper.yaml) with the generic 85 mm "
               "gripper; ranking from a computed grasp map (best of 3), the map and the "
               "evaluation timed once. The evaluation is two event squeezes with the pads: "
               "to the scene's closing (15 % of the aperture at first contact) and on to half "
               "the aperture, for the slip/strain/inversion limit. Target of issue 31: "
               "ranking 100 candidates on a cached 2,000-node object under 50 ms."),
    )]
    if all(installed(m) for m in ("rclpy", "squeeze_grasp_interfaces")):
        from squeeze_grasp_ros.bench.first_command import first_command_table
        tables.append(first_command_table(3 if quick else 10, progress))
    else:
        progress(f"gripper: the first-command table needs ROS: {EXTRAS['ros'][1]}")
    return tables
