# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""BLAS threading of the processes this package starts.

The mechanics solve many tiny dense systems (m x m, m ~ 2-50); multithreaded BLAS only adds
overhead there and, on an oversubscribed machine (several node processes on 2 cores), its
spinning threads made them up to 1000x slower in our measurements. So the executables this
package installs (:mod:`squeeze_grasp_ros.entry`) and the node processes ``run --processes``
starts run with single-threaded BLAS unless the user set the variables. Importing the package
as a library changes nothing.

>>> env = single_thread_blas({"OMP_NUM_THREADS": "4"})
>>> env["OMP_NUM_THREADS"], env["OPENBLAS_NUM_THREADS"]
('4', '1')
"""
from __future__ import annotations

import os
from collections.abc import MutableMapping

__all__ = ["BLAS_THREAD_VARIABLES", "single_thread_blas"]

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
