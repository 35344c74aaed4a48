# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Session-wide test set-up: DDS isolation, the ``slow`` marker and an isolated rclpy context.

Every test session claims its own ``ROS_DOMAIN_ID`` (1-101, held by a file lock so concurrent
sessions on one machine never share one) and restricts discovery to localhost, before any test
module is imported, so no run sees another run or the network.
"""
from __future__ import annotations

import fcntl
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, TYPE_CHECKING

import pytest

from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel
from squeeze_grasp_ros.threads import single_thread_blas

single_thread_blas()  # as the installed executables do, before any test imports numpy

try:  # hypothesis is a test dependency, but conftest must load without it (colcon test)
    from hypothesis import settings
except ImportError:
    pass
else:
    # No per-example deadline: on a shared machine an example's wall time says nothing about
    # the code (a 0.6 ms example took 289 ms under load and failed as "Unreliable timings").
    settings.register_profile("squeeze_grasp_ros", deadline=None)
    settings.load_profile("squeeze_grasp_ros")

if TYPE_CHECKING:
    from rclpy.context import Context

DOMAIN_IDS = range(1, 102)
DOMAIN_LOCK = pytest.StashKey[IO[str]]()


def claim_domain_id() -> tuple[int, IO[str]]:
    """Lock a ROS domain id no other test session on this machine holds.

    Returns
    -------
    tuple of (int, file)
        The domain id and the open lock file; the id is held while the file stays open.
    """
    lock_dir = Path(tempfile.gettempdir()) / "squeeze_grasp_ros-domains"
    lock_dir.mkdir(exist_ok=True)
    start = os.getpid() % len(DOMAIN_IDS)
    for offset in range(len(DOMAIN_IDS)):
        domain_id = DOMAIN_IDS[(start + offset) % len(DOMAIN_IDS)]
        handle = (lock_dir / f"{domain_id}.lock").open("w")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            continue
        return domain_id, handle
    raise RuntimeError(f"every ROS domain id in {DOMAIN_IDS} is held by another test session")


def pytest_configure(config: pytest.Config) -> None:
    """Isolate DDS for this session and register the ``slow`` marker."""
    domain_id, config.stash[DOMAIN_LOCK] = claim_domain_id()
    os.environ["ROS_DOMAIN_ID"] = str(domain_id)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    config.addinivalue_line(
        "markers", "slow: long-running test, excluded by default (select with -m slow)"
    )


def pytest_unconfigure(config: pytest.Config) -> None:
    """Release this session's domain id."""
    if DOMAIN_LOCK in config.stash:
        config.stash[DOMAIN_LOCK].close()


@pytest.fixture(autouse=True)
def kernel_route_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    """Whatever a test does to the kernel route's variable is undone after it: ``sweep``
    called in-process sets it to numba (as its command does), which made the tests after it
    run on the compiled route (seen: test_events after test_sweep aborted in the kernel).
    """
    value = os.environ.get(KERNEL_VARIABLE)
    if value is None:  # setenv records "unset" for the undo; delenv of an unset name does not
        monkeypatch.setenv(KERNEL_VARIABLE, "")
        monkeypatch.delenv(KERNEL_VARIABLE)
    else:
        monkeypatch.setenv(KERNEL_VARIABLE, value)


@pytest.fixture(params=[k.value for k in Kernel])
def kernel(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> Kernel:
    """Each route of the linear model's fixed-set solve in turn (numpy, numba); the numba one
    skips, with the install line, without the ``fast`` extra.
    """
    if request.param == Kernel.NUMBA:
        pytest.importorskip("numba", reason="the fast extra is not installed: "
                                            "pip install '.[fast]'")
    monkeypatch.setenv(KERNEL_VARIABLE, request.param)
    return Kernel(request.param)


@pytest.fixture
def ros_context() -> Iterator[Context]:
    """Yield an initialised rclpy context of its own; shut it down after the test.

    No signal handlers are installed, so Ctrl-C still stops pytest.
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.signals import SignalHandlerOptions

    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    try:
        yield context
    finally:
        context.try_shutdown()


@pytest.fixture
def planner(ros_context: Context) -> Iterator:
    """A planner and a client on one executor spun by the test thread (a
    :class:`planner_support.Harness`); afterwards no worker thread is left.
    """
    from planner_support import Harness, planner_threads

    harness = Harness(ros_context)
    try:
        yield harness
    finally:
        harness.close()
    assert planner_threads() == []
