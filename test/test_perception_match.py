# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Matching an observed outline against the predicted deformed boundary (App. C, live).

The prediction is the mechanics API's event-driven squeeze of the foam square (12 %); the
observation is that deformed boundary rendered by the simulated camera and extracted again.
The residual is a fraction of a pixel for the right model and grows with a wrong Poisson's
ratio. A wrong Young's modulus leaves the deformed shape exactly as it is: under prescribed
finger displacements, E scales the forces and nothing else (DEFINITIONS, scaling laws) -- so no
shape residual can see it.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest
import yaml
from perception_support import CAMERA, pose, skimage_or_skip

from squeeze_grasp_ros.api import build_mesh, event_squeeze_scene, scene_file, scene_solid
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline, ellipse, resample
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.perception.render import render_views
from squeeze_grasp_ros.perception.shape_match import (
    closest_on_curves,
    deformed_outline,
    shape_residual,
)
from squeeze_grasp_ros.scene import parse_scene

THICKNESS = 0.0254


@lru_cache(maxsize=None)
def foam_square(E_factor: float = 1.0, nu: float = 0.3, model: str = "linear") -> Outline:
    """The foam square's deformed boundary after its 12 % squeeze, m."""
    data = yaml.safe_load(scene_file("foam_square").read_text())
    material = data["object"]["material"]
    material.update(E=E_factor * float(material["E"]), nu=nu, model=model)
    scene = parse_scene(data)
    result = event_squeeze_scene(scene, scene_solid(scene))
    return deformed_outline(build_mesh(scene), result.displacement)


def seen(outline: Outline):
    """What the camera extracts from ``outline``'s top face (needs scikit-image)."""
    skimage_or_skip()
    from squeeze_grasp_ros.perception.extract import extract_outline

    view = pose(dx=4e-4, dy=-3e-4, yaw=0.25)
    views = render_views(outline, CAMERA, view, top_height=THICKNESS)
    return extract_outline(views.mask, "mono8", CAMERA, view, object_height_m=THICKNESS)


def test_the_right_model_matches_its_camera_view_within_a_fraction_of_a_pixel():
    predicted = foam_square()
    observed = seen(predicted)
    pixel = observed.pixel_size_m
    for fit in ("similarity", "rigid", "none"):
        match = shape_residual(observed.outline, predicted, fit=fit)
        assert match.converged
        assert match.max_m <= 0.5 * pixel and match.rms_m <= 0.15 * pixel, fit
        assert match.reverse_max_m <= 0.5 * pixel
    assert shape_residual(observed.outline, predicted).scale == pytest.approx(1.0, abs=2e-3)


def test_a_wrong_poisson_ratio_grows_the_residual():
    """The camera watches the squeeze of nu = 0.3; predictions with other nu are farther."""
    observed = seen(foam_square()).outline
    right = shape_residual(observed, foam_square(), fit="rigid").max_m
    residuals = [shape_residual(observed, foam_square(nu=nu), fit="rigid").max_m
                 for nu in (0.1, 0.2, 0.45)]
    assert all(r > 2 * right for r in residuals)
    assert residuals[0] > residuals[1]  # farther from 0.3, farther off


@pytest.mark.parametrize("model", ["linear", pytest.param("neo_hookean",
                                                          marks=pytest.mark.slow)])
def test_young_modulus_leaves_the_deformed_shape_unchanged(model):
    """E + 30 %: the same boundary to round-off: a shape residual cannot tell a wrong E, only
    the forces can.
    """
    a, b = foam_square(model=model), foam_square(E_factor=1.3, model=model)
    assert shape_residual(a, b, fit="none").max_m <= 1e-12


def test_the_similarity_undoes_a_known_transform():
    nodes = Outline(resample(ellipse(0.05, 0.03).points, 0.003))
    c, s = np.cos(0.2), np.sin(0.2)
    dense = resample(ellipse(0.05, 0.03).points, 0.0005)
    moved = Outline(1.05 * dense @ np.array([[c, -s], [s, c]]).T + [0.01, -0.004])
    match = shape_residual(moved, nodes)
    assert match.scale == pytest.approx(1 / 1.05, rel=1e-4)
    assert match.rotation == pytest.approx(-0.2, abs=1e-4)
    assert match.max_m < 2e-6  # the dense polyline's chords
    rigid = shape_residual(Outline(dense @ np.array([[c, -s], [s, c]]).T + [0.01, 0.0]), nodes,
                           fit="rigid")
    assert rigid.scale == 1.0 and rigid.max_m < 2e-6


def test_what_the_prediction_lacks_shows_in_the_reverse_distance():
    """An observed bump the prediction does not have: small node distances (nodes sit on the
    unchanged part) but a large reverse distance.
    """
    nodes = Outline(resample(ellipse(0.05, 0.03).points, 0.002))
    t = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    r = 1 + 0.08 * np.exp(-((t - 0.5) / 0.05) ** 2)
    bumped = Outline(np.column_stack([0.05 * r * np.cos(t), 0.03 * r * np.sin(t)]))
    match = shape_residual(bumped, nodes, fit="none")
    assert match.reverse_max_m > 0.003 > match.rms_m


def test_closest_points_are_exact_against_a_brute_force_line_search():
    loop = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    points = np.random.default_rng(1).uniform(-0.5, 1.5, (200, 2))
    closest, dist, normal = closest_on_curves(points, [loop])
    s = np.linspace(0, 1, 5001)
    dense = np.concatenate([a + s[:, None] * (np.roll(loop, -1, 0)[k] - a)
                            for k, a in enumerate(loop)])
    brute = np.linalg.norm(points[:, None] - dense[None], axis=2).min(axis=1)
    assert np.allclose(dist, brute, atol=1.5e-4)  # the samples are 2e-4 apart
    assert np.allclose(np.linalg.norm(normal, axis=1), 1.0)


def test_bad_requests_name_the_field():
    square = Outline(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    with pytest.raises(InvalidInputError, match="fit must be one of"):
        shape_residual(square, square, fit="affine")
    with pytest.raises(InvalidInputError, match="at least 3"):
        shape_residual(Outline(np.zeros((2, 2))), square)
    with pytest.raises(InvalidInputError, match="max_iterations"):
        shape_residual(square, square, max_iterations=0)


@pytest.mark.parametrize("size", [5, 2])
def test_a_displacement_of_another_mesh_is_refused(size):
    """Five values used to fail in numpy's reshape (ValueError); one row too many in its
    broadcast.
    """
    mesh = build_mesh(parse_scene(yaml.safe_load(scene_file("disk").read_text())))
    shape = (5,) if size == 5 else (mesh.n + 1, 2)
    with pytest.raises(InvalidInputError, match=f"displacement must be .n, 2. with n = {mesh.n}"):
        deformed_outline(mesh, np.zeros(shape))
