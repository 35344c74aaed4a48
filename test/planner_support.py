# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Shared pieces of the planner node tests: scenes and an in-process harness.

Nothing here sleeps: waiting is a ``spin_once`` loop with a deadline on the test's own executor,
and results arrive through futures and done-callbacks.
"""
from __future__ import annotations

import threading
import uuid
from collections.abc import Callable
from typing import Any

import numpy as np
import rclpy
import yaml
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.task import Future
from unique_identifier_msgs.msg import UUID

from squeeze_grasp_interfaces.srv import LoadObject
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.ros.nodes.planner import PlannerNode
from squeeze_grasp_ros.ros.nodes.planner_client import PlannerClient
from squeeze_grasp_ros.scene import Scene, build_mesh, parse_scene, scene_material

BLOB = """
name: blob
object:
  shape: {type: fourier_blob, radius: 0.055, cos: [0.0, 0.08, 0.0], sin: [0.04, 0.0, 0.01]}
  material: {E: 5.0e4, nu: 0.3, thickness: 0.0254}
  mesh: {nodes: 300}
fingers:
  F1: {tip_radius: 0.015, placement: {angle_deg: 235}}
  F2: {tip_radius: 0.015, placement: {angle_deg: 75}}
squeeze: {type: stable, relative_depth: 0.05}
friction: {mu: 0.4}
effects: [friction]
"""
"""A small solid with rounded fingertips: squeezes, maps, resistance and event squeezes."""

RING = """
name: ring
object:
  model: ring
  shape: {type: ellipse, a: 0.045, b: 0.03}
  material: {E: 3.0e9, nu: 0.0, thickness: 0.01}
  ring: {wall_thickness: 0.003, elements: 80}
fingers:
  F1: {placement: {point: [0.013, 0.0287]}}
  F2: {placement: {point: [-0.0199, -0.0269]}}
squeeze: {type: stable, relative_depth: 0.15}
friction: {mu: 0.5}
strain_limit: {epsilon: 0.03}
effects: [friction, strain_limit]
"""
"""A small ring (curved-beam model, Sec. 7)."""


def big_disk(nodes: int) -> str:
    """A foam disk of about ``nodes`` nodes: its precompute takes a noticeable time."""
    return f"""
name: big_disk
object:
  shape: {{type: disk, radius: 0.05}}
  material: {{E: 5.0e4, nu: 0.3, thickness: 0.0254}}
  mesh: {{nodes: {nodes}}}
fingers:
  F1: {{placement: {{angle_deg: 180}}}}
  F2: {{placement: {{angle_deg: 0}}}}
"""


def scene_of(text: str) -> Scene:
    """The validated scene of a YAML text."""
    return parse_scene(yaml.safe_load(text))


def solid_of(text: str) -> ElasticObject:
    """The mechanics API's own object of a scene: what the planner's numbers must equal."""
    scene = scene_of(text)
    return ElasticObject(build_mesh(scene), scene_material(scene))


class Harness(PlannerClient):
    """A client node on the test thread's executor, optionally with a planner node on it too.

    Parameters
    ----------
    context : Context
        An initialised rclpy context of the test.
    with_planner : bool
        Put a :class:`PlannerNode` on the same executor (in-process tests).
    **planner_kwargs
        Passed to :class:`PlannerNode` (e.g. ``parameter_overrides``).
    """

    def __init__(self, context: Context, with_planner: bool = True, **planner_kwargs: Any) -> None:
        executor = SingleThreadedExecutor(context=context)
        self.planner = PlannerNode(context=context, **planner_kwargs) if with_planner else None
        super().__init__(rclpy.create_node("planner_test_client", context=context), executor)
        for node in (self.planner, self.node):
            if node is not None:
                executor.add_node(node)
        self._actions: dict[str, ActionClient] = {}
        self._feedback_callbacks: dict[str, dict[bytes, Callable[[Any], None]]] = {}

    def action(self, action_type: Any, name: str) -> ActionClient:
        """A (cached) client of action ``<planner>/<name>`` that has found its server."""
        if name not in self._actions:
            client = ActionClient(self.node, action_type, f"{self.planner_name}/{name}")
            if not client.wait_for_server(timeout_sec=30.0):
                raise TimeoutError(f"action {self.planner_name}/{name} not available")
            self._actions[name] = client
        return self._actions[name]

    def load(self, text: str, object_id: str = "", **fields: Any) -> LoadObject.Response:
        """Load a scene given as YAML text; assert it succeeded."""
        response = self.call(LoadObject, "load_object",
                             LoadObject.Request(scene_yaml=text, object_id=object_id, **fields))
        assert response.success, response.message
        return response

    def goal(self, action_type: Any, name: str, goal: Any,
             on_feedback: Callable[[Any], None] | None = None) -> tuple[Future, Future]:
        """Send a goal; return the futures of its goal handle and of its result response.

        The result is requested from a done-callback as soon as the goal is accepted.
        ``on_feedback`` receives the goal's feedback messages as the server publishes them, from
        a subscription to the action's feedback topic (matched before the goal is sent) rather
        than from the action client: when rclpy 7.1.6's ``ActionClient`` takes the result and
        the last feedback in one wait, it handles the result first, and the result's
        done-callback deletes the goal's feedback callback before that feedback is dispatched,
        so a client-side callback can miss the last feedback (seen once in a clean-clone CI).
        """
        goal_id = UUID(uuid=list(uuid.uuid4().bytes))
        if on_feedback is not None:
            self._feedback(action_type, name)[bytes(goal_id.uuid)] = on_feedback
        accepted, outcome = Future(), Future()
        sent = self.action(action_type, name).send_goal_async(goal, goal_uuid=goal_id)

        def on_accepted(future: Future) -> None:
            handle = future.result()
            accepted.set_result(handle)
            handle.get_result_async().add_done_callback(
                lambda result: outcome.set_result(result.result()))
        sent.add_done_callback(on_accepted)
        return accepted, outcome

    def _feedback(self, action_type: Any, name: str) -> dict[bytes, Callable[[Any], None]]:
        """The feedback callbacks by goal id of a (cached) subscription to action ``name``'s
        feedback topic, once it has matched the server's publisher (at most 30 s).
        """
        if name not in self._feedback_callbacks:
            callbacks: dict[bytes, Callable[[Any], None]] = {}

            def dispatch(message: Any) -> None:
                callback = callbacks.get(bytes(message.goal_id.uuid))
                if callback is not None:
                    callback(message)
            subscription = self.node.create_subscription(
                action_type.Impl.FeedbackMessage, f"{self.planner_name}/{name}/_action/feedback",
                dispatch, 1000)
            self.spin_until(lambda: subscription.get_publisher_count() > 0, timeout=30.0)
            self._feedback_callbacks[name] = callbacks
        return self._feedback_callbacks[name]

    def close(self) -> None:
        """Destroy the nodes (the planner joins its workers) and the executor."""
        for client in self._actions.values():
            client.destroy()
        if self.planner is not None:
            self.planner.destroy_node()
        self.node.destroy_node()
        self.executor.shutdown()


def planner_threads() -> list[threading.Thread]:
    """Live worker threads of any planner (none after a clean shutdown)."""
    return [t for t in threading.enumerate() if t.name.startswith("planner-worker")]


def flat(values: Any) -> np.ndarray:
    """A message array field as a flat float ndarray."""
    return np.asarray(values, dtype=float).reshape(-1)
