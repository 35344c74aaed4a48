# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The support plane seen in a depth image, checked against the declared camera pose.

Heights above the declared plane are averaged over blocks of ``BLOCK`` x ``BLOCK`` pixels
(noise falls by the block's side), a plane h = c0 + c1 x + c2 y is fitted to the blocks by a
seeded RANSAC (objects are outliers) and refined by least squares on its inliers. The view is
refused when the fitted plane is tilted, shifted or when blocks away from every object deviate
from it: then the heights, and so the outline, would be wrong.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose

__all__ = ["BLOCK", "SupportPlane", "fit_support", "floor_grids"]

BLOCK = 16
"""Side of the averaging blocks, px."""

MIN_BLOCKS = 6
"""Blocks at least half valid the support plane is fitted to, at least."""

RANSAC_TRIALS = 64
"""Random block triples tried by the plane fit (seeded: the fit is deterministic)."""


@dataclass(frozen=True)
class SupportPlane:
    """The support plane fitted to a depth image, in the declared plane frame.

    Attributes
    ----------
    coefficients : tuple of 3 float
        (c0 m, c1, c2) of h = c0 + c1 x + c2 y (heights and x, y in m).
    tilt_deg : float
        Angle between the fitted and the declared plane, deg.
    inlier_blocks : int
        Blocks within the tolerance of the fitted plane.
    flatness_m : float
        Largest deviation from the plane of a block mean away from the objects, m.
    """

    coefficients: tuple[float, float, float]
    tilt_deg: float
    inlier_blocks: int
    flatness_m: float

    def height_at(self, x: np.ndarray | float, y: np.ndarray | float) -> np.ndarray | float:
        """Plane height (m) at plane-frame x, y (m)."""
        c0, c1, c2 = self.coefficients
        return c0 + c1 * x + c2 * y

    def to_json(self) -> dict:
        """``{"coefficients", "tilt_deg", "inlier_blocks", "flatness_m"}``."""
        return {"coefficients": list(self.coefficients), "tilt_deg": self.tilt_deg,
                "inlier_blocks": self.inlier_blocks, "flatness_m": self.flatness_m}


@lru_cache(maxsize=2)
def floor_grids(camera: CameraModel, pose: CameraPose) -> tuple[np.ndarray, ...]:
    """Per pixel: the ray's plane-frame z per unit depth, and the x, y where it meets z = 0 (m);
    cached for the last two cameras and poses (a fixed camera pays once; three float64 grids
    are 7 MB at 640 x 480).
    """
    gz = camera.ray_grid(pose, 2)
    if not np.all(gz < 0):
        raise InvalidInputError("camera pose: some pixels do not see the support plane "
                                "(horizon in view); tilt the camera down")
    t = pose.position
    floor = -t[2] / gz
    return gz, t[0] + floor * camera.ray_grid(pose, 0), t[1] + floor * camera.ray_grid(pose, 1)


@lru_cache(maxsize=2)
def _block_centres(camera: CameraModel, pose: CameraPose) -> tuple[np.ndarray, np.ndarray]:
    """Plane-frame x, y (m) of each block's mean floor point; cached per camera and pose."""
    _, fx, fy = floor_grids(camera, pose)
    everywhere = np.ones(fx.shape, bool)
    return _block_means(fx, everywhere)[0], _block_means(fy, everywhere)[0]


def _block_means(values: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean of ``values`` over the valid pixels of each block, and the valid count."""
    H, W = values.shape
    h, w = H // BLOCK, W // BLOCK
    v = np.where(valid, values, 0.0)[:h * BLOCK, :w * BLOCK].reshape(h, BLOCK, w, BLOCK)
    n = valid[:h * BLOCK, :w * BLOCK].reshape(h, BLOCK, w, BLOCK).sum(axis=(1, 3))
    with np.errstate(invalid="ignore", divide="ignore"):
        return v.sum(axis=(1, 3)) / n, n


def fit_support(heights: np.ndarray, valid: np.ndarray, camera: CameraModel, pose: CameraPose,
                *, tolerance_m: float, min_height_m: float, max_tilt_deg: float) -> SupportPlane:
    """Fit and check the support plane of a depth view.

    Parameters
    ----------
    heights : (H, W) ndarray
        Heights above the declared plane, m (anything where not ``valid``).
    valid : (H, W) ndarray of bool
    camera, pose : CameraModel, CameraPose
    tolerance_m : float
        Largest deviation of the support from the declared plane (offset under the object,
        flatness), m.
    min_height_m : float
        Height above which a pixel belongs to an object, m.
    max_tilt_deg : float
        Largest tilt of the fitted plane against the declared one, deg.

    Raises
    ------
    InvalidInputError
        Too little support in view, or a support that is tilted, shifted (more than
        ``tolerance_m`` off the declared plane at the middle of the support in view) or not
        planar.
    """
    from scipy import ndimage

    bx, by = _block_centres(camera, pose)
    mean_h, count = _block_means(heights, valid)
    full = count >= BLOCK * BLOCK // 2
    x, y, h = bx[full], by[full], mean_h[full]
    if full.size < MIN_BLOCKS:
        raise InvalidInputError(f"depth image: {camera.width} x {camera.height} px is too small "
                                f"to see the support plane: it holds {full.size} blocks of "
                                f"{BLOCK} x {BLOCK} px, the plane fit needs {MIN_BLOCKS} (e.g. "
                                f"{3 * BLOCK} x {2 * BLOCK} px)")
    if len(h) < MIN_BLOCKS:
        raise InvalidInputError(f"depth image: too few valid pixels to see the support plane "
                                f"({len(h)} blocks of {BLOCK} x {BLOCK} px at least half valid; "
                                f"need {MIN_BLOCKS})")
    rng = np.random.default_rng(0)
    triples = rng.integers(0, len(h), size=(RANSAC_TRIALS, 3))
    A = np.stack([np.ones((RANSAC_TRIALS, 3)), x[triples], y[triples]], axis=2)
    good = np.abs(np.linalg.det(A)) > 1e-12
    coef = np.linalg.solve(A[good], h[triples[good]][..., None])[..., 0]
    fits = coef[:, :1] + coef[:, 1:2] * x + coef[:, 2:3] * y
    inliers = np.abs(fits - h) <= tolerance_m
    best = inliers[int(np.argmax(inliers.sum(axis=1)))]
    if best.sum() < 3:
        raise InvalidInputError("depth image: no planar support in view (no three blocks agree "
                                f"on a plane within {tolerance_m:g} m)")
    design = np.column_stack([np.ones(best.sum()), x[best], y[best]])
    c = np.linalg.lstsq(design, h[best], rcond=None)[0]
    tilt = float(np.degrees(np.arctan(np.hypot(c[1], c[2]))))
    if tilt > max_tilt_deg:
        raise InvalidInputError(f"depth image: the support plane is tilted by {tilt:.2f} deg "
                                f"against the declared camera pose (max_tilt_deg = "
                                f"{max_tilt_deg:g}); check the camera pose or level the support")
    _check_offset(c, x[best], y[best], pose, tolerance_m)
    residual = mean_h - (c[0] + c[1] * bx + c[2] * by)
    objects = ndimage.binary_dilation(_block_any(heights > min_height_m, valid), iterations=1)
    away = full & ~objects
    flatness = float(np.abs(residual[away]).max()) if away.any() else 0.0
    if flatness > tolerance_m:
        k = np.unravel_index(np.argmax(np.where(away, np.abs(residual), -1.0)), residual.shape)
        raise InvalidInputError(
            f"depth image: the support is not planar: the {BLOCK} x {BLOCK} px block at rows "
            f"{k[0] * BLOCK}-{k[0] * BLOCK + BLOCK - 1}, columns {k[1] * BLOCK}-"
            f"{k[1] * BLOCK + BLOCK - 1} is {1e3 * residual[k]:+.1f} mm off the fitted plane "
            f"(tolerance {1e3 * tolerance_m:g} mm) and holds no object")
    return SupportPlane((float(c[0]), float(c[1]), float(c[2])), tilt, int(best.sum()),
                        flatness)


def _check_offset(c: np.ndarray, x: np.ndarray, y: np.ndarray, pose: CameraPose,
                  tolerance_m: float) -> None:
    """Refuse a fitted support plane h = c0 + c1 x + c2 y (m) that lies more than
    ``tolerance_m`` (m) off the declared plane z = 0 at the middle of the support in view (the
    mean of the inlier blocks' plane-frame ``x``, ``y``, m): a camera height or depth unit the
    pose and the image disagree on.
    """
    offset = float(c[0] + c[1] * np.mean(x) + c[2] * np.mean(y))
    if abs(offset) > tolerance_m:
        raise InvalidInputError(
            f"depth image: the support is {1e3 * offset:+.1f} mm off the declared plane z = 0 "
            f"(plane_tolerance {1e3 * tolerance_m:g} mm) with the camera {pose.position[2]:g} m "
            "above it: check the camera pose's height and the depth's unit (16UC1 in mm, "
            "32FC1 in m)")


def _block_any(flags: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """True for the blocks holding at least one valid flagged pixel."""
    H, W = flags.shape
    h, w = H // BLOCK, W // BLOCK
    f = (flags & valid)[:h * BLOCK, :w * BLOCK].reshape(h, BLOCK, w, BLOCK)
    return f.any(axis=(1, 3))
