# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A calibrated camera above a support plane: pinhole intrinsics, plumb-bob distortion, pose.

Conventions are ROS's (REP 103/104/118, ``sensor_msgs/CameraInfo``):

- pixel coordinates (u, v): u to the right, v down, the centre of pixel (row r, column c) at
  (u, v) = (c, r), as in OpenCV and ``camera_calibration``;
- the camera's optical frame: z along the view, x right, y down;
- the **plane frame**: the support plane is z = 0, z up; outlines are in its x-y plane, m;
- the camera pose is the optical frame's pose in the plane frame (rotation R, position t), so a
  point p_c in the optical frame is R p_c + t in the plane frame;
- a depth pixel holds the z of the surface point in the optical frame (not the ray length).

Plumb-bob distortion (k1, k2, p1, p2, k3) maps normalised coordinates (a, b) = (x/z, y/z) to

    a' = a (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 a b + p2 (r^2 + 2 a^2)
    b' = b (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 b^2) + 2 p2 a b,   r^2 = a^2 + b^2,

and (u, v) = (fx a' + cx, fy b' + cy). Undistortion inverts this by fixed-point iteration and
reports its residual in pixels.

>>> camera = CameraModel(640, 480, fx=600.0, fy=600.0, cx=319.5, cy=239.5)
>>> pose = CameraPose.looking_down(0.5)
>>> uv = camera.project(pose, np.array([[0.05, 0.0, 0.0]]))
>>> print(np.round(uv, 6))
[[379.5 239.5]]
>>> print(np.round(camera.back_project(pose, uv, 0.0).points, 9))
[[0.05 0.  ]]
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from squeeze_grasp_ros.mechanics.errors import (
    InvalidInputError,
    NumericalError,
    unit_quaternion,
)
from squeeze_grasp_ros.mechanics.vocabulary import DistortionModel

__all__ = ["BackProjection", "CameraModel", "CameraPose", "UNDISTORT_TOLERANCE_PX"]

UNDISTORT_TOLERANCE_PX = 1e-6
"""Largest reprojection residual (px) accepted from :meth:`CameraModel.undistort`."""

MAX_PIXELS = 50_000_000
"""Largest image (width x height) a camera model may declare."""


@dataclass(frozen=True)
class CameraPose:
    """The camera's optical frame in the plane frame.

    Attributes
    ----------
    rotation : tuple of 9 float
        R, row-major: its columns are the optical x, y, z axes in the plane frame.
    translation : tuple of 3 float
        t, the optical centre in the plane frame, m (t_z > 0: above the plane).
    """

    rotation: tuple[float, ...]
    translation: tuple[float, ...]

    def __post_init__(self) -> None:
        R = np.asarray(self.rotation, float)
        t = np.asarray(self.translation, float)
        if R.shape != (9,) or t.shape != (3,) or not (np.all(np.isfinite(R))
                                                       and np.all(np.isfinite(t))):
            raise InvalidInputError("camera pose: rotation must be 9 finite numbers and "
                                    "translation 3 finite numbers (m)")
        R = R.reshape(3, 3)
        if np.abs(R @ R.T - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0:
            raise InvalidInputError("camera pose: the rotation is not a proper rotation matrix "
                                    "(check the quaternion or roll/pitch/yaw)")
        if not t[2] > 0:
            raise InvalidInputError(f"camera pose: the camera must be above the support plane "
                                    f"(z > 0 m), got z = {t[2]:g} m")
        if not R[2, 2] < 0:
            raise InvalidInputError("camera pose: the camera must look down at the plane (its "
                                    f"optical z axis has plane z component {R[2, 2]:.3g}, must "
                                    "be < 0)")

    @property
    def matrix(self) -> np.ndarray:
        """The rotation R (3, 3)."""
        return np.asarray(self.rotation, float).reshape(3, 3)

    @property
    def position(self) -> np.ndarray:
        """The position t (3,), m."""
        return np.asarray(self.translation, float)

    @classmethod
    def from_xyz_rpy(cls, x: float, y: float, z: float, roll: float, pitch: float,
                     yaw: float) -> CameraPose:
        """Pose from a position (m) and fixed-axis roll, pitch, yaw (rad), as tf2 and URDF do:
        R = Rz(yaw) Ry(pitch) Rx(roll).
        """
        cr, sr, cp, sp, cy, sy = (np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch),
                                  np.cos(yaw), np.sin(yaw))
        R = np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                      [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                      [-sp, cp * sr, cp * cr]])
        return cls(tuple(R.ravel().tolist()), (float(x), float(y), float(z)))

    @classmethod
    def from_xyz_quaternion(cls, x: float, y: float, z: float, qx: float, qy: float, qz: float,
                            qw: float) -> CameraPose:
        """Pose from a position (m) and a unit quaternion (x, y, z, w), as
        ``geometry_msgs/Pose`` holds it (normalised here, within tf2's tolerance:
        :func:`~squeeze_grasp_ros.mechanics.errors.unit_quaternion`).
        """
        qx, qy, qz, qw = unit_quaternion("the camera pose's orientation", [qx, qy, qz, qw])
        R = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw),
                       2 * (qx * qz + qy * qw)],
                      [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz),
                       2 * (qy * qz - qx * qw)],
                      [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw),
                       1 - 2 * (qx * qx + qy * qy)]])
        return cls(tuple(R.ravel().tolist()), (float(x), float(y), float(z)))

    @classmethod
    def looking_down(cls, height: float, *, x: float = 0.0, y: float = 0.0,
                     yaw: float = 0.0) -> CameraPose:
        """A camera ``height`` m above (x, y), looking straight down; with ``yaw`` = 0 the
        image's u axis is the plane's x axis and v is -y (roll = pi).
        """
        return cls.from_xyz_rpy(x, y, height, np.pi, 0.0, yaw)

    def to_json(self) -> dict:
        """``{"position": [x, y, z], "quaternion": [qx, qy, qz, qw]}`` (m)."""
        R = self.matrix
        w = 0.5 * np.sqrt(max(1.0 + np.trace(R), 0.0))
        if w > 1e-3:
            q = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (4 * w)
        else:  # rotation near pi: take the largest diagonal axis
            k = int(np.argmax(np.diag(R)))
            i, j = (k + 1) % 3, (k + 2) % 3
            s = 2.0 * np.sqrt(max(1.0 + R[k, k] - R[i, i] - R[j, j], 0.0))
            q = np.zeros(3)
            q[k], q[i], q[j] = 0.25 * s, (R[i, k] + R[k, i]) / s, (R[j, k] + R[k, j]) / s
            w = (R[j, i] - R[i, j]) / s
        return {"position": self.position.tolist(), "quaternion": [*q.tolist(), float(w)]}


@dataclass(frozen=True)
class BackProjection:
    """Pixels back-projected onto a horizontal plane.

    Attributes
    ----------
    points : (n, 2) ndarray
        Plane-frame x, y of each ray's intersection with the plane, m.
    undistort_residual_px : float
        Largest reprojection error of the undistorted pixels, px.
    """

    points: np.ndarray
    undistort_residual_px: float


@dataclass(frozen=True)
class CameraModel:
    """A pinhole camera with plumb-bob distortion (the ``sensor_msgs/CameraInfo`` of a raw
    image).

    Attributes
    ----------
    width, height : int
        Image size, px.
    fx, fy, cx, cy : float
        Intrinsics K, px.
    distortion : tuple of 5 float
        k1, k2, p1, p2, k3 (dimensionless; all zero: no distortion).
    frame_id : str
        The optical frame's name (``header.frame_id`` of the images).
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    distortion: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)
    frame_id: str = "camera_optical_frame"

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 8:
                raise InvalidInputError(f"camera {name} must be an integer >= 8 px, got "
                                        f"{value!r}")
        if self.width * self.height > MAX_PIXELS:
            raise InvalidInputError(f"camera image {self.width} x {self.height} px exceeds "
                                    f"{MAX_PIXELS} pixels")
        for name in ("fx", "fy"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InvalidInputError(f"camera {name} must be a positive focal length in px, "
                                        f"got {value!r}")
        for name in ("cx", "cy"):
            if not np.isfinite(getattr(self, name)):
                raise InvalidInputError(f"camera {name} must be finite (px)")
        if len(self.distortion) != 5 or not np.all(np.isfinite(self.distortion)):
            raise InvalidInputError("camera distortion must be 5 finite plumb-bob coefficients "
                                    f"(k1, k2, p1, p2, k3), got {list(self.distortion)}")

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width): the shape of its images."""
        return (self.height, self.width)

    def distort(self, normalised: np.ndarray) -> np.ndarray:
        """Pixels (n, 2) of normalised image coordinates (n, 2) (a, b) = (x/z, y/z)."""
        k1, k2, p1, p2, k3 = self.distortion
        a, b = normalised[:, 0], normalised[:, 1]
        r2 = a * a + b * b
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        ad = a * radial + 2 * p1 * a * b + p2 * (r2 + 2 * a * a)
        bd = b * radial + p1 * (r2 + 2 * b * b) + 2 * p2 * a * b
        return np.column_stack([self.fx * ad + self.cx, self.fy * bd + self.cy])

    def undistort(self, pixels: np.ndarray, *, iterations: int = 40) -> tuple[np.ndarray, float]:
        """Normalised coordinates (n, 2) of ``pixels`` (n, 2) and the largest residual (px).

        Raises
        ------
        NumericalError
            When the iteration leaves a residual above :data:`UNDISTORT_TOLERANCE_PX` (strong
            distortion outside the calibrated field of view).
        """
        pixels = np.asarray(pixels, float).reshape(-1, 2)
        ad = (pixels[:, 0] - self.cx) / self.fx
        bd = (pixels[:, 1] - self.cy) / self.fy
        if not any(self.distortion):
            return np.column_stack([ad, bd]), 0.0
        k1, k2, p1, p2, k3 = self.distortion
        a, b = ad.copy(), bd.copy()
        residual = np.inf
        for done in range(1, iterations + 1):
            r2 = a * a + b * b
            radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
            a = (ad - 2 * p1 * a * b - p2 * (r2 + 2 * a * a)) / radial
            b = (bd - p1 * (r2 + 2 * b * b) - 2 * p2 * a * b) / radial
            if done % 8 == 0 or done == iterations:
                normalised = np.column_stack([a, b])
                residual = (float(np.abs(self.distort(normalised) - pixels).max())
                            if len(pixels) else 0.0)
                if residual <= 0.01 * UNDISTORT_TOLERANCE_PX:
                    break
        if not residual <= UNDISTORT_TOLERANCE_PX:
            raise NumericalError(
                f"undistortion did not converge: the plumb-bob model is not invertible at some "
                f"pixels, {float(np.hypot(ad, bd).max()):.3g} focal lengths from the principal "
                f"point ({self._why_far()})", residuals={"reprojection_px": residual})
        return normalised, residual

    def _why_far(self) -> str:
        """The likelier cause of pixels beyond the distortion's invertible radius."""
        if not (0.0 <= self.cx <= self.width and 0.0 <= self.cy <= self.height):
            return (f"the principal point ({self.cx:g}, {self.cy:g}) px lies outside the "
                    f"{self.width} x {self.height} px image: check K")
        return "distortion too strong for the image size?"

    def project(self, pose: CameraPose, points: np.ndarray) -> np.ndarray:
        """Pixels (n, 2) of plane-frame points (n, 3), m; points behind the camera are refused."""
        p = (np.asarray(points, float) - pose.position) @ pose.matrix
        if not np.all(p[:, 2] > 0):
            raise InvalidInputError("a point to project lies behind the camera")
        return self.distort(p[:, :2] / p[:, 2:3])

    def ray_directions(self, pose: CameraPose, normalised: np.ndarray) -> np.ndarray:
        """Plane-frame directions (n, 3) of the rays through normalised coordinates (n, 2);
        scaled so that their optical z component is 1 (a depth d gives the point t + d dir).
        """
        R = pose.matrix
        a, b = normalised[:, :1], normalised[:, 1:2]
        return a * R[:, 0] + b * R[:, 1] + R[:, 2]

    def ray_grid(self, pose: CameraPose, axis: int) -> np.ndarray:
        """Plane-frame component ``axis`` (0 x, 1 y, 2 z) of :meth:`ray_directions` at every
        pixel centre, (height, width).
        """
        R, grid = pose.matrix, self.pixel_grid
        return R[axis, 0] * grid[..., 0] + R[axis, 1] * grid[..., 1] + R[axis, 2]

    def back_project(self, pose: CameraPose, pixels: np.ndarray,
                     plane_height: float) -> BackProjection:
        """Plane-frame x, y where the rays through ``pixels`` (n, 2) meet z = ``plane_height``.

        Raises
        ------
        InvalidInputError
            When a ray does not meet the plane in front of the camera (it looks at the horizon
            or the plane is above the camera).
        """
        normalised, residual = self.undistort(pixels)
        rays = self.ray_directions(pose, normalised)
        t = pose.position
        with np.errstate(divide="ignore", invalid="ignore"):
            depth = (plane_height - t[2]) / rays[:, 2]
        if not np.all(depth > 0):
            raise InvalidInputError(f"some pixels look away from the plane z = "
                                    f"{plane_height:g} m (horizon in view, or the plane is not "
                                    "below the camera)")
        return BackProjection(t[:2] + depth[:, None] * rays[:, :2], residual)

    @cached_property
    def pixel_grid(self) -> np.ndarray:
        """Normalised coordinates (height, width, 2) of every pixel centre (cached)."""
        v, u = np.mgrid[0:self.height, 0:self.width]
        pixels = np.column_stack([u.ravel(), v.ravel()]).astype(float)
        normalised, _ = self.undistort(pixels)
        return normalised.reshape(self.height, self.width, 2)

    def ground_pixel_size(self, pose: CameraPose, point: np.ndarray) -> float:
        """Side (m) of one pixel's footprint at plane-frame ``point`` (3,): the mean of the
        plane distances to the points one pixel right and one pixel down.
        """
        uv = self.project(pose, np.asarray(point, float).reshape(1, 3))[0]
        z = float(np.asarray(point, float)[2])
        corners = self.back_project(pose, np.array([uv, uv + (1.0, 0.0), uv + (0.0, 1.0)]),
                                    z).points
        return 0.5 * float(np.linalg.norm(corners[1] - corners[0])
                           + np.linalg.norm(corners[2] - corners[0]))

    def to_camera_info(self) -> dict:
        """The ``sensor_msgs/CameraInfo`` fields (``height, width, distortion_model, d, k, r,
        p``; ``header.frame_id``) as plain values.
        """
        k = [self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0]
        return {"header": {"frame_id": self.frame_id}, "height": self.height,
                "width": self.width, "distortion_model": DistortionModel.PLUMB_BOB,
                "d": list(map(float, self.distortion)), "k": k,
                "r": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                "p": [self.fx, 0.0, self.cx, 0.0, 0.0, self.fy, self.cy, 0.0, 0.0, 0.0, 1.0, 0.0]}
