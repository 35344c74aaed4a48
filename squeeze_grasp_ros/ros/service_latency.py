# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Measurements of the ``ros_services`` benchmark section on real rclpy (imported only when
rclpy and the interfaces are installed). Every row is measured in the calling run; processes
are isolated by a unique node namespace and localhost-only discovery.
"""

from __future__ import annotations

import contextlib
import os
import resource
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import rclpy
import yaml
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future

from squeeze_grasp_interfaces.action import GraspMap
from squeeze_grasp_interfaces.srv import LoadObject, PlanSqueeze
from squeeze_grasp_ros import planning
from squeeze_grasp_ros.mechanics.elastic.reduced import boundary_displacement, reduced_stiffness
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import SqueezeKind
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes.planner import PlannerNode
from squeeze_grasp_ros.ros.nodes.planner_client import PlannerClient
from squeeze_grasp_ros.threads import single_thread_blas

DEPTH = 0.004
"""Squeeze depth rho of the benchmarked requests, m."""
SCENE = """
name: bench_blob
object:
  shape: {type: fourier_blob, radius: 0.06, cos: [0.0, 0.15, 0.05], sin: [0.05]}
  material: {E: 5.0e4, nu: 0.3, thickness: 0.0254}
  mesh: {nodes: 0}
fingers:
  F1: {placement: {angle_deg: 180}}
  F2: {placement: {angle_deg: 0}}
"""
"""The benchmark object (the solver benchmark's blob); ``nodes`` is set per size."""
Progress = Callable[[str], None]


def scene_text(nodes: int) -> str:
    """The benchmark scene with a mesh of about ``nodes`` nodes."""
    data = yaml.safe_load(SCENE)
    data["object"]["mesh"]["nodes"] = nodes
    return yaml.safe_dump(data)


@contextlib.contextmanager
def localhost_only() -> Iterator[str]:
    """Restrict DDS discovery to this machine; yield a node namespace no one else uses."""
    previous = os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE")
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    try:
        yield f"/sg_bench_{os.getpid()}"
    finally:
        if previous is None:
            os.environ.pop("ROS_AUTOMATIC_DISCOVERY_RANGE")
        else:
            os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = previous


def per_call(fn: Callable[[], object], count: int, warmup: int = 10) -> np.ndarray:
    """Wall time (s) of each of ``count`` calls of ``fn`` after ``warmup`` calls."""
    for _ in range(warmup):
        fn()
    times = np.empty(count)
    for k in range(count):
        start = time.perf_counter()
        fn()
        times[k] = time.perf_counter() - start
    return times


def ms(times: np.ndarray) -> float:
    """Median of ``times`` (s) in ms."""
    return float(np.median(times) * 1e3)


def thread_cpu() -> float:
    """CPU time (s) of the calling thread."""
    usage = resource.getrusage(resource.RUSAGE_THREAD)
    return usage.ru_utime + usage.ru_stime


class Session:
    """A client (and optionally a planner) in a fresh rclpy context, spun by this thread.

    Parameters
    ----------
    namespace : str
        Namespace of the planner and the client.
    executor_type : callable
        ``SingleThreadedExecutor`` or ``EventsExecutor``.
    in_process : bool
        Also create the planner node on the same executor.
    """

    def __init__(
        self, namespace: str, executor_type: Callable[..., Executor], in_process: bool
    ) -> None:
        self.context = Context()
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.executor = executor_type(context=self.context)
        self.planner = (
            PlannerNode(context=self.context, namespace=namespace) if in_process else None
        )
        node = rclpy.create_node("bench_client", namespace=namespace, context=self.context)
        for member in (self.planner, node):
            if member is not None:
                self.executor.add_node(member)
        self.client = PlannerClient(node, self.executor, f"{namespace}/planner")

    def plan(self, object_id: str) -> PlanSqueeze.Response:
        """A stable squeeze of ``object_id`` at :data:`DEPTH` (cross-process: re-sent if lost)."""
        return self.client.call(
            PlanSqueeze,
            "plan_squeeze",
            PlanSqueeze.Request(object_id=object_id, squeeze_type=SqueezeKind.STABLE, depth=DEPTH),
            20.0,
            3,
        )

    def close(self) -> None:
        """Destroy nodes, executor and context."""
        if self.planner is not None:
            self.planner.destroy_node()
        self.client.node.destroy_node()
        self.executor.shutdown()
        self.context.try_shutdown()


def build_object(nodes: int) -> planning.LoadedObject:
    """The benchmark object of about ``nodes`` nodes, loaded under ``n<nodes>`` in this process."""
    source = planning.read_scene(scene_text(nodes), "")
    limits = planning.PlannerLimits()
    return planning.load_object(
        source, planning.object_key(source, f"n{nodes}", "", limits), limits
    )


def load_directly(session: Session, nodes: int) -> planning.LoadedObject:
    """Put the benchmark object into an in-process planner's cache without a service call
    (EventsExecutor in rclpy 7.1.6 rejects the coroutine callback of ``load_object``).
    """
    loaded = build_object(nodes)
    session.planner.cache.put(loaded)
    return loaded


def load_by_service(session: Session, nodes: int) -> None:
    """Load the benchmark object of about ``nodes`` nodes through ``load_object``."""
    response = session.client.call(
        LoadObject,
        "load_object",
        LoadObject.Request(scene_yaml=scene_text(nodes), object_id=f"n{nodes}"),
        120.0,
        3,
    )
    if not response.success:
        raise RuntimeError(f"the planner refused the benchmark scene: {response.message}")


def bare_times(loaded: planning.LoadedObject, count: int) -> tuple[np.ndarray, np.ndarray]:
    """(mechanics, callback work) per call, s: reduced stiffness + squeeze + boundary
    displacement; and the planner callback's validation + mechanics + message building.
    """
    obj, contacts = loaded.solid(), list(loaded.finger_nodes)

    def mechanics() -> None:
        red = reduced_stiffness(obj, contacts)
        sq = plan_squeeze(obj, contacts, kind=SqueezeKind.STABLE, red=red)
        boundary_displacement(obj, red, DEPTH * sq.displacement)

    def callback() -> None:
        messages.plan_squeeze_response(
            planning.squeeze_plan(loaded, [], SqueezeKind.STABLE, DEPTH)
        )

    return per_call(mechanics, count), per_call(callback, count)


class PlannerProcess:
    """The planner as its own process (``python -m squeeze_grasp_ros.ros.nodes.planner``).

    Parameters
    ----------
    namespace : str
    parameters : dict, optional
        Planner parameters given on the command line (``-p name:=value``).
    """

    def __init__(self, namespace: str, parameters: dict[str, Any] | None = None) -> None:
        command = [
            sys.executable,
            "-m",
            "squeeze_grasp_ros.ros.nodes.planner",
            "--ros-args",
            "-r",
            f"__ns:={namespace}",
            "--log-level",
            "warn",
        ]
        for name, value in (parameters or {}).items():
            command += ["-p", f"{name}:={value}"]
        self.process = subprocess.Popen(
            command,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            env=single_thread_blas(dict(os.environ)),
        )

    def stop(self) -> None:
        """SIGINT, then wait for a clean exit."""
        self.process.send_signal(signal.SIGINT)
        self.process.wait(timeout=30)


def overhead_rows(
    namespace: str, sizes: tuple[int, ...], count: int, progress: Progress
) -> tuple[list[list[Any]], list[list[Any]]]:
    """Rows of the overhead table and of the per-size table, measured in this run."""
    base = sizes[0]
    overhead: list[list[Any]] = []
    by_size: dict[int, list[Any]] = {}
    for label, executor_type in (
        ("SingleThreadedExecutor", SingleThreadedExecutor),
        ("EventsExecutor", EventsExecutor),
    ):
        progress(f"ros_services: one process, {label}")
        session = Session(namespace, executor_type, in_process=True)
        try:
            for n in sizes:
                loaded = load_directly(session, n)
                mech, work = bare_times(loaded, count)
                reply = per_call(lambda: session.plan(f"n{n}"), count)
                if n == base:
                    error = per_call(lambda: session.plan("unknown"), count)
                    overhead.append(
                        [
                            "one process",
                            label,
                            ms(error),
                            ms(reply),
                            ms(work),
                            ms(mech),
                            ms(reply) - ms(mech),
                            ms(reply) / ms(mech),
                        ]
                    )
                if label == "SingleThreadedExecutor":
                    by_size[n] = [loaded.num_nodes, len(loaded.boundary), ms(mech), ms(reply)]
        finally:
            session.close()
    progress("ros_services: planner in its own process")
    process = PlannerProcess(namespace)
    session = Session(namespace, SingleThreadedExecutor, in_process=False)
    try:
        for n in sizes:
            load_by_service(session, n)
            session.plan(f"n{n}")
            reply = per_call(lambda: session.plan(f"n{n}"), count)
            by_size[n] += [ms(reply), "yes" if ms(reply) < 10.0 else "no"]
            if n == base:
                mech, work = bare_times(build_object(n), count)
                error = per_call(lambda: session.plan("unknown"), count)
                overhead.append(
                    [
                        "two processes",
                        "SingleThreadedExecutor",
                        ms(error),
                        ms(reply),
                        ms(work),
                        ms(mech),
                        ms(reply) - ms(mech),
                        ms(reply) / ms(mech),
                    ]
                )
    finally:
        session.close()
        process.stop()
    return overhead, [by_size[n] for n in sizes]


def long_request_rows(namespace: str, big: int, progress: Progress) -> list[list[Any]]:
    """Per executor: a GraspMap goal loading a ``big``-node mesh with the executor otherwise
    idle (executor-thread CPU and spin_once returns), then another one while plan_squeeze
    requests are sent back to back (their round trips).
    """
    rows = []
    for label, executor_type in (
        ("SingleThreadedExecutor", SingleThreadedExecutor),
        ("EventsExecutor", EventsExecutor),
    ):
        progress(f"ros_services: long goal beside quick requests, {label}")
        session = Session(namespace, executor_type, in_process=True)
        action = ActionClient(
            session.client.node, GraspMap, f"{session.client.planner_name}/grasp_map"
        )
        try:
            if not action.wait_for_server(timeout_sec=30.0):
                raise TimeoutError("the GraspMap action server did not appear")
            load_directly(session, 500)
            idle = per_call(lambda: session.plan("n500"), 50)
            result = start_goal(session, action, big, "alone")
            spins, cpu0, wall0 = 0, thread_cpu(), time.perf_counter()
            while not result.done():
                session.executor.spin_once(timeout_sec=1.0)
                spins += 1
            alone, cpu = time.perf_counter() - wall0, thread_cpu() - cpu0
            result = start_goal(session, action, big, "beside")
            busy: list[float] = []
            while not result.done():
                start = time.perf_counter()
                session.plan("n500")
                busy.append(time.perf_counter() - start)
            p99 = float(np.percentile(busy, 99) * 1e3) if busy else float("nan")
            rows.append(
                [
                    label,
                    big,
                    alone,
                    cpu / alone,
                    spins / alone,
                    len(busy),
                    ms(np.array(busy)),
                    p99,
                    1e3 * max(busy, default=float("nan")),
                    ms(idle),
                    "yes" if p99 < 10 else "no",
                ]
            )
        finally:
            action.destroy()
            session.close()
    return rows


def start_goal(session: Session, action: ActionClient, nodes: int, object_id: str) -> Future:
    """Send a GraspMap goal that loads the ``nodes``-node object under ``object_id``; return
    the future of its result once the first feedback (the worker started) has arrived.
    """
    started: list[bool] = []
    sent = action.send_goal_async(
        GraspMap.Goal(scene_yaml=scene_text(nodes), mu=0.4, object_id=object_id),
        feedback_callback=lambda _: started.append(True),
    )
    session.client.spin_until(lambda: sent.done() and bool(started), 120.0)
    return sent.result().get_result_async()


BURST_QUEUES: tuple[tuple[str, int], ...] = (
    ("keep-last 10 (rclpy's default)", 10),
    ("keep-all (the planner's default)", 0),
)
"""Request queues the burst table compares: (label, planner parameter service_queue_depth)."""
KEEP_ALL = QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=1,
                      reliability=ReliabilityPolicy.RELIABLE)
"""The burst client's own queues (a keep-last-10 client would drop responses itself)."""


def answered(session: Session, futures: list[Future], quiet: float) -> tuple[int, float]:
    """Spin until every future is done or ``quiet`` s pass without a new one; (done, seconds
    until the last one was done).
    """
    start = last = time.perf_counter()
    done = 0
    while done < len(futures) and time.perf_counter() - last < quiet:
        session.executor.spin_once(timeout_sec=0.05)
        now = sum(f.done() for f in futures)
        if now > done:
            done, last = now, time.perf_counter()
    return done, last - start


def burst_rows(
    namespace: str, sizes: tuple[int, ...], progress: Progress, quiet: float = 10.0
) -> list[list[Any]]:
    """Per request queue and burst size: how many of ``size`` requests sent at once by one
    client are answered (``plan_squeeze`` on a cached object; ``load_object`` of distinct ids,
    OK or BUSY; ``grasp_map`` goals, responses and results), the planner in its own process.
    A request counts as lost when ``quiet`` s pass without any answer.
    """
    rows = []
    for label, depth in BURST_QUEUES:
        progress(f"ros_services: bursts, {label}")
        process = PlannerProcess(namespace, {"service_queue_depth": depth})
        session = Session(namespace, SingleThreadedExecutor, in_process=False)
        node, planner = session.client.node, session.client.planner_name
        plan = node.create_client(PlanSqueeze, f"{planner}/plan_squeeze", qos_profile=KEEP_ALL)
        load = node.create_client(LoadObject, f"{planner}/load_object", qos_profile=KEEP_ALL)
        action = ActionClient(node, GraspMap, f"{planner}/grasp_map",
                              goal_service_qos_profile=KEEP_ALL,
                              result_service_qos_profile=KEEP_ALL)
        try:
            load_by_service(session, 500)
            if not action.wait_for_server(timeout_sec=30.0):
                raise TimeoutError("the GraspMap action server did not appear")
            for size in sizes:
                request = PlanSqueeze.Request(object_id="n500", squeeze_type=SqueezeKind.STABLE,
                                              depth=DEPTH)
                plans, seconds = answered(
                    session, [plan.call_async(request) for _ in range(size)], quiet)
                loads = [load.call_async(LoadObject.Request(scene_yaml=scene_text(500),
                                                            object_id=f"burst{k}"))
                         for k in range(size)]
                loaded, _ = answered(session, loads, quiet)
                codes = [f.result().error_code for f in loads if f.done()]
                goals = [action.send_goal_async(GraspMap.Goal(object_id="n500", mu=0.4))
                         for _ in range(size)]
                responses, _ = answered(session, goals, quiet)
                results = [f.result().get_result_async() for f in goals
                           if f.done() and f.result().accepted]
                ended, _ = answered(session, results, quiet)
                busy = sum(f.result().result.error_code == planning.ErrorCode.BUSY
                           for f in results if f.done())
                rows.append([label, size, plans, seconds,
                             f"{loaded} ({codes.count(planning.ErrorCode.OK)} OK, "
                             f"{codes.count(planning.ErrorCode.BUSY)} BUSY)",
                             responses, f"{ended} ({busy} BUSY)",
                             "yes" if plans == loaded == responses == ended == size else "no"])
        finally:
            action.destroy()
            session.close()
            process.stop()
    return rows
