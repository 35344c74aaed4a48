# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Shared set-up of the perception tests: the camera, every shipped shape, and the Hausdorff
distance in pixels measured with SciPy (independent of the product's curve code).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.distance import directed_hausdorff

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline, resample
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.render import ring_band
from squeeze_grasp_ros.resources import config_dir
from squeeze_grasp_ros.scene import build_outline, load_scene

INSTALL = "scikit-image is not installed: pip install '.[perception]'"

CAMERA = CameraModel(640, 480, fx=465.0, fy=468.0, cx=321.3, cy=238.1,
                     distortion=(-0.04, 0.012, 0.0004, -0.0003, 0.001))
"""A 640 x 480 camera with mild barrel distortion (config/examples/camera_top.yaml-like)."""


def skimage_or_skip():
    """Skip visibly, with the install line, when the perception extra is missing."""
    return pytest.importorskip("skimage", reason=INSTALL)


def pose(dx: float = 0.0, dy: float = 0.0, yaw: float = 0.0, tilt: float = 0.04,
         height: float = 0.5) -> CameraPose:
    """A camera ``height`` m above (dx, dy), tilted by ``tilt`` rad, turned by ``yaw``."""
    return CameraPose.from_xyz_rpy(dx, dy, height, np.pi + tilt, -0.5 * tilt, yaw)


def shipped_shapes() -> dict[str, tuple[Outline, float]]:
    """Every shipped scene's object outline (a ring's wall band) and its top height, m, plus
    the shape library's types not used by a scene.
    """
    found = {}
    for path in sorted((config_dir() / "scenes").glob("*.yaml")):
        scene = load_scene(path)
        outline = build_outline(scene.object.shape)
        if scene.object.ring is not None:
            outline = ring_band(outline, scene.object.ring.wall_thickness)
        key = repr(scene.object.shape) + repr(scene.object.ring)
        found.setdefault(key, (path.stem, outline, scene.object.material.thickness))
    library = {"superellipse": shapes.superellipse(0.06, 0.04, 4.0),
               "polygon_with_hole": shapes.polygon(
                   [[-0.06, -0.04], [0.07, -0.05], [0.05, 0.05], [-0.05, 0.04]],
                   holes=[[[-0.02, -0.02], [0.03, -0.01], [0.0, 0.025]]]),
               "annulus": shapes.annulus(0.05, 0.02)}
    out = {name: (outline, height) for name, outline, height in found.values()}
    out.update({name: (outline, 0.01) for name, outline in library.items()})
    return out


def transformed(outline: Outline, scale: float, angle: float, shift) -> Outline:
    """``outline`` scaled about the origin, turned by ``angle`` and shifted (m)."""
    c, s = np.cos(angle), np.sin(angle)
    R = scale * np.array([[c, -s], [s, c]])
    return Outline(outline.points @ R.T + shift, tuple(h @ R.T + shift for h in outline.holes))


def hausdorff_px(a: Outline, b: Outline, camera: CameraModel, camera_pose: CameraPose,
                 height: float, *, exclude: np.ndarray | None = None,
                 radius_px: float = 3.0) -> float:
    """Symmetric Hausdorff distance (px) between the images of two outlines at ``height``:
    each curve projected and sampled every 0.05 px; the samples of either curve within
    ``radius_px`` of the images of the ``exclude`` points (m) are not measured, but are still
    there to be measured to (else a sample just outside the radius, whose nearest neighbour on
    the other curve lies just inside it, is measured to a farther one).
    """
    def project(points: np.ndarray) -> np.ndarray:
        return camera.project(camera_pose, np.column_stack([points, np.full(len(points),
                                                                             height)]))

    def samples(outline: Outline) -> tuple[np.ndarray, np.ndarray]:
        loops = [resample(uv, 0.05, np.arange(len(uv)))
                 for uv in map(project, (outline.points, *outline.holes))]
        points = np.concatenate(loops)
        if exclude is not None and len(exclude):
            near = np.linalg.norm(points[:, None] - project(exclude)[None], axis=2).min(axis=1)
            return points[near > radius_px], points
        return points, points

    assert len(a.holes) == len(b.holes), f"{len(a.holes)} holes against {len(b.holes)}"
    (pa, all_a), (pb, all_b) = samples(a), samples(b)
    return max(directed_hausdorff(pa, all_b)[0], directed_hausdorff(pb, all_a)[0])
