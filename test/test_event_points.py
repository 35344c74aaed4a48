# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event points on the numba route: the reads of one solution share one kernel call, and each
read is what a fresh read gives.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel
from squeeze_grasp_ros.mechanics.squeeze.stepper import processing
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
