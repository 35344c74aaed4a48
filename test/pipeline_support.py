# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Scenes and comparisons shared by the simulated-world and pipeline tests."""
from __future__ import annotations

import contextlib
import copy
from pathlib import Path

import yaml

EVENT_TOLERANCE_TICKS = 8
"""Monitor events vs ground truth: type and finger exact, tick within this many ticks."""

SMALL_SQUARE = {
    "name": "small_square",
    "object": {"shape": {"type": "square", "side": 0.1},
               "material": {"E": 5.0e4, "nu": 0.3, "thickness": 0.0254},
               "mesh": {"nodes": 1000, "min_angle": 30}},
    "fingers": {"F1": {"tip_radius": 0.02, "placement": {"point": [-0.05, 0.0]}},
                "F2": {"tip_radius": 0.02, "placement": {"point": [0.05, 0.002]}}},
    "squeeze": {"type": "stable", "relative_depth": 0.08},
    "friction": {"mu": 0.05},
    "effects": ["friction", "force_sensing", "tactile_sensing"],
}
"""A 1000-node foam square squeezed 8 % at mu = 0.05: contact growth, sticking and sliding
(events A, C, D). F2 sits 2 mm off the axis: on the axis the squeeze is symmetric and no
contact starts to slide (no event C)."""

SLIPPING_SQUARE = {**copy.deepcopy(SMALL_SQUARE), "name": "slipping_square",
                   "object": {**SMALL_SQUARE["object"], "mesh": {"nodes": 800, "min_angle": 30}},
                   "squeeze": {"type": "stable", "relative_depth": 0.10}}
"""An 800-node square at mu = 0.05 whose squeeze ends with a finger slipping (Sec. 5.1)."""


class LogLines:
    """A node logger stand-in that keeps its warning and info lines."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def warning(self, text: str) -> None:
        self.lines.append(text)

    info = warning


def scene_data(base: dict, **changes) -> dict:
    """A deep copy of ``base`` with top-level keys replaced (None deletes a key)."""
    data = copy.deepcopy(base)
    for key, value in changes.items():
        if value is None:
            data.pop(key, None)
        else:
            data[key] = value
    return data


def write_scene(directory: Path, data: dict) -> str:
    """Write a scene mapping to ``directory/<name>.yaml``; returns the path."""
    path = Path(directory) / f"{data['name']}.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)


def net_events(states) -> list[tuple[int, str, str]]:
    """(tick, type, finger) of the net contact changes between consecutive ground-truth states.

    ``states`` are, in tick order, mappings contact node -> (finger, "stick" | "slip"). Several
    located events of one node within one tick (slip -> stick -> slip) are one net change or
    none: what any sensor sampled once per tick can see.
    """
    out = []
    for tick, (prev, cur) in enumerate(zip(states, states[1:]), start=1):
        out += [(tick, "A", cur[n][0]) for n in sorted(cur.keys() - prev.keys())]
        out += [(tick, "B", prev[n][0]) for n in sorted(prev.keys() - cur.keys())]
        out += [(tick, "C" if cur[n][1] == "slip" else "D", cur[n][0])
                for n in sorted(cur.keys() & prev.keys()) if cur[n][1] != prev[n][1]]
    return out


def contact_modes(state) -> dict:
    """Node -> (finger, mode) of a stepper ``ContactState`` or a ``SimState`` message."""
    if not hasattr(state, "header"):
        return {c.node: (c.finger, c.mode) for c in state.contacts}
    from squeeze_grasp_ros.ros.messages import contact_records
    return {c["node"]: (c["finger"], c["mode"]) for c in contact_records(state.contacts)}


def match_within(expected, observed, ticks: int) -> list[str]:
    """Problems matching (tick, type, finger) events one to one per (type, finger) within ticks."""
    problems = []
    for key in sorted({e[1:] for e in expected} | {e[1:] for e in observed}):
        a = sorted(e[0] for e in expected if e[1:] == key)
        b = sorted(e[0] for e in observed if e[1:] == key)
        if len(a) != len(b) or any(abs(x - y) > ticks for x, y in zip(a, b)):
            problems.append(f"{key}: ground truth at ticks {a}, monitor at {b}")
    return problems


def closed_loop(scene, tracker_config=None, limits=None, prediction=()):
    """Run the ROS-free loop world -> tracker -> program -> world until the goal ends
    (``prediction``: the tracker's predicted events, PredictedEvent each).
    """
    import numpy as np

    from squeeze_grasp_ros.control.motion import GraspGoal, GraspProgram, MotionLimits, Observation
    from squeeze_grasp_ros.control.tracker import ContactTracker, FingerSample, TrackerConfig
    from squeeze_grasp_ros.scene import GraspSetup
    from squeeze_grasp_ros.sim.world import SimWorld

    world = SimWorld(GraspSetup.build(scene))
    depth = scene.squeeze.relative_depth / world.relative_per_depth
    goal = GraspGoal(("F1", "F2"), np.array([world.directions["F1"], world.directions["F2"]]),
                     depth, world.relative_per_depth)
    program = GraspProgram(goal, limits or MotionLimits(), world.fingers)
    tracker = ContactTracker(tracker_config or TrackerConfig(mu=scene.mu), world.fingers,
                             prediction=prediction)
    out = world.start()
    outputs, observed, commands = [out], [], []
    while True:
        samples = {r.finger: FingerSample(
            r.position, r.force, out.stamp_ns if r.force is not None else None,
            world.layouts[r.finger].angles if r.normal is not None else None, r.normal,
            r.tangential, out.stamp_ns if r.normal is not None else None) for r in out.readings}
        tracked = tracker.update(out.stamp_ns, samples)
        observed.append(tracked)
        command = program.step(Observation(
            out.stamp_ns, tracked.positions, tracked.forces, tracked.normals,
            tuple((a.type, a.finger) for a in tracked.alarms),
            tuple(e.type for e in tracked.events), tracked.depth), world.dt)
        commands.append(command)
        out = world.step(command.setpoints)
        outputs.append(out)
        if command.termination is not None:
            return {"world": world, "outputs": outputs, "observed": observed,
                    "commands": commands, "program": program}


def run_scene(tmp_path: Path, data: dict, world: dict | None = None, record: bool = False):
    """A ``run`` of scene ``data`` through the real nodes (one executor); ``world``: the
    simulated world's scene instead (what the planner does not know); ``record``: into
    ``tmp_path / "bag"``. Returns the run's summary.
    """
    from squeeze_grasp_ros.ros.run.options import RunOptions
    from squeeze_grasp_ros.ros.run.runner import PipelineRunner

    path = tmp_path / f"{data['name']}.yaml"
    path.write_text(yaml.safe_dump(data))
    overrides = {}
    if world is not None:
        world_path = tmp_path / "world.yaml"
        world_path.write_text(yaml.safe_dump(world))
        overrides = {"sim_hardware": {"scene": str(world_path)}}
    return PipelineRunner(RunOptions(str(path), overrides=overrides,
                                     record=str(tmp_path / "bag") if record else None)).run()


def run_observed(path: str, topics=(), record: str | None = None,
                 cancel_after: float | None = None) -> dict:
    """Run scene file ``path`` (planned with the mechanics) through the real nodes: its result,
    the ground-truth events as (stamp s, stamp ns, type, finger, node), the final forces on the
    object (N, one row per finger) and depth (m), and under each key of ``topics`` ((key, topic,
    message class) each) the messages the run published there. ``cancel_after``: cancel the
    goal once that much sim time (s) has passed.
    """
    import numpy as np

    from squeeze_grasp_ros.ros.nodes import pipeline
    from squeeze_grasp_ros.ros.run.options import RunOptions
    from squeeze_grasp_ros.ros.run.runner import PipelineRunner

    runner = PipelineRunner(RunOptions(path, planner=False, record=record))
    seen = {key: [] for key, _, _ in topics}
    for key, topic, cls in topics:
        runner.client.create_subscription(cls, topic, seen[key].append, pipeline.loop_qos(1000))
    try:
        runner.start()
        if cancel_after is not None:
            failed = runner.observer.world_failed
            runner.observer.world_failed = lambda: failed() or (
                runner.observer.sim_state_ns - runner.start_ns > cancel_after * 1e9)
        runner.send_goal()
        result = runner.wait_result()
        state = runner.observer.sim_states[-1]
    finally:
        runner.shutdown()
    events = [(e.header.stamp.sec, e.header.stamp.nanosec, e.type, e.finger, e.node)
              for e in runner.observer.sim_events]
    return {"result": result, "events": events, "depth": state.contacts.depth,
            "forces": np.array([[v.x, v.y] for v in state.forces]), **seen}


@contextlib.contextmanager
def sim_and_client(scene: str, name: str = "hostile"):
    """A simulated hardware node of scene file ``scene`` and a client node ``name`` (the one
    lockstep participant it waits for), on one executor of a context of their own; yields
    (executor, sim, client) and shuts everything down after.
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    from squeeze_grasp_ros.ros.nodes.sim_hardware import SimHardwareNode

    context = Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    sim = SimHardwareNode(context=context, parameter_overrides=[
        rclpy.parameter.Parameter("scene", value=str(scene)),
        rclpy.parameter.Parameter("participants", value=[name])])
    client = Node(name, context=context)
    try:
        executor.add_node(sim)
        executor.add_node(client)
        yield executor, sim, client
    finally:
        executor.shutdown()
        sim.destroy_node()
        client.destroy_node()
        rclpy.shutdown(context=context)
