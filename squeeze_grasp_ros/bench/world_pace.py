# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated world's mechanics against the mechanics API's event squeeze of the same motion
(part of ``bench --only pipeline``; issue 33 §2).
"""
from __future__ import annotations

import os
import time
from pathlib import Path

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner
from squeeze_grasp_ros.scene import GraspSetup, load_scene
from squeeze_grasp_ros.sim.world import SimWorld

__all__ = ["TARGET_RATIO", "api_squeeze_cpu", "world_pace_table"]

TARGET_RATIO = 1.5
"""Issue 33's target: the world's mechanics at most this many times the API's event squeeze."""
TICKS = 700
"""World ticks of the ROS-free loop (the foam square's run has 700 too)."""


def api_squeeze_cpu(path: Path) -> float:
    """CPU seconds of the mechanics API's event squeeze of the scene (Algorithm 1), the mesh and
    its precomputation excluded (as the world's stepper time excludes them).
    """
    setup = GraspSetup.build(load_scene(path)).precompute()
    cpu = time.thread_time()
    setup.event_squeeze()
    return time.thread_time() - cpu


def _world_cpu(path: Path, quiet: bool) -> tuple[float, dict]:
    """(stepper CPU seconds, quiet/full call counts and evaluations) of the ROS-free world
    driven along the scene's squeeze for :data:`TICKS` ticks.
    """
    from squeeze_grasp_ros.bench.pipeline import squeeze_world

    world = SimWorld(GraspSetup.build(load_scene(path)), quiet=quiet)
    squeeze_world(world, TICKS)
    return world.stepper_cpu_seconds, _calls(world)


def _run_cpu(path: Path) -> tuple[float, dict]:
    """(stepper CPU seconds, calls and evaluations) of the world in one ``squeeze-grasp run``
    of the scene.
    """
    runner = PipelineRunner(RunOptions(str(path)))
    try:
        runner.start()
        world = runner.nodes["sim_hardware"].world
        runner.send_goal()
        runner.wait_result()
    finally:
        runner.shutdown()
    return world.stepper_cpu_seconds, _calls(world)


def _calls(world: SimWorld) -> dict:
    """The world stepper's quiet and full calls, and how many quiet ones evaluated the watched
    functions.
    """
    return {**world.stepper.calls, "evaluations": world.stepper.evaluations}


def world_pace_table(path: Path, repeats: int, progress) -> Table:
    """The world's mechanics (quiet ticks on and off, ROS-free and in a run) against the API's
    event squeeze, interleaved, best of ``repeats`` each, as ratios.
    """
    cases = {"ROS-free world, quiet ticks": lambda: _world_cpu(path, True),
             "ROS-free world, every tick through advance()": lambda: _world_cpu(path, False),
             "squeeze-grasp run (one process), quiet ticks": lambda: _run_cpu(path)}
    best = dict.fromkeys(cases, (float("inf"), {}))
    api = float("inf")
    for r in range(repeats):
        progress(f"pipeline: world mechanics against the event squeeze, run {r + 1} of {repeats}")
        api = min(api, api_squeeze_cpu(path))
        for name, case in cases.items():
            best[name] = min(best[name], case(), key=lambda c: c[0])
    rows = [[name, seconds, calls.get("quiet", 0), calls.get("evaluations", 0),
             calls.get("full", 0), api, seconds / api, f"<= {TARGET_RATIO:g}"]
            for name, (seconds, calls) in best.items()]
    load = "/".join(f"{v:.1f}" for v in os.getloadavg())
    return Table(
        "The simulated world's mechanics against the API's event squeeze of the same motion",
        ["world", "stepper CPU [s]", "quiet ticks", "of which evaluating",
         "ticks through advance()", "event squeeze CPU [s]", "world / event squeeze", "target"],
        rows,
        f"Best of {repeats} interleaved runs each, CPU time (thread), load {load}. World: "
        f"the stepper's time in SimWorld.step over the foam square's squeeze ({TICKS} ticks of "
        "1 ms driven ROS-free, or the executor's motion in a run), devices and sensors excluded. "
        "Event squeeze: GraspSetup.event_squeeze() of the same scene (Algorithm 1 to the same "
        "depth, its substeps on the step grid), mesh and precomputation excluded for both. A "
        "quiet tick (mechanics/squeeze/stepper/quiet.py) makes the same two fixed-set solves as "
        "advance(), keeps what its contact mode fixes from the mode's first quiet tick, "
        "checks the contacts' normal forces and cone margins at its end (one product with the "
        "forces), and evaluates the gaps and the area check only when it ends outside the "
        "travel within which their last evaluation showed neither can reach the margin "
        "(stepper/travel.py: their rates in a sticking mode); ticks that cross an event, slide "
        "or use a finite-deformation material go through advance(). Both give the same states "
        "bit for bit (test/test_world_pace.py).",
    )
