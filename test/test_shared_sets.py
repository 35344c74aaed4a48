# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""What the contact models of one object share: the reduced contact sets (the fast model's
set data) and the planner's reduced stiffnesses, reduced once per object and identical to what
a model of a fresh object computes.
"""
from __future__ import annotations

import numpy as np
import pytest

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.elastic.reduced import reduced_stiffness
from squeeze_grasp_ros.mechanics.squeeze import contact_model
from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    ContactModel,
    SharedSets,
    TerminationLimits,
)
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import finger_motion, plan_squeeze
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipShape

W, H = 0.04, 0.02


def fresh_block() -> tuple[ElasticObject, tuple[int, int]]:
    """A block that no model has used yet, and its nodes nearest the middles of its sides."""
    outline = shapes.rectangle(W, H)
    obj = ElasticObject(generate_mesh(outline, target_max_area(outline, 300)),
                        Material(2e5, 0.3, 0.01)).precompute()
    nodes = obj.mesh.nodes[obj.mesh.boundary]
    ends = tuple(int(obj.mesh.boundary[np.argmin(np.linalg.norm(nodes - p, axis=1))])
                 for p in ([-W / 2, 0.0], [W / 2, 0.0]))
    return obj, ends


def squeeze(obj, ends, mu):
    return event_squeeze(obj, ends, TipShape.circle(0.004), mu, depth=0.002)


def test_models_of_one_object_share_its_sets_and_squeeze_as_on_a_fresh_object(kernel,
                                                                             monkeypatch):
    reductions = []
    reduce_blocks = contact_model.reduce_blocks
    monkeypatch.setattr(contact_model, "reduce_blocks",
                        lambda *args: reductions.append(1) or reduce_blocks(*args))
    obj, ends = fresh_block()
    warm = {0.4: squeeze(obj, ends, 0.4)}
    assert warm[0.4].event_counts["A"] >= 1 and len(reductions) == 1 + warm[0.4].event_counts["A"]
    # the other friction's model of the object takes the sets the first one reduced
    warm[0.05] = squeeze(obj, ends, 0.05)
    assert warm[0.05].event_counts == warm[0.4].event_counts
    assert len(reductions) == 1 + warm[0.4].event_counts["A"]
    for mu in (0.05, 0.4):
        cold_obj, cold_ends = fresh_block()
        assert cold_ends == ends
        cold = squeeze(cold_obj, cold_ends, mu)
        assert warm[mu].events == cold.events and warm[mu].termination == cold.termination
        np.testing.assert_array_equal(warm[mu].displacement, cold.displacement)
        assert warm[mu].finger_force == cold.finger_force
        assert warm[mu].health == cold.health  # strains from the object's shared B matrices

    nodes = tuple(sorted(ends))
    a, b = ContactModel(obj, 0.4), ContactModel(obj, 0.05)
    assert a.set_data(nodes) is b.set_data(nodes)
    B, dofs = contact_model.strain_tables(obj, a.length)
    assert contact_model.strain_tables(obj, b.length)[0] is B and not B.flags.writeable
    # a strain limit needs the strain map: its sets are kept apart, with it
    strained = ContactModel(obj, 0.4, TerminationLimits(strain=0.1)).set_data(nodes)
    assert strained is not a.set_data(nodes) and strained.strain_map is not None
    assert a.set_data(nodes).strain_map is None
    np.testing.assert_array_equal(strained.C, a.set_data(nodes).C)
    # the paper's literal route reduces its own sets
    assert ContactModel(obj, 0.4, reference=True).set_data(nodes) is not a.set_data(nodes)


def test_the_shared_sets_stay_within_their_budget(monkeypatch):
    obj, ends = fresh_block()
    model = ContactModel(obj, 0.4)
    loop = obj.mesh.boundary.tolist()
    sets = [model.set_data(tuple(sorted((loop[0], loop[k])))) for k in (5, 10, 15)]
    size = sum(x.nbytes for x in (sets[0].C, sets[0].E, sets[0].A_bc))
    monkeypatch.setattr(contact_model, "SHARED_SET_BYTES", 2 * size)
    kept = SharedSets()
    for k, data in enumerate(sets[:2]):
        assert kept.put(("set", k), data) is data
    assert kept.get(("set", 0)) is sets[0]  # now the most recently used
    kept.put(("set", 2), sets[2])
    assert kept.get(("set", 1)) is None  # the least recently used went
    assert kept.get(("set", 0)) is sets[0] and kept.get(("set", 2)) is sets[2]
    assert kept.nbytes == 2 * size
    monkeypatch.setattr(contact_model, "SHARED_SET_BYTES", 0)
    kept.put(("set", 3), sets[1])
    assert kept.get(("set", 3)) is sets[1] and kept.nbytes == size  # the last always stays


@pytest.mark.parametrize("order", [(0, 1), (1, 0)])
def test_the_planners_reduced_stiffness_is_kept_per_object_and_equals_a_fresh_ones(order):
    obj, ends = fresh_block()
    nodes = [ends[k] for k in order]
    first = reduced_stiffness(obj, nodes)
    assert reduced_stiffness(obj, np.array(nodes)) is first
    fresh = reduced_stiffness(fresh_block()[0], nodes)
    for name in ("contacts", "A", "B", "C", "E", "H"):
        np.testing.assert_array_equal(getattr(first, name), getattr(fresh, name))
    assert reduced_stiffness(obj, nodes[::-1]) is not first


@pytest.mark.parametrize("kind", ["stable", "pure"])
def test_the_squeeze_plan_is_kept_per_object_and_its_motion_is_a_fresh_plans(kind, monkeypatch):
    from squeeze_grasp_ros.mechanics.squeeze import stable_pure

    obj, ends = fresh_block()
    plans = []
    plan = stable_pure.plan_squeeze
    monkeypatch.setattr(stable_pure, "plan_squeeze",
                        lambda *a, **k: plans.append(1) or plan(*a, **k))
    first = finger_motion(obj, ends, kind=kind)
    first.directions["F1"][:] = 0.0  # a caller's copy: the kept plan is not touched
    again = finger_motion(obj, ends, kind=kind)
    assert len(plans) == 1
    fresh_obj, _ = fresh_block()
    fresh = plan_squeeze(fresh_obj, list(ends), kind=kind).displacement.reshape(2, 2)
    np.testing.assert_array_equal(again.directions["F1"], fresh[0])
    np.testing.assert_array_equal(again.directions["F2"], fresh[1])
    assert again.kind == kind
    finger_motion(obj, ends[::-1], kind=kind)
    assert len(plans) == 2


def test_models_in_threads_end_with_one_set_per_contact_set():
    """Models of one object in four threads reduce the same sets at once: each thread's model
    holds the one set the object kept (a second reduction of a set gives way to the first).
    """
    from concurrent.futures import ThreadPoolExecutor

    obj, _ = fresh_block()
    loop = obj.mesh.boundary.tolist()
    pairs = [tuple(sorted((loop[0], loop[k]))) for k in range(3, 30, 3)]

    def reduce_all(mu: float) -> list:
        model = ContactModel(obj, mu)
        return [model.set_data(pair) for pair in pairs]

    with ThreadPoolExecutor(4) as pool:
        runs = list(pool.map(reduce_all, (0.1, 0.2, 0.3, 0.4)))
    for k, pair in enumerate(pairs):
        assert all(run[k] is runs[0][k] for run in runs)
        assert ContactModel(obj, 0.5).set_data(pair) is runs[0][k]
