# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Run a scene through the real nodes: all on one rclpy executor, or one process per node.

:class:`PipelineRunner` is what ``squeeze-grasp run`` does, step by step (tests and benchmarks
drive the steps themselves):

1. the scene, read and parsed once (:class:`.planning.RunObject`); in one process its object
   is meshed and precomputed once too, for the planner and the simulated world alike;
2. the plan (:mod:`.planning`): the run's own planner node, asked through ``PlannerClient``, or
   the mechanics API (``--no-planner``); the prediction is latched on
   ``planner/predicted_events``;
3. the nodes: ``sim_hardware``, ``monitor``, ``executor``, ``recorder`` (with ``record``) with
   the parameters of :func:`.options.node_parameters`, by default on one executor in this
   process (``EventsExecutor`` in the main thread, or ``SingleThreadedExecutor``), with
   ``processes`` each as its own Python process (:mod:`.processes`, as ``ros2 launch`` would
   start them);
4. the ``ExecuteGrasp`` goal (:mod:`.goal_client`), progress from its feedback, the result, the
   ground truth from ``sim/events`` and ``sim/state`` (:mod:`.observer`), and the summary
   (:mod:`.summary`), with whether the recording stopped early, as its recorder reports it.

Every wait spins the executor with a wall-clock timeout, watching for Ctrl-C, dead node
processes and foreign traffic in the run's namespace (:mod:`.graph`); nothing sleeps to
synchronise.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.util
import signal
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import rclpy
import yaml
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.logging import LoggingSeverity
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.msg import ContactEventArray, PredictedShapes
from squeeze_grasp_ros.control.motion import RESQUEEZE
from squeeze_grasp_ros.exit_codes import Interrupted, SignalFlag
from squeeze_grasp_ros.mechanics.vocabulary import Effect
from squeeze_grasp_ros.perception.extract import ObjectOutline
from squeeze_grasp_ros.planning.typed_objects import typed_scene
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.objects import typed_object
from squeeze_grasp_ros.ros.nodes import Spinner, pipeline
from squeeze_grasp_ros.ros.nodes.planner_client import PlannerClient
from squeeze_grasp_ros.ros.run.camera_plan import (
    first_outline,
    predicted_shapes_msg,
    seen_description,
    seen_mirror_tolerance,
    seen_report,
)
from squeeze_grasp_ros.ros.run.goal_client import GoalClient
from squeeze_grasp_ros.ros.run.graph import GraphWatch, run_namespace, run_topics
from squeeze_grasp_ros.ros.run.observer import Observer, Progress
from squeeze_grasp_ros.ros.run.options import (
    EXECUTORS,
    PLANNER_MODULE,
    RunError,
    RunOptions,
    node_parameters,
)
from squeeze_grasp_ros.ros.run.planning import (
    Plan,
    PlannerHost,
    RunObject,
    plan_with_mechanics,
    plan_with_planner,
    planner_roots,
)
from squeeze_grasp_ros.ros.run.processes import NodeProcesses, ros_arguments
from squeeze_grasp_ros.ros.run.summary import run_summary
from squeeze_grasp_ros.scene import GraspSetup, SceneError

__all__ = ["EVENTS_PER_CHECK", "STOP_SIGNALS", "WAKE_PERIOD", "PipelineRunner"]

EVENTS_PER_CHECK = 16
"""Queued events :meth:`PipelineRunner.wait` executes between two checks of its condition."""
WAKE_PERIOD = 0.05
"""Wall-clock s: the period of the wall timer that ends a ``per_tick`` spin of
:meth:`PipelineRunner.wait`, about the longest it spins without checking its condition."""
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
"""Signals that stop a run cleanly (the recording is finished, node processes are stopped)."""


class PipelineRunner:
    """The pipeline of one scene on real rclpy nodes (see the module docstring).

    Parameters
    ----------
    options : RunOptions
    progress : callable, optional
        Called with a dict (state, depth, relative_depth, forces, events) at every feedback.
    """

    def __init__(self, options: RunOptions, progress: Progress | None = None) -> None:
        if options.executor not in EXECUTORS:
            raise RunError(f"executor must be one of {EXECUTORS}, got {options.executor!r}")
        if options.attach and (options.processes or options.record):
            raise RunError(
                "attach uses the nodes already running: it starts no processes and "
                "records nothing itself (record with the launch file's record:=)"
            )
        self.options = options
        self.run_object = RunObject.read(options.scene_path)
        self.scene = self.run_object.scene
        for name, finger in self.scene.fingers.items():
            if not finger.tip_radius > 0:
                raise SceneError(
                    f"fingers.{name}.tip_radius must be > 0 m: the simulated "
                    "hardware tracks rounded fingertips (Sec. 5)"
                )
        self.t0 = time.perf_counter()
        self.timing: dict[str, float] = {}
        self.interrupted = SignalFlag()  # set by signal handlers: no lock
        self.signal = signal.SIGINT
        self.context = Context()
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.executor = (
            EventsExecutor(context=self.context)
            if options.executor == "events"
            else SingleThreadedExecutor(context=self.context)
        )
        self.events_per_check = EVENTS_PER_CHECK if options.executor == "events" else 0
        self.namespace = (options.namespace or "/") if options.attach else (
            options.namespace or run_namespace())
        """The run's namespace: its own (a fresh one unless given), or the attached nodes'."""
        self.client = Node("run", context=self.context, cli_args=ros_arguments(self.namespace))
        self.executor.add_node(self.client)
        self.graph = (None if options.attach
                      else GraphWatch(self.client, self.namespace, run_topics(self.scene)))
        """The watch on the run's namespace (none with ``attach``: those nodes are not ours)."""
        self.processes = NodeProcesses(self.namespace) if options.processes else None
        self.nodes: dict[str, Node] = {}
        """The pipeline nodes built in this process, by name."""
        self.recorder = None
        """The in-process recorder node (with ``record``, without ``processes``)."""
        self.spinner = Spinner(self.executor, self.client, WAKE_PERIOD)
        """The ``per_tick`` spins of :meth:`wait`, each ended by a tick's ground truth, the
        goal's result or the spinner's :data:`WAKE_PERIOD` wall timer."""
        self.observer = Observer(self.client, progress, kept=not options.attach,
                                 on_state=self.spinner.wake)
        self.prediction_pub = self.client.create_publisher(
            ContactEventArray, pipeline.PREDICTION, pipeline.LATCHED)
        self.goal = GoalClient(self.client, self.observer.on_feedback)
        self.plan: Plan | None = None
        self.seen: ObjectOutline | None = None
        self.mirror: dict | None = None  # the seen object's mirror tolerance, and its sources
        """The outline the camera's first frame showed (camera.plan_from_images)."""
        self.start_ns = 0

    # ----------------------------------------------------------------- waiting
    def wait(self, done: Callable[[], bool], timeout: float, *, per_tick: bool = False) -> None:
        """Spin the executor until ``done()``; TimeoutError after ``timeout`` wall-clock s.

        Between spins it raises :class:`Interrupted` after a stop signal, :class:`RunError` if
        a node process died or foreign traffic appeared. On ``EventsExecutor``, after waiting
        (at most 50 ms) for one event, up to ``EVENTS_PER_CHECK`` more events that are already
        queued are executed before the conditions are checked again (a tick is about 13
        events; checking after each cost about 5 % of the loop). Not on
        ``SingleThreadedExecutor``: its ``spin_once`` keeps a generator of ready entities per
        timeout argument, and alternating timeouts discard it together with triggers it has
        already taken (a run then waits forever for a lost result).

        With ``per_tick`` (the lockstep loop's wait for the goal's result) on
        ``EventsExecutor``, each spin is one slice of :attr:`spinner`
        (:class:`~squeeze_grasp_ros.ros.nodes.Spinner`), which the tick's ground truth
        (``sim/state``, the client's one delivery a tick), the goal's result or its
        :data:`WAKE_PERIOD` wall timer ends: the executor dispatches a tick's events in C++,
        where a ``spin_once`` an event cost about 35 us of CPU of its own (context check,
        timeout set-up, the call), and the conditions are checked once a tick.
        """
        deadline = time.monotonic() + timeout
        while not done():
            if self.interrupted.is_set():
                raise Interrupted(self.signal)
            if time.monotonic() > deadline:
                raise TimeoutError(f"not done within {timeout:.0f} s")
            if self.processes is not None:
                self.processes.check()
            if self.graph is not None and self.graph.due():
                self.graph.check()
            if per_tick and self.events_per_check:
                self.spinner()
            else:
                self.executor.spin_once(0.05)
                for _ in range(self.events_per_check):
                    self.executor.spin_once(0.0)

    def spin_until(self, done: Callable[[], bool], timeout: float, what: str, *,
                   per_tick: bool = False) -> None:
        """:meth:`wait`, raising :class:`RunError` naming ``what`` after ``timeout``."""
        try:
            self.wait(done, timeout, per_tick=per_tick)
        except TimeoutError:
            raise RunError(f"timed out after {timeout:.0f} s waiting for {what}") from None

    # ----------------------------------------------------------------- start-up
    def start(self) -> None:
        """Plan, start the nodes and wait until the loop stands at tick 0, the executor serves
        and this client's subscriptions to the outcome (ground-truth state and events, monitor
        events and alarms) have matched their publishers.

        The last wait matters across processes: those publishers are not part of the lockstep
        handshake, and simulated time only moves once the goal is sent, so waiting here loses
        nothing; without it a fast loop could publish its first events before discovery
        between this process and the monitor had settled (seen: a run whose 7 monitor events
        never reached the client). Seeing a publisher is the reader's side of discovery only:
        the publisher's writer may match this client's reader later, so the subscriptions are
        transient-local (:class:`.observer.Observer`), and a publisher that is not (a loop node
        taken out of lockstep) is refused here rather than never heard.
        """
        options = self.options
        started = time.perf_counter()
        if not (options.processes or options.attach):
            self.run_object = self.run_object.build()
        if self.sees_object:
            if not (options.attach or (options.planner and _planner_installed())):
                raise RunError("camera.plan_from_images plans with the planner node: install "
                               "it (pip install -e '.[ros]' and squeeze-grasp ros-setup)")
            # the world and its camera first (attached: already running, its first frame
            # latched): the planner sees the object in its first frame
            self._start_nodes({"sim_hardware": node_parameters(
                self.scene, options.scene_path, options, 0.0)["sim_hardware"]})
            frame = time.perf_counter()
            self.seen = first_outline(self.client, self.spin_until, self.scene, options.timeout)
            self.timing["first_frame"] = time.perf_counter() - frame
        self.plan = self._plan()
        self.timing["plan"] = time.perf_counter() - started
        self.prediction_pub.publish(self.plan.prediction)
        if self.scene.has(Effect.CAMERA):
            self._publish_predicted_shapes()
        derived = None if self.mirror is None else self.mirror["value"]
        params = node_parameters(self.scene, options.scene_path, options,
                                 self.plan.goal.relative_per_depth, mirror_tolerance=derived)
        if self.mirror is not None:  # what the monitor runs with (an override wins; attached:
            # the running monitor keeps its own)
            self.mirror["used"] = None if options.attach else float(
                params["monitor"]["mirror_tolerance"])
        if not options.record:
            del params["recorder"]
        if self.sees_object:
            del params["sim_hardware"]
        started = time.perf_counter()
        self._start_nodes(params)
        self.spin_until(lambda: self.goal.action.server_is_ready(), options.timeout,
                        "the executor's action server")
        self.spin_until(lambda: self.observer.sim_state_ns >= 0, options.timeout, "tick 0")
        self.spin_until(lambda: self.observer.matched() or self.observer.incompatible(),
                        options.timeout, "the publishers of the run's outcome topics")
        volatile = self.observer.incompatible()  # they never match: refused, not awaited
        if volatile:
            raise RunError("the run's outcome topics need their lockstep publishers "
                           "(transient-local); volatile, so never received: "
                           + ", ".join(volatile))
        if self.graph is not None:
            self.graph.check()
        self.start_ns = self.observer.sim_state_ns
        self.timing["start_nodes"] = time.perf_counter() - started

    def _start_nodes(self, params: dict[str, dict]) -> None:
        """Start the nodes of ``params`` (processes or in this process; none when attached)."""
        if self.graph is not None:
            self.graph.ours |= set(params)
        if self.processes is not None:
            self.processes.start_nodes(params)
        elif not self.options.attach:
            self._construct(params)

    @property
    def sees_object(self) -> bool:
        """Whether the planner sees the object through the camera (camera.plan_from_images)."""
        return self.scene.has(Effect.CAMERA) and self.scene.camera.plan_from_images

    def _publish_predicted_shapes(self) -> None:
        """Latch the predicted deformed boundary along the squeeze for the monitor's shape
        watch: the planner's model (the seen outline's typed scene on the camera route, else
        the scene) squeezed to the planned depth.
        """
        started = time.perf_counter()
        model = self.scene if self.seen is None else typed_scene(typed_object(
            seen_description(self.scene, self.seen))).scene
        model = GraspSetup.build(dataclasses.replace(model, squeeze=self.scene.squeeze))
        model = model.precompute()
        if self.seen is not None:
            self.mirror = seen_mirror_tolerance(model, self.scene, self.seen)
        msg = predicted_shapes_msg(model, self.plan.goal.depth, 0)
        self.client.create_publisher(PredictedShapes, pipeline.PREDICTED_SHAPES,
                                     pipeline.LATCHED).publish(msg)
        self.timing["predicted_shapes"] = time.perf_counter() - started

    def _plan(self) -> Plan:
        """The plan, from the run's own planner (started for it and stopped after it), the
        attached nodes' planner, or the mechanics (:mod:`.planning`).
        """
        options = self.options
        if not options.attach and not (options.planner and _planner_installed()):
            return plan_with_mechanics(self.run_object, options)
        host = None
        if not options.attach:
            if self.graph is not None:
                self.graph.ours.add("planner")
            roots = planner_roots(options.scene_path, self.scene)
            host = PlannerHost(self.context, self.namespace, roots, self.processes,
                               None if options.processes else self.run_object)
        try:
            client = PlannerClient(self.client, self.executor, "planner", wait=self.wait)
            seen = None if self.seen is None else seen_description(self.scene, self.seen)
            return plan_with_planner(client, self.run_object, options.scene_path, options, seen)
        finally:
            if host is not None:
                host.stop()

    def _construct(self, params: dict[str, dict]) -> None:
        """Build the pipeline nodes in this process; the simulated world of the run's scene gets
        the run's object (no second mesh).

        Their loggers report warnings and errors, not the information a node started on its
        own announces (``ros2 run``, ``--processes``): the run prints its own progress and
        summary, and rclpy looks up every log call's caller with ``inspect`` (in this process
        of 1,200 modules the first call took 0.09 s, every later one 4 ms).
        """
        from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
        from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode
        from squeeze_grasp_ros.ros.nodes.sim_hardware import SimHardwareNode
        from squeeze_grasp_ros.sim.world import SimWorld

        classes = {"sim_hardware": SimHardwareNode, "monitor": MonitorNode,
                   "executor": ExecutorNode}
        if "recorder" in params:  # the MCAP writer's libraries load only for a recording
            from squeeze_grasp_ros.ros.nodes.recorder import RecorderNode

            classes["recorder"] = RecorderNode
        own_scene = str(Path(self.options.scene_path).resolve())
        for name, values in params.items():
            overrides = [Parameter(k, value=v) for k, v in values.items()]
            # the world of the run's own scene is built from the run's object; a world given
            # another scene (an override: the world differs from what the planner is told)
            # builds its own
            extra = ({"world": SimWorld(self.run_object.loaded.setup)}
                     if name == "sim_hardware" and values.get("scene") == own_scene else {})
            node = classes[name](context=self.context, parameter_overrides=overrides,
                                 cli_args=ros_arguments(self.namespace), **extra)
            node.get_logger().set_level(LoggingSeverity.WARN)
            self.nodes[name] = node
            self.executor.add_node(node)
        self.recorder = self.nodes.get("recorder")

    # ----------------------------------------------------------------- the goal
    def send_goal(self) -> None:
        """Send the plan's goal and wait until it is accepted (:class:`.goal_client.GoalClient`:
        across processes a response can be lost while discovery is still settling).
        """
        self.goal.send(messages.grasp_goal_msg(self.plan.goal), self.spin_until,
                       self.options.timeout)
        self.loop_started = time.perf_counter()
        self.loop_cpu_started = time.process_time()

    @property
    def joint_feedback(self) -> bool:
        """The monitor watches the jaws (or the hand's fingers) on ``joint_states`` alone (a
        controller, no sensors).
        """
        return self.scene.controller is not None and not (
            self.scene.has(Effect.FORCE_SENSING) or self.scene.has(Effect.TACTILE_SENSING))

    def cancel(self) -> None:
        """Ask the executor to cancel the goal (it holds position)."""
        self.goal.cancel()

    def wait_result(self) -> ExecuteGrasp.Result:
        """Spin until the goal's result, then until the ground truth of its last tick arrived.

        When the simulated world ends with a lost grasp (a finger slipped, the strain limit), the
        goal is cancelled, so the executor holds instead of driving fingers that no longer move
        the object; not when the monitor watches the jaws on joint feedback alone (a gripper
        scene without wrench and tactile sensing): its slip watch, not the ground truth, is
        then what stops the goal; nor when the goal re-squeezes after a slip alarm (the world
        releases the object when the fingers open, :mod:`...sim.world`). If the status topic
        reports the goal finished but the result response does not come within a few seconds
        (lost across processes), the result is requested again.
        """
        self.goal.result_future.add_done_callback(lambda _: self.spinner.wake())
        result = self.goal.result(functools.partial(self.spin_until, per_tick=True),
                                  self.options.timeout,
                                  (lambda: False) if self.joint_feedback
                                  or self.plan.goal.on_slip_alarm == RESQUEEZE
                                  else self.observer.world_failed)
        self.timing["loop"] = time.perf_counter() - self.loop_started
        self.timing["loop_cpu"] = time.process_time() - self.loop_cpu_started
        final = self.start_ns + result.ticks * int(round(self.scene.sim.dt * 1e9))
        self.spin_until(lambda: self.observer.sim_state_ns >= final, self.options.timeout,
                        "the ground truth of the last tick")
        if self.options.record and self.options.processes:
            self.spin_until(lambda: self.observer.recorder_ns >= final, self.options.timeout,
                            "the recorder to reach the last tick")
        return result

    # ----------------------------------------------------------------- shutdown
    def shutdown(self) -> None:
        """Stop every node (the recorder finishes its bag) and the rclpy context.

        After an interruption the simulated hardware leaves the executor first, so the lockstep
        loop stops at once and the recorder drains only what it has already received.
        """
        try:
            if self.interrupted.is_set() and "sim_hardware" in self.nodes:
                self.executor.remove_node(self.nodes["sim_hardware"])
            if self.recorder is not None:
                self.recorder.drain(self.executor)
                self.recorder.close()
            if self.processes is not None:
                self.processes.stop_all()
        finally:
            for node in [*self.nodes.values(), self.client]:
                if node in self.executor.get_nodes():
                    self.executor.remove_node(node)
                node.destroy_node()
            self.executor.shutdown()
            self.context.try_shutdown()

    def recording_defects(self) -> dict:
        """What is wrong with the finished run's recording: ``recording_stopped``, why it
        stopped early (a full disk), ``recording_lost``, the messages per topic the
        middleware reported lost on their way to the recorder, and ``recording_incompatible``,
        the topics with a publisher whose QoS the recorder could not take (the QoS policy, by
        topic: nothing of that publisher was recorded); as the recorder node reports
        them in this process, or, for a recorder process, as it wrote them into the bag it
        finished. Empty when the recording is complete (or there is none).
        """
        if not self.options.record:
            return {}
        if self.recorder is not None:
            stopped, lost = self.recorder.writer.stopped, dict(self.recorder.lost)
            incompatible = dict(self.recorder.incompatible)
        else:
            from squeeze_grasp_ros.ros.recording.bag import (
                INCOMPATIBLE_KEY,
                LOST_KEY,
                STOPPED_KEY,
                BagError,
                bag_info,
            )

            try:
                custom = bag_info(self.options.record).get("custom_data", {})
            except BagError as exc:
                return {"recording_stopped": f"the recording is not readable: {exc}"}
            stopped, lost = custom.get(STOPPED_KEY), yaml.safe_load(custom.get(LOST_KEY, "{}"))
            incompatible = yaml.safe_load(custom.get(INCOMPATIBLE_KEY, "{}"))
        return {**({"recording_stopped": stopped} if stopped is not None else {}),
                **({"recording_lost": lost} if lost else {}),
                **({"recording_incompatible": incompatible} if incompatible else {})}

    # ----------------------------------------------------------------- the whole run
    def run(self) -> dict:
        """Start, execute the goal, shut down; returns the JSON summary, with
        ``recording_stopped`` if the recording stopped early and ``recording_lost`` if it
        misses messages (:meth:`recording_defects`).

        SIGINT (Ctrl-C), SIGTERM and SIGHUP set a flag that the waiting loop turns into
        :class:`Interrupted` between callbacks, so no callback (a recorder write) is cut in half;
        the shutdown then stops the simulated world first (no new ticks), lets the recorder
        write what it has received and finishes the recording, and stops every node process.
        """

        def on_signal(signum: int, _frame: Any) -> None:
            self.signal = signum
            self.interrupted.set()

        previous = {s: signal.signal(s, on_signal) for s in STOP_SIGNALS}
        try:
            self.start()
            self.send_goal()
            result = self.wait_result()
            if self.graph is not None:
                self.graph.check_before_success(lambda: self.executor.spin_once(0.1))
            summary = self.summary(result)
        finally:
            try:
                self.shutdown()
            finally:
                for signum, handler in previous.items():
                    signal.signal(signum, handler)
        return {**summary, **self.recording_defects()}

    def summary(self, result: ExecuteGrasp.Result) -> dict:
        """JSON-able summary of a finished goal (:func:`.summary.run_summary`)."""
        timing = {**self.timing, "total": time.perf_counter() - self.t0, **self._node_timing()}
        return {**run_summary(scene=self.scene.name, mode=self.mode(), plan=self.plan,
                              observed=self.observer.observed(), result=result,
                              recording=self.options.record, timing=timing),
                "namespace": self.namespace,
                **({"seen_outline": {**seen_report(self.scene, self.seen),
                                     "mirror_tolerance": self.mirror}} if self.seen else {})}

    def _node_timing(self) -> dict:
        """Wall and CPU time of the stepper (``mechanics``) and of whole world ticks (``world``:
        devices, stepper, sensors) inside the in-process simulated hardware (absent with
        processes; ``loop_cpu`` is then only this process's CPU time).
        """
        if "sim_hardware" not in self.nodes:
            return {}
        world = self.nodes["sim_hardware"].world
        return {
            "mechanics": world.stepper_seconds,
            "mechanics_cpu": world.stepper_cpu_seconds,
            "world": world.step_seconds,
            "world_cpu": world.step_cpu_seconds,
        }

    def mode(self) -> str:
        """How the nodes ran."""
        if self.options.attach:
            return "attached to running nodes"
        if self.options.processes:
            return "processes"
        return "one process, " + (
            "EventsExecutor" if self.options.executor == "events" else "SingleThreadedExecutor"
        )


def _planner_installed() -> bool:
    """True if the planner node can be imported (the ``ros`` extra with our interfaces)."""
    return importlib.util.find_spec(PLANNER_MODULE) is not None
