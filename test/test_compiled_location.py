# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The compiled event location (numba route, ``fast`` extra) against the Python location: its
Hermite helpers bit for bit on crafted cubics, every located event of shipped squeezes (as they
come, with the skips of dear evaluations, with every crossed function zero by construction at
the substep's start) the same bracket end, evaluations, solution and counters, and the cases
that stay in Python.
"""
from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np
import pytest

from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.event_key import EventFunction
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel
from squeeze_grasp_ros.mechanics.squeeze.stepper import compiled_location as located_module
from squeeze_grasp_ros.mechanics.squeeze.stepper import location, run
from squeeze_grasp_ros.scene import GraspSetup, load_scene

numba = pytest.importorskip("numba", reason="the fast extra is not installed: "
                                            "pip install '.[fast]'")
location_numba = pytest.importorskip("squeeze_grasp_ros.mechanics.squeeze.location_numba")

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
CompiledLocation = located_module.CompiledLocation


@functools.lru_cache(maxsize=None)
def _setup(name: str) -> GraspSetup:
    return GraspSetup.build(load_scene(SCENES / f"{name}.yaml")).precompute()


def _root(x):
    root = location_numba.hermite_root(*x)
    return None if np.isnan(root) else root


def test_the_hermite_helpers_are_pythons_to_the_bit():
    """Roots (None as NaN), curvatures and sure signs of crafted cubics: crossings, dips,
    double roots, leading coefficients below round-off, a zero value at a, magnitudes from 1e-9
    to 1e9.
    """
    rng = np.random.default_rng(33)
    crafted = [(0.0, 2.0, 1.0, -3.0, -2.0, -2.0), (0.0, 1.0, 1.0, 1.0, -3.0, 3.0),
               (0.0, 1.0, 1.0, 1.0 + 5e-324, 5e-324, 0.0), (0.0, 1.0, 1.0, 1.0, -6.0, 6.0),
               (0.0, 1.0, 0.0, -1.0, -1.0, -1.0), (0.0, 1.0, 1.0, -1.0, -2.0, -2.0),
               (0.5, 0.5 + 1e-9, 1e-10, -3e-10, -0.4, -0.4), (0.0, 1.0, 0.0, 0.0, 0.0, 0.0)]
    for _ in range(3000):
        a = rng.uniform(0, 1)
        h = 10.0 ** rng.uniform(-9, 0)
        ga, gb, ra, rb = rng.standard_normal(4) * 10.0 ** rng.integers(-9, 9, 4)
        crafted.append((a, a + h, abs(ga), -abs(gb) if rng.random() < 0.7 else abs(gb), ra, rb))
    roots = 0
    for x in crafted:
        want = location.hermite_root(*x)
        assert _root(x) == want, x
        roots += want is not None
        assert location_numba.hermite_curvature(*x) == location.hermite_curvature(*x), x
        g, r, h, curvature = x[2], x[4], x[1] - x[0], abs(x[5])
        assert (location_numba.surely_positive(g, r, h, curvature, location.SURE_MARGIN)
                == location.surely_positive(g, r, h, curvature)), x
    assert 0.3 * len(crafted) < roots < len(crafted)  # both outcomes, often


def _checking(monkeypatch, variants=(lambda call: None,)):
    """Patch ``_Call.locate`` to locate every event by the kernel and by Python (for each
    variant: a function of the call that changes what the location sees, or returns an undo)
    and assert the same event point, evaluations, solution and counters; the located events'
    count list.
    """
    locate = run._Call.locate
    counts = []

    def twice(self, crossed, sol_a, sol_b, a, b, start, end):
        kept, first = self.compiled_location, None
        assert kept is not None
        for variant in variants:
            undo = variant(self)
            before = dataclasses.replace(self.counters)
            got = locate(self, crossed, sol_a, sol_b, a, b, start, end)
            after = dataclasses.replace(self.counters)
            for field in dataclasses.fields(before):  # in place: the solver counts into it
                setattr(self.counters, field.name, getattr(before, field.name))
            self.compiled_location = None
            want = locate(self, crossed, sol_a, sol_b, a, b, start, end)
            self.compiled_location = kept
            assert got[0] == want[0]
            for field in ("theta", "delta", "F", "dtheta", "dF", "ddelta", "nu", "kappa"):
                np.testing.assert_array_equal(getattr(got[1], field), getattr(want[1], field))
            for field in ("iterations", "residual", "jacobian_condition"):
                assert getattr(got[1], field) == getattr(want[1], field), field
            assert after == self.counters
            if undo is not None:
                undo()
            first = got if first is None else first
        counts.append(len(crossed))
        return first

    monkeypatch.setattr(run._Call, "locate", twice)
    return counts


def _taken(monkeypatch) -> list[bool]:
    """Patch the kernel wrapper to record whether each location ran compiled."""
    took, locate = [], CompiledLocation.locate

    def recording(self, *args):
        out = locate(self, *args)
        took.append(out is not None)
        return out

    monkeypatch.setattr(CompiledLocation, "locate", recording)
    return took


@pytest.mark.parametrize("name", ["foam_square", "foam_square_low_friction", "disk_finger_slip",
                                  "sponge_gripper_slip", "foam_square_pickup"])
def test_every_located_event_is_the_python_locations(name, monkeypatch):
    """At every location of a squeeze on the numba route the kernel gives the Python
    location's event point, evaluations, solution there and Newton counters, bit for bit:
    as the squeeze has it, with dear evaluations (the skips of sure outcomes) switched the
    other way, and with every crossed function zero by construction at the start (each
    located from a + tol).
    """
    def dear(call):
        flipped = not call.model.dear_evaluations
        monkeypatch.setattr(type(call.model), "dear_evaluations", property(lambda _: flipped))
        return lambda: monkeypatch.setattr(type(call.model), "dear_evaluations",
                                           ContactModel.dear_evaluations)

    def fresh(call):
        kept = call.events.fresh
        call.events.fresh = kept | {key.at_node for key in run_crossed[-1]}

        def undo():
            call.events.fresh = kept
        return undo

    run_crossed = []
    crossings = run.crossings

    def keeping(*args):
        out = crossings(*args)
        run_crossed.append(out)
        return out

    monkeypatch.setattr(run, "crossings", keeping)
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    took = _taken(monkeypatch)
    counts = _checking(monkeypatch, (lambda call: None, dear, fresh))
    _setup(name).event_squeeze()
    assert counts and all(took), took
    if name == "foam_square_pickup":  # the pickup margin's crossings located by the kernel too
        assert any(key.function == EventFunction.PICKUP for keys in run_crossed
                   for key in keys)


@pytest.mark.parametrize("name, located", [("foam_square", 10), ("sponge_gripper_slip", 10),
                                            ("foam_square_pickup", 5)])
def test_squeezes_with_the_compiled_location_are_the_numpy_routes(name, located, monkeypatch):
    """Whole event squeezes on the numba route, located by the kernel, are the numpy route's
    field by field (the compiled substeps' test compares more scenes).
    """
    from test_compiled_substeps import _same

    results = {}
    for route in Kernel:
        monkeypatch.setenv(KERNEL_VARIABLE, route.value)
        took = _taken(monkeypatch)
        results[route] = _setup(name).event_squeeze()
        assert all(took) and len(took) >= located if route == Kernel.NUMBA else not took
    _same(results[Kernel.NUMPY], results[Kernel.NUMBA])


def test_what_the_kernel_does_not_take_stays_in_python(monkeypatch):
    """The numpy route and the nonlinear models have no compiled location; a crossed strain
    limit and a location needing more solved points than the kernel has room for run the
    Python location (the same squeeze).
    """
    from test_compiled_substeps import _same

    calls = []
    kernel = location_numba.earliest_crossing
    monkeypatch.setattr(location_numba, "earliest_crossing",
                        lambda *args: calls.append(args[5]) or kernel(*args))
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMPY.value)
    _setup("foam_square").event_squeeze()
    assert calls == []
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    _setup("foam_square").event_squeeze(material_model="neo_hookean", relative_depth=0.02)
    assert calls == []
    took = _taken(monkeypatch)
    _setup("foam_square_strain_limit").event_squeeze()
    assert False in took and len(calls) == sum(took)  # the strain limit's: no kernel call
    want = _setup("foam_square").event_squeeze()
    monkeypatch.setattr(located_module, "CAPACITY", 3)
    took.clear()
    _same(_setup("foam_square").event_squeeze(), want)
    assert took and not any(took)  # each location solves at least two points


def test_a_numba_without_its_lapack_binding_locates_in_python(monkeypatch):
    """The kernel calls dgeev through ``numba.np.linalg._LAPACK``, not a public API: a numba
    without it leaves every location to Python, with the same squeeze.
    """
    import sys

    from test_compiled_substeps import _same

    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    want = _setup("foam_square").event_squeeze()
    monkeypatch.delattr(numba.np.linalg, "_LAPACK")
    monkeypatch.delitem(sys.modules, location_numba.__name__)
    monkeypatch.delattr(sys.modules["squeeze_grasp_ros.mechanics.squeeze"], "location_numba")
    located_module._kernel.cache_clear()
    try:
        took = _taken(monkeypatch)
        _same(_setup("foam_square").event_squeeze(), want)
        assert located_module._kernel() is None and took == []
    finally:
        located_module._kernel.cache_clear()
