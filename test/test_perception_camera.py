# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The camera model and the simulated camera's rendering (no scikit-image needed).

Projection and back-projection are inverse to each other through plumb-bob distortion; the
pose constructors agree with each other and with ROS conventions; calibration files in both
layouts give the same camera; the rasteriser's coverage is checked against exact polygon areas
and an independent supersampled point-in-polygon count; depth pixels mix heights by coverage.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath

from squeeze_grasp_ros.inputs import load_yaml
from squeeze_grasp_ros.mechanics.elastic.shapes import (
    Outline,
    annulus,
    fourier_blob,
    polygon,
    rectangle,
    resample,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.camera_info import camera_from_info
from squeeze_grasp_ros.perception.render import coverage, render_views, ring_band

DISTORTED = CameraModel(640, 480, fx=465.0, fy=468.0, cx=321.3, cy=238.1,
                        distortion=(-0.04, 0.012, 0.0004, -0.0003, 0.001))
PINHOLE = CameraModel(640, 480, fx=500.0, fy=500.0, cx=319.5, cy=239.5)


@settings(max_examples=60, deadline=None)
@given(x=st.floats(-0.25, 0.25), y=st.floats(-0.18, 0.18), z=st.floats(0.0, 0.05),
       roll=st.floats(-0.1, 0.1), pitch=st.floats(-0.1, 0.1), yaw=st.floats(-3.1, 3.1))
def test_back_projection_inverts_projection_through_distortion(x, y, z, roll, pitch, yaw):
    pose = CameraPose.from_xyz_rpy(0.01, -0.02, 0.5, np.pi + roll, pitch, yaw)
    uv = DISTORTED.project(pose, np.array([[x, y, z]]))
    back = DISTORTED.back_project(pose, uv, z)
    assert np.allclose(back.points, [[x, y]], atol=1e-9)
    assert back.undistort_residual_px <= 1e-6


def test_looking_down_maps_plane_axes_to_image_axes():
    """The image u axis follows x and v follows -y; the principal point sees the foot point."""
    pose = CameraPose.looking_down(0.5, x=0.1, y=-0.2)
    uv = PINHOLE.project(pose, np.array([[0.1, -0.2, 0.0], [0.2, -0.2, 0.0], [0.1, -0.1, 0.0]]))
    assert np.allclose(uv[0], [319.5, 239.5])
    assert np.allclose(uv[1] - uv[0], [100.0, 0.0])  # f * 0.1 m / 0.5 m
    assert np.allclose(uv[2] - uv[0], [0.0, -100.0])


def test_quaternion_and_rpy_give_the_same_pose_and_json_round_trips():
    pose = CameraPose.from_xyz_rpy(0.1, 0.2, 0.6, 3.0, 0.1, -0.7)
    q = pose.to_json()["quaternion"]
    again = CameraPose.from_xyz_quaternion(0.1, 0.2, 0.6, *q)
    assert np.allclose(again.matrix, pose.matrix, atol=1e-12)
    # roll = pi: the quaternion (1, 0, 0, 0), where the trace branch is singular
    assert np.allclose(np.abs(CameraPose.looking_down(0.5).to_json()["quaternion"]),
                       [1, 0, 0, 0], atol=1e-12)


@pytest.mark.parametrize("bad, field", [
    (dict(translation=(0.0, 0.0, -0.1)), "above the support plane"),
    (dict(rotation=tuple(np.eye(3).ravel())), "must look down"),
    (dict(rotation=(2.0,) + (0.0,) * 8), "proper rotation"),
])
def test_bad_poses_are_refused(bad, field):
    kwargs = {"rotation": CameraPose.looking_down(0.5).rotation,
              "translation": (0.0, 0.0, 0.5)} | bad
    with pytest.raises(InvalidInputError, match=field):
        CameraPose(**kwargs)


def test_calibration_layouts_agree_and_bad_files_name_the_field():
    yaml_layout = {"image_width": 640, "image_height": 480, "camera_name": "top",
                   "camera_matrix": {"rows": 3, "cols": 3,
                                     "data": [465, 0, 321.3, 0, 468, 238.1, 0, 0, 1]},
                   "distortion_model": "plumb_bob",
                   "distortion_coefficients": {"data": list(DISTORTED.distortion)}}
    info_layout = {"width": 640, "height": 480, "header": {"frame_id": "top"},
                   "k": [465, 0, 321.3, 0, 468, 238.1, 0, 0, 1], "distortion_model": "plumb_bob",
                   "d": list(DISTORTED.distortion)}
    a, b = camera_from_info(yaml_layout), camera_from_info(info_layout)
    assert a == b and a.fx == 465 and a.frame_id == "top"
    assert camera_from_info(a.to_camera_info()) == a  # CameraInfo fields round-trip
    with pytest.raises(InvalidInputError, match="distortion_model"):
        camera_from_info(info_layout | {"distortion_model": "equidistant"})
    with pytest.raises(InvalidInputError, match="k must have 9"):
        camera_from_info(info_layout | {"k": [1, 2, 3]})
    with pytest.raises(InvalidInputError, match="k4-k6"):
        camera_from_info(info_layout | {"distortion_model": "rational_polynomial",
                                        "d": [0, 0, 0, 0, 0, 0.1, 0, 0]})
    with pytest.raises(InvalidInputError, match="width must be an integer"):
        CameraModel(6.5, 480, fx=1.0, fy=1.0, cx=0.0, cy=0.0)


def test_calibration_files_take_exponents_as_scenes_do():
    """YAML 1.1 (PyYAML) reads ``-4e-2`` or ``1e3`` as text; a scene takes them as numbers, and
    a calibration file read them as "k must be a list of numbers". A word in the list is named
    by its index.
    """
    text = ("width: 640\nheight: 480\nk: [4.65e2, 0, 319.5, 0, 465, 239.5, 0, 0, 1]\n"
            "d: [-4e-2, 1.2e-2, 4e-4, -3e-4, 0]\n")
    camera = camera_from_info(load_yaml(text, what="camera info"))
    assert camera.fx == 465.0 and camera.distortion == (-0.04, 0.012, 0.0004, -0.0003, 0.0)
    with pytest.raises(InvalidInputError,
                       match=r"camera info: distortion coefficients\[1\] must be a number, "
                             "got 'x'"):
        camera_from_info(load_yaml(text.replace("1.2e-2", "x"), what="camera info"))


def test_an_uncalibrated_camera_info_says_so():
    """A driver without a calibration publishes CameraInfo with k all zero and d empty; the
    error used to ask for an intrinsics matrix without skew.
    """
    info = {"width": 640, "height": 480, "k": [0.0] * 9, "d": [], "distortion_model": ""}
    with pytest.raises(InvalidInputError, match="camera_info: the camera is uncalibrated"):
        camera_from_info(info, what="camera_info")
    with pytest.raises(InvalidInputError, match=r"no skew\), got \[465"):
        camera_from_info(info | {"k": [465, 3, 320, 0, 465, 240, 0, 0, 1],
                                 "distortion_model": "plumb_bob"})


def test_strong_distortion_that_cannot_be_inverted_raises_with_its_residual():
    wild = CameraModel(640, 480, fx=200.0, fy=200.0, cx=319.5, cy=239.5,
                       distortion=(-0.9, 0.0, 0.0, 0.0, 0.0))
    with pytest.raises(NumericalError, match="reprojection_px") as info:
        wild.undistort(np.array([[0.0, 0.0]]))
    assert ", 2 focal lengths from the principal point (distortion too strong" in str(info.value)


def test_a_principal_point_outside_the_image_is_named_when_undistortion_fails():
    """A K with cx and cy swapped or in other units put every pixel far off axis, and the
    refusal blamed the distortion; a principal point outside the image is legal (cropped
    images), so it is named only when undistortion fails.
    """
    distortion = (-0.2, 0.05, 0.0, 0.0, 0.0)
    shifted = CameraModel(640, 480, fx=600.0, fy=600.0, cx=-2000.0, cy=239.5,
                          distortion=distortion)
    with pytest.raises(NumericalError, match=r"principal point \(-2000, 239.5\) px lies outside "
                                             r"the 640 x 480 px image: check K"):
        shifted.undistort(np.array([[639.0, 479.0]]))
    cropped = CameraModel(640, 480, fx=600.0, fy=600.0, cx=-5.0, cy=239.5,
                          distortion=distortion)
    assert cropped.undistort(np.array([[0.0, 0.0], [639.0, 479.0]]))[1] < 1e-3


def supersampled(loops_px, shape, k=16):
    """Coverage by counting k x k sub-pixel samples inside the region (even-odd rule), with
    matplotlib's point-in-polygon test: independent of the rasteriser.
    """
    H, W = shape
    s = (np.arange(k) + 0.5) / k - 0.5  # pixel (r, c) covers [c - 1/2, c + 1/2] in u
    U, V = np.meshgrid((np.arange(W)[:, None] + s).ravel(), (np.arange(H)[:, None] + s).ravel())
    points = np.column_stack([U.ravel(), V.ravel()])
    inside = np.zeros(len(points), bool)
    for loop in loops_px:
        inside ^= MplPath(loop).contains_points(points)
    return inside.reshape(H, k, W, k).mean(axis=(1, 3))


def coarse(shape, spacing=0.002):
    """``shape`` with its curves resampled (fewer vertices keep the reference count fast)."""
    return Outline(resample(shape.points, spacing), tuple(resample(h, spacing)
                                                          for h in shape.holes))


def test_coverage_matches_exact_areas_and_a_supersampled_count():
    small = CameraModel(100, 80, fx=300.0, fy=300.0, cx=49.5, cy=39.5)
    pose = CameraPose.looking_down(0.5, x=0.0013, y=-0.0007, yaw=0.4)
    ring = coarse(annulus(0.05, 0.025))
    star = coarse(fourier_blob(0.035, cos=[0.0, 0.2], sin=[0.1, 0.0, 0.15]))
    for shape in (ring, star, rectangle(0.071, 0.047)):
        loops = [small.project(pose, np.column_stack([loop, np.zeros(len(loop))]))
                 for loop in (shape.points, *shape.holes)]
        cov = coverage([loops[0]] + [h[::-1] for h in loops[1:]], small.shape)
        area_px = shape.area * (300 / 0.5) ** 2  # the view is a similarity: exact
        assert cov.sum() == pytest.approx(area_px, rel=1e-9)
        assert np.abs(cov - supersampled(loops, small.shape)).max() < 1.5 / 16


def test_objects_reaching_far_out_of_view_render_what_the_camera_sees():
    """An object far from the view, or a strip reaching 1 km beyond it, met the distortion
    polynomial far outside its field: the pixels overflowed and ``render`` ended in a
    MemoryError or "repeats may not contain negative values" (exit 1). Such loops are clipped
    to the view first: the image is the same.
    """
    pose = CameraPose.looking_down(0.5)
    far = render_views(rectangle(0.1, 0.1), DISTORTED, CameraPose.looking_down(0.5, x=100.0),
                       top_height=0.02)
    assert not far.coverage.any() and not far.mask.any()
    strips = [render_views(Outline(np.array([[-w, -0.01], [w, -0.01], [w, 0.01], [-w, 0.01]])),
                           camera, pose, top_height=0.0).coverage
              for camera in (PINHOLE, DISTORTED) for w in (1.0, 1e3)]
    assert strips[0].sum() == pytest.approx(640 * 20, rel=1e-12)  # 20 rows of the pinhole
    assert np.array_equal(strips[0], strips[1])
    assert np.abs(strips[2] - strips[3]).max() < 1e-9
    with pytest.raises(InvalidInputError, match="behind the camera"):
        render_views(rectangle(0.1, 0.1), DISTORTED, CameraPose.from_xyz_rpy(0, 0, 0.5, 1.6, 0, 0),
                     top_height=0.0)


def test_depth_mixes_the_two_heights_by_coverage_and_noise_is_seeded():
    pose = CameraPose.from_xyz_rpy(0.0, 0.0, 0.5, np.pi + 0.05, -0.03, 0.2)
    views = render_views(polygon([[-0.05, -0.04], [0.06, -0.05], [0.04, 0.05], [-0.05, 0.03]]),
                         DISTORTED, pose, top_height=0.02)
    gz = DISTORTED.ray_grid(pose, 2)
    heights = pose.position[2] + views.depth.astype(float) * gz
    assert np.abs(heights - 0.02 * views.coverage).max() < 1e-6  # float32 depth
    assert np.array_equal(views.mask, np.rint(255 * views.coverage).astype(np.uint8))
    assert views.depth_mm().dtype == np.uint16
    clean = render_views(rectangle(0.1, 0.1), DISTORTED, pose, top_height=0.02)
    a, b = (render_views(rectangle(0.1, 0.1), DISTORTED, pose, top_height=0.02,
                         depth_noise_m=0.001, seed=3) for _ in range(2))
    assert np.array_equal(a.depth, b.depth)
    assert np.std(a.depth - clean.depth) == pytest.approx(0.001, rel=0.02)


def test_ring_band_is_the_wall_around_the_middle_curve():
    band = ring_band(annulus(0.04, 0.039), 0.004)  # middle curve: the outer circle
    assert band.area == pytest.approx(2 * np.pi * 0.04 * 0.004, rel=1e-3)
    with pytest.raises(InvalidInputError, match="too thick"):
        ring_band(annulus(0.01, 0.009), 0.03)
