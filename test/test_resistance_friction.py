# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Algorithm 2 (frictional segment contacts) as a loop over the incremental stepper.

While every contact sticks and no event occurs the contact set is fixed, so the stepper's
integrated work and final forces must equal the fixed-segment linear model with the squeeze's
forces as preload: W_F = d1 . F1_0 + d2 . F2_0 + 1/2 (d1, d2, 0) . G (d1, d2, a).
"""

import dataclasses
import json

import numpy as np
import pytest

from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.resistance.frictional import (
    _outcome,
    add_adversary,
    frictional_resistance,
    slipping_fingers,
)
from squeeze_grasp_ros.mechanics.resistance.optimal import evaluate_resistance, resistance_grasp
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import Finger, Termination


@pytest.fixture(scope="module")
def squeezed_disk():
    """A disk squeezed 3 % between F1 (left) and F2 (right); A below it, all tips 0.02 m."""
    outline = shapes.disk(0.05)
    obj = ElasticObject(generate_mesh(outline, outline.area / 800), Material(5e4, 0.3, 0.0254))
    obj.precompute()
    b = obj.mesh.boundary
    p = obj.mesh.nodes[b]
    i, j, k = b[np.argmin(p[:, 0])], b[np.argmax(p[:, 0])], b[np.argmin(p[:, 1])]
    squeeze = event_squeeze(obj, (i, j), 0.02, 0.4, kind="stable", relative_depth=0.03)
    model = ContactModel(obj, 0.4)
    return model, add_adversary(squeeze.state, model, squeeze.displacement, k, 0.02), (i, j, k)


def cross2(u, v):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


@pytest.mark.parametrize("mode", ["stable", "pure"])
def test_small_push_matches_the_preloaded_fixed_segment_model(squeezed_disk, mode):
    model, state, contacts = squeezed_disk
    a = np.array([0.0, 0.001])
    res = frictional_resistance(model, state, a, mode=mode, contacts=contacts)
    assert res.success and res.reason == "adversary completed a"
    assert res.travelled == pytest.approx(1e-3, rel=1e-12)
    assert res.event_counts == dict.fromkeys("ABCD", 0) and len(res.stages) == 1
    assert all(c.mode == "stick" for c in res.state.contacts)
    segments = res.stages[0].segments
    grasp = resistance_grasp(model.obj, segments)
    linear = evaluate_resistance(grasp, res.d1, res.d2, a, mode)
    assert linear.success, linear.reason  # the constraints of the mode hold
    f0 = {f: state.finger_force(f) for f in tuple(Finger)}
    expected = res.d1 @ f0["F1"] + res.d2 @ f0["F2"] + linear.work["total"]
    assert res.work["total"] == pytest.approx(expected, rel=1e-6)
    for f in tuple(Finger):
        assert np.allclose(res.forces[f][1], f0[f] + linear.forces[f], atol=1e-9)
    assert np.allclose(res.trajectories["A"][-1], a, atol=1e-15)
    assert np.allclose(res.trajectories["F1"][-1], res.d1, atol=1e-15)


def test_end_state_is_in_equilibrium_and_stable_sum_holds(squeezed_disk):
    model, state, contacts = squeezed_disk
    a = np.array([0.0, 0.001])
    res = frictional_resistance(model, state, a, mode="stable", contacts=contacts)
    nodes = np.array([c.node for c in res.state.contacts])
    f = np.array([c.force for c in res.state.contacts])
    p = model.obj.mesh.nodes[nodes]
    scale = np.abs(f).sum()
    assert np.allclose(f.sum(axis=0), 0, atol=1e-10 * scale)
    assert abs(cross2(p, f).sum()) < 1e-10 * scale * model.obj.scale
    counts = [len(res.stages[0].segments[g]) for g in tuple(Finger)]
    total = counts[0] * res.d1 + counts[1] * res.d2 + counts[2] * a  # eq. (54), segments
    assert np.allclose(total, 0, atol=1e-15)


def test_large_push_makes_a_grasping_finger_slip(squeezed_disk):
    model, state, contacts = squeezed_disk
    res = frictional_resistance(model, state, (0.0, 0.004), mode="stable", contacts=contacts)
    assert not res.success and res.reason in ("F1 slips", "F2 slips")
    assert res.reason.split()[0] in slipping_fingers(res.state)
    assert 0 < res.travelled < 0.004 and res.event_counts["C"] >= 1
    out = res.to_json()
    json.dumps(out, allow_nan=False)
    assert out["contacts"] == list(contacts)
    assert [e["travel"] for e in out["events"]] == sorted(e["travel"] for e in out["events"])


def test_both_grasping_fingers_slipping_are_both_named(squeezed_disk):
    """A finger_slip where F1 and F2 both slide (every contact of each the same way) names
    both; one finger sliding names that one (before, the reason always named the first).
    """
    model, state, contacts = squeezed_disk
    res = frictional_resistance(model, state, (0.0, 0.004), mode="stable", contacts=contacts)

    def sliding(fingers):
        """res.state with the contacts of ``fingers`` sliding (+1), F1's and F2's others stuck."""
        return dataclasses.replace(res.state, contacts=tuple(
            dataclasses.replace(c, mode="slip", slip=1) if c.finger in fingers
            else dataclasses.replace(c, mode="stick", slip=0) if c.finger in ("F1", "F2")
            else c for c in res.state.contacts))

    both = sliding({"F1", "F2"})
    assert slipping_fingers(both) == ["F1", "F2"]
    assert _outcome(Termination.FINGER_SLIP, both) == (False, "F1 and F2 slip")
    assert _outcome(Termination.FINGER_SLIP, sliding({"F2"})) == (False, "F2 slips")


def test_oblique_push_outside_the_adversary_cone_slips_at_once(squeezed_disk):
    model, state, contacts = squeezed_disk
    res = frictional_resistance(model, state, (0.004, 0.001), mode="stable", contacts=contacts)
    assert res.success and res.reason == "adversary slips" and res.travelled == 0.0


def test_bad_inputs(squeezed_disk):
    model, state, _ = squeezed_disk
    with pytest.raises(InvalidInputError, match="nonzero"):
        frictional_resistance(model, state, (0.0, 0.0))
    with pytest.raises(InvalidInputError, match="already touches"):
        add_adversary(
            state, model, np.zeros_like(model.obj.mesh.nodes), state.contacts[0].node, 0.02
        )


def test_cli_friction_runs_the_fig10_scene(capsys):
    assert main(["resist", "config/scenes/resist_fig10.yaml", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["contact_model"] == "friction" and isinstance(out["success"], bool)
    for key in (
        "d1",
        "d2",
        "a",
        "work",
        "forces",
        "forces_start",
        "trajectories",
        "event_counts",
        "squeeze",
    ):
        assert key in out
    assert set(out["trajectories"]) == set(tuple(Finger))
