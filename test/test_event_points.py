# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event points on the numba route: the reads of one solution share one kernel call, and each
read is what a fresh read gives.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel
from squeeze_grasp_ros.mechanics.squeeze.stepper import compiled_functions, processing
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions
from squeeze_grasp_ros.scene import GraspSetup, load_scene

pytest.importorskip("numba", reason="the fast extra is not installed: pip install '.[fast]'")
substeps_numba = pytest.importorskip("squeeze_grasp_ros.mechanics.squeeze.substeps_numba")

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"


@pytest.mark.parametrize("name", ["foam_square", "foam_square_pickup"])
def test_the_terminations_at_an_event_point_reuse_the_pending_checks_kernel_call(name,
                                                                                 monkeypatch):
    """The termination check after the last pending check at a point (values and slopes in
    one kernel call, or the values alone) reads the same contact set and solution: it makes
    no kernel call, and its (area, element, strain, pickup) are
    those of a fresh read.
    """
    calls = []

    def counted(kernel):
        def call(*args):
            calls.append(1)
            return kernel(*args)
        return call

    end_values, last, shared = EventFunctions.end_values, {}, []

    def recording(read):
        def record(self, contacts, sol, *args, **kwargs):
            last[id(self)] = (contacts, sol)
            return read(self, contacts, sol, *args, **kwargs)
        return record

    def checked(self, contacts, sol):
        before = len(calls)
        got = end_values(self, contacts, sol)
        seen = last.get(id(self), (None, None))
        if seen[0] is contacts and seen[1] is sol:
            shared.append(len(calls) == before)
        assert got == end_values(EventFunctions(self.model, self.motion, self.terminate_on),
                                 contacts, sol)
        return got

    for kernel in ("watched_values", "point_values"):
        monkeypatch.setattr(substeps_numba, kernel, counted(getattr(substeps_numba, kernel)))
    monkeypatch.setattr(EventFunctions, "watched", recording(EventFunctions.watched))
    monkeypatch.setattr(processing, "pending_values", recording(processing.pending_values))
    monkeypatch.setattr(EventFunctions, "end_values", checked)
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    GraspSetup.build(load_scene(SCENES / f"{name}.yaml")).precompute().event_squeeze()
    assert len(shared) >= 3 and all(shared), shared


def _outcome(result) -> tuple:
    """What a squeeze reports, in full: every event, the displacement, the finger forces and
    the grasp health.
    """
    return ([e.to_json() for e in result.events], result.displacement.tobytes(),
            repr(result.finger_force), repr(result.health.to_json()))


@pytest.mark.parametrize("name", ["foam_square", "foam_square_pickup"])
def test_a_large_meshs_pending_reads_leave_the_area_check_to_the_terminations(name,
                                                                           monkeypatch):
    """From AREA_DEFERRED_FROM elements times contacts (here lowered to every mesh) a read for
    the pending events alone makes no area check: the terminations after it make one kernel
    call for it, whose (area, element, strain, pickup) are a fresh read's, and the squeeze
    is bit for bit the one whose every read computes the area.
    """
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    setup = GraspSetup.build(load_scene(SCENES / f"{name}.yaml")).precompute()
    every_read = _outcome(setup.event_squeeze())

    calls, ends, end_values = [], [], EventFunctions.end_values

    def counted(*args):
        calls.append(args[21].shape[0])  # the area bounds' rows: none when not checked
        return watched_values(*args)

    def checked(self, contacts, sol):
        before = len(calls)
        got = end_values(self, contacts, sol)
        ends.append(calls[before:])
        assert got == end_values(EventFunctions(self.model, self.motion, self.terminate_on),
                                 contacts, sol)
        return got

    watched_values = substeps_numba.watched_values
    monkeypatch.setattr(compiled_functions, "AREA_DEFERRED_FROM", 0)
    monkeypatch.setattr(substeps_numba, "watched_values", counted)
    monkeypatch.setattr(EventFunctions, "end_values", checked)
    assert _outcome(setup.event_squeeze()) == every_read
    # each termination check made one area call or none (the next substep's read had it)
    assert len(ends) >= 3 and all(len(made) <= 1 and all(made) for made in ends), ends
    assert sum(map(len, ends)) >= 3
