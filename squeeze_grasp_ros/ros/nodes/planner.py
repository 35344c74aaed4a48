# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner node: squeezes, grasp maps, resistance and ring tests as ROS 2 services and actions.

Run it with ``ros2 run squeeze_grasp_ros planner --ros-args --params-file config/planner.yaml``
(or the ``planner`` console script). Services and actions live under the node's name:

=========================  =======  ====================================================
name                       kind     computation
=========================  =======  ====================================================
``~/load_object``          service  mesh, factor and cache a scene's or typed object (worker)
``~/plan_squeeze``         service  stable / pure squeeze at point contacts (inline)
``~/grasp_map``            service  all-pairs grasp map of a loaded solid (worker)
``~/plan_resistance``      service  optimal resistance to an adversary finger (worker)
``~/ring_grasp_test``      service  ring grasp test and ring grasp map (worker)
``~/event_squeeze``        service  event-driven squeeze, Algorithm 1 (worker)
``~/plan_gripper_grasp``   service  parallel-jaw gripper grasps: pose, aperture, effort (worker)
``~/grasp_map``            action   load + precompute + map with progress and cancel
``~/event_squeeze``        action   event-driven squeeze with progress and cancel
=========================  =======  ====================================================

Threading (measured in docs/ros.md): the node is spun by a ``SingleThreadedExecutor`` in the
main thread. Quick requests run inline in their callback. Long ones run on a worker pool: the
service or action callback is a coroutine that awaits an rclpy future which the worker
completes, so the executor keeps serving other requests meanwhile. Workers never touch rclpy
objects except to complete their future; action feedback is queued and published from the
executor thread.
"""
from __future__ import annotations

import math
import queue
import sys
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, TypeVar

from rcl_interfaces.msg import SetParametersResult
from rclpy.action import ActionServer, CancelResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.task import Future

from squeeze_grasp_interfaces.action import EventSqueeze as EventSqueezeAction
from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.srv import (
    EventSqueeze,
    GraspMap,
    LoadObject,
    PlanGripperGrasp,
    PlanResistance,
    PlanSqueeze,
    RingGraspTest,
)
from squeeze_grasp_ros import planning
from squeeze_grasp_ros.mechanics.vocabulary import ObjectModel
from squeeze_grasp_ros.planning import Cancelled, ErrorCode, PlannerLimits
from squeeze_grasp_ros.resources import share_dir
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import DRAIN_SPIN, ParameterError, pipeline, run_node, spin_until
from squeeze_grasp_ros.ros.nodes.frame_pose_topic import frame_pose_topic
from squeeze_grasp_ros.ros.refusals import RefusalLog

Response = TypeVar("Response")
WATCH_PERIOD = 0.1
"""Wall-clock seconds between two graph queries of a request's abandonment check."""
DISCOVERY_GRACE = 5.0
"""Wall-clock seconds a request's client may stay unknown to the planner's graph before its
absence counts as abandonment (across processes the graph can learn of a client after its
request arrived)."""
DRAIN_SECONDS = 4.0
"""How long a stopping planner (SIGINT, SIGTERM) waits, at most, for the long requests in
flight to be answered: running ones stop at their next stage, queued ones are refused at once
(launch sends SIGTERM 5 s after SIGINT by default)."""

PARAMETERS: dict[str, tuple[Any, str]] = {
    "max_nodes": (60_000, "largest solid mesh (nodes) the planner builds; larger scenes are "
                          "refused as oversized"),
    "max_spectral_nodes": (3_000, "largest mesh for the dense spectral solver route"),
    "max_ring_elements": (1_000, "largest ring model (elements); its compliance is dense"),
    "default_solver_route": ("factorized", "solver route when a request leaves it empty: "
                                           "factorized or spectral"),
    "cache_size": (8, "objects kept in the cache; the least recently used is evicted"),
    "cache_max_megabytes": (2048, "MiB of arrays (meshes, factorisations, compliances) the "
                                  "cache keeps; least recently used objects are evicted"),
    "worker_threads": (2, "threads computing long requests (loads, maps, event squeezes)"),
    "best_count": (10, "placements a grasp map returns when a request asks for 0"),
    "min_step": (1e-5, "smallest event-squeeze substep, relative to the object size"),
    "service_queue_depth": (0, "requests each service and action queues: 0 = all of them (DDS "
                               "never drops a request; a client beyond the reader's resource "
                               "limits is held back), N = the last N (older unread requests "
                               "are dropped)"),
    "max_pending": (16, "long requests (loads, maps, event squeezes) queued or running at "
                        "once; more are answered BUSY at once (0: every one)"),
    "frame_pose_topic": ("", "geometry_msgs/PoseStamped topic (latched) with the pose of "
                             "frame_pose_frame in the object frame, for typed objects whose "
                             "outline is in that frame and whose frame_pose is unset; '' = none"),
    "frame_pose_frame": ("", "the outline frame whose pose frame_pose_topic carries"),
    "frame_pose_max_age": (1.0, "s, largest distance of the topic's pose stamp from the "
                                "outline's stamp (unstamped: the planner's clock); 0 = any age"),
    "allowed_roots": ([""], "folders whose files scene_path and a scene's outline file may "
                            "name (symlinks and '..' resolved first); [''] = the package share "
                            "folder and the node's working directory"),
}
"""Parameter name -> (typed default, description); config/planner.yaml sets the same names."""
LIVE = ("max_pending",)
"""The parameters read at every request, which ``ros2 param set`` changes on a running planner
(within :data:`BOUNDS`); the others are read at start-up and read-only."""
BOUNDS = {**{name: pipeline.Bound(1) for name in (
    "max_nodes", "max_spectral_nodes", "max_ring_elements", "cache_size", "cache_max_megabytes",
    "worker_threads", "best_count")},
    "max_pending": pipeline.Bound(0),  # 0: every long request is answered BUSY
    "min_step": pipeline.Bound(0.0, above=True)}
"""The range of each numeric parameter (``service_queue_depth`` and ``frame_pose_max_age``
are checked where they are used)."""


def _set_live(parameters: list[Parameter]) -> SetParametersResult:
    """Refuse a ``ros2 param set`` of a live parameter out of its range (the read-only ones
    rclpy refuses itself).
    """
    for parameter in parameters:
        reason = (BOUNDS[parameter.name].why(parameter.name, parameter.value)
                  if parameter.name in LIVE else None)
        if reason:
            return SetParametersResult(successful=False, reason=reason)
    return SetParametersResult(successful=True)


def _resume(_: Future) -> None:
    """Done-callback of worker futures: scheduling it wakes the executor (see PlannerNode)."""


class PlannerNode(Node):
    """Planner services and actions backed by :mod:`squeeze_grasp_ros.planning`.

    Parameters
    ----------
    objects : sequence of planning.LoadedObject
        Objects loaded already, put into the cache under their ids (a run in this process hands
        over the object it built for its simulated world, so the scene is meshed once).
    **kwargs
        Passed to :class:`rclpy.node.Node` (e.g. ``context``, ``parameter_overrides``).
    """

    def __init__(self, *, objects: Sequence[planning.LoadedObject] = (), **kwargs: Any) -> None:
        super().__init__("planner", **kwargs)
        # float parameters also take YAML integers (``min_step: 1`` is an int in YAML)
        value = pipeline.declare(self, PARAMETERS, live=LIVE, bounds=BOUNDS).__getitem__
        try:
            route = planning.solver_route(value("default_solver_route"), PlannerLimits())
        except planning.PlannerError as error:  # a traceback before: not a ValueError
            raise ParameterError(f"parameter 'default_solver_route': {error}") from None
        self.add_on_set_parameters_callback(_set_live)
        self.limits = PlannerLimits(max_nodes=value("max_nodes"),
                             max_spectral_nodes=value("max_spectral_nodes"),
                             max_ring_elements=value("max_ring_elements"),
                             default_route=route,
                             best_count=value("best_count"), min_step=float(value("min_step")),
                             max_bytes=int(value("cache_max_megabytes")) * 2**20)
        roots = [Path(r) for r in value("allowed_roots") if r] or [share_dir(), Path.cwd()]
        self.roots = list(dict.fromkeys(r.resolve() for r in roots))
        self.cache = planning.ObjectCache(value("cache_size"), self.limits.max_bytes)
        for loaded in objects:
            self.cache.put(loaded)
        self._pool = ThreadPoolExecutor(max_workers=value("worker_threads"),
                                        thread_name_prefix="planner-worker")
        self._stopping = threading.Event()
        self.abandoned: list[tuple] = []
        """Progress (the arguments of the last report before it, () if none) of service
        requests stopped because their client left the graph."""
        self._feedback: queue.SimpleQueue[tuple[ServerGoalHandle, Any]] = queue.SimpleQueue()
        self.frame_poses = frame_pose_topic(self, value)

        services = pipeline.request_queue(value("service_queue_depth"))
        self._pending = 0
        self._pending_lock = threading.Lock()
        self._awaiting = 0  # long requests whose handler awaits its worker (executor thread)
        self._held: dict[Future, type] = {}  # their futures and response types
        self._held_lock = threading.Lock()  # a future is answered once: by its worker or drain
        self.refusals = RefusalLog(self.get_logger().info)
        # Reentrant: a long request awaiting its worker must not hold the node's default
        # (mutually exclusive) group, or every other request waits for it (measured: a
        # plan_squeeze waited the whole 7 s of an event_squeeze).
        self._group = ReentrantCallbackGroup()
        for srv_type, name, callback in (
                (LoadObject, "load_object", self._load_object),
                (PlanSqueeze, "plan_squeeze", self._plan_squeeze),
                (GraspMap, "grasp_map", self._grasp_map),
                (PlanResistance, "plan_resistance", self._plan_resistance),
                (RingGraspTest, "ring_grasp_test", self._ring_grasp_test),
                (EventSqueeze, "event_squeeze", self._event_squeeze),
                (PlanGripperGrasp, "plan_gripper_grasp", self._plan_gripper_grasp)):
            self.create_service(srv_type, f"~/{name}", callback, qos_profile=services,
                                callback_group=self._group)
        # The action servers' goal, cancel and result services default to a queue of 10 too:
        # 200 goals sent at once got 20 responses (issue 34).
        queues = {f"{kind}_service_qos_profile": services for kind in ("goal", "cancel", "result")}
        self._actions = [
            ActionServer(self, GraspMapAction, pipeline.action_name(self, "~/grasp_map"),
                         self._execute_grasp_map, cancel_callback=self._accept_cancel,
                         callback_group=self._group, **queues),
            ActionServer(self, EventSqueezeAction,
                         pipeline.action_name(self, "~/event_squeeze"),
                         self._execute_event_squeeze, cancel_callback=self._accept_cancel,
                         callback_group=self._group, **queues),
        ]

    def ready_summary(self) -> str:
        """What the ready line of ``ros2 run`` says: the limits and the readable folders."""
        return f"{self.limits}; files from {[str(r) for r in self.roots]}"

    def _parameter(self, name: str) -> Any:
        """The value of a declared parameter (an int given for a float is accepted)."""
        return self.get_parameter(name).value

    # ------------------------------------------------------------------ services

    async def _load_object(self, request: LoadObject.Request,
                           response: LoadObject.Response) -> LoadObject.Response:
        """Mesh, factor and cache the scene's object on a worker."""
        watch = self._client_watch("load_object")

        def load() -> LoadObject.Response:
            typed = messages.typed_object(request.object)
            if self.frame_poses is not None:
                typed = self.frame_poses.resolve(request.object, typed)
            source = planning.object_source(request.scene_yaml, request.scene_path, typed,
                                            self.roots)
            loaded, cached = planning.load_cached(self.cache, source, request.object_id,
                                                  request.solver_route, self.limits, watch,
                                                  request.replace)
            return messages.load_object_response(loaded, cached, request.return_model)
        return await self._in_worker(LoadObject.Response, load)

    def _plan_squeeze(self, request: PlanSqueeze.Request,
                      response: PlanSqueeze.Response) -> PlanSqueeze.Response:
        """Stable or pure squeeze of a cached object, inline (milliseconds); the request's own
        fields are checked before its object is looked up.
        """
        def plan() -> PlanSqueeze.Response:
            planning.squeeze_fields(request.squeeze_type, request.depth)
            return messages.plan_squeeze_response(planning.squeeze_plan(
                self._object(request), request.contacts, request.squeeze_type, request.depth))
        return self._answer(PlanSqueeze.Response, plan)

    async def _grasp_map(self, request: GraspMap.Request,
                         response: GraspMap.Response) -> GraspMap.Response:
        """All-pairs grasp map of a cached object on a worker."""
        def compute() -> GraspMap.Response:
            loaded = self._object(request)
            gmap = planning.object_grasp_map(loaded, request.mu)
            return messages.success(GraspMap.Response, map=messages.grasp_map_data(
                gmap, loaded.object_id, planning.best_count(request.best_count, self.limits),
                request.full_matrices, digest=loaded.digest))
        return await self._in_worker(GraspMap.Response, compute)

    async def _plan_resistance(self, request: PlanResistance.Request,
                               response: PlanResistance.Response) -> PlanResistance.Response:
        """Optimal resistance on a worker (fixed contacts: milliseconds; friction: a squeeze
        and Algorithm 2).
        """
        a = request.a
        watch = self._client_watch("plan_resistance")
        return await self._in_worker(PlanResistance.Response, lambda: (
            messages.plan_resistance_response(planning.resistance_plan(
                self._object(request), request.contacts, (a.x, a.y, a.z),
                request.mode, request.contact_model, request.segment_half_width,
                request.directions, request.adversary_tip_radius, self.limits, watch))))

    async def _ring_grasp_test(self, request: RingGraspTest.Request,
                               response: RingGraspTest.Response) -> RingGraspTest.Response:
        """Ring grasp test (and all-pairs map) on a worker."""
        def compute() -> RingGraspTest.Response:
            test = planning.ring_grasp_test(
                self._object(request), request.contacts, request.squeeze_type,
                request.mu, request.strain_limit, request.relative_depth, request.all_pairs)
            return messages.ring_grasp_test_response(
                test, planning.best_count(request.best_count, self.limits))
        return await self._in_worker(RingGraspTest.Response, compute)

    async def _event_squeeze(self, request: EventSqueeze.Request,
                             response: EventSqueeze.Response) -> EventSqueeze.Response:
        """Event-driven squeeze on a worker; stopped if its client leaves."""
        watch = self._client_watch("event_squeeze")
        return await self._in_worker(EventSqueeze.Response,
                                     lambda: self._event_squeeze_result(EventSqueeze.Response,
                                                                        request, watch, watch))

    async def _plan_gripper_grasp(self, request: PlanGripperGrasp.Request,
                                  response: PlanGripperGrasp.Response
                                  ) -> PlanGripperGrasp.Response:
        """Ranked gripper grasps of a cached solid on a worker (a grasp map, then the best
        candidates' event squeezes with pads).
        """
        def compute() -> PlanGripperGrasp.Response:
            loaded = self._object(request)
            plan = planning.gripper_grasp_plan(
                loaded, planning.read_gripper(request.gripper_yaml, request.gripper_name),
                mu=request.mu, relative_closing=request.relative_closing,
                count=request.count, evaluate=request.evaluate,
                yaw_range=(request.yaw_min, request.yaw_max) if request.use_yaw_range else None,
                weight=request.weight, force_margin=request.force_margin,
                strain_limit=request.strain_limit, limits=self.limits)
            return messages.plan_gripper_grasp_response(plan, loaded.digest)
        return await self._in_worker(PlanGripperGrasp.Response, compute)

    # ------------------------------------------------------------------ actions

    def _accept_cancel(self, goal_handle: ServerGoalHandle) -> CancelResponse:
        """Accept every cancel request; the worker stops at its next stage."""
        return CancelResponse.ACCEPT

    async def _execute_grasp_map(self, goal_handle: ServerGoalHandle) -> GraspMapAction.Result:
        """Load (when the goal has a scene), precompute and map, with a feedback per stage."""
        goal = goal_handle.request
        report = self._reporter(goal_handle, messages.grasp_map_feedback)

        def compute() -> GraspMapAction.Result:
            stages = 1
            if goal.scene_yaml or goal.scene_path:
                source = planning.read_scene(goal.scene_yaml, goal.scene_path, self.roots)
                stages += len(planning.RING_STAGES if source.scene.object.model == ObjectModel.RING
                              else planning.SOLID_STAGES)
                loaded, _ = planning.load_cached(
                    self.cache, source, goal.object_id, goal.solver_route, self.limits,
                    lambda stage, index, count, nodes: report(stage, index, stages, nodes),
                    goal.replace)
            elif not goal.object_id:  # before: "unknown object_id '': load it first with
                # load_object", though this action loads a scene itself
                raise planning.PlannerError(
                    ErrorCode.INVALID_ARGUMENT,
                    "give scene_yaml or scene_path (the action loads it), or the object_id of "
                    "a loaded object")
            else:
                loaded = self._object(goal)
            report("grasp map", stages - 1, stages, loaded.num_nodes)
            gmap = planning.object_grasp_map(loaded, goal.mu)
            best = planning.best_count(goal.best_count, self.limits)
            return messages.success(GraspMapAction.Result, map=messages.grasp_map_data(
                gmap, loaded.object_id, best, goal.full_matrices, digest=loaded.digest))
        return self._finish(goal_handle, await self._in_worker(GraspMapAction.Result, compute))

    async def _execute_event_squeeze(self,
                                     goal_handle: ServerGoalHandle) -> EventSqueezeAction.Result:
        """Event-driven squeeze with the completed fraction as feedback."""
        report = self._reporter(goal_handle, messages.event_squeeze_feedback)
        result = await self._in_worker(
            EventSqueezeAction.Result,
            lambda: self._event_squeeze_result(EventSqueezeAction.Result, goal_handle.request,
                                               report, self._goal_check(goal_handle)))
        return self._finish(goal_handle, result)

    # ------------------------------------------------------------------ plumbing

    def _event_squeeze_result(self, response_type: type[Response], request: Any,
                              progress: Callable[[float], None],
                              checkpoint: Callable[[], None]) -> Response:
        """The event squeeze of a service request or action goal as ``response_type``; the
        callbacks may raise :class:`Cancelled` (after every event, before every substep and
        fixed-set solve).
        """
        loaded = self._object(request)
        result = planning.event_squeeze_run(
            loaded, request.contacts, request.squeeze_type, request.depth,
            request.relative_depth, request.step, request.event_tol, self.limits, progress,
            checkpoint)
        return messages.success(response_type,
                                squeeze=messages.event_squeeze_data(result, loaded.object_id,
                                                                    digest=loaded.digest))

    def _object(self, request: Any) -> planning.LoadedObject:
        """The cached object a request names (``object_id``, checked against its
        ``object_digest`` when the request quotes one).
        """
        return self.cache.get(request.object_id, request.object_digest)

    def _answer(self, response_type: type[Response], compute: Callable[[], Response]) -> Response:
        """``compute()``, or a failure response naming the reason (CANCELLED without computing
        once the node is stopping); never raises for a request.
        """
        try:
            if self._stopping.is_set():
                raise Cancelled("the planner is shutting down")
            return compute()
        except Exception as exc:
            code, message = planning.classify(exc)
            if code == ErrorCode.INTERNAL_ERROR:
                self.get_logger().error(f"{response_type.__name__}: {message}")
            else:
                self.refusals.refused(code.name, message)
            return messages.failure(response_type, code, message)

    async def _in_worker(self, response_type: type[Response],
                         compute: Callable[[], Response]) -> Response:
        """Run ``compute`` on the worker pool; the executor serves other requests meanwhile.

        The worker completes an rclpy future. In rclpy 7.1.6 a coroutine awaiting a future is
        resumed only when the executor wakes up; completing a future that has a done-callback
        schedules that callback as a task, which wakes the executor at once (measured: the
        response follows the worker within a millisecond, with no busy loop).
        """
        with self._pending_lock:
            if self._pending >= self._parameter("max_pending"):
                return messages.failure(response_type, ErrorCode.BUSY,
                                        f"planner busy: {self._pending} long requests queued or "
                                        f"running (max_pending); retry later")
            self._pending += 1

        def work() -> None:
            try:
                answer = self._answer(response_type, compute)
                with self._held_lock:
                    if self._held.pop(future, None) is not None:  # else drain has answered
                        future.set_result(answer)
            finally:
                with self._pending_lock:
                    self._pending -= 1
        future = Future(executor=self.executor)
        future.add_done_callback(_resume)
        self._awaiting += 1
        self._held[future] = response_type
        try:
            self._pool.submit(work)
        except RuntimeError:
            with self._pending_lock:
                self._pending -= 1
            self._awaiting -= 1
            del self._held[future]
            return messages.failure(response_type, ErrorCode.CANCELLED,
                                    "the planner is shutting down")
        try:
            return await future
        finally:
            self._awaiting -= 1

    def _client_watch(self, service: str) -> Callable[..., None]:
        """A progress callback (and checkpoint) for the worker of a ``~/<service>`` request:
        raises :class:`Cancelled` once no client of the service is left on the graph (the
        requester has gone, so nobody can take the answer) or the node is shutting down.

        ROS 2 services have no cancel; a client that gives up and destroys its client (or
        whose process ends) leaves the graph, and its work stops at the next progress report
        or checkpoint (the long loops call it before every stepper substep and fixed-set
        solve). The graph is asked at most every :data:`WATCH_PERIOD` s; a progress report
        always asks. Clients count as gone only once the graph has shown one during this
        request, or after :data:`DISCOVERY_GRACE` s: across processes the graph can learn of a
        client after its request arrived (a run's first ``load_object`` was refused as
        abandoned).
        """
        name = f"{self.get_fully_qualified_name()}/{service}"
        asked, reported = [-math.inf], [()]
        seen, since = [self.count_clients(name) > 0], time.monotonic()

        def check(*progress: Any) -> None:
            if self._stopping.is_set():
                raise Cancelled("the planner is shutting down")
            now = time.monotonic()
            if progress:
                reported[0] = progress
            elif now - asked[0] < WATCH_PERIOD:
                return
            asked[0] = now
            if self.count_clients(name) > 0:
                seen[0] = True
            elif seen[0] or now - since > DISCOVERY_GRACE:
                self.abandoned.append(reported[0])
                raise Cancelled(f"abandoned: no client of {name} is left to take the answer")
        return check

    def _goal_check(self, goal_handle: ServerGoalHandle) -> Callable[[], None]:
        """A checkpoint for the worker of a goal: raises :class:`Cancelled` when the goal is
        being cancelled or the node is shutting down.
        """
        def check() -> None:
            if goal_handle.is_cancel_requested:
                raise Cancelled("cancelled by the client")
            if self._stopping.is_set():
                raise Cancelled("the planner is shutting down")
        return check

    def _reporter(self, goal_handle: ServerGoalHandle,
                  feedback: Callable[..., Any]) -> Callable[..., None]:
        """A progress callback for a worker: queues ``feedback(*args)`` for the goal, or raises
        :class:`Cancelled` when the goal is being cancelled or the node is shutting down.
        """
        check = self._goal_check(goal_handle)

        def report(*args: Any) -> None:
            check()
            self._feedback.put((goal_handle, feedback(*args)))
            self.executor.create_task(self._publish_feedback)
        return report

    def _publish_feedback(self) -> None:
        """Publish queued feedback in order (runs on the executor thread)."""
        while True:
            try:
                goal_handle, message = self._feedback.get_nowait()
            except queue.Empty:
                return
            if goal_handle.is_active:
                goal_handle.publish_feedback(message)

    def _finish(self, goal_handle: ServerGoalHandle, result: Response) -> Response:
        """Publish pending feedback, then end the goal as succeeded, canceled or aborted."""
        self._publish_feedback()
        if result.success:
            goal_handle.succeed()
        elif result.error_code == ErrorCode.CANCELLED and goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:
            goal_handle.abort()
        return result

    def drain(self, executor: Any, timeout: float = DRAIN_SECONDS) -> None:
        """Answer the long requests in flight before the node ends (SIGINT, SIGTERM): stop the
        workers (a running computation stops at its next stage, a queued one is refused
        CANCELLED, "the planner is shutting down") and spin ``executor`` until every such
        request's handler has answered, ``timeout`` s at most. A request whose computation is
        still inside one stage then (a call into C, such as meshing) is refused CANCELLED
        without waiting for it. Goals end aborted with that message; their results go to the
        clients that asked for them.
        """
        self._stopping.set()
        if not self._awaiting:
            return
        # then goals' result requests, answered once the goals have ended
        if spin_until(executor, lambda: not self._awaiting, timeout, then=4):
            return
        with self._held_lock:  # a stage in one call into C (meshing) has not returned: its
            late, self._held = self._held, {}  # client is answered now, its result dropped
        message = (f"the planner is shutting down (its computation did not reach a stage "
                   f"boundary within {timeout:g} s)")
        for future, response_type in late.items():
            self.refusals.refused(ErrorCode.CANCELLED.name, message)
            future.set_result(messages.failure(response_type, ErrorCode.CANCELLED, message))
        spin_until(executor, lambda: not self._awaiting, DRAIN_SPIN * 20, then=4)

    def destroy_node(self) -> None:
        """Stop the workers (running computations stop at their next stage), then the node."""
        self._stopping.set()
        self._pool.shutdown(wait=True, cancel_futures=True)
        for server in self._actions:
            server.destroy()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the planner on a SingleThreadedExecutor in the main thread until Ctrl-C or
    shutdown; return the exit code.
    """
    return run_node(PlannerNode, args, SingleThreadedExecutor)


if __name__ == "__main__":
    sys.exit(main())
