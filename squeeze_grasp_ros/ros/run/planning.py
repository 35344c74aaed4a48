# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A run's plan: the executor's goal and the planner's prediction.

With the planner (the default), the run starts its own planner node, in a thread of this
process or as a process (``--processes``), and asks it through :class:`..nodes.planner_client.
PlannerClient`: ``event_squeeze`` for the directions and the predicted events, ``plan_squeeze``
for the pure directions (a slip reaction). In one process the planner is handed the object the
run built (:class:`RunObject`: the scene parsed and meshed once, shared with the simulated
world), so it loads nothing; as a process it loads the scene file itself (``load_object``).
Without the planner (``--no-planner``) :func:`...scene.goal.plan_scene` plans with the mechanics.
The resistance waypoints of a scene with a frictional adversary come from Algorithm 2
(:func:`...scene.goal.resistance_goal`) either way: no service returns them.
"""
from __future__ import annotations

import dataclasses
import json
import math
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from squeeze_grasp_interfaces.msg import ContactEventArray, ObjectDescription
from squeeze_grasp_interfaces.srv import EventSqueeze, LoadObject, PlanSqueeze
from squeeze_grasp_ros import planning
from squeeze_grasp_ros.control.force_watch import squeeze_forces
from squeeze_grasp_ros.control.motion import GraspGoal
from squeeze_grasp_ros.inputs import InputError, load_yaml, read_text
from squeeze_grasp_ros.mechanics.vocabulary import SQUEEZING_FINGERS, ShapeType, SqueezeKind
from squeeze_grasp_ros.resources import config_dir, share_dir
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes.planner_client import PlannerClient
from squeeze_grasp_ros.ros.run.options import RunError, RunOptions
from squeeze_grasp_ros.ros.run.processes import NodeProcesses, ros_arguments
from squeeze_grasp_ros.scene import GraspSetup, Scene, SceneError, parse_scene
from squeeze_grasp_ros.scene.goal import plan_scene, resistance_goal, resists

__all__ = ["SERVICE_RETRY", "Plan", "PlannerHost", "RunObject", "plan_with_mechanics",
           "plan_with_planner", "planner_roots"]

SERVICE_RETRY = 30.0
"""Wall-clock seconds after which an unanswered planner request is sent again."""


@dataclass(frozen=True)
class Plan:
    """What the executor is asked to do and what the planner predicts.

    Attributes
    ----------
    goal : GraspGoal
    prediction : ContactEventArray
        The predicted events, latched on ``planner/predicted_events`` for the monitor.
    source : str
        "planner" or "mechanics".
    seconds : float
        Wall-clock time of the planning, s.
    """

    goal: GraspGoal
    prediction: ContactEventArray
    source: str
    seconds: float


@dataclass(frozen=True)
class RunObject:
    """The scene of a run, read and parsed once, and (in one process) its object, meshed and
    precomputed once for the planner and the simulated world alike.

    Attributes
    ----------
    source : planning.SceneSource
        The validated scene and the text it was parsed from.
    loaded : planning.LoadedObject or None
        The precomputed object as the planner caches it (None until :meth:`build`).
    """

    source: planning.SceneSource
    loaded: planning.LoadedObject | None = None

    @classmethod
    def read(cls, path: str) -> RunObject:
        """Read and validate the scene file (one parse).

        Raises
        ------
        SceneError
            For a file that cannot be read or parsed, or a bad scene (naming the field).
        """
        try:
            text = read_text(path, what="scene")
            data = load_yaml(text, what=f"scene {path}")
        except InputError as exc:
            raise SceneError(str(exc)) from None
        return cls(planning.SceneSource(parse_scene(data, base_dir=Path(path).parent), text))

    @property
    def scene(self) -> Scene:
        """The validated scene."""
        return self.source.scene

    def build(self) -> RunObject:
        """This scene with its object meshed and precomputed under the planner's default limits
        (one mesh), registered under the scene's name as a planner would.
        """
        limits = planning.PlannerLimits()
        key = planning.object_key(self.source, "", "", limits)
        return RunObject(self.source, planning.load_object(self.source, key, limits))


def planner_roots(scene_path: str, scene: Scene) -> list[str]:
    """Folders the run's own planner may read: the scene's (and its outline file's), the package
    share folder and the working directory.
    """
    folders = [Path(scene_path).resolve().parent, share_dir(), Path.cwd()]
    shape = scene.object.shape
    if shape["type"] == ShapeType.FILE:
        folders.append(Path(shape["path"]).resolve().parent)
    return [str(f) for f in folders]


class PlannerHost:
    """The run's own planner, started for the planning and stopped after it.

    In one process it is a :class:`..nodes.planner.PlannerNode` spun by its own
    ``SingleThreadedExecutor`` in a thread (the run's ``EventsExecutor`` must stay in the main
    thread), holding the run's object; with ``processes`` it is a node process of the run.

    Parameters
    ----------
    context : Context
        The run's rclpy context.
    namespace : str
        The run's namespace.
    roots : list of str
        The planner's ``allowed_roots``.
    processes : NodeProcesses or None
        Start it as a process of these.
    run_object : RunObject or None
        In one process: the object to hand over (built).
    """

    def __init__(self, context: Context, namespace: str, roots: list[str],
                 processes: NodeProcesses | None, run_object: RunObject | None) -> None:
        self.processes = processes
        if processes is not None:
            processes.start("planner", ["--params-file", str(config_dir() / "planner.yaml"),
                                        "-p", f"allowed_roots:={json.dumps(roots)}"])
            return
        from squeeze_grasp_ros.ros.nodes.planner import PlannerNode

        objects = [run_object.loaded] if run_object is not None else []
        self.node = PlannerNode(
            context=context, parameter_overrides=[Parameter("allowed_roots", value=roots)],
            cli_args=ros_arguments(namespace), objects=objects,
        )
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, name="planner", daemon=True)
        self.thread.start()

    def stop(self) -> None:
        """Stop the planner (the thread and its node, or the process)."""
        if self.processes is not None:
            self.processes.stop("planner")
            return
        self.executor.shutdown()
        self.thread.join(30)
        self.node.destroy_node()


def _call(planner: PlannerClient, srv_type: Any, name: str, request: Any, timeout: float) -> Any:
    """Call a planner service, re-sent every :data:`SERVICE_RETRY` s until ``timeout``; raise
    :class:`RunError` if it is never answered or refuses.
    """
    attempts = max(1, math.ceil(timeout / SERVICE_RETRY))
    try:
        response = planner.call(srv_type, name, request, timeout=min(timeout, SERVICE_RETRY),
                                attempts=attempts)
    except TimeoutError:
        raise RunError(f"planner/{name} did not answer within {timeout:.0f} s") from None
    if not response.success:
        raise RunError(f"planner/{name}: {response.message}")
    return response


def plan_with_planner(planner: PlannerClient, run_object: RunObject, scene_path: str,
                      options: RunOptions, seen: ObjectDescription | None = None) -> Plan:
    """Plan with the planner node: ``event_squeeze`` and ``plan_squeeze`` of the object it
    holds (``run_object.loaded``), of the scene file it loads (``load_object``), or, with
    ``seen`` (camera.plan_from_images), of the object the camera saw, squeezed as the scene says.
    """
    t0 = time.perf_counter()
    loaded, timeout = run_object.loaded, options.timeout
    if loaded is not None and seen is None:
        object_id, digest, nodes = loaded.object_id, loaded.digest, list(loaded.finger_nodes)
    else:
        request = (LoadObject.Request(object=seen) if seen is not None
                   else LoadObject.Request(scene_path=str(Path(scene_path).resolve())))
        response = _call(planner, LoadObject, "load_object", request, timeout)
        object_id, digest = response.object_id, response.object_digest
        nodes = list(response.finger_nodes)
    request = EventSqueeze.Request(object_id=object_id, object_digest=digest)
    if seen is not None:  # a typed object has no squeeze section: the scene's squeeze
        spec = run_object.scene.squeeze
        request.squeeze_type = spec.type.value
        request.depth, request.relative_depth = spec.depth or 0.0, spec.relative_depth or 0.0
        request.step, request.event_tol = spec.step, spec.event_tol
    squeeze = _call(planner, EventSqueeze, "event_squeeze", request, timeout).squeeze
    pure = _call(planner, PlanSqueeze, "plan_squeeze",
                 PlanSqueeze.Request(object_id=object_id, object_digest=digest, contacts=nodes,
                                     squeeze_type=SqueezeKind.PURE), timeout)
    directions = np.array([[squeeze.direction_f1.x, squeeze.direction_f1.y],
                           [squeeze.direction_f2.x, squeeze.direction_f2.y]])
    rpd = squeeze.relative_depth / squeeze.depth if squeeze.depth > 0 else 0.0
    resistance = _resistance(run_object, options)
    goal = GraspGoal(SQUEEZING_FINGERS, directions, squeeze.target_depth, rpd,
                     options.on_slip_alarm, np.asarray(pure.displacement, float).reshape(2, 2),
                     options.max_attempts, options.resqueeze_margin, **resistance)
    prediction = messages.prediction_msg(
        list(squeeze.events), squeeze.termination, squeeze.depth,
        messages.force_curve(squeeze.curve_depths, squeeze.curve_force_f1,
                             squeeze.curve_force_f2))
    return Plan(goal, prediction, "planner", time.perf_counter() - t0)


def _resistance(run_object: RunObject, options: RunOptions) -> dict:
    """The goal's resistance fields (Algorithm 2 on the run's object when it has one)."""
    scene = run_object.scene
    if not resists(scene, resist=options.resist):
        return {}
    loaded = run_object.loaded
    return resistance_goal(GraspSetup.build(scene) if loaded is None else loaded.setup)


def plan_with_mechanics(run_object: RunObject, options: RunOptions) -> Plan:
    """Plan with the mechanics API (``--no-planner``), on the run's object when it has one."""
    loaded = run_object.loaded
    plan = plan_scene(run_object.scene, on_slip_alarm=options.on_slip_alarm,
                      resist=options.resist,
                      setup=loaded.setup if loaded is not None else None)
    squeeze = plan.squeeze
    prediction = messages.prediction_msg(
        [messages.contact_event_msg(e) for e in squeeze.events], squeeze.termination,
        squeeze.depth, squeeze_forces(squeeze))
    goal = dataclasses.replace(plan.goal, max_attempts=options.max_attempts,
                               resqueeze_margin=options.resqueeze_margin)
    return Plan(goal, prediction, "mechanics", plan.seconds)


