# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The pipeline's lockstep loop against rclpy's floor: the bare loop with the same messages per
tick on the same executor, and one tick's time by node and stage (part of ``bench --only
pipeline``).
"""
from __future__ import annotations

import os
from pathlib import Path

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.ros.bare_loop import bare_loop_rate
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner
from squeeze_grasp_ros.ros.run.tick_profile import STAGES, TickProfile

__all__ = ["TARGET_RATIO", "bare_ratio_table", "profile_table", "tick_profile"]

TARGET_RATIO = 0.5
"""Issue 33's target: the pipeline's ticks/s, mechanics excluded, over the bare loop's."""
EXECUTORS = (("events", "EventsExecutor"), ("single", "SingleThreadedExecutor"))


def tick_profile(path: Path, record: Path | None, executor: str = "events") -> tuple[dict, dict]:
    """One run of ``path`` in one process with :class:`.TickProfile` on its nodes: (microseconds
    per tick by node and stage, the run's summary).
    """
    runner = PipelineRunner(RunOptions(str(path), record=str(record) if record else None,
                                       executor=executor))
    try:
        runner.start()
        world = runner.nodes["sim_hardware"].world
        profile = TickProfile({**runner.nodes, "run client": runner.client})
        before = world.stepper_seconds
        runner.send_goal()
        result = runner.wait_result()
        mechanics = world.stepper_seconds - before
        summary = runner.summary(result)
    finally:
        runner.shutdown()
    return profile.table(summary["ticks"], summary["timing"]["loop"], mechanics), summary


def profile_table(path: Path, record: Path) -> Table:
    """The tick profile of one recorded run on the EventsExecutor, as a table."""
    table, summary = tick_profile(path, record)
    total = sum(sum(row.values()) for name, row in table.items() if name != "mechanics")
    rows = [[name, *(row[s] for s in STAGES), sum(row.values()),
             "-" if name == "mechanics" else 100.0 * sum(row.values()) / total]
            for name, row in table.items()]
    rows.append(["all but mechanics", *(sum(r[s] for n, r in table.items() if n != "mechanics")
                                        for s in STAGES), total, 100.0])
    return Table(
        "One lockstep tick by node and stage (foam square, one process, EventsExecutor, "
        "recording on)",
        ["node", "deserialise [us/tick]", "logic [us/tick]", "serialise + publish [us/tick]",
         "total [us/tick]", "share excl. mechanics [%]"],
        rows,
        f"One run of {summary['ticks']} ticks; load {_load()}. Every subscription callback and "
        "every publish of the run's nodes timed in place (wall clock, "
        "ros/run/tick_profile.py): logic = time in a node's callbacks minus its publishing "
        "(and, for sim_hardware, minus the mechanics step, its own row); the recorder's logic "
        "is the recording; deserialise = messages received x rclpy's deserialisation time of "
        "the last one on each subscription (raw subscriptions: 0); rclpy executor = the "
        "loop's wall time not spent in any callback or deserialisation (waiting, taking, "
        "dispatching).",
    )


def bare_ratio_table(path: Path, repeats: int, progress) -> Table:
    """Pipeline ticks/s (mechanics excluded, no recording) against the bare loop with the same
    messages per tick (:mod:`..ros.bare_loop`) on the same executor, with the pipeline's 11
    deliveries a tick and with the 13 of the loop issue 33 measured, interleaved, best of
    ``repeats``.
    """
    rows = []
    for executor, label in EXECUTORS:
        pipeline, bare, ticks = 0.0, {11: 0.0, 13: 0.0}, 0
        for r in range(repeats):
            progress(f"pipeline: loop against the bare loop, {label}, run {r + 1} of {repeats}")
            summary = PipelineRunner(RunOptions(str(path), executor=executor)).run()
            timing, ticks = summary["timing"], summary["ticks"]
            pipeline = max(pipeline, ticks / (timing["loop"] - timing["mechanics"]))
            for deliveries in bare:
                bare[deliveries] = max(bare[deliveries], bare_loop_rate(
                    ticks, executor=executor, namespace=f"/bench_bare_{os.getpid()}",
                    clock_deliveries=deliveries == 13))
        rows.append([label, ticks, pipeline, bare[11], 100.0 * pipeline / bare[11], bare[13],
                     100.0 * pipeline / bare[13], f">= {100 * TARGET_RATIO:.0f}"])
    return Table(
        "Lockstep loop against rclpy's floor: the bare loop with the same messages per tick",
        ["executor", "ticks", "pipeline ticks/s excl. mechanics",
         "bare loop, 11 deliveries, ticks/s", "pipeline / bare (11) [%]",
         "bare loop, 13 deliveries, ticks/s", "pipeline / bare (13) [%]", "target [%]"],
        rows,
        f"Best of {repeats} interleaved runs each; load {_load()}. Pipeline: `squeeze-grasp "
        "run config/scenes/foam_square.yaml` in one process without recording, ticks / (loop "
        "wall time - the world's mechanics step); 13 messages and 11 deliveries a tick (in "
        "lockstep the monitor and the executor take no /clock). Bare loop (ros/bare_loop.py): "
        "three nodes and a client on the same executor passing the pipeline's 13 messages per "
        "tick (std_msgs/Header, reliable), lockstep, with no work in the callbacks; with 11 "
        "deliveries (the pipeline's: the target is judged on this column) and with 13 (the "
        "clock also delivered to the monitor and the executor, as in the loop issue 33 "
        "measured).",
    )


def _load() -> str:
    """The machine's load averages (1, 5, 15 min), for the notes."""
    return "/".join(f"{v:.1f}" for v in os.getloadavg())
