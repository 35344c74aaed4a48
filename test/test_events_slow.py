# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Slow cross-checks of the event-driven squeeze (run with ``-m slow``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from squeeze_grasp_ros.bench.events import event_error, foam_square
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.oneshot import one_shot_solve
from squeeze_grasp_ros.scene import GraspSetup, load_scene

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
pytestmark = pytest.mark.slow


def test_literal_fixed_step_route_converges_to_the_located_events():
    obj, contacts = foam_square(2000)
    obj.precompute()
    truth = event_squeeze(obj, contacts, 0.02, 0.05, relative_depth=0.12, event_tol=1e-12)
    errors = []
    for h in (1e-4, 1e-5):
        ref = event_squeeze(obj, contacts, 0.02, 0.05, relative_depth=0.12, step=h, reference=True)
        same, err = event_error(ref, truth, obj.scale)
        assert same and err <= 3 * h  # a late event also shifts the slip history after it
        errors.append(err)
    assert errors[1] < 0.25 * errors[0]


@pytest.mark.parametrize(
    "name",
    [
        "foam_square",
        "foam_square_low_friction",
        "disk_finger_slip",
        "foam_square_strain_limit",
        "foam_square_pickup",
    ],
)
def test_one_shot_invariant_on_every_event_scene(name):
    setup = GraspSetup.build(load_scene(SCENES / f"{name}.yaml")).precompute()
    res = setup.event_squeeze()
    shot = one_shot_solve(setup.solid, res.state, res.mu)
    F = np.array([c.force for c in res.state.contacts])
    assert np.abs(shot.forces - F).max() < 1e-8 * np.abs(F).max()
    assert (
        np.abs(shot.displacement - res.displacement).max() < 1e-8 * np.abs(res.displacement).max()
    )


def test_large_mesh_squeeze_stays_consistent():
    obj, contacts = foam_square(10000)
    obj.precompute()
    res = event_squeeze(obj, contacts, 0.02, 0.05, relative_depth=0.12)
    assert res.termination == "depth_reached"
    assert res.event_counts["A"] >= 20
    shot = one_shot_solve(obj, res.state, 0.05)
    F = np.array([c.force for c in res.state.contacts])
    assert np.abs(shot.forces - F).max() < 1e-8 * np.abs(F).max()
