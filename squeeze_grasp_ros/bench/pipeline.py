# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The pipeline on real rclpy nodes: end-to-end time, lockstep rate, recording and effect costs."""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import yaml

from squeeze_grasp_ros.bench.lockstep import bare_ratio_table, profile_table
from squeeze_grasp_ros.bench.startup import startup_table
from squeeze_grasp_ros.bench.table import Table, best_time, timed
from squeeze_grasp_ros.bench.world_pace import world_pace_table
from squeeze_grasp_ros.mechanics.vocabulary import SQUEEZING_FINGERS, Effect
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.recording.bag import read_bag
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner
from squeeze_grasp_ros.scene import GraspSetup, load_scene
from squeeze_grasp_ros.sim.world import SimWorld, TickOutput

TITLE = ("Pipeline on real rclpy nodes: end to end, lockstep rate against the bare loop, one "
         "tick's profile, the world's mechanics against the event squeeze, start-up, recording, "
         "effects")
EFFECT_SCENE = yaml.safe_load("""
name: effects
object:
  shape: {type: square, side: 0.1}
  material: {E: 5.0e4, nu: 0.3, thickness: 0.0254}
  mesh: {nodes: 2000, min_angle: 30}
fingers:
  F1: {tip_radius: 0.02, placement: {point: [-0.05, 0.0]}}
  F2: {tip_radius: 0.02, placement: {point: [0.05, 0.0]}}
squeeze: {type: stable, relative_depth: 0.12}
friction: {mu: 0.4}
""")
"""The foam square of Sec. 5.5 with friction only; each row of the effect table adds effects."""
BASE_ROW = f"{Effect.FRICTION} (base)"
SENSED_ROW = "force + tactile sensing"
SENSED = (Effect.FRICTION, Effect.FORCE_SENSING, Effect.TACTILE_SENSING)
EFFECTS = (
    (BASE_ROW, (Effect.FRICTION,), "", None),
    (str(Effect.FORCE_SENSING), (Effect.FRICTION, Effect.FORCE_SENSING), "", BASE_ROW),
    (str(Effect.TACTILE_SENSING), (Effect.FRICTION, Effect.TACTILE_SENSING), "", BASE_ROW),
    (SENSED_ROW, SENSED, "", BASE_ROW),
    (str(Effect.SENSOR_NOISE), SENSED + (Effect.SENSOR_NOISE,),
     "sensors: {noise_std: 0.001, seed: 1}", SENSED_ROW),
    (str(Effect.SENSOR_DROPOUT), SENSED + (Effect.SENSOR_DROPOUT,),
     "sensors: {dropout: 0.02, seed: 1}", SENSED_ROW),
    (str(Effect.ACTUATOR_LAG), (Effect.FRICTION, Effect.ACTUATOR_LAG),
     "actuators: {time_constant: 0.005}", BASE_ROW),
    (str(Effect.STRAIN_LIMIT), (Effect.FRICTION, Effect.STRAIN_LIMIT),
     "strain_limit: {epsilon: 0.5}", BASE_ROW),
    (str(Effect.PICKUP), (Effect.FRICTION, Effect.PICKUP), "pickup: {weight: 100.0}", BASE_ROW),
)
"""(row, effects, their sections as YAML, base row): a strain limit the squeeze never reaches
and a weight it never lifts, so every run makes the same motion and only the checks cost."""


def bare_mechanics(path: Path) -> float:
    """Seconds of the mechanics API's event-driven squeeze of the scene (mesh and precompute
    included, as the pipeline builds them too).
    """
    def squeeze():
        return GraspSetup.build(load_scene(path)).event_squeeze()
    return timed(squeeze)[1]


def run_once(path: Path, record: Path | None = None, **options) -> dict:
    """One ``squeeze-grasp run`` of ``path``: its summary."""
    return PipelineRunner(RunOptions(str(path), record=str(record) if record else None,
                                     **options)).run()


def serialization_per_tick(bag_path: Path) -> tuple[float, float, float]:
    """(messages per tick, bytes per tick, serialise + deserialise us per tick) of a recording.

    The round trip is timed on the messages stamped with one tick near the end (no markers)
    plus the markers amortised over the ticks (they go out at the display rate only).
    """
    bag = read_bag(bag_path)
    ticks = bag.counts()["/sim/tick"]
    count, size = len(bag.messages), sum(len(m.data) for m in bag.messages)
    last = max(m.log_time_ns for m in bag.messages if m.topic == "/sim/tick")
    sample = [m for m in bag.messages if m.log_time_ns == last - 1_000_000
              and m.topic != "/sim/markers" and not m.topic.startswith("/executor/execute_grasp")]
    markers = [m for m in bag.messages if m.topic == "/sim/markers"]

    def cost(batch) -> float:
        convert = pipeline.round_trip([(bag.types[m.topic], m.data) for m in batch])
        return best_time(convert, repeat=3, min_time=0.1)
    per_tick = cost(sample) + cost(markers[-1:]) * len(markers) / ticks
    return count / ticks, size / ticks, 1e6 * per_tick


def loop_rate(runs: list[dict], excluded: str = "mechanics", clock: str = "") -> float:
    """Best lockstep ticks per second over ``runs`` with the time of ``excluded`` taken out
    ("mechanics": the stepper; "world": whole world ticks, i.e. devices, stepper and sensor
    rendering), in wall time or, with ``clock="_cpu"``, CPU time of the whole one-process
    pipeline. NaN with processes (the world runs in another process).
    """
    rates = [r["ticks"] / (r["timing"]["loop" + clock] - r["timing"][excluded + clock])
             for r in runs if excluded in r["timing"]]
    return max(rates, default=float("nan"))


def squeeze_world(world: SimWorld, ticks: int = 700) -> list[TickOutput]:
    """Drive ``world`` along its scene's squeeze (both fingers to the squeeze depth in equal
    setpoint steps) for ``ticks`` ticks, ROS-free: every tick's output, tick 0 included.
    """
    depth = world.scene.squeeze.relative_depth / world.relative_per_depth
    start = {f: world.positions[f].copy() for f in SQUEEZING_FINGERS}
    out = [world.start()]
    for k in range(1, ticks + 1):
        out.append(world.step({f: start[f] + depth * k / ticks * world.directions[f]
                               for f in start}))
    return out


def world_loop(scene_path: Path, ticks: int = 700) -> float:
    """CPU seconds of the ROS-free simulated world driven along the scene's squeeze for
    ``ticks`` ticks (devices, stepper, sensors; no messages).
    """
    world = SimWorld(GraspSetup.build(load_scene(scene_path)))
    cpu = time.process_time()
    squeeze_world(world, ticks)
    return time.process_time() - cpu


def effect_rows(out_dir: Path, progress, repeats: int) -> list:
    """Marginal time of each effect on the foam square: with it minus its base, per tick, for
    the ROS-free world and for the whole pipeline (best of ``repeats`` each, the effects
    interleaved so that slow phases of a shared machine hit them alike).
    """
    paths = {}
    for k, (name, effects, sections, _) in enumerate(EFFECTS):
        paths[name] = out_dir / f"effect_{k}.yaml"
        scene = {**EFFECT_SCENE, **(yaml.safe_load(sections) if sections else {}),
                 "effects": [e.value for e in effects]}
        paths[name].write_text(yaml.safe_dump(scene))
    world: dict[str, float] = {name: float("inf") for name in paths}
    loop: dict[str, float] = {name: float("inf") for name in paths}
    world_loop(scene_file("foam_square"))
    for r in range(repeats):
        for name, path in paths.items():
            progress(f"pipeline: effect {name}, run {r + 1} of {repeats}")
            world[name] = min(world[name], world_loop(path) / 700)
            result = run_once(path)
            loop[name] = min(loop[name], result["timing"]["loop_cpu"] / result["ticks"])
    return [[name, base or "-", 1e6 * world[name], 1e6 * loop[name],
             1e6 * (world[name] - world[base]) if base else "-",
             1e6 * (loop[name] - loop[base]) if base else "-"]
            for name, _, _, base in EFFECTS]


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """Foam square end to end (recording on/off, executors, processes), loop rate, effects.

    The recordings and scenes of the runs go to a temporary folder, removed afterwards (also
    when a run fails): ``out_dir`` gets only what the report shows.
    """
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="bench_pipeline_") as work:
        return _tables(quick, progress, Path(work))


def _tables(quick: bool, progress, work: Path) -> list[Table]:
    """The tables of :func:`run`, with scratch files in ``work``."""
    progress("pipeline: bare mechanics (and a warm-up run)")
    foam = scene_file("foam_square")
    bare = min(bare_mechanics(foam) for _ in range(2))
    run_once(foam)
    configs = [("one process, EventsExecutor", True, {}),
               ("one process, EventsExecutor", False, {}),
               ("one process, SingleThreadedExecutor", True, {"executor": "single"}),
               ("one process, SingleThreadedExecutor", False, {"executor": "single"})]
    if not quick:
        configs += [("processes (ros2 launch layout)", True, {"processes": True}),
                    ("processes (ros2 launch layout)", False, {"processes": True})]
    repeats = 1 if quick else 5
    runs = [(mode, record, [work / f"foam_{k}_{r}" if record else None for r in range(repeats)],
             []) for k, (mode, record, _) in enumerate(configs)]
    for r in range(repeats):
        for (mode, record, bags, results), (_, _, options) in zip(runs, configs):
            progress(f"pipeline: foam square, {mode}, recording {'on' if record else 'off'}, "
                     f"run {r + 1} of {repeats}")
            results.append(run_once(foam, bags[r], **options))
    rows, rate_rows = [], []
    for mode, record, bags, results in runs:
        best = min(range(repeats), key=lambda r: results[r]["timing"]["total"])
        result, timing = results[best], results[best]["timing"]
        twin = next(r for m, rec, _, r in runs if m == mode and rec != record)
        with_rec, without = (results, twin) if record else (twin, results)
        loop = {name: min(r["timing"]["loop"] for r in group)
                for name, group in (("with", with_rec), ("without", without))}
        overhead = (loop["with"] - loop["without"]) / min(r["timing"]["total"] for r in with_rec)
        rows.append([mode, "on" if record else "off", timing["total"], timing["plan"],
                     timing["start_nodes"], timing["loop"], result["ticks"],
                     timing["total"] / bare, 100.0 * overhead if record else "-"])
        if record:
            per_tick, size, cost = serialization_per_tick(bags[best])
            rate_rows.append([mode, result["ticks"], timing["loop"],
                              timing.get("mechanics", float("nan")),
                              timing.get("world", float("nan")),
                              loop_rate(without), loop_rate(without, "world"),
                              loop_rate(without, "world", "_cpu"), loop_rate(with_rec, "world"),
                              per_tick, size, cost])
    end_to_end = Table(
        "Foam square (Sec. 5.5) through every node: end to end",
        [
            "mode",
            "recording",
            "total [s]",
            "plan [s]",
            "nodes up [s]",
            "lockstep loop [s]",
            "ticks",
            "total / bare mechanics",
            "recording overhead [% of total]",
        ],
        rows,
        f"`squeeze-grasp run config/scenes/foam_square.yaml [--record DIR] [--processes] "
        f"[--executor single]`, best of {repeats} runs by total time (the configurations "
        f"interleaved, so slow phases of a shared machine hit them alike); plan = the planner "
        f"node's load_object + event_squeeze + plan_squeeze services. Bare mechanics: the same "
        "scene's event-driven squeeze through "
        f"the mechanics API (mesh, precompute, Algorithm 1) took {bare:.3f} s. Recording "
        f"overhead = (best loop with - best loop without recording) / best total with "
        f"recording.",
    )
    rate = Table(
        "Lockstep loop with the real nodes, mechanics step excluded",
        ["mode", "ticks", "loop [s]", "stepper [s]", "world step [s]",
         "ticks/s excl. stepper", "ticks/s excl. world step", "ticks/CPU-s excl. world step",
         "ticks/s excl. world step (recording)", "messages/tick", "bytes/tick",
         "(de)serialise one tick [us]"],
        rate_rows,
        f"Best of {repeats} runs without recording unless marked. Ticks/s = ticks / (loop time - "
        "excluded time): excluding the stepper leaves the devices and sensor rendering in; "
        "excluding the world step (the ROS-free SimWorld.step: devices, stepper, sensor "
        "rendering) leaves exactly the nodes: every message, every callback, the monitor's "
        "tracker and the executor's program (and the recorder when marked). The CPU column "
        "divides by the process's CPU time (all nodes and DDS threads; less sensitive to other "
        "load on the machine). Messages and bytes per tick from the recording (all topics); the "
        "last column re-serialises and deserialises one tick's messages (markers amortised) "
        "with rclpy.serialization: the floor of what rclpy's message conversion costs per tick, "
        "before any delivery or callback.")
    effects = Table(
        "Marginal time of each effect (foam square, one process, no recording)",
        ["effect", "compared with", "world CPU per tick [us]", "pipeline CPU per tick [us]",
         "marginal, world [us/tick]", "marginal, pipeline [us/tick]"],
        effect_rows(work, progress, repeats),
        f"Each row runs the foam square with its effect added to the base in the second column, "
        f"best of {repeats}, in CPU time (wall time on this shared machine is dominated by other "
        f"load): the ROS-free simulated world alone (devices, stepper, sensors) driven along the "
        f"squeeze for 700 ticks, and the whole one-process pipeline (every node's messages and "
        f"callbacks). An undeclared effect costs nothing by construction "
        "(test_sim_world counts the work); a declared one costs what is shown. The strain limit "
        "is never reached and the weight never lifted, so only the checks cost. The adversary "
        "costs nothing during the squeeze (its fingertip joins the stepper when it first moves); "
        "without friction the squeeze is a different motion (every node slides), so friction is "
        "the base.")
    progress("pipeline: one tick's profile")
    profile = profile_table(foam, work / "profiled")
    ratio = bare_ratio_table(foam, 2 if quick else repeats, progress)
    startup = startup_table(2 if quick else repeats, progress)
    pace = world_pace_table(foam, 2 if quick else repeats, progress)
    return [end_to_end, rate, ratio, profile, pace, startup, effects]
