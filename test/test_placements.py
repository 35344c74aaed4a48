# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A placement given as a point is a mesh node exactly (its projection on the boundary); a
rounded tip placed on a node starts touching the object, never inside it.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from contact_support import check_state
from hypothesis import given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.api import event_squeeze_scene, load_scene, scene_file, scene_solid
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.fingertips import TOUCH_TOLERANCE, place_fingertip
from squeeze_grasp_ros.scene import build_mesh, build_outline, finger_nodes, placement_points

POINT_SCENES = ["foam_square", "foam_square_pickup", "nonconvex_blob", "resist_fig10",
                "resist_fig9"]


@pytest.mark.parametrize("name", POINT_SCENES)
def test_point_placements_are_boundary_nodes(name):
    scene = load_scene(scene_file(name))
    points = placement_points(scene)
    assert points, "the scene places its fingers by points"
    mesh = build_mesh(scene)
    boundary = mesh.nodes[mesh.boundary]
    for point in points:
        outline = shapes.with_boundary_points(build_outline(scene.object.shape), [point])
        kept = outline.points[outline.corners]
        foot = kept[np.argmin(np.linalg.norm(kept - point, axis=1))]
        gap = np.linalg.norm(boundary - foot, axis=1).min()
        assert gap < 1e-12 * mesh.size


def test_the_foam_square_is_squeezed_along_its_axis():
    """The fingers at (+-0.05, 0) touch nodes at y = 0: the stable squeeze is horizontal."""
    scene = load_scene(scene_file("foam_square"))
    obj = scene_solid(scene)
    i, j = finger_nodes(scene, obj.mesh)
    assert obj.mesh.nodes[i].tolist() == [-0.05, 0.0] and obj.mesh.nodes[j].tolist() == [0.05, 0.0]
    result = event_squeeze_scene(scene, obj, relative_depth=0.02)
    for direction in result.directions.values():
        assert abs(direction[1]) < 1e-12 * abs(direction[0])


def test_low_friction_no_longer_slips_at_the_first_step():
    """With the squeeze line tilted by snapping (1.7 deg before), mu = 0.005 ended at depth 0."""
    scene = load_scene(scene_file("foam_square"))
    scene = dataclasses.replace(scene, friction=dataclasses.replace(scene.friction, mu=0.005))
    result = event_squeeze_scene(scene, relative_depth=0.02)
    assert result.relative_depth > 0.01


@settings(max_examples=40, deadline=None)
@given(st.floats(-0.2, 0.2), st.floats(-0.2, 0.2))
def test_inserted_points_lie_on_the_outline_and_keep_it(x, y):
    square = shapes.rectangle(0.1, 0.06)
    out = shapes.with_boundary_points(square, [(x, y)])
    assert abs(out.area - square.area) < 1e-15
    new = out.points[out.corners]
    w, h = 0.05, 0.03
    on_edge = np.minimum(np.abs(np.abs(new[:, 0]) - w), np.abs(np.abs(new[:, 1]) - h))
    assert on_edge.max() < 1e-15 and np.all(np.abs(new) <= [w + 1e-15, h + 1e-15])


TIP = 0.02
"""m: a tip too wide for some of the non-convex blob's concave stretches."""


def _blob():
    """The shipped non-convex blob's object and the boundary nodes where the paper's placement
    of a TIP circle (centre p + r n) holds other boundary nodes inside it.
    """
    obj = scene_solid(load_scene(scene_file("nonconvex_blob")))
    mesh = obj.mesh
    b = mesh.boundary
    inside = [int(k) for k in b
              if (np.hypot(*(mesh.nodes[b] - mesh.nodes[k] - TIP * mesh.normal_at(k)).T)
                  - TIP).min() < -TOUCH_TOLERANCE * mesh.size]
    return obj, inside


def test_a_rounded_tip_never_starts_inside_the_object():
    """On every boundary node of the non-convex blob a 20 mm tip starts with no boundary node
    inside it: on a concave stretch tighter than the tip (the paper's centre p + r n would hold
    nodes up to 1.3 mm inside) it approaches along the inward normal until it first touches;
    elsewhere it sits exactly where the paper puts it.
    """
    obj, inside = _blob()
    mesh = obj.mesh
    assert len(inside) >= 3  # the case this test is about occurs
    for k in mesh.boundary:
        tip = place_fingertip(mesh, "F1", int(k), TIP)
        gaps = np.hypot(*(mesh.nodes[mesh.boundary] - tip.center).T) - TIP
        assert gaps.min() >= -TOUCH_TOLERANCE * mesh.size
        if k in inside:
            assert tip.node != k and abs(gaps[mesh.boundary == tip.node][0]) < 1e-12 * mesh.size
        else:
            assert tip.node == k
            assert np.array_equal(tip.center, mesh.nodes[k] + TIP * mesh.normal_at(int(k)))


def test_a_squeeze_from_a_concave_node_starts_at_zero_force_and_keeps_its_invariants():
    """From each concave node of the blob against the farthest boundary node, mu = 0.8: the
    squeeze starts at zero force, its end state is in equilibrium with every force in its cone
    and no node inside a tip, and the fingers' work covers the stored energy. Before, the tips
    started overlapping the object and every such squeeze ended at depth 0 (finger_slip) with
    nodes inside the tip.
    """
    obj, inside = _blob()
    mesh, b = obj.mesh, obj.mesh.boundary
    for k in inside[::2]:
        far = int(b[np.argmax(np.hypot(*(mesh.nodes[b] - mesh.nodes[k]).T))])
        res = event_squeeze(obj, (k, far), TIP, 0.8, relative_depth=0.04)
        start = {name: forces[0] for name, forces in res.finger_force.items()}
        assert max(abs(f) for f in start.values()) < 1e-9, start
        assert res.relative_depth > 0.02, (k, res.termination)
        check_state(ContactModel(obj, 0.8), res.state)
        assert res.diagnostics["work_minus_energy"] >= -1e-9 * res.energy
