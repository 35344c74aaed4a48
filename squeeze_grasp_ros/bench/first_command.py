# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor's first command to a stock controller after the goal's acceptance (issue 31's
target: within one control period), measured on the gripper scene in one process.
"""
from __future__ import annotations

import os
import time

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner


def first_command(scene: str) -> dict[str, float]:
    """One run of ``scene`` up to the executor's first JointTrajectory, then cancelled.

    Returns the wall time (s) from the executor's acceptance of the goal to the publication of
    its first trajectory, the sim time (s) between the tick the executor was at then and the
    first trajectory's ``header.stamp``, its point's ``time_from_start`` (s) and the control
    period (s). Both instants are taken in the executor node (its goal callback, its publisher).
    """
    runner = PipelineRunner(RunOptions(scene, planner=False))
    marks: dict[str, float] = {}
    try:
        runner.start()
        executor = runner.nodes["executor"]
        accept = executor._accept_goal

        def on_goal(goal):
            answer = accept(goal)
            marks.setdefault("accepted", time.perf_counter())
            latest = executor.latest
            marks.setdefault("tick_ns", messages.cdr_stamp_ns(latest) if latest else 0)
            return answer

        executor.server.register_goal_callback(on_goal)
        publisher = executor.jaws.publisher
        publish = publisher.publish

        def on_publish(msg):
            if "published" not in marks:
                marks["published"] = time.perf_counter()
                marks["stamp_ns"] = messages.stamp_ns(msg.header.stamp)
                tfs = msg.points[0].time_from_start
                marks["horizon"] = tfs.sec + 1e-9 * tfs.nanosec
            publish(msg)

        publisher.publish = on_publish
        runner.send_goal()
        runner.spin_until(lambda: "published" in marks, 60.0, "the first JointTrajectory")
        runner.cancel()
        runner.wait_result()
    finally:
        runner.shutdown()
    return {"wall": marks["published"] - marks["accepted"],
            "sim": (marks["stamp_ns"] - marks["tick_ns"]) * 1e-9,
            "horizon": marks["horizon"], "period": float(executor.p["period"])}


def first_command_table(runs: int, progress) -> Table:
    """``runs`` runs of the sponge gripper scene: acceptance -> first JointTrajectory."""
    rows = []
    scene = str(scene_file("sponge_gripper"))
    for k in range(runs):
        progress(f"gripper: first command, run {k + 1} of {runs}")
        m = first_command(scene)
        rows.append([k + 1, 1e3 * m["wall"], 1e3 * m["period"], m["wall"] / m["period"],
                     1e3 * m["sim"], 1e3 * m["horizon"]])
    load = "/".join(f"{v:.1f}" for v in os.getloadavg())
    return Table(
        "gripper: the executor's first command after the goal's acceptance",
        ["run", "wall [ms]", "control period [ms]", "wall / period", "sim time [ms]",
         "commanded for [ms] after"],
        rows,
        notes=("The sponge gripper scene (config/scenes/sponge_gripper.yaml) in one process "
               "(EventsExecutor): wall time from the executor's goal callback accepting the "
               "goal to its publishing the first trajectory_msgs/JointTrajectory on "
               "gripper_controller/joint_trajectory, both taken in the executor node; sim time "
               "from the tick the executor was at when it accepted (simulated time waits for "
               "a goal) to the trajectory's header.stamp, and the point's time_from_start "
               "(the command is for one control period after that stamp). Target of issue 31: "
               f"the first command within one control period. Load average {load} (1/5/15 "
               "min) on the shared machine."),
    )
