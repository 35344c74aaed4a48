# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Boundary nodes as resampled, or split by the mesher (issue 32: a seen outline's events).

Triangle's quality refinement splits a boundary segment when a triangle on it is too large or
too flat; with the boundary resampled at the element size, whether it does is a tie (a segment
a hair longer than the element size carries a triangle a hair over the area bound), so two
outlines micrometres apart could get different boundary nodes. ``split_boundary=False`` keeps
the resampled loops as the boundary nodes (Triangle's ``Y``); scenes use it for splines.
"""
from __future__ import annotations

import numpy as np
import pytest
import yaml

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.mesh import (
    ANGLE_SLACK,
    TriangleMesher,
    generate_mesh,
    target_max_area,
)
from squeeze_grasp_ros.mechanics.elastic.mesh_size import estimate_mesh
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.scene import build_mesh, build_outline, load_scene, parse_scene
from squeeze_grasp_ros.scene.build import placement_points


class RecordingMesher(TriangleMesher):
    """Triangle, recording whether each call let it split the boundary."""

    def __init__(self) -> None:
        self.splits: list[bool] = []

    def triangulate(self, *args, split_boundary=True):
        self.splits.append(split_boundary)
        return super().triangulate(*args, split_boundary=split_boundary)


def on_loop(mesh, loop: np.ndarray) -> np.ndarray:
    """For each outer boundary node of ``mesh``, its distance to the nearest ``loop`` vertex, m."""
    nodes = mesh.nodes[mesh.boundary]
    return np.linalg.norm(nodes[:, None] - loop[None], axis=2).min(axis=1)


def meshed_outline(scene):
    """The outline ``build_mesh`` meshes (finger points as kept vertices), its element area
    (m^2) and its resampled outer loop (m).
    """
    outline = shapes.with_boundary_points(build_outline(scene.object.shape),
                                          placement_points(scene))
    area = target_max_area(outline, scene.object.mesh.nodes)
    return outline, area, estimate_mesh(outline, area).loops[0]


def test_kept_boundary_nodes_are_the_resampled_loop_and_splits_only_add_nodes():
    """The shipped foam square's outline and element size: kept, the boundary nodes are
    exactly the resampled vertices; split (the default), Triangle adds nodes between them and
    keeps every resampled vertex, and the scene (a rectangle) is meshed so. Both meshes meet
    the 30 degree bound.
    """
    scene = load_scene(scene_file("foam_square"))
    outline, area, loop = meshed_outline(scene)
    kept = generate_mesh(outline, area, split_boundary=False)
    split = generate_mesh(outline, area)
    assert len(kept.boundary) == len(loop) and on_loop(kept, loop).max() < 1e-12
    assert len(split.boundary) > len(loop)
    nodes = split.nodes[split.boundary]
    assert np.linalg.norm(loop[:, None] - nodes[None], axis=2).min(axis=1).max() < 1e-12
    assert min(kept.min_angle_deg(), split.min_angle_deg()) >= 30.0 - 1e-9
    np.testing.assert_array_equal(build_mesh(scene).nodes, split.nodes)


def test_a_spline_thinner_than_its_elements_is_meshed_again_with_splits():
    """A 4 mm strip meshed with 2 cm elements cannot meet the angle bound on its resampled
    boundary: the mesh is made again with splits, meets 30 degrees and has more boundary nodes
    than the resampled loop.
    """
    t = np.linspace(0.0, 2.0 * np.pi, 64, endpoint=False)
    strip = shapes.spline(np.c_[0.05 * np.cos(t), 0.002 * np.sin(t)])
    area = target_max_area(strip, 200)
    mesher = RecordingMesher()
    mesh = generate_mesh(strip, area, split_boundary=False, mesher=mesher)
    assert mesher.splits == [False, True]
    assert mesh.min_angle_deg() >= 30.0 - ANGLE_SLACK
    assert len(mesh.boundary) > len(estimate_mesh(strip, area).loops[0])


@pytest.mark.parametrize("nodes", [400, 1000, 2000])
def test_scene_splines_keep_their_resampled_boundary(nodes):
    """A scene's spline (the shipped non-convex blob at several sizes) is meshed on its
    resampled boundary, finger points included: each boundary node is a resampled vertex and
    there are as many.
    """
    raw = yaml.safe_load(scene_file("nonconvex_blob").read_text())
    raw["object"]["mesh"] = {"nodes": nodes}
    scene = parse_scene(raw)
    _, _, loop = meshed_outline(scene)
    mesh = build_mesh(scene)
    assert len(mesh.boundary) == len(loop) and on_loop(mesh, loop).max() < 1e-12
