# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ROS 2 nodes: thin rclpy wiring around the mechanics, one console script each."""
from __future__ import annotations

import ctypes
import os
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path

import rclpy
from rclpy.duration import Duration
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.experimental import EventsExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future

from squeeze_grasp_ros.exit_codes import ExitCode, SignalFlag
from squeeze_grasp_ros.mechanics.errors import InvalidInputError

RCLError = rclpy_implementation.RCLError
"""What rcl raises, e.g. on ``--ros-args`` it cannot parse."""

PARENT_PID_ENV = "SQUEEZE_GRASP_PARENT_PID"
"""Environment variable naming the process that started a node (``squeeze-grasp run
--processes``): the node ends when that process dies."""
PARAMS_FILE_ENV = "SQUEEZE_GRASP_PARAMS_FILE"
"""Environment variable naming the parameter file the starting process wrote: a node that
outlives that process removes it."""
PR_SET_PDEATHSIG = 1
"""prctl(2) option: the signal this process gets when the thread that forked it ends."""
PARENT_DEATH_SIGNAL = signal.SIGUSR1
"""The signal a node started by a run asks for when that run dies."""


def parent_watch(stop: SignalFlag) -> Callable[[], bool]:
    """'Has the process that started this node died?', for a node started by a run.

    With :data:`PARENT_PID_ENV` set, asks Linux for :data:`PARENT_DEATH_SIGNAL` when the parent
    dies (``prctl(PR_SET_PDEATHSIG)``: the parent cannot catch SIGKILL, so only the children can
    notice); its handler sets ``stop``. A signal of its own, not SIGTERM: it comes as the
    forking thread ends, while the dying process's other threads may still be this process's
    parent, so the parent pid cannot tell it yet. The returned check also compares the parent
    pid (re-parented: the parent died, also where prctl does not exist). Without the variable,
    a check that is never true.
    """
    text = os.environ.get(PARENT_PID_ENV, "")
    if not text.isdigit():
        return lambda: False
    parent, died = int(text), SignalFlag()  # set in a handler: no lock (SignalFlag)

    def on_parent_death(*_: object) -> None:
        died.set()
        stop.set()

    if sys.platform.startswith("linux"):
        signal.signal(PARENT_DEATH_SIGNAL, on_parent_death)
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(PARENT_DEATH_SIGNAL),
                                                0, 0, 0)
    return lambda: died.is_set() or os.getppid() != parent


class ParameterError(InvalidInputError):
    """A node parameter is missing or invalid; the message names it."""


DRAIN_SPIN = 0.05
"""s each ``spin_once`` of a draining node waits for work (one value throughout:
``SingleThreadedExecutor`` discards its ready entities when the timeout changes)."""


SPIN_PERIOD = 0.1
"""Wall-clock s: the period of a :class:`Spinner`'s wall timer, about how long one of its spins
lasts (a node started by :func:`run_node` checks for its stop between spins)."""


class Spinner:
    """Spins ``executor`` (``node`` on it) in slices of about ``period`` wall-clock s; call it
    for one slice.

    On ``rclpy.experimental.EventsExecutor`` a slice is one ``spin_until_future_complete`` on a
    future that a ``period`` wall timer on ``node``, or any callback calling :meth:`wake`,
    completes: events are dispatched in C++ and
    a suspended coroutine (a goal's execute callback awaiting its end) is resumed after each
    event. The timeout alone does not end a spin while events keep coming, hence the timer; the
    timeout, two periods, is a guard (at one period it raced the timer, and a slice could end
    twice a period). Not ``spin_once`` in a loop: in rclpy 7.1.6 each ``spin_once`` first
    resumes every suspended coroutine, which counts as its one callback, so the loop returned
    about 90,000 times a second for as long as a goal ran (the executor node's process at
    100.8 % CPU while a hardware-mode goal waited, against 2.3 % now;
    ``test_a_waiting_hardware_goal_does_not_make_the_nodes_spin_poll``). On rclpy's
    ``Executor`` classes (they do not resume a suspended coroutine without an event, and their
    ``spin_until_future_complete`` keeps a done callback per call) a slice is ``spin_once``.
    """

    def __init__(self, executor: Executor, node: Node, period: float = SPIN_PERIOD) -> None:
        from squeeze_grasp_ros.ros.nodes.pipeline import wall_timer  # it imports this module
        self.executor, self.period = executor, period
        self.events = not isinstance(executor, Executor)
        self.slice_end = Future()
        """Completed to end the current slice."""
        if self.events:
            wall_timer(node, period, self.wake)

    def wake(self) -> None:
        """End the current slice (``EventsExecutor``; a callback that wants its spinner to
        look at its conditions now).
        """
        if not self.slice_end.done():
            self.slice_end.set_result(None)

    def __call__(self) -> None:
        if not self.events:
            self.executor.spin_once(self.period)
            return
        self.slice_end = Future()
        self.executor.spin_until_future_complete(self.slice_end, 2.0 * self.period)


def spin_until(executor: Executor, done: Callable[[], bool], timeout: float, *,
               then: int = 0) -> bool:
    """Spin ``executor`` until ``done()`` or for ``timeout`` s of wall time, then ``then`` more
    times (work the last callbacks scheduled: the result request of a goal that just ended);
    whether ``done()`` held. A node's ``drain`` uses it to answer what it holds before it ends.
    """
    deadline = time.monotonic() + timeout
    while not done() and time.monotonic() < deadline:
        executor.spin_once(DRAIN_SPIN)
    finished = done()
    for _ in range(then):
        executor.spin_once(DRAIN_SPIN)
    return finished


TWIN_CHECKS = (2.0, 10.0, 60.0)
"""s of wall time after a node is ready at which :func:`run_node` looks for other nodes of its
name (discovery across processes takes up to a few seconds)."""


def twins(node: Node) -> int:
    """How many other nodes on ``node``'s graph have its fully qualified name.

    ROS 2 lets two nodes share a name: both then serve its services and actions (a request or a
    goal reaches both, and two executors would both command the fingers) and publish its
    topics, and nothing refuses either.
    """
    name = node.get_fully_qualified_name()
    return sum(f"{space.rstrip('/')}/{other}" == name
               for other, space in node.get_node_names_and_namespaces()) - 1


ACK_TIMEOUT = 5.0
"""s of wall time a node waits at its end for its readers to acknowledge what it published
(longer than Fast DDS's default heartbeat period of 3 s, which paces the repair of a lost
message)."""


def wait_acknowledged(node: Node, timeout: float = ACK_TIMEOUT) -> list[str]:
    """Before a node ends: wait until every reliable reader has acknowledged every message
    of each of ``node``'s publishers, at most ``timeout`` s of wall time in all.

    A message lost on its way to another process is sent again only after its writer's next
    heartbeat, and a reliable reader delivers nothing of that writer after the gap until then:
    a reader stopped before that repair (the recorder at the end of a run) never receives the
    messages of the run's last seconds. Returns the topics not acknowledged in time (each
    logged as a warning).
    """
    deadline = time.monotonic() + timeout
    late = [p.topic_name for p in node.publishers
            if not p.wait_for_all_acked(Duration(seconds=max(deadline - time.monotonic(), 0.0)))]
    for topic in late:
        node.get_logger().warning(f"{topic}: not acknowledged by every reader within "
                                  f"{timeout:g} s")
    return late


def _warn_twins(node: Node) -> bool:
    """Log an error if other nodes have ``node``'s name (:func:`twins`); whether any had."""
    found = twins(node)
    if found:
        node.get_logger().error(
            f"{found} other node(s) named {node.get_fully_qualified_name()} are on this ROS "
            f"domain: each gets the requests, goals and topics meant for one (two executors "
            f"would both command the fingers); stop the other or rename this one (--ros-args "
            f"-r __node:=NAME)")
    return found > 0


def run_node(factory: Callable[[], Node], args: list[str] | None = None,
             executor_type: Callable[[], Executor] = EventsExecutor) -> int:
    """A node's ``main``: init rclpy, spin the node in the main thread until SIGINT, SIGTERM or
    shutdown, then clean up.

    The executor (default ``rclpy.experimental.EventsExecutor``; the planner, whose worker
    threads hand results back through futures, uses ``SingleThreadedExecutor``) is spun in
    slices of about :data:`SPIN_PERIOD` by a :class:`Spinner`: in rclpy 7.1.6
    ``EventsExecutor.spin()`` without a timeout holds the GIL at 100 % CPU once a node has a
    timer (measured: no callback runs, no other thread gets the GIL) and does not return after
    shutdown. SIGINT (Ctrl-C, also what ``ros2 launch`` sends first) and
    SIGTERM only set a flag, so no callback is interrupted halfway; the loop then ends, a node
    with ``drain(executor)`` processes what has already arrived, the node waits until its readers
    have acknowledged what it published (:func:`wait_acknowledged`; not a node whose
    ``acknowledged_at_end`` is False), its ``close()`` is called, and
    the node is destroyed (the planner joins its workers there). A node started by a run ends
    the same way when that process dies (:func:`parent_watch`), and removes the run's
    parameter file.

    Parameters
    ----------
    factory : callable
        Builds the node (after ``rclpy.init``).
    args : list of str, optional
        Command-line arguments for ``rclpy.init`` (``--ros-args ...``); None = ``sys.argv``.
    executor_type : callable
        Builds the executor.

    Returns
    -------
    int
        The exit code: 0, or 2 (:attr:`~.ExitCode.USAGE`) when rcl could not parse the
        ``--ros-args`` or the node refused its parameters (a missing scene, output folder,
        ...). That error is one line on stderr (rcl logs its own ``[ERROR]`` line first),
        ``<program>: error: <what>``, not a traceback. Once built, the node logs
        ``<name> ready: <its configuration>``, and an error if other nodes of its name are on
        the ROS domain (:func:`twins`, looked for at :data:`TWIN_CHECKS`).
    """
    stop = SignalFlag()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, stop.set)
    orphaned = parent_watch(stop)
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except RCLError as error:  # a --ros-args rule rcl cannot parse (e.g. unquoted YAML)
        print(f"{Path(sys.argv[0]).stem}: error: {error}", file=sys.stderr)
        return ExitCode.USAGE
    try:
        node = factory()
    except ValueError as error:  # InvalidInputError, or a recorder that cannot start its bag
        print(f"{Path(sys.argv[0]).stem}: error: {error}", file=sys.stderr)
        rclpy.try_shutdown()
        return ExitCode.USAGE
    summary = getattr(node, "ready_summary", lambda: "")()
    node.get_logger().info(f"{node.get_name()} ready" + (f": {summary}" if summary else ""))
    executor = executor_type()
    executor.add_node(node)
    spin = Spinner(executor, node)
    checks = [time.monotonic() + delay for delay in TWIN_CHECKS]
    try:
        while rclpy.ok() and not stop.is_set() and not orphaned():
            spin()
            if checks and time.monotonic() >= checks[0]:
                checks = [] if _warn_twins(node) else checks[1:]
        if orphaned():
            node.get_logger().error(f"the process that started this node "
                                    f"({os.environ[PARENT_PID_ENV]}) has died: shutting down")
            params = os.environ.get(PARAMS_FILE_ENV)
            if params:
                Path(params).unlink(missing_ok=True)
        if (stop.is_set() or orphaned()) and hasattr(node, "drain"):
            node.drain(executor)
        if getattr(node, "acknowledged_at_end", True):
            wait_acknowledged(node)
    except ExternalShutdownException:
        pass
    finally:
        if hasattr(node, "close"):
            node.close()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return ExitCode.OK
