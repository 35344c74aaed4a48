# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The compiled substeps between events (numba route, ``fast`` extra) against the Python loop:
numpy's summation order reproduced, whole event squeezes of shipped scenes identical field by
field with the kernel doing most substeps, and the cases that must stay in Python.
"""
from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np
import pytest

from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel
from squeeze_grasp_ros.mechanics.squeeze.stepper import compiled as compiled_module
from squeeze_grasp_ros.scene import GraspSetup, load_scene

numba = pytest.importorskip("numba", reason="the fast extra is not installed: "
                                            "pip install '.[fast]'")
substeps_numba = pytest.importorskip("squeeze_grasp_ros.mechanics.squeeze.substeps_numba")

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"


def test_sums_are_numpys_to_the_bit():
    rng = np.random.default_rng(33)
    for n in [0, 1, 2, 7, 8, 9, 15, 16, 17, 127, 128, 129, 255, 256, 1000, 2049]:
        for _ in range(5):
            a = rng.standard_normal(n) * 10.0 ** rng.integers(-8, 8, n)
            assert substeps_numba.np_sum(a) == a.sum(), n
    assert str(substeps_numba.np_sum(np.array([-0.0, -0.0]))) == str(np.array([-0.0]).sum())
    F = rng.standard_normal((9, 2))
    finger = rng.integers(0, 2, 9)
    for f in (0, 1, 2):
        assert substeps_numba._finger_sums(F, finger, f) == tuple(F[finger == f].sum(axis=0))


def test_the_quiet_area_bound_is_below_the_area_check():
    """A substep's quiet area bound (watched elements one by one, the rest at once) is at most
    the area check's value, through loads that bring elements near inversion, and gives way
    (-inf) when the rest's bound reaches the threshold.
    """
    from squeeze_grasp_ros.mechanics.squeeze.contact_model import GRADIENT_BOUND_EXACT
    from squeeze_grasp_ros.mechanics.squeeze.stepper.compiled import quiet_area_tables

    rng = np.random.default_rng(7)
    t, m = 300, 6
    gradients = rng.standard_normal((m, t, 4, 2)) * rng.random((1, t, 1, 1)) ** 4
    bounds = np.sqrt((gradients * gradients).sum(axis=(2, 3))).T.copy()
    loads = substeps_numba.load_list(list(gradients))  # as the model keeps them for the kernels
    rigid_gradients = rng.standard_normal((4 * t, 3)) * 1e-2
    E = np.asfortranarray(rng.standard_normal((2 * m, 3)))
    tables = quiet_area_tables(bounds, rigid_gradients)
    assert 0 < len(tables[0]) < t
    seen = set()
    for scale in np.geomspace(1e-3, 3.0, 40):
        F, delta = rng.standard_normal((m, 2)) * scale, rng.standard_normal((m, 2)) * 1e-3
        det, element = substeps_numba._area_ratio(delta, F, E, rigid_gradients, bounds, loads,
                                                  GRADIENT_BOUND_EXACT, True)
        lower = substeps_numba._area_lower(delta, F, E, *tables, loads, GRADIENT_BOUND_EXACT)
        assert lower <= det + 1e-12, (scale, lower, det)
        seen.add((element >= 0, lower > -np.inf))
    assert {(False, True), (True, True), (True, False)} <= seen, seen


def _same(a, b, path: str = "") -> None:
    """Assert two results equal field by field, floats bit for bit (NaN equal to NaN)."""
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            _same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for key in a:
            if not (path.endswith("diagnostics") and key == "compliance"):  # an estimate
                _same(a[key], b[key], f"{path}[{key}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    elif isinstance(a, np.ndarray):
        np.testing.assert_array_equal(a, b, err_msg=path)
    elif isinstance(a, float):
        assert a == b or (a != a and b != b), (path, a, b)
    else:
        assert a == b, (path, a, b)


@functools.lru_cache(maxsize=None)
def _setup(name: str) -> GraspSetup:
    return GraspSetup.build(load_scene(SCENES / f"{name}.yaml")).precompute()


@pytest.mark.parametrize("name", ["foam_square", "foam_square_low_friction", "disk_finger_slip",
                                  "foam_square_pickup", "sponge_gripper_slip"])
def test_event_squeezes_are_identical_with_the_compiled_substeps(name, monkeypatch):
    """Events, samples, forces, work and diagnostics of the numba route are the numpy route's
    to the bit, while the kernel runs most of the substeps (stick and slip, circles and pads,
    pickup, finger slip), whether the object keeps its sets' load gradients already or not.
    """
    accepted = []
    run = compiled_module.CompiledSubsteps.run

    def counting(self, *args):
        chunk = run(self, *args)
        accepted.append(chunk.count)
        return chunk

    monkeypatch.setattr(compiled_module.CompiledSubsteps, "run", counting)
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    # an object whose sets' load gradients are not kept yet (the model computes the det F of
    # an element near inversion until they are), then one that keeps them (the kernel does)
    first = GraspSetup.build(load_scene(SCENES / f"{name}.yaml")).precompute().event_squeeze()
    accepted.clear()
    results = {}
    for route in Kernel:
        monkeypatch.setenv(KERNEL_VARIABLE, route.value)
        results[route] = _setup(name).event_squeeze()
        if route == Kernel.NUMPY:
            assert not accepted  # the reference path never calls the kernel
    a, b = results[Kernel.NUMPY], results[Kernel.NUMBA]
    _same(a, b)
    _same(a, first)
    # the substeps the kernel stops before (a crossing, the first after an event) run in
    # Python: about one in three in these short squeezes of 33-94 substeps
    substeps = b.diagnostics["substeps"]
    assert sum(accepted) >= 0.4 * substeps > 0, (sum(accepted), substeps)


@pytest.mark.parametrize("name", ["foam_square", "foam_square_pickup", "sponge_gripper_slip",
                                  "foam_square_low_friction"])
def test_the_compiled_watched_values_and_slopes_are_the_numpy_codes(name, monkeypatch):
    """Wherever an event squeeze on the numba route reads its watched functions (a substep's
    ends, the pending events at a point), their slopes (pending events, location) or the
    terminations at a point, the compiled per-contact values, gaps, terminations and slopes
    are the floats the numpy code computes at the same solution (a zero's sign aside):
    circles and pads, stick and slip, pickup.
    """
    from squeeze_grasp_ros.mechanics.squeeze.stepper import processing
    from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions

    watched, slopes, compiled = EventFunctions.watched, EventFunctions.slopes, []
    end_values, pending_values = EventFunctions.end_values, processing.pending_values
    sloped_reads: list[int] = []

    def numpy_twin(self) -> EventFunctions:
        with monkeypatch.context() as m:
            m.setenv(KERNEL_VARIABLE, Kernel.NUMPY.value)
            twin = EventFunctions(self.model, self.motion, self.terminate_on)
            assert twin._compiled is None
        return twin

    def checking_values(self, contacts, sol, s, rows, held, *, terminations=True):
        got = watched(self, contacts, sol, s, rows, held, terminations=terminations)
        want = watched(numpy_twin(self), contacts, sol, s, rows, held,
                       terminations=terminations)
        assert got.order.keys == want.order.keys
        np.testing.assert_array_equal(got.values, want.values)
        assert got.ends == want.ends
        compiled.append(self._compiled is not None)
        return got

    def checking_slopes(self, contacts, sol, s, rows):
        got = slopes(self, contacts, sol, s, rows)
        want = slopes(numpy_twin(self), contacts, sol, s, rows)
        assert list(got) == list(want) and list(got.values()) == list(want.values())
        compiled.append(self._compiled is not None)
        return got

    def checking_pending(self, contacts, sol, s, rows, held, sloped, gap_nodes):
        got = pending_values(self, contacts, sol, s, rows, held, sloped, gap_nodes)
        with monkeypatch.context() as m:  # the twin's own reads are not checked
            m.setattr(EventFunctions, "watched", watched)
            m.setattr(EventFunctions, "slopes", slopes)
            want = pending_values(numpy_twin(self), contacts, sol, s, rows, held, sloped,
                                  gap_nodes)
        assert got[0].keys == want[0].keys and got[2] == want[2]
        np.testing.assert_array_equal(got[1], want[1])
        # a gap's slope is the free rows' product here, the fresh gaps' rows' in numpy
        np.testing.assert_allclose(got[3], want[3], rtol=1e-12, atol=1e-15)
        assert np.array_equal(np.less(got[3], 0), np.less(want[3], 0))
        sloped_reads.append(len(got[3]))
        compiled.append(self._compiled is not None)
        return got

    def checking_ends(self, contacts, sol):
        got = end_values(self, contacts, sol)
        assert got == end_values(numpy_twin(self), contacts, sol)
        compiled.append(self._compiled is not None)
        return got

    monkeypatch.setattr(EventFunctions, "watched", checking_values)
    monkeypatch.setattr(EventFunctions, "slopes", checking_slopes)
    monkeypatch.setattr(EventFunctions, "end_values", checking_ends)
    monkeypatch.setattr(processing, "pending_values", checking_pending)
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    _setup(name).event_squeeze()
    assert len(compiled) >= 10 and all(compiled), compiled
    assert any(sloped_reads), sloped_reads


def test_the_compiled_area_check_computes_elements_near_inversion_as_the_model(monkeypatch):
    """The compiled area ratio is the model's bound while no element nears inversion and the
    model's exact det F and element once one does (the same floats), computed in the kernel
    from the set's load gradients the object keeps (no call of the model's area check), up to
    loads that invert elements.
    """
    from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
    from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions

    seen = []
    watched = EventFunctions.watched

    def keeping(self, *args, **kwargs):
        seen.append((self, args))
        return watched(self, *args, **kwargs)

    monkeypatch.setattr(EventFunctions, "watched", keeping)
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    _setup("foam_square").event_squeeze()
    functions, (contacts, sol, s, rows, held) = seen[-1]
    monkeypatch.setattr(EventFunctions, "watched", watched)
    model = functions.model
    model.area_tables(contacts.data, loads=True)  # kept after the set's first near element
    area_ratio, calls = ContactModel.area_ratio, []
    monkeypatch.setattr(ContactModel, "area_ratio",
                        lambda self, *args: calls.append(1) or area_ratio(self, *args))
    near = []
    for scale in (1.0, 3.0, 10.0, 30.0, 100.0):
        scaled = dataclasses.replace(sol, F=sol.F * scale, delta=sol.delta * scale)
        got = functions.watched(contacts, scaled, s, rows, held)
        ends = functions.end_values(contacts, dataclasses.replace(scaled))  # a fresh read
        assert not calls, scale
        det, element = area_ratio(model, contacts.data, scaled.delta, scaled.F)
        want = functions.entries(contacts, functions.values(contacts, scaled, s, rows), rows,
                                 held)
        np.testing.assert_array_equal(got.values, want.values)
        assert got.ends == want.ends, scale
        assert ends[:2] == (det, element), (scale, ends, det, element)
        calls.clear()
        near.append(element >= 0)
    assert not near[0] and near[-1], near  # both branches taken


def test_low_friction_squeeze_keeps_its_physics_on_the_compiled_route(monkeypatch):
    """An independent check of what the kernel produced: sliding contacts on their cone edge,
    sticking ones inside it, and the fingers' work at least the stored energy (friction
    dissipates).
    """
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    res = _setup("foam_square_low_friction").event_squeeze()
    assert res.event_counts["C"] >= 1
    for seg in res.segments.values():
        for s in seg:
            assert s.slip_margin >= -1e-9 * abs(s.normal_force)
    assert sum(res.work.values()) > res.energy


def test_what_the_kernel_does_not_take_stays_in_python(monkeypatch):
    """Nonlinear materials and strain limits run the Python loop on the numba route (their
    results are those of the numpy route, which the golden tests check).
    """
    calls = []
    monkeypatch.setattr(compiled_module.CompiledSubsteps, "run",
                        lambda self, *args: calls.append(args))
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    _setup("foam_square_strain_limit").event_squeeze()
    _setup("foam_square").event_squeeze(material_model="neo_hookean", relative_depth=0.02)
    assert calls == []


@pytest.mark.parametrize("name", ["foam_square", "foam_square_low_friction"])
def test_a_checkpointed_squeeze_runs_the_kernel_and_checks_between_its_calls(name, monkeypatch):
    """A checkpoint (the planner's cancellation) no longer sends the numba route back to the
    Python loop: the kernel runs the quiet substeps, the checkpoint runs before each of its
    calls (at most CHUNK substeps each) as before every Python substep and solve, and the
    result is the squeeze's without a checkpoint to the bit.
    """
    log: list[str] = []
    run = compiled_module.CompiledSubsteps.run

    def logged(self, *args):
        log.append("kernel")
        return run(self, *args)
    monkeypatch.setattr(compiled_module.CompiledSubsteps, "run", logged)
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    plain = _setup(name).event_squeeze()
    log.clear()
    checked = _setup(name).event_squeeze(checkpoint=lambda: log.append("check"))
    _same(plain, checked)
    kernel = [k for k, entry in enumerate(log) if entry == "kernel"]
    assert kernel and all(log[k - 1] == "check" for k in kernel)


def _example_rows(route: Kernel, tasks: int | None, monkeypatch) -> list[dict]:
    """The example sweep's rows (its first ``tasks`` tasks) on ``route``, without time_s."""
    import yaml

    from squeeze_grasp_ros.sweep.evaluate import clear_cache, prepare, run_task
    from squeeze_grasp_ros.sweep.plan import plan_tasks
    from squeeze_grasp_ros.sweep.spec import parse_sweep_spec

    spec = SCENES.parent / "sweeps" / "example.yaml"
    every = list(plan_tasks(parse_sweep_spec(yaml.safe_load(spec.read_text()), spec.parent)))
    monkeypatch.setenv(KERNEL_VARIABLE, route.value)
    clear_cache()  # fresh groups: what objects keep from the other route is not reused
    rows = []
    for task in every[:tasks]:
        prepare(task)
        rows += [{k: v for k, v in row.items() if k != "time_s"} for row in run_task(task)["rows"]]
    return rows


@pytest.mark.parametrize("tasks", [1, pytest.param(None, marks=pytest.mark.slow)])
def test_the_example_sweep_rows_are_identical_on_both_routes(tasks, monkeypatch):
    """The example sweep's rows (one task of 48 by default, all 288 in the slow suite) are the
    same on both routes apart from their timing (NaN fields NaN on both).
    """
    a = _example_rows(Kernel.NUMPY, tasks, monkeypatch)
    b = _example_rows(Kernel.NUMBA, tasks, monkeypatch)
    assert len(a) == len(b) >= 48
    for x, y in zip(a, b):
        _same(x, y)
