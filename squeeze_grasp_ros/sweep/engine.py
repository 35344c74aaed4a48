# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Run a sweep on Dask distributed: a local cluster by default, any cluster by address.

The client plans the tasks, skips those whose Parquet part exists, submits the rest with
deterministic keys and writes each part as its task finishes (:class:`~.store.Store`). Workers
only compute (:func:`~.evaluate.run_task`) and need not share a file system with the client.
Local default: one worker process per core, one thread each (Dask's nannies start workers with
``OMP_NUM_THREADS=MKL_NUM_THREADS=OPENBLAS_NUM_THREADS=1``, so BLAS does not oversubscribe).
A worker that dies mid-task has its task rescheduled by Dask; a client that dies loses only the
tasks in flight. SIGINT and SIGTERM are flags from planning to the closing of the cluster
(:class:`StopSignals`), so an interrupt at any point ends the same way: the cluster closed, no
traceback, the signal in :attr:`Outcome.interrupted`.
"""
from __future__ import annotations

import contextlib
import importlib.util
import logging
import os
import signal
import sys
import threading
import time
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from squeeze_grasp_ros.extras import install_hint
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import prefer_compiled
from squeeze_grasp_ros.sweep.evaluate import prepare, run_task
from squeeze_grasp_ros.sweep.plan import Task, plan_tasks
from squeeze_grasp_ros.sweep.spec import LoadedSpec, SweepError

BAR_WIDTH = 24
POLL_S = 0.05
"""Seconds between checks for finished tasks and stop signals."""
DRY_RUN_SAMPLE = 4
"""Evaluations timed by ``--dry-run``."""
LOCAL_HOUSEKEEPING = {
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "2s",
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.admin.system-monitor.gil.enabled": False,
}
"""Dask settings of the local cluster, whose scheduler and nannies share the client's process
and whose workers have a core each, so that every CPU cycle Dask's housekeeping takes is taken
from the evaluations. Dask's defaults sample every worker's stacks each 10 ms (the profiler),
each process's memory each 100 ms (nanny and worker), its event loop each 20 ms and the system
each 500 ms; on 2 cores they made a 2-worker sweep about 5-10 % slower. Here the profiler is off
and the rest sample every few seconds: the memory limit is still enforced, within 2 s. A remote
cluster keeps its own configuration."""


def require_extra(verb: str = "sweep", modules: tuple[str, ...] = ("distributed", "pyarrow")
                  ) -> None:
    """Raise :class:`ModuleNotFoundError` naming ``verb``, the missing module and the install
    command if one of ``modules`` (for ``sweep``: Dask distributed and pyarrow; ``sweep-report``
    reads Parquet only) is missing (the CLI prints it and exits with status 4, as for every
    missing extra).
    """
    for module in modules:
        try:
            importlib.import_module(module)
        except ImportError as exc:
            raise ModuleNotFoundError(f"squeeze-grasp {verb} needs {module}, which is not "
                                      f"installed: {install_hint(module)} ({exc})",
                                      name=module) from None


class Progress:
    """One stderr line: evaluations done/total, rate, ETA and the dashboard address.

    Redrawn in place on a terminal; otherwise printed at most every ``interval`` seconds.
    """

    def __init__(self, total: int, dashboard: Optional[str], enabled: bool = True,
                 interval: float = 10.0, stream=None) -> None:
        self.total, self.done, self.dashboard = total, 0, dashboard
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.enabled, self.interval = enabled, interval
        self.start = time.perf_counter()
        self.last = -float("inf")
        self.width = 0
        """Characters of the line last drawn on a terminal (a shorter one is padded over it)."""

    def line(self) -> str:
        """The progress text."""
        elapsed = time.perf_counter() - self.start
        rate = self.done / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        eta = time.strftime("%H:%M:%S", time.gmtime(left)) if left == left else "--:--:--"
        pct = 100.0 * self.done / self.total if self.total else 100.0
        filled = int(BAR_WIDTH * pct / 100)
        text = (f"sweep [{'#' * filled}{'.' * (BAR_WIDTH - filled)}] {self.done}/{self.total} "
                f"evaluations ({pct:.0f} %), {rate:.2f} eval/s, ETA {eta}")
        return text + (f", dashboard {self.dashboard}" if self.dashboard else "")

    def update(self, count: int, final: bool = False) -> None:
        """Add ``count`` finished evaluations and redraw when due."""
        self.done += count
        if not self.enabled:
            return
        now = time.perf_counter()
        if self.tty:
            text = self.line()
            self.stream.write("\r" + text.ljust(self.width) + ("\n" if final else ""))
            self.width = 0 if final else len(text)
        elif final or now - self.last >= self.interval:
            self.stream.write(self.line() + "\n")
            self.last = now
        self.stream.flush()


@dataclass
class Outcome:
    """What a sweep run did: counts of tasks and evaluations; seconds in all, summed over the
    tasks for preparing groups and evaluating, and until the cluster was ready; the signal
    (SIGINT, SIGTERM) that stopped it, or None; one line per bad part found at the start, moved
    to ``damaged/`` and redone (:attr:`.store.Store.repaired`); the local workers' route
    (:func:`~.fixed_set_kernel.prefer_compiled`: ``numpy`` or ``numba``; None with a
    scheduler, whose workers read their own environment).
    """

    tasks: int
    skipped: int
    done: int
    failed: int
    evaluations: int
    errors: int
    seconds: float
    workers: int
    dashboard: Optional[str]
    interrupted: Optional[int]
    prepare_s: float
    evaluate_s: float
    startup_s: float = 0.0
    repaired: list = field(default_factory=list)
    kernel: Optional[str] = None


@contextlib.contextmanager
def _sigint_blocked():
    """SIGINT blocked in this thread while a local cluster starts.

    The threads started meanwhile inherit the mask, and so do the worker processes they spawn,
    from their first instruction on: Ctrl-C, which the terminal sends to the whole process
    group, never reaches a local worker (one still importing would print a traceback and fail
    the cluster's start). A SIGINT that arrives meanwhile waits and reaches the client's
    handler when the block ends. The multiprocessing resource tracker is started first
    because its first start unblocks SIGINT in the thread that starts it.
    """
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


CONNECT_TIMEOUT_S = 20.0
"""Seconds a ``--scheduler`` has to accept a TCP connection (Dask retries within them)."""
ANSWER_TIMEOUT_S = 10.0
"""Seconds more it has to answer Dask's handshake once connected."""


def probe_scheduler(address: str, connect_timeout: float = CONNECT_TIMEOUT_S,
                    answer_timeout: float = ANSWER_TIMEOUT_S) -> None:
    """Connect to ``address`` and complete Dask's handshake, or raise :class:`SweepError`
    with one line: "cannot connect" after ``connect_timeout`` seconds, "no Dask scheduler
    answered" after ``answer_timeout`` more.

    Dask bounds the TCP connect but not the handshake after it, so a port that accepts the
    connection and never answers in Dask's protocol (the dashboard's HTTP port, a web server)
    held ``Client()`` for ever; this probe bounds both.
    """
    import asyncio

    from distributed.comm import connect

    total = connect_timeout + answer_timeout

    async def handshake() -> None:
        comm = await asyncio.wait_for(connect(address, timeout=connect_timeout), total)
        await comm.close()

    try:
        asyncio.run(handshake())
    except asyncio.TimeoutError:
        raise SweepError(
            f"--scheduler {address}: no Dask scheduler answered within {total:g} s (the port "
            "accepted the connection but did not answer in Dask's protocol: is it the "
            "dashboard's HTTP port? A scheduler listens on tcp://HOST:8786 by default)") from None
    except (OSError, ValueError, TypeError) as exc:
        raise SweepError(f"--scheduler {address}: cannot connect ({exc})") from None


def _start(scheduler: Optional[str], workers: Optional[int], stop: "StopSignals"):
    """The client and the local cluster it drives (None with ``scheduler``).

    Connecting to a remote scheduler can take its whole timeout, and holds nothing that must be
    closed, so a stop signal interrupts it at once (:class:`Stopped`); a local cluster is let
    finish starting, with SIGINT kept from its workers, and is then closed by the caller.
    """
    import dask
    from distributed import Client, LocalCluster
    if scheduler is not None:
        try:
            with stop.at_once():
                probe_scheduler(scheduler)
                return Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S:g}s"), None
        except (OSError, TimeoutError) as exc:
            raise SweepError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
    n = workers or os.cpu_count() or 1
    # Dask's HTTP server runs with or without bokeh; given no address it takes port 8787 and,
    # when that is taken (another sweep, any Dask cluster), warns in four lines on stderr
    dashboard = "127.0.0.1:0"
    # Dask's own logs stay below CRITICAL: what goes wrong in a task is recorded (manifest,
    # summary, exit status) and a cluster closed right after its start has workers log
    # tracebacks of heartbeats cut short.
    with _sigint_blocked(), dask.config.set(LOCAL_HOUSEKEEPING):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=dashboard,
                               silence_logs=logging.CRITICAL)
        try:
            return Client(cluster), cluster
        except BaseException:
            cluster.close()
            raise


def _dashboard(client, local: bool) -> Optional[str]:
    """The dashboard address if the scheduler serves one that answers from here (Dask serves
    a stub page without bokeh, and its HTTP server also runs with ``--no-dashboard``).
    """
    if local and importlib.util.find_spec("bokeh") is None:
        return None
    link = client.dashboard_link
    try:
        with urllib.request.urlopen(link, timeout=2) as reply:
            page = reply.read(4096)
    except (OSError, ValueError):
        return None
    return link if b"needs bokeh" not in page else None


def _check_workers(client) -> int:
    """The number of the cluster's workers, once each has shown that it runs this client's
    version of the package.

    Raises
    ------
    SweepError
        If there is no worker, or a worker cannot import the package (its error, e.g. a
        ModuleNotFoundError, is named) or runs another version.
    """
    from squeeze_grasp_ros.sweep.store import package_version
    versions = client.run(package_version, on_error="return")
    mine = package_version()
    bad = {w: v for w, v in versions.items() if v != mine}
    if bad:
        worker, version = sorted(bad.items(), key=lambda item: item[0])[0]
        runs = (f"cannot run squeeze_grasp_ros ({version})" if isinstance(version, BaseException)
                else f"runs squeeze_grasp_ros {version}")
        raise SweepError(f"worker {worker} {runs}, this client {mine}: install the same version, "
                         "with its sweep extra, on every worker")
    if not versions:
        raise SweepError("the Dask cluster has no workers")
    return len(versions)


class Stopped(KeyboardInterrupt):
    """A stop signal inside :meth:`StopSignals.at_once`."""


class StopSignals:
    """Within ``with``: SIGINT and SIGTERM set :attr:`signal` instead of raising, so that a
    part and its manifest update are never cut in half and a cluster that is starting is
    closed, not abandoned (main thread only; elsewhere a no-op). Within :meth:`at_once` they
    raise :class:`Stopped` as well, for a step that holds nothing to close.
    """

    def __init__(self) -> None:
        self.signal: Optional[int] = None
        self._old: dict = {}
        self._raise = False

    def _handle(self, signum, _frame) -> None:
        # Attributes only: a handler may interrupt another handler, or code inside a lock,
        # and must not take one (a threading.Event here deadlocked under a burst of signals).
        self.signal = signum
        if self._raise:
            self._raise = False
            raise Stopped(signum)

    @staticmethod
    def wait(seconds: float) -> None:
        """Sleep ``seconds`` (keep it short: a signal is seen when the sleep ends)."""
        time.sleep(seconds)

    @contextlib.contextmanager
    def at_once(self):
        """Within: a stop signal (or one already received) raises :class:`Stopped`."""
        if self.signal is not None:
            raise Stopped(self.signal)
        self._raise = True
        try:
            yield
        finally:
            self._raise = False

    def __enter__(self) -> "StopSignals":
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM):
                self._old[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc) -> None:
        for signum, old in self._old.items():
            signal.signal(signum, old)


def _collect(future, task: Task, store, outcome: "Outcome", bar: Progress) -> None:
    """Write a finished task's part (or record its failure) and count it."""
    try:
        result = future.result()
    except Exception as exc:  # noqa: BLE001 - a task that raises is recorded
        store.fail(task, f"{type(exc).__name__}: {exc}")
        outcome.failed += 1
        bar.total -= task.evaluations
        bar.update(0)
        return
    rows = result["rows"]
    store.write(task, rows, result["outline"])
    outcome.done += 1
    outcome.evaluations += len(rows)
    outcome.errors += sum(1 for r in rows if r.get("error"))
    outcome.prepare_s += result["prepare_s"]
    outcome.evaluate_s += result["evaluate_s"]
    bar.total -= task.evaluations - len(rows)
    bar.update(len(rows))


def run_sweep(loaded: LoadedSpec, out: str | Path, *, scheduler: Optional[str] = None,
              workers: Optional[int] = None, progress: bool = True,
              on_task: Optional[Callable[[Task], None]] = None) -> Outcome:
    """Run (or resume) a sweep into ``out``; returns what was done.

    Parameters
    ----------
    loaded : LoadedSpec
    out : path
        Output directory (created; must be empty or hold this spec's sweep).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``); default: a local cluster.
    workers : int, optional
        Local cluster size (default: one worker per core).
    progress : bool
        Draw the progress line on stderr.
    on_task : callable, optional
        Called after each part is written (tests use it to kill the client at a known point).
    """
    start = time.perf_counter()
    with StopSignals() as stop:
        require_extra()
        from squeeze_grasp_ros.sweep.store import Store
        tasks = plan_tasks(loaded)
        store = Store(out, loaded, tasks)  # the folder is locked until store.close()
        client = cluster = None
        try:
            todo = [t for t in tasks if not store.done(t.id)]
            # the local workers inherit the route: compiled for sweeps that repay compiling
            kernel = (None if scheduler
                      else prefer_compiled(sum(t.evaluations for t in tasks)).value)
            outcome = Outcome(len(tasks), len(tasks) - len(todo), 0, 0, 0, 0, 0.0, 0, None,
                              None, 0.0, 0.0, repaired=list(store.repaired), kernel=kernel)
            if todo and stop.signal is None:
                try:
                    client, cluster = _start(scheduler, workers, stop)
                    if stop.signal is None:
                        outcome.workers = _check_workers(client)
                        outcome.dashboard = _dashboard(client, cluster is not None)
                        outcome.startup_s = time.perf_counter() - start
                except Stopped:
                    pass
                except Exception:
                    # SIGTERM to the process group also kills local workers that are still
                    # starting, and the cluster fails to start (it closes itself): report the
                    # stop, not that failure.
                    if stop.signal is None:
                        raise
            if client is not None and stop.signal is None:
                _run_tasks(loaded, todo, client, store, outcome, stop, progress, on_task)
        finally:
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()
            store.close()
    outcome.interrupted = stop.signal
    outcome.seconds = time.perf_counter() - start
    return outcome


def _run_tasks(loaded: LoadedSpec, todo: list[Task], client, store, outcome: Outcome,
               stop: StopSignals, progress: bool,
               on_task: Optional[Callable[[Task], None]]) -> None:
    """Submit the tasks, write each part as its task finishes, until done or a stop signal
    (then cancel the rest).
    """
    from distributed import as_completed
    bar = Progress(sum(t.evaluations for t in todo), outcome.dashboard, progress)
    bar.update(0)
    futures = {client.submit(run_task, t, key=f"sweep-{loaded.hash[:12]}-{t.id}",
                             pure=False): t for t in todo}
    pending = as_completed(futures)
    while not pending.is_empty() and stop.signal is None:
        batch = pending.next_batch(block=False)
        if not batch:
            stop.wait(POLL_S)
        for future in batch:
            task = futures.pop(future)
            _collect(future, task, store, outcome, bar)
            if on_task is not None:
                on_task(task)
    if stop.signal is not None:
        client.cancel(list(futures))
    bar.update(0, final=True)


def dry_run(loaded: LoadedSpec, *, workers: Optional[int] = None,
            scheduler: Optional[str] = None) -> dict:
    """Task and evaluation counts and an estimated time from a small timed sample.

    The sample runs in this process: the first task's group is prepared (mesh, factorisation,
    grasp map) and up to :data:`DRY_RUN_SAMPLE` of its evaluations are timed; the estimate is
    groups x prepare + evaluations x mean evaluation time / workers (each worker prepares a
    group at most once).
    """
    from squeeze_grasp_ros.sweep.evaluate import evaluate
    tasks = plan_tasks(loaded)
    groups = sorted({t.group for t in tasks})
    total = sum(t.evaluations for t in tasks)
    n = workers or (None if scheduler else os.cpu_count() or 1)
    first = tasks[0]
    group = prepare(first)
    times, resist = [], {}
    for index in range(first.start, min(first.stop, len(group.placements))):
        for params in first.params:
            if len(times) < DRY_RUN_SAMPLE:
                times.append(evaluate(first, group, index, params, resist)["time_s"])
    per_eval = sum(times) / max(len(times), 1)
    out = {"tasks": len(tasks), "groups": len(groups), "evaluations": total,
           "objects": len({t.obj.id for t in tasks}), "parameters": len(first.params),
           "sample": {"evaluations": len(times), "mean_evaluation_s": per_eval,
                      "prepare_s": group.prepare_s, "group": first.group}}
    if n:
        out["workers"] = n
        out["estimate_s"] = len(groups) * group.prepare_s + total * per_eval / n
    return out
