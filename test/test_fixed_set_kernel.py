# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The linear fixed-set solve's two routes (numpy, and the numba kernel of the ``fast`` extra):
the same floats on random contact sets and on whole event squeezes, eq. 47 held by both, and
the route chosen by ``SQUEEZE_GRASP_KERNEL`` with clear errors.
"""
from __future__ import annotations

import os

import numpy as np
import pytest

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze import fixed_set_kernel
from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    Configuration,
    LinearResponse,
    SolveFailure,
    attempt_fixed_set,
)
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import (
    COMPILED_FROM_EVALUATIONS,
    KERNEL_VARIABLE,
    Kernel,
    prefer_compiled,
    selected,
)
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry, cross, unit

numba = pytest.importorskip("numba", reason="the fast extra is not installed: "
                                            "pip install '.[fast]'")
FIELDS = ("theta", "delta", "F", "dtheta", "dF", "ddelta", "iterations", "residual",
          "jacobian_condition", "nu", "kappa")


def random_set(rng: np.random.Generator, m: int):
    """A random stiff contact set of m nodes on circles and pads near equilibrium:
    (response, configuration, centres, directions, initial coordinates, friction angle).
    """
    A = rng.standard_normal((2 * m, 2 * m))
    C = A @ A.T + 2 * m * np.eye(2 * m)
    pads = rng.random(m) < 0.5
    radius = rng.uniform(0.05, 0.2, m)
    tip = TipGeometry(radius, np.where(pads, rng.uniform(0.0, 0.3, m), 0.0),
                      rng.uniform(-np.pi, np.pi, m))
    stick = rng.random(m) < 0.4
    slip = np.where(stick, 0, rng.choice([-1, 1], m))
    centers = rng.uniform(-1, 1, (m, 2))
    theta = tip.facing + rng.uniform(-1.0, 1.0, m)
    p0 = centers + tip.offset(theta) + 0.02 * rng.standard_normal((m, 2))
    theta0 = theta + np.where(stick, 0.0, 0.05 * rng.standard_normal(m))
    dirs = rng.standard_normal((m, 2))
    phi = float(np.arctan(rng.uniform(0.05, 1.0)))
    return LinearResponse(C), Configuration(p0, stick, slip, tip), centers, dirs, theta0, phi


def solve(route: Kernel, monkeypatch, *problem):
    monkeypatch.setenv(KERNEL_VARIABLE, route.value)
    return attempt_fixed_set(*problem)


def test_both_routes_give_the_same_floats_and_solve_eq_47(monkeypatch):
    rng = np.random.default_rng(2014)
    solved = 0
    for case in range(300):
        problem = random_set(rng, m=int(rng.integers(2, 9)))
        a = solve(Kernel.NUMPY, monkeypatch, *problem)
        b = solve(Kernel.NUMBA, monkeypatch, *problem)
        assert type(a) is type(b), case
        if isinstance(a, SolveFailure):
            assert a == b, case
            continue
        solved += 1
        for name in FIELDS:  # bit for bit: the same BLAS/LAPACK calls, the same order
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
        response, cfg, centers, dirs, theta0, phi = problem
        # an independent check of what was solved: F = C delta, sticking nodes kept their
        # coordinate, sliding forces on their cone's edge (eq. 47)
        np.testing.assert_allclose(b.delta, centers + cfg.tip.offset(b.theta) - cfg.p0,
                                   atol=1e-14)
        np.testing.assert_allclose(b.F.reshape(-1), response.C @ b.delta.reshape(-1),
                                   rtol=1e-13, atol=1e-13 * np.abs(response.C).max())
        np.testing.assert_array_equal(b.theta[cfg.stick], theta0[cfg.stick])
        P = ~cfg.stick
        edge = unit(cfg.tip.normal_angle(b.theta)[P] - cfg.slip[P] * phi)
        assert np.abs(cross(b.F[P], edge)).max(initial=0.0) <= 1e-12 * np.abs(b.F).max()
    assert solved >= 150  # most random sets are solvable: the comparison is not vacuous


def test_a_frictionless_block_under_one_node_each_side_is_singular_on_both_routes(
        monkeypatch):
    rng = np.random.default_rng(5)
    response, cfg, centers, dirs, theta0, _ = random_set(rng, m=2)
    cfg = Configuration(cfg.p0, np.zeros(2, bool), np.ones(2, int), cfg.tip)
    response = LinearResponse(np.zeros((4, 4)))  # no stiffness along the sliding angles
    a = solve(Kernel.NUMPY, monkeypatch, response, cfg, centers, dirs, theta0, 0.0)
    b = solve(Kernel.NUMBA, monkeypatch, response, cfg, centers, dirs, theta0, 0.0)
    assert isinstance(a, SolveFailure) and a == b


@pytest.mark.parametrize("mu", [0.05, 0.4])
def test_an_event_squeeze_is_the_same_on_both_routes(mu, monkeypatch):
    from test_pads import WIDE_PAD, block

    obj, ends = block(0.3)
    runs = {}
    for route in Kernel:
        monkeypatch.setenv(KERNEL_VARIABLE, route.value)
        runs[route] = event_squeeze(obj, ends, WIDE_PAD, mu, depth=0.002)
    a, b = runs[Kernel.NUMPY], runs[Kernel.NUMBA]
    assert a.events == b.events and a.termination == b.termination
    if mu == 0.05:  # nodes slip and may stick again: the sliding Newton is exercised
        assert a.event_counts["C"] >= 1
    np.testing.assert_array_equal(a.displacement, b.displacement)
    assert a.finger_force == b.finger_force


def test_the_route_is_chosen_by_the_environment(monkeypatch):
    monkeypatch.setenv(KERNEL_VARIABLE, "numpy")  # restored (unset or as it was) after the test
    monkeypatch.delenv(KERNEL_VARIABLE)
    assert selected() == Kernel.NUMPY  # a one-off process does not pay numba's start-up
    # what the sweep does (numba is installed here: the module skips else): a sweep too small
    # to repay a compilation keeps numpy, a larger one sends its workers by numba
    assert prefer_compiled(COMPILED_FROM_EVALUATIONS - 1) == Kernel.NUMPY
    assert KERNEL_VARIABLE not in os.environ
    assert prefer_compiled(COMPILED_FROM_EVALUATIONS) == Kernel.NUMBA
    assert os.environ[KERNEL_VARIABLE] == "numba" and selected() == Kernel.NUMBA
    monkeypatch.setenv(KERNEL_VARIABLE, "numpy")
    assert prefer_compiled(10 ** 9) == Kernel.NUMPY  # a route the user chose stays
    assert selected() == Kernel.NUMPY
    monkeypatch.setenv(KERNEL_VARIABLE, "numpy")
    assert selected() == Kernel.NUMPY
    monkeypatch.setenv(KERNEL_VARIABLE, "fortran")
    with pytest.raises(InvalidInputError, match=r"SQUEEZE_GRASP_KERNEL must be one of "
                                                r"\['numpy', 'numba'\], got 'fortran'"):
        selected()


def test_without_numba_the_numpy_route_runs_and_asking_for_numba_names_the_extra(monkeypatch):
    monkeypatch.setattr(fixed_set_kernel, "compiled", lambda: None)
    monkeypatch.setattr(fixed_set_kernel, "installed", lambda module: False)
    monkeypatch.setenv(KERNEL_VARIABLE, "numpy")
    monkeypatch.delenv(KERNEL_VARIABLE)
    assert prefer_compiled(10 ** 9) == Kernel.NUMPY
    assert KERNEL_VARIABLE not in os.environ and selected() == Kernel.NUMPY
    monkeypatch.setenv(KERNEL_VARIABLE, "numba")
    with pytest.raises(InvalidInputError, match=r"needs numba: pip install '\.\[fast\]'"):
        selected()
