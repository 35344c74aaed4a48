# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The linear model's fixed-set solve as one compiled kernel (numba), with the numpy route as
its fallback.

:func:`~.contact_model.attempt_fixed_set` solves the sliding constraints (eq. 47) by Newton on
a handful of contact coordinates. With the linear model's constant stiffness, F = C delta, the
whole loop is small dense arithmetic on m <= a few tens of contacts: in numpy it is some forty
Python-level calls per Newton iteration on 2-vectors, most of an evaluation's fixed-set time.
:func:`.fixed_set_numba.solve_linear` runs the same iteration, the same backtracking, stopping
tests and rates, in one call compiled by numba (``pip install '.[fast]'``). Its products and
solves call the BLAS and LAPACK routines numpy calls (gemv, gemm, gesv), its sines and cosines
are the same, and its elementwise arithmetic is written in numpy's order, so the two routes give
the same floats: the example sweep's 288 rows and the golden runs are identical bit for bit
(docs/design.md, "The evaluation kernel").

The route is chosen at each solve (once per stepper call for the stepper's solves):
:data:`KERNEL_VARIABLE` = ``numpy`` or ``numba``
(:class:`Kernel`); unset means numpy, because a process pays numba's import and the load of its
cached code (about 1 s of CPU; about 85 s to compile the kernels on first use after an install
or an upgrade) for a few milliseconds saved per evaluation. ``squeeze-grasp sweep`` and the
large bench sweep set it to numba for their local workers when numba is installed and the sweep
is large enough to pay for a compilation (:func:`prefer_compiled`). Asking for numba without it
installed raises an error that names the extra.
"""
from __future__ import annotations

import os
from enum import Enum
from functools import cache
from importlib import import_module

from squeeze_grasp_ros.extras import EXTRAS, installed
from squeeze_grasp_ros.mechanics.errors import InvalidInputError

KERNEL_VARIABLE = "SQUEEZE_GRASP_KERNEL"
"""Environment variable that selects the fixed-set route (:class:`Kernel` values)."""


class Kernel(str, Enum):
    """Route of the linear model's fixed-set solve."""

    NUMPY = "numpy"
    """The numpy route (:func:`~.contact_model.attempt_fixed_set`'s own loop)."""
    NUMBA = "numba"
    """:func:`.fixed_set_numba.solve_linear`, compiled by numba (the ``fast`` extra)."""


def selected() -> Kernel:
    """The route :data:`KERNEL_VARIABLE` asks for (default: numpy).

    >>> import os; os.environ[KERNEL_VARIABLE] = "numpy"; selected()
    <Kernel.NUMPY: 'numpy'>
    >>> del os.environ[KERNEL_VARIABLE]
    """
    text = os.environ.get(KERNEL_VARIABLE, "")
    kernel = _SELECTED.get(text)
    if kernel is None:
        try:
            kernel = _SELECTED[text] = Kernel(text)
        except ValueError:
            raise InvalidInputError(
                f"{KERNEL_VARIABLE} must be one of {[k.value for k in Kernel]}, got {text!r}"
            ) from None
    if kernel == Kernel.NUMBA and compiled() is None:
        raise InvalidInputError(f"{KERNEL_VARIABLE}=numba needs numba: {EXTRAS['fast'][1]}")
    return kernel


_SELECTED: dict[str, Kernel] = {"": Kernel.NUMPY}
"""The routes :func:`selected` has parsed, by the variable's text (it is read at every
fixed-set solve; whether numba is there is checked at every read)."""


@cache
def _kernel_module(name: str):
    """The compiled module ``name`` of this package's squeeze, or None without numba."""
    try:
        return import_module(f"squeeze_grasp_ros.mechanics.squeeze.{name}")
    except ImportError:
        return None


def compiled():
    """The compiled module :mod:`.fixed_set_numba`, or None without numba."""
    return _kernel_module("fixed_set_numba")


def compiled_substeps():
    """The compiled module :mod:`.substeps_numba` (the substeps between events), or None
    without numba.
    """
    return _kernel_module("substeps_numba")


def compiled_health():
    """The compiled module :mod:`.health_numba` (the linear model's grasp-health field pass),
    or None without numba.
    """
    return _kernel_module("health_numba")


def chosen() -> Kernel | None:
    """The route :data:`KERNEL_VARIABLE` names, None when it is unset (:func:`selected` reads
    that as numpy; the neo-Hookean assembly decides by the mesh:
    :func:`~.nonlinear_model.compiled_assembly`).
    """
    return selected() if os.environ.get(KERNEL_VARIABLE, "") else None


COMPILE_CPU_S = 85
"""Seconds of CPU a process spends compiling the kernels on first use after an install or an
upgrade (measured on a 2-core machine, 2026-11-28: 84.9 s in a 500-node squeeze)."""
COMPILED_FROM_EVALUATIONS = 25_000
"""The sweeps whose local workers :func:`prefer_compiled` sends by the compiled route: at least
this many evaluations. Measured on a 2-core machine (2026-11-28): compiling the kernels after an
install takes about :data:`COMPILE_CPU_S` of CPU in each worker; compiled, an evaluation of the
example sweep's kind saves about 6 ms of CPU (2,496 evaluations on 2 workers: 10.2 against
18.2 s), and a worker's numba start-up costs about 1 s (288 evaluations: 3.7 s on either
route). About 25,000 evaluations on two workers repay a compilation; the rule reads the spec
alone, so every run and resume of a sweep takes the same route."""


def sweep_route(evaluations: int) -> Kernel:
    """The route of the local workers of a sweep of ``evaluations`` evaluations: the one
    :data:`KERNEL_VARIABLE` names when it is set; else numba when it is installed and the
    sweep has at least :data:`COMPILED_FROM_EVALUATIONS` evaluations; else numpy.
    """
    kernel = chosen()
    if kernel is not None:
        return kernel
    if installed("numba") and evaluations >= COMPILED_FROM_EVALUATIONS:
        return Kernel.NUMBA
    return Kernel.NUMPY


def prefer_compiled(evaluations: int) -> Kernel:
    """Set :data:`KERNEL_VARIABLE` to numba in this process's environment, which the processes
    it starts (a local Dask cluster's workers) inherit, when :func:`sweep_route` chooses numba
    for ``evaluations`` evaluations; the route chosen.
    """
    kernel = sweep_route(evaluations)
    if kernel == Kernel.NUMBA:
        os.environ.setdefault(KERNEL_VARIABLE, kernel.value)
    return kernel
