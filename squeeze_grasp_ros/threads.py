# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""BLAS threading of the processes this package starts.

The mechanics solve many tiny dense systems (m x m, m ~ 2-50); multithreaded BLAS only adds
overhead there and, on an oversubscribed machine (several node processes on 2 cores), its
spinning threads made them up to 1000x slower in our measurements. So the executables this
package installs (:mod:`squeeze_grasp_ros.entry`) and the node processes ``run --processes``
starts run with single-threaded BLAS unless the user set the variables. Importing the package
as a library changes nothing; a library caller's large nonlinear solves run their blocks
under :func:`one_blas_thread` instead (threadpoolctl), which holds BLAS at one thread for the
block and restores the caller's setting after it.

>>> env = single_thread_blas({"OMP_NUM_THREADS": "4"})
>>> env["OMP_NUM_THREADS"], env["OPENBLAS_NUM_THREADS"]
('4', '1')
"""
from __future__ import annotations

import os
import threading
from collections.abc import Iterator, MutableMapping
from contextlib import contextmanager

__all__ = ["BLAS_THREAD_VARIABLES", "one_blas_thread", "single_thread_blas"]

BLAS_THREAD_VARIABLES: tuple[str, ...] = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                          "MKL_NUM_THREADS")


def single_thread_blas(env: MutableMapping[str, str] | None = None) -> MutableMapping[str, str]:
    """Set every BLAS thread variable the user has not set to 1 in ``env`` (default: this
    process's environment, which must happen before numpy is imported) and return it.
    """
    env = os.environ if env is None else env
    for name in BLAS_THREAD_VARIABLES:
        env.setdefault(name, "1")
    return env


_CONTROLLER: list = []
"""The process's threadpoolctl.ThreadpoolController, made at the first :func:`one_blas_thread`
(finding the loaded BLAS libraries costs about 0.2 ms; limiting them with it about 15 us)."""
_HELD = {"depth": 0, "limiter": None}
"""How many :func:`one_blas_thread` blocks are open in this process, and the limiter of the
outermost (the thread counts are process-wide, so is the count)."""
_LOCK = threading.Lock()


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """A context in which every BLAS library loaded in this process runs one thread, whatever
    the environment; the previous thread counts come back when the outermost such block ends
    (a nested block costs a counter, not a limit).

    The nonlinear contact model's evaluations and the interior factorisations and solves run
    in it: numpy's multithreaded OpenBLAS, woken by the small products between the sparse
    factorisations, spins on the second core and made a neo-Hookean squeeze use 2.0x the CPU
    time on 2 cores, and up to 2.1x the wall time when another process held the other core
    (CHOLMOD's own OpenBLAS, loaded by cvxopt, runs one thread already). The libraries are
    those loaded at the first call. Without threadpoolctl (a pip dependency; a colcon build
    may lack it) the context changes nothing: the installed executables set the thread
    variables themselves.

    >>> import numpy
    >>> with one_blas_thread():
    ...     import threadpoolctl
    ...     {info["num_threads"] for info in threadpoolctl.threadpool_info()
    ...      if info["user_api"] == "blas"}
    {1}
    """
    if not _CONTROLLER:
        try:
            from threadpoolctl import ThreadpoolController  # imported where solves need it
        except ImportError:  # a colcon build without it: its executables set the variables
            _CONTROLLER.append(None)
        else:
            _CONTROLLER.append(ThreadpoolController().select(user_api="blas"))
    controller = _CONTROLLER[0]
    if controller is not None:
        with _LOCK:
            _HELD["depth"] += 1
            if _HELD["depth"] == 1:
                _HELD["limiter"] = controller.limit(limits=1)
    try:
        yield
    finally:
        if controller is not None:
            with _LOCK:
                _HELD["depth"] -= 1
                if _HELD["depth"] == 0:
                    _HELD["limiter"].restore_original_limits()
                    _HELD["limiter"] = None
