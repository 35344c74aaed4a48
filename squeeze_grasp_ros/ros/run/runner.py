# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Run a scene through the real nodes: all on one rclpy executor, or one process per node.

:class:`PipelineRunner` is what ``squeeze-grasp run`` does, step by step (tests and benchmarks
drive the steps themselves):

1. node parameters from ``config/*.yaml`` plus what the scene decides (devices, sensors, mu,
   tick, recording);
2. the nodes: ``sim_hardware``, ``monitor``, ``executor``, ``recorder`` (with ``record``) as
   real rclpy nodes, by default on one executor in this process (``EventsExecutor`` in the main
   thread, or ``SingleThreadedExecutor``), with ``processes`` each as its own Python process
   (``python -m squeeze_grasp_ros.ros.nodes.<node> --ros-args --params-file ...``, as ``ros2
   launch`` would start them);
3. the plan: the planner node's services when the planner exists (``load_object``,
   ``event_squeeze`` for the directions and the predicted events, ``plan_squeeze`` for the pure
   directions), else :func:`squeeze_grasp_ros.scene.goal.plan_scene` directly; the resistance
   waypoints (scenes with a frictional adversary) from Algorithm 2
   (:func:`squeeze_grasp_ros.scene.goal.resistance_goal`);
4. the prediction latched on ``planner/predicted_events``, the ``ExecuteGrasp`` goal, progress
   from its feedback, the result; ground truth from ``sim/events`` and ``sim/state``.

Every wait spins the executor with a wall-clock timeout; nothing sleeps to synchronise. The
options and node parameters are in :mod:`.options`, the action client in
:mod:`.goal_client`, the summary in :mod:`.summary`.

Isolation: a run's own nodes (its planner, the pipeline nodes, its client) live in a namespace
of their own (:func:`run_namespace`), and ``/clock`` is remapped into it, so every topic,
service and action of the run carries the run's identity in its name and two runs on one ROS
domain never see each other's traffic. The run watches its topics (:meth:`PipelineRunner.
check_graph`): a publisher it did not start on one of them, or a second node with the name of
one of its nodes, ends the run with :class:`RunError` (exit 4), never a success.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import os
import secrets
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.serialization import deserialize_message
from rclpy.signals import SignalHandlerOptions
from std_msgs.msg import Header

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.msg import (Alarm, ContactEvent, ContactEventArray,
                                          PredictedShapes, SimState)

from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.control.motion import GraspGoal
from squeeze_grasp_ros.exit_codes import Interrupted
from squeeze_grasp_ros.perception.extract import ObjectOutline
from squeeze_grasp_ros.ros.recording.bag import plain_yaml
from squeeze_grasp_ros.resources import config_dir, share_dir
from squeeze_grasp_ros.scene import GraspSetup, Scene, SceneError, finger_devices, load_scene
from squeeze_grasp_ros.ros.nodes import PARAMS_FILE_ENV, PARENT_PID_ENV, pipeline
from squeeze_grasp_ros.ros.nodes.recorder import cdr_stamp_ns
from squeeze_grasp_ros.planning.typed_objects import typed_scene
from squeeze_grasp_ros.ros.messages.objects import typed_object
from squeeze_grasp_ros.control.force_watch import squeeze_forces
from squeeze_grasp_ros.ros.run.camera_plan import (first_outline, predicted_shapes_msg,
                                                   seen_description, seen_report)
from squeeze_grasp_ros.ros.run.goal_client import GoalClient
from squeeze_grasp_ros.ros.run.options import (EXECUTORS, PLANNER_MODULE, RunError,
                                               RunOptions, node_parameters)
from squeeze_grasp_ros.ros.run.summary import GRASP_HELD, Observed, Plan, run_summary
from squeeze_grasp_ros.scene.goal import plan_scene, resistance_goal, resists
from squeeze_grasp_ros.threads import single_thread_blas
from squeeze_grasp_ros.mechanics.vocabulary import (SQUEEZING_FINGERS, Effect, ShapeType,
                                                    SqueezeKind)

GRAPH_CHECK_PERIOD = 1.0
"""Wall-clock seconds between two checks of the run's namespace for foreign traffic."""
UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"
"""The node name rmw reports for a publisher discovered before its node's graph information."""
UNKNOWN_NODE_GRACE = 10.0
"""Wall-clock seconds a publisher may stay without a node name before it counts as foreign (a
plain DDS writer never gets one)."""
EVENTS_PER_CHECK = 16
"""Queued events :meth:`PipelineRunner.spin_until` executes between two checks of its condition."""
SERVICE_RETRY = 30.0
"""Wall-clock seconds after which an unanswered planner request is sent again."""


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
"""Signals that stop a run cleanly (the recording is finished, node processes are stopped)."""


PARAMS_PREFIX = "squeeze_grasp_run_"
"""Name prefix of the parameter files ``--processes`` writes to the temp folder
(``squeeze_grasp_run_<pid>_<random>.yaml``)."""


def remove_stale_parameter_files() -> list[Path]:
    """Remove the parameter files of runs whose process no longer exists (a run killed with
    SIGKILL cannot remove its own; its nodes remove it when they notice); returns them.
    """
    stale = []
    for path in Path(tempfile.gettempdir()).glob(f"{PARAMS_PREFIX}*_*.yaml"):
        pid = path.name[len(PARAMS_PREFIX):].split("_", 1)[0]
        if pid.isdigit() and not process_exists(int(pid)):
            path.unlink(missing_ok=True)
            stale.append(path)
    return stale


def process_exists(pid: int) -> bool:
    """True if a process ``pid`` exists (of any user)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def run_namespace() -> str:
    """A namespace no other run uses: ``/squeeze_grasp/run_<pid>_<8 random hex digits>``."""
    return f"/squeeze_grasp/run_{os.getpid()}_{secrets.token_hex(4)}"


def run_topics(scene: Scene) -> list[str]:
    """Every topic of a run of ``scene`` (action topics and handshake included), relative
    (``/clock`` as ``clock``: it is remapped into the run's namespace).
    """
    devices = finger_devices(scene).values()
    names = list(pipeline.pipeline_topics(devices, hidden=True, camera=scene.has(Effect.CAMERA)))
    names += [f"/{t}" for t in (pipeline.HELLO, pipeline.READY, pipeline.RECORDER_PROGRESS)]
    return [t.lstrip("/") for t in names]


def node_topic(namespace: str, topic: str) -> str:
    """``topic`` (relative) in ``namespace``.

    >>> node_topic("/lab/run_1", "sim/tick"), node_topic("/", "sim/tick")
    ('/lab/run_1/sim/tick', '/sim/tick')
    """
    return f"{namespace.rstrip('/')}/{topic}"


def ros_arguments(namespace: str) -> list[str]:
    """Command-line ROS arguments that put a node into ``namespace`` with ``/clock`` remapped
    into it (the nodes on sim time subscribe to the absolute ``/clock``).

    >>> ros_arguments("/lab/run_1")
    ['--ros-args', '-r', '__ns:=/lab/run_1', '-r', '/clock:=/lab/run_1/clock']
    """
    if not namespace or namespace == "/":
        return ["--ros-args"]
    return ["--ros-args", "-r", f"__ns:={namespace}", "-r", f"/clock:={namespace}/clock"]



CHILD_STOP_TIMEOUT = 30.0
"""Wall-clock seconds a node process has to end after SIGINT before it is killed."""


def stop_child(proc: subprocess.Popen, signum: int | None = signal.SIGINT) -> None:
    """Stop a node process: ``signum`` (None: already sent), then SIGKILL if it has not ended
    within :data:`CHILD_STOP_TIMEOUT` (a process still importing under load ignores SIGINT
    until its handlers are installed).
    """
    if signum is not None and proc.poll() is None:
        proc.send_signal(signum)
    try:
        proc.wait(CHILD_STOP_TIMEOUT)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()

class PipelineRunner:
    """The pipeline of one scene on real rclpy nodes (see the module docstring).

    Parameters
    ----------
    options : RunOptions
    progress : callable, optional
        Called with a dict (state, depth, relative_depth, forces, events) at every feedback.
    """

    def __init__(
        self, options: RunOptions, progress: Callable[[dict], None] | None = None
    ) -> None:
        if options.executor not in EXECUTORS:
            raise RunError(f"executor must be one of {EXECUTORS}, got {options.executor!r}")
        if options.attach and (options.processes or options.record):
            raise RunError(
                "attach uses the nodes already running: it starts no processes and "
                "records nothing itself (record with the launch file's record:=)"
            )
        self.options = options
        self.progress = progress
        self.scene = load_scene(options.scene_path)
        for name, finger in self.scene.fingers.items():
            if not finger.tip_radius > 0:
                raise SceneError(
                    f"fingers.{name}.tip_radius must be > 0 m: the simulated "
                    "hardware tracks rounded fingertips (Sec. 5)"
                )
        self.t0 = time.perf_counter()
        self.timing: dict[str, float] = {}
        self.interrupted = threading.Event()
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
        self.ours = {"run"}
        """Names of the nodes this run started in its namespace (grows as they start)."""
        self.graph_checked = -float("inf")
        self.topics = [node_topic(self.namespace, t) for t in run_topics(self.scene)]
        """The run's topics, fully qualified: the ones :meth:`check_graph` watches."""
        self.unknown_since: dict[bytes, float] = {}
        """Publisher GID -> when it was first seen without a node name (discovery pending)."""
        self.client = Node("run", context=self.context, cli_args=ros_arguments(self.namespace))
        self.executor.add_node(self.client)
        self.nodes: list[Node] = []
        self.processes: list[subprocess.Popen] = []
        self.params_files: list[Path] = []
        self.sim_events: list[ContactEvent] = []
        self.world_end: dict | None = None
        self.monitor_events: list[ContactEvent] = []
        self.alarms: Counter = Counter()
        self.first_alarm: dict[str, dict] = {}
        self.sim_state_data: list[bytes] = []
        self.sim_state_ns = -1
        self.recorder_ns = -1
        self.feedback: list[ExecuteGrasp.Feedback] = []
        loop = pipeline.loop_qos(1000)
        c = self.client
        self.outcome_subscriptions = [
            c.create_subscription(ContactEventArray, pipeline.SIM_EVENTS, self._sim_events, loop),
            c.create_subscription(
                ContactEventArray,
                pipeline.EVENTS,
                lambda msg: self.monitor_events.extend(msg.events),
                loop,
            ),
            c.create_subscription(Alarm, pipeline.ALARMS, self._alarm, loop),
            c.create_subscription(SimState, pipeline.SIM_STATE, self._state, loop, raw=True),
        ]
        c.create_subscription(Header, pipeline.RECORDER_PROGRESS, self._recorder_progress, loop)
        self.prediction_pub = c.create_publisher(
            ContactEventArray, pipeline.PREDICTION, pipeline.LATCHED
        )
        self.goal = GoalClient(c, self._feedback)
        self.plan: Plan | None = None
        self.seen: ObjectOutline | None = None
        """The outline the camera's first frame showed (camera.plan_from_images)."""
        self.start_ns = 0

    # ----------------------------------------------------------------- callbacks
    def _sim_events(self, msg: ContactEventArray) -> None:
        self.sim_events += msg.events
        if msg.termination:
            self.world_end = {
                "termination": msg.termination,
                "depth": float(msg.depth),
                "stamp_ns": messages.stamp_ns(msg.header.stamp),
            }

    def _alarm(self, msg: Alarm) -> None:
        self.alarms[msg.type] += 1
        self.first_alarm.setdefault(
            msg.type,
            {
                "stamp_ns": messages.stamp_ns(msg.header.stamp),
                "finger": msg.finger,
                "message": msg.message,
            },
        )

    def _state(self, data: bytes) -> None:
        self.sim_state_data.append(data)
        self.sim_state_ns = cdr_stamp_ns(data)

    @property
    def sim_state(self) -> SimState | None:
        """The newest ground-truth state (kept serialised; decoded on demand)."""
        return (
            deserialize_message(self.sim_state_data[-1], SimState) if self.sim_state_data else None
        )

    @property
    def sim_states(self) -> list[SimState]:
        """Every ground-truth state received, in order (one per tick, re-sent ticks repeated)."""
        return [deserialize_message(data, SimState) for data in self.sim_state_data]

    def _recorder_progress(self, msg: Header) -> None:
        self.recorder_ns = max(self.recorder_ns, messages.stamp_ns(msg.stamp))

    def _feedback(self, msg: Any) -> None:
        fb = msg.feedback
        self.feedback.append(fb)
        if self.progress is not None:
            self.progress(
                {
                    "state": fb.state,
                    "depth": fb.depth,
                    "relative_depth": fb.relative_depth,
                    "forces": {f: [v.x, v.y] for f, v in zip(fb.fingers, fb.forces)},
                    "events": len(self.monitor_events),
                }
            )

    # ----------------------------------------------------------------- waiting
    def spin_until(self, done: Callable[[], bool], timeout: float, what: str) -> None:
        """Spin the executor until ``done()`` or ``timeout`` wall-clock seconds (then raise).

        On ``EventsExecutor``, after waiting (at most 50 ms) for one event, up to
        ``EVENTS_PER_CHECK`` more events that are already queued are executed before the
        conditions are checked again (a tick is about 13 events; checking after each cost about
        5 % of the loop). Not on ``SingleThreadedExecutor``: its ``spin_once`` keeps a generator
        of ready entities per timeout argument, and alternating timeouts discard it together
        with triggers it has already taken (a run then waits forever for a lost result).
        """
        deadline = time.monotonic() + timeout
        while not done():
            if self.interrupted.is_set():
                raise Interrupted(self.signal)
            if time.monotonic() > deadline:
                raise RunError(f"timed out after {timeout:.0f} s waiting for {what}")
            self._check_processes()
            if time.monotonic() > self.graph_checked + GRAPH_CHECK_PERIOD:
                self.check_graph()
            self.executor.spin_once(0.05)
            for _ in range(self.events_per_check):
                self.executor.spin_once(0.0)

    def check_graph(self) -> bool:
        """Raise :class:`RunError` if anything foreign takes part in the run.

        Foreign: a publisher on one of the run's topics (the pipeline's, resolved in the run's
        namespace) from a node this run did not start, or a second node with the name of one
        of the run's nodes in its namespace (another run, or a planner answering in its
        place). Subscribers (a viewer) and other nodes are not the run's business. (Not for
        ``attach``: the nodes there are not the run's own.)

        Returns
        -------
        bool
            Whether a publisher on the run's topics is still unnamed (discovered before its
            node, and younger than :data:`UNKNOWN_NODE_GRACE`): neither cleared nor foreign yet.
        """
        self.graph_checked = time.monotonic()
        if self.options.attach:
            return False
        ns, node, now = self.namespace, self.client, time.monotonic()
        pending = False
        names = Counter(n for n, space in node.get_node_names_and_namespaces()
                        if space == ns and n in self.ours)
        foreign = [f"{k} nodes named {ns.rstrip('/')}/{n}" for n, k in names.items() if k > 1]
        for topic in self.topics:
            for info in node.get_publishers_info_by_topic(topic):
                if info.node_name == UNKNOWN_NODE:  # discovered before its node's name
                    first = self.unknown_since.setdefault(bytes(info.endpoint_gid), now)
                    if now - first < UNKNOWN_NODE_GRACE:
                        pending = True
                        continue
                elif info.node_namespace == ns and info.node_name in self.ours:
                    continue
                foreign.append(f"{info.node_namespace.rstrip('/')}/{info.node_name} "
                               f"publishing on {topic}")
        if foreign:
            raise RunError(
                f"foreign traffic in this run's namespace {ns}: {'; '.join(sorted(foreign)[:3])}"
                f"{' and more' if len(foreign) > 3 else ''}; the run's results cannot be "
                "trusted, so it is stopped"
            )
        return pending

    def check_graph_before_success(self) -> None:
        """The last :meth:`check_graph` before a result is reported: a publisher still unnamed
        is waited for until it is named (ours) or its grace ends (foreign: raised), so a run
        that ends inside an intruder's grace never reports success.
        """
        while self.check_graph():
            self.executor.spin_once(0.1)

    def _check_processes(self) -> None:
        for proc in self.processes:
            if proc.poll() is not None:
                raise RunError(f"node process {proc.args[2]} exited with code {proc.returncode}")

    # ----------------------------------------------------------------- start-up
    def start(self) -> None:
        """Plan, start the nodes and wait until the loop stands at tick 0, the executor serves
        and this client's subscriptions to the outcome (ground-truth state and events, monitor
        events and alarms) have matched their publishers.

        The last wait matters across processes: those publishers are not part of the lockstep
        handshake, and simulated time only moves once the goal is sent, so waiting here loses
        nothing; without it a fast loop could publish its first events before discovery
        between this process and the monitor had settled (seen: a run whose 7 monitor events
        never reached the client).
        """
        plan_source = self._use_planner()
        if self.sees_object:
            if not plan_source:
                raise RunError("camera.plan_from_images plans with the planner node: install "
                               "it (pip install -e '.[ros]' and squeeze-grasp ros-setup)")
            # the world and its camera first (attached: already running, its first frame
            # latched): the planner sees the object in its first frame
            self._start_nodes({"sim_hardware": node_parameters(
                self.scene, self.options.scene_path, self.options, 0.0)["sim_hardware"]})
            started = time.perf_counter()
            self.seen = first_outline(self.client, self.spin_until, self.scene,
                                      self.options.timeout)
            self.timing["first_frame"] = time.perf_counter() - started
        planner = self._start_planner() if plan_source and not self.options.attach else None
        try:
            self.plan = self._plan_with_planner() if plan_source else self._plan_with_mechanics()
        finally:
            if planner is not None:
                planner()
        self.timing["plan"] = self.plan.seconds
        self.prediction_pub.publish(self.plan.prediction)
        if self.scene.has(Effect.CAMERA):
            self._publish_predicted_shapes()
        params = node_parameters(
            self.scene, self.options.scene_path, self.options, self.plan.goal.relative_per_depth
        )
        if not self.options.record:
            del params["recorder"]
        if self.sees_object:
            del params["sim_hardware"]
        started = time.perf_counter()
        self._start_nodes(params)
        self.spin_until(
            lambda: self.goal.action.server_is_ready(),
            self.options.timeout,
            "the executor's action server",
        )
        self.spin_until(lambda: self.sim_state_ns >= 0, self.options.timeout, "tick 0")
        self.spin_until(
            lambda: all(s.get_publisher_count() > 0 for s in self.outcome_subscriptions),
            self.options.timeout,
            "the publishers of the run's outcome topics",
        )
        self.check_graph()
        self.start_ns = self.sim_state_ns
        self.timing["start_nodes"] = time.perf_counter() - started

    def _publish_predicted_shapes(self) -> None:
        """Latch the predicted deformed boundary along the squeeze for the monitor's shape
        watch: the planner's model (the seen outline's typed scene on the camera route, else
        the scene) squeezed to the planned depth.
        """
        started = time.perf_counter()
        model = self.scene if self.seen is None else typed_scene(typed_object(
            seen_description(self.scene, self.seen))).scene
        model = dataclasses.replace(model, squeeze=self.scene.squeeze)
        msg = predicted_shapes_msg(model, self.plan.goal.depth, 0)
        self.client.create_publisher(PredictedShapes, pipeline.PREDICTED_SHAPES,
                                     pipeline.LATCHED).publish(msg)
        self.timing["predicted_shapes"] = time.perf_counter() - started

    def _start_nodes(self, params: dict[str, dict]) -> None:
        """Start the nodes of ``params`` (processes or in this process; none when attached)."""
        self.ours |= set(params)
        if self.options.processes:
            self._spawn(params)
        elif not self.options.attach:
            self._construct(params)

    @property
    def sees_object(self) -> bool:
        """Whether the planner sees the object through the camera (camera.plan_from_images)."""
        return self.scene.has(Effect.CAMERA) and self.scene.camera.plan_from_images

    def _use_planner(self) -> bool:
        return self.options.attach or (
            self.options.planner and importlib.util.find_spec(PLANNER_MODULE) is not None
        )

    def _construct(self, params: dict[str, dict]) -> None:
        from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
        from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode
        from squeeze_grasp_ros.ros.nodes.recorder import RecorderNode
        from squeeze_grasp_ros.ros.nodes.sim_hardware import SimHardwareNode

        classes = {
            "sim_hardware": SimHardwareNode,
            "monitor": MonitorNode,
            "executor": ExecutorNode,
            "recorder": RecorderNode,
        }
        for name, values in params.items():
            overrides = [Parameter(k, value=v) for k, v in values.items()]
            node = classes[name](context=self.context, parameter_overrides=overrides,
                                 cli_args=ros_arguments(self.namespace))
            self.nodes.append(node)
            self.executor.add_node(node)

    def _spawn(self, params: dict[str, dict]) -> None:
        remove_stale_parameter_files()
        handle, path = tempfile.mkstemp(prefix=f"{PARAMS_PREFIX}{os.getpid()}_", suffix=".yaml")
        os.close(handle)
        params_file = Path(path)
        self.params_files.append(params_file)
        params_file.write_text(
            plain_yaml({f"{self.namespace}/{name}": {"ros__parameters": values}
                        for name, values in params.items()})
        )
        for name in params:
            self.processes.append(
                subprocess.Popen(
                    [
                        sys.executable,
                        "-m",
                        f"squeeze_grasp_ros.ros.nodes.{name}",
                        *ros_arguments(self.namespace),
                        "--params-file",
                        str(params_file),
                    ],
                    stdin=subprocess.DEVNULL,
                    env=self._child_environment(),
                )
            )

    def _child_environment(self) -> dict[str, str]:
        """The environment of a node process: single-threaded BLAS, and this process's pid and
        parameter file, so that the node ends (and removes the file) if this process dies
        without stopping it (SIGKILL): :func:`..nodes.parent_watch`.
        """
        env = dict(single_thread_blas(dict(os.environ)))
        env[PARENT_PID_ENV] = str(os.getpid())
        if self.params_files:
            env[PARAMS_FILE_ENV] = str(self.params_files[-1])
        return env

    def node(self, name: str) -> Node:
        """The in-process node called ``name``."""
        return next(n for n in self.nodes if n.get_name() == name)

    # ----------------------------------------------------------------- planning
    def _planner_roots(self) -> list[str]:
        """Folders the run's own planner may read: the scene's (and its outline file's), the
        package share folder and the working directory.
        """
        folders = [Path(self.options.scene_path).resolve().parent, share_dir(), Path.cwd()]
        shape = self.scene.object.shape
        if shape["type"] == ShapeType.FILE:
            folders.append(Path(shape["path"]).resolve().parent)
        return [str(f) for f in folders]

    def _start_planner(self) -> Callable[[], None]:
        """Start the planner (thread or process); return the function that stops it."""
        roots = self._planner_roots()
        self.ours.add("planner")
        if self.options.processes:
            proc = subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    PLANNER_MODULE,
                    *ros_arguments(self.namespace),
                    "--params-file",
                    str(config_dir() / "planner.yaml"),
                    "-p",
                    f"allowed_roots:={json.dumps(roots)}",
                ],
                stdin=subprocess.DEVNULL,
                env=self._child_environment(),
            )

            return lambda: stop_child(proc)
        from squeeze_grasp_ros.ros.nodes.planner import PlannerNode

        node = PlannerNode(
            context=self.context, parameter_overrides=[Parameter("allowed_roots", value=roots)],
            cli_args=ros_arguments(self.namespace),
        )
        spinner = SingleThreadedExecutor(context=self.context)
        spinner.add_node(node)
        thread = threading.Thread(target=spinner.spin, name="planner", daemon=True)
        thread.start()

        def stop_thread() -> None:
            spinner.shutdown()
            thread.join(30)
            node.destroy_node()

        return stop_thread

    def _call(self, srv_type: Any, name: str, request: Any) -> Any:
        """Call a planner service; the request is repeated if its response is lost (the
        planner's requests are idempotent).
        """
        client = self.client.create_client(srv_type, f"planner/{name}")
        self.spin_until(client.service_is_ready, self.options.timeout, f"planner/{name}")
        deadline = time.monotonic() + self.options.timeout
        while True:
            future = client.call_async(request)
            retry = min(time.monotonic() + SERVICE_RETRY, deadline)
            self.spin_until(
                lambda: future.done() or time.monotonic() > retry,
                self.options.timeout,
                f"planner/{name}",
            )
            if future.done():
                break
            if time.monotonic() > deadline:
                raise RunError(f"planner/{name} did not answer")
        response = future.result()
        self.client.destroy_client(client)
        if not response.success:
            raise RunError(f"planner/{name}: {response.message}")
        return response

    def _plan_with_planner(self) -> Plan:
        from squeeze_grasp_interfaces.srv import EventSqueeze, LoadObject, PlanSqueeze

        t0 = time.perf_counter()
        path = str(Path(self.options.scene_path).resolve())
        request = (LoadObject.Request(object=seen_description(self.scene, self.seen))
                   if self.seen is not None else LoadObject.Request(scene_path=path))
        loaded = self._call(LoadObject, "load_object", request)
        request = EventSqueeze.Request(object_id=loaded.object_id,
                                       object_digest=loaded.object_digest)
        if self.seen is not None:  # a typed object has no squeeze section: the scene's squeeze
            spec = self.scene.squeeze
            request.squeeze_type = spec.type.value
            request.depth, request.relative_depth = spec.depth or 0.0, spec.relative_depth or 0.0
            request.step, request.event_tol = spec.step, spec.event_tol
        squeeze = self._call(EventSqueeze, "event_squeeze", request).squeeze
        pure = self._call(
            PlanSqueeze,
            "plan_squeeze",
            PlanSqueeze.Request(
                object_id=loaded.object_id,
                object_digest=loaded.object_digest,
                contacts=list(loaded.finger_nodes),
                squeeze_type=SqueezeKind.PURE,
            ),
        )
        directions = np.array(
            [
                [squeeze.direction_f1.x, squeeze.direction_f1.y],
                [squeeze.direction_f2.x, squeeze.direction_f2.y],
            ]
        )
        rpd = squeeze.relative_depth / squeeze.depth if squeeze.depth > 0 else 0.0
        resist = resists(self.scene, resist=self.options.resist)
        resistance = resistance_goal(GraspSetup.build(self.scene)) if resist else {}
        goal = GraspGoal(
            SQUEEZING_FINGERS,
            directions,
            squeeze.target_depth,
            rpd,
            self.options.on_slip_alarm,
            np.asarray(pure.displacement, float).reshape(2, 2),
            **resistance,
        )
        prediction = messages.prediction_msg(
            list(squeeze.events), squeeze.termination, squeeze.depth,
            messages.force_curve(squeeze.curve_depths, squeeze.curve_force_f1,
                                 squeeze.curve_force_f2))
        return Plan(goal, prediction, "planner", time.perf_counter() - t0)

    def _plan_with_mechanics(self) -> Plan:
        plan = plan_scene(self.scene, on_slip_alarm=self.options.on_slip_alarm,
                          resist=self.options.resist)
        squeeze = plan.squeeze
        prediction = messages.prediction_msg(
            [messages.contact_event_msg(e) for e in squeeze.events], squeeze.termination,
            squeeze.depth, squeeze_forces(squeeze))
        return Plan(plan.goal, prediction, "mechanics", plan.seconds)

    # ----------------------------------------------------------------- the goal
    def send_goal(self) -> None:
        """Send the plan's goal and wait until it is accepted (:class:`.goal_client.GoalClient`:
        across processes a response can be lost while discovery is still settling).
        """
        self.goal.send(messages.grasp_goal_msg(self.plan.goal), self.spin_until,
                       self.options.timeout)
        self.loop_started = time.perf_counter()
        self.loop_cpu_started = time.process_time()

    def cancel(self) -> None:
        """Ask the executor to cancel the goal (it holds position)."""
        self.goal.cancel()

    def _world_failed(self) -> bool:
        """True once the simulated world has ended with a termination that loses the grasp."""
        return self.world_end is not None and self.world_end["termination"] not in GRASP_HELD

    def wait_result(self) -> ExecuteGrasp.Result:
        """Spin until the goal's result, then until the ground truth of its last tick arrived.

        When the simulated world ends with a lost grasp (a finger slipped, the strain limit), the
        goal is cancelled, so the executor holds instead of driving fingers that no longer move
        the object. If the status topic reports the goal finished but the result response does
        not come within a few seconds (lost across processes), the result is requested again.
        """
        result = self.goal.result(self.spin_until, self.options.timeout, self._world_failed)
        self.timing["loop"] = time.perf_counter() - self.loop_started
        self.timing["loop_cpu"] = time.process_time() - self.loop_cpu_started
        final = self.start_ns + result.ticks * self._dt_ns()
        self.spin_until(
            lambda: self.sim_state_ns >= final,
            self.options.timeout,
            "the ground truth of the last tick",
        )
        if self.options.record and self.options.processes:
            self.spin_until(
                lambda: self.recorder_ns >= final,
                self.options.timeout,
                "the recorder to reach the last tick",
            )
        return result

    def _dt_ns(self) -> int:
        return int(round(self.scene.sim.dt * 1e9))

    # ----------------------------------------------------------------- shutdown
    def shutdown(self) -> None:
        """Stop every node (the recorder finishes its bag) and the rclpy context.

        After an interruption the simulated hardware leaves the executor first, so the lockstep
        loop stops at once and the recorder drains only what it has already received.
        """
        try:
            if self.interrupted.is_set():
                for node in self.nodes:
                    if node.get_name() == "sim_hardware":
                        self.executor.remove_node(node)
            for node in self.nodes:
                if hasattr(node, "drain"):
                    node.drain(self.executor)
                    node.close()
            for proc in self.processes:
                if proc.poll() is None:
                    proc.send_signal(signal.SIGINT)
            for proc in self.processes:
                stop_child(proc, signum=None)
        finally:
            for node in self.nodes + [self.client]:
                if node in self.executor.get_nodes():
                    self.executor.remove_node(node)
                node.destroy_node()
            self.executor.shutdown()
            self.context.try_shutdown()
            for params_file in self.params_files:
                params_file.unlink(missing_ok=True)

    # ----------------------------------------------------------------- the whole run
    def run(self) -> dict:
        """Start, execute the goal, collect the summary, shut down; returns the JSON summary.

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
            self.check_graph_before_success()
            return self.summary(result)
        finally:
            try:
                self.shutdown()
            finally:
                for signum, handler in previous.items():
                    signal.signal(signum, handler)

    def summary(self, result: ExecuteGrasp.Result) -> dict:
        """JSON-able summary of a finished goal (:func:`.summary.run_summary`)."""
        observed = Observed(self.sim_state, list(self.sim_events), self.world_end,
                            list(self.monitor_events), self.alarms, self.first_alarm)
        timing = {**self.timing, "total": time.perf_counter() - self.t0, **self._node_timing()}
        return {**run_summary(scene=self.scene.name, mode=self.mode(), plan=self.plan,
                              observed=observed, result=result, recording=self.options.record,
                              timing=timing), "namespace": self.namespace,
                **({"seen_outline": seen_report(self.scene, self.seen)} if self.seen else {})}

    def _node_timing(self) -> dict:
        """Wall and CPU time of the stepper (``mechanics``) and of whole world ticks (``world``:
        devices, stepper, sensors) inside the in-process simulated hardware (absent with
        processes; ``loop_cpu`` is then only this process's CPU time).
        """
        sims = [n for n in self.nodes if n.get_name() == "sim_hardware"]
        if not sims:
            return {}
        world = sims[0].world
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
