# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A placement given as a point is a mesh node exactly (its projection on the boundary)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.api import event_squeeze_scene, load_scene, scene_file, scene_solid
from squeeze_grasp_ros.mechanics.elastic import shapes
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
