# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""What a run is asked to do: its options and every node's parameters (no rclpy).

The parameters of a node are ``config/<node>.yaml``, then what the scene decides (devices,
sensors, mu, tick, recording), then the user's overrides; ``squeeze-grasp run`` and
``sim_pipeline.launch.py`` both use :func:`node_parameters`, so the two routes start the same
nodes.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from squeeze_grasp_ros.control.motion import DEFAULT_ATTEMPTS, DEFAULT_MARGIN
from squeeze_grasp_ros.mechanics.vocabulary import ControllerKind, Effect
from squeeze_grasp_ros.resources import config_dir
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.scene import Scene, finger_devices
from squeeze_grasp_ros.scene.specs import ControllerSpec

__all__ = ["EXECUTORS", "NODES", "PLANNER_MODULE", "RunError", "RunOptions", "config_parameters",
           "node_parameters", "without_run"]

NODES: tuple[str, ...] = ("sim_hardware", "monitor", "executor", "recorder")
EXECUTORS: tuple[str, ...] = ("events", "single")
PLANNER_MODULE = "squeeze_grasp_ros.ros.nodes.planner"


class RunError(RuntimeError):
    """The pipeline could not be started or did not finish in time."""


def config_parameters(node: str) -> dict[str, Any]:
    """The ``ros__parameters`` of ``config/<node>.yaml`` (read with libyaml's safe loader when
    PyYAML has it: 0.3 ms for the four nodes' files against 6 ms in Python, same values).
    """
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    data = yaml.load((config_dir() / f"{node}.yaml").read_text(), Loader=loader)  # noqa: S506
    section = data.get(node) or data.get("/**") or {}
    return dict(section.get("ros__parameters", {}))


@dataclass(frozen=True)
class RunOptions:
    """What to run and how.

    Attributes
    ----------
    scene_path : str
    record : str or None
        Bag folder to record into.
    include_hidden_topics : bool
        Record the executor action's hidden ``_action/`` topics too.
    attach : bool
        Use the nodes already running on this ROS domain (started by ``ros2 launch
        squeeze_grasp_ros sim_pipeline.launch.py``) instead of starting them: plan with the
        running planner, send the goal, summarise. Recording is then the launched recorder's.
    processes : bool
        One process per node instead of one executor in this process.
    executor : {"events", "single"}
        rclpy executor of the one-process mode.
    on_slip_alarm : {"hold", "pure", "normals", "resqueeze"}
        The executor's reaction to an imminent-slip alarm.
    max_attempts : int
        With "resqueeze": squeezes in all, the first included.
    resqueeze_margin : float
        With "resqueeze": a re-squeeze's depth is (1 - margin) x the alarm's, margin in (0, 1).
    resist : bool
        Run the resistance phase when the scene has a frictional adversary.
    planner : bool
        Plan with the planner node if it exists (else with the mechanics API).
    overrides : dict
        Node name -> parameter overrides (applied last).
    timeout : float
        Wall-clock seconds a run may take.
    namespace : str or None
        Namespace of the run's nodes: None = a fresh one of its own (two runs on one ROS domain
        never see each other), or the namespace of the nodes ``attach`` drives (None: "/").
    """

    scene_path: str
    record: str | None = None
    include_hidden_topics: bool = False
    attach: bool = False
    processes: bool = False
    executor: str = "events"
    on_slip_alarm: str = "hold"
    max_attempts: int = DEFAULT_ATTEMPTS
    resqueeze_margin: float = DEFAULT_MARGIN
    resist: bool = True
    planner: bool = True
    overrides: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    timeout: float = 300.0
    namespace: str | None = None


def node_parameters(
    scene: Scene, scene_path: str, options: RunOptions, relative_per_depth: float, *,
    mirror_tolerance: float | None = None
) -> dict[str, dict[str, Any]]:
    """Parameters of every node: the config files, then the scene's values, then overrides.

    ``mirror_tolerance`` (a fraction, see ``tracker.mirror_tolerance_for``), when given, is the
    monitor's: derived for an object the planner saw through the camera; None keeps the
    configured default.
    """
    params = {name: config_parameters(name) for name in NODES}
    devices = finger_devices(scene)
    mapping = [f"{f}:{d}" for f, d in devices.items()]
    streams = [
        s
        for s, effect in (("wrench", Effect.FORCE_SENSING), ("tactile", Effect.TACTILE_SENSING))
        if scene.has(effect)
    ]
    noise = scene.sensors.noise_std if scene.has(Effect.SENSOR_NOISE) else 0.0
    params["sim_hardware"].update(
        scene=str(Path(scene_path).resolve()),
        participants=["monitor", "executor"] + (["recorder"] if options.record else []),
    )
    monitor = params["monitor"]
    monitor.update(
        finger_devices=mapping,
        streams=streams or [""],
        mu=float(scene.mu),
        weight=float(scene.pickup.believed_weight) if scene.has(Effect.PICKUP) else 0.0,
        relative_per_depth=float(relative_per_depth),
        await_prediction=True,
        load_threshold=max(float(monitor.get("load_threshold", 0.005)), 6.0 * noise),
    )
    if scene.has(Effect.CAMERA):
        monitor.update(shape_watch=True,
                       shape_mismatch_threshold=float(scene.camera.shape_mismatch_threshold),
                       shape_at_force_threshold=float(scene.camera.shape_at_force_threshold),
                       shape_min_force=max(float(monitor.get("shape_min_force", 0.05)),
                                           20.0 * noise),
                       object_height=float(scene.object.material.thickness))
    if mirror_tolerance is not None:
        monitor["mirror_tolerance"] = float(mirror_tolerance)
    if not options.record:  # nobody records: the monitor's outputs only while subscribed
        monitor["every_output"] = False
    controller_scene = str(Path(scene_path).resolve()) if scene.controller else ""
    monitor["controller_scene"] = controller_scene
    params["executor"].update(
        finger_devices=mapping, period=float(scene.sim.dt), controller_scene=controller_scene,
        lift_watch=lift_watch(scene), await_prediction=True)
    custom = {"scene": Path(scene_path).read_text(), "scene_path": str(scene_path)}
    params["recorder"].update(
        output=str(options.record or ""),
        devices=list(devices.values()),
        include_hidden_topics=options.include_hidden_topics,
        camera=scene.has(Effect.CAMERA),
    )
    if scene.controller is not None:
        params["recorder"]["extra_topics"] = controller_topics(scene.controller)
        params["recorder"]["silent_setpoints"] = [devices[f] for f in scene.controller.jaws]
        params["recorder"]["lockstep_topics"] = controller_lockstep_topics(scene.controller)
    for name, values in options.overrides.items():
        params[name].update(values)
    custom["monitor_parameters"] = yaml.safe_dump(params["monitor"], sort_keys=True)
    params["recorder"]["custom_data"] = yaml.safe_dump(custom)
    return params


def without_run(params: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """``params`` (of :func:`node_parameters`) for nodes that no run drives
    (``sim_pipeline.launch.py run:=false``): nobody latches ``planner/predicted_events``, so no
    node awaits it. A monitor or executor awaiting it is never lockstep-ready, the simulated
    hardware never starts tick 0, and every goal sent to the executor is accepted and then
    waits for ever (no feedback, no result).
    """
    out = {name: dict(values) for name, values in params.items()}
    for name in ("monitor", "executor"):
        if name in out:
            out[name]["await_prediction"] = False
    return out


LIFT_WATCH = 0.02
"""s the executor watches a lift past the world's ``pickup.lift_after`` (run's lift_watch)."""


def lift_watch(scene: Scene) -> float:
    """The executor's ``lift_watch`` for ``scene``: a scene with a ``controller:`` and the
    pickup effect is lifted by the world ``pickup.lift_after`` s after its jaws stand still
    (:mod:`..sim.world`), so the executor watches that long and ``LIFT_WATCH`` more; other
    scenes end at ``picked_up`` (0).
    """
    if scene.controller is None or not scene.has(Effect.PICKUP):
        return 0.0
    return float(scene.pickup.lift_after) + LIFT_WATCH


def controller_lockstep_topics(spec: ControllerSpec) -> list[str]:
    """The recorded topics of a scene's controller that every lockstep tick publishes
    (relative): its command (the executor's trajectory, or its cycle on an action route) and
    joint_states. Their publishers are transient-local and the recorder awaits them, so a
    recorder in another process does not miss their first messages (docs/design.md).
    """
    command = (pipeline.EXECUTOR_CYCLE if ControllerKind(spec.type).is_action
               else f"{spec.name}/joint_trajectory")
    return [command, pipeline.JOINT_STATES]


def controller_topics(spec: ControllerSpec) -> list[str]:
    """"topic type" of each recorded topic of a scene's controller (relative): its command
    topic or its action's status, the executor's cycle, and joint_states.
    """
    if not ControllerKind(spec.type).is_action:
        return [f"{spec.name}/joint_trajectory trajectory_msgs/msg/JointTrajectory",
                "joint_states sensor_msgs/msg/JointState"]
    return [f"{spec.name}/gripper_cmd/_action/status action_msgs/msg/GoalStatusArray",
            f"{pipeline.EXECUTOR_CYCLE} std_msgs/msg/Header",
            "joint_states sensor_msgs/msg/JointState"]
