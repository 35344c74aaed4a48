# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Camera models from calibration data: ``camera_calibration`` YAML or ``CameraInfo`` fields.

Two layouts are read, from a parsed YAML or JSON mapping:

- the ``camera_calibration`` / ``camera_info_manager`` file: ``image_width``, ``image_height``,
  ``camera_name``, ``camera_matrix: {rows: 3, cols: 3, data: [9]}``, ``distortion_model``,
  ``distortion_coefficients: {rows: 1, cols: 5, data: [5]}`` (the rectification and
  projection matrices are not needed for a raw image and are ignored);
- the ``sensor_msgs/CameraInfo`` field names: ``width``, ``height``, ``k`` (9),
  ``distortion_model``, ``d`` and optionally ``header: {frame_id}`` (as ``ros2 topic echo
  --once /camera_info`` prints them).

>>> info = {"image_width": 640, "image_height": 480, "camera_name": "top",
...         "camera_matrix": {"rows": 3, "cols": 3,
...                           "data": [600, 0, 319.5, 0, 600, 239.5, 0, 0, 1]},
...         "distortion_model": "plumb_bob",
...         "distortion_coefficients": {"rows": 1, "cols": 5, "data": [-0.1, 0.01, 0, 0, 0]}}
>>> camera = camera_from_info(info)
>>> camera.fx, camera.distortion[0], camera.frame_id
(600.0, -0.1, 'top')
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from squeeze_grasp_ros.inputs import yaml11_number
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import DistortionModel
from squeeze_grasp_ros.perception.camera import CameraModel

__all__ = ["camera_from_info"]


def _numbers(value: Any, count: int | None, where: str) -> list[float]:
    if isinstance(value, Mapping):
        value = value.get("data")
    if not isinstance(value, list):
        raise InvalidInputError(f"{where} must be a list of numbers (or {{data: [...]}})")
    value = [yaml11_number(v) for v in value]
    for k, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InvalidInputError(f"{where}[{k}] must be a number, got {v!r}")
    if count is not None and len(value) != count:
        raise InvalidInputError(f"{where} must have {count} numbers, got {len(value)}")
    return [float(v) for v in value]


def _integer(data: Mapping, keys: tuple[str, str], what: str) -> int:
    key = next((k for k in keys if k in data), None)
    if key is None:
        raise InvalidInputError(f"{what}: missing {keys[0]} (or {keys[1]}), the image size in px")
    value = data[key]
    if isinstance(value, bool) or not isinstance(value, int):
        raise InvalidInputError(f"{what}: {key} must be an integer (px), got {value!r}")
    return value


def camera_from_info(data: Any, *, what: str = "camera info") -> CameraModel:
    """A :class:`CameraModel` from a ``camera_calibration`` mapping or ``CameraInfo`` fields.

    Raises
    ------
    InvalidInputError
        A missing or malformed field (named), an unsupported distortion model, or
        ``rational_polynomial`` coefficients beyond plumb-bob's five that are not zero.
    """
    if not isinstance(data, Mapping):
        raise InvalidInputError(f"{what} must be a mapping of calibration fields")
    width = _integer(data, ("image_width", "width"), what)
    height = _integer(data, ("image_height", "height"), what)
    if "camera_matrix" in data:
        k = _numbers(data["camera_matrix"], 9, f"{what}: camera_matrix")
    elif "k" in data or "K" in data:
        k = _numbers(data.get("k", data.get("K")), 9, f"{what}: k")
    else:
        raise InvalidInputError(f"{what}: missing camera_matrix (or k), the 3 x 3 intrinsics")
    if not any(k):  # CameraInfo's convention for a camera without calibration
        raise InvalidInputError(f"{what}: the camera is uncalibrated (its intrinsics are all "
                                "zero); calibrate it (camera_calibration) and publish or pass "
                                "its calibration")
    if abs(k[1]) > 1e-9 or any(abs(v) > 1e-9 for v in k[3:4] + k[6:8]) or abs(k[8] - 1) > 1e-9:
        raise InvalidInputError(f"{what}: the intrinsics must be [fx, 0, cx, 0, fy, cy, 0, 0, 1] "
                                f"(no skew), got {k}")
    model = data.get("distortion_model", DistortionModel.PLUMB_BOB.value)
    if model not in DistortionModel.values():
        raise InvalidInputError(f"{what}: distortion_model must be one of "
                                f"{list(DistortionModel.values())}, got {model!r}")
    raw = data.get("distortion_coefficients", data.get("d", data.get("D", [])))
    d = _numbers(raw, None, f"{what}: distortion coefficients")
    if len(d) > 5 and any(d[5:]):
        raise InvalidInputError(f"{what}: only the five plumb-bob coefficients (k1, k2, p1, p2, "
                                f"k3) are supported; got non-zero k4-k6 {d[5:8]}")
    if len(d) not in (0, 4, 5) and not (len(d) > 5 and model != DistortionModel.PLUMB_BOB):
        raise InvalidInputError(f"{what}: plumb_bob needs 5 distortion coefficients, got {len(d)}")
    d = (d + [0.0] * 5)[:5]
    header = data.get("header")
    frame = header.get("frame_id") if isinstance(header, Mapping) else data.get("camera_name")
    frame = frame if isinstance(frame, str) and frame else "camera_optical_frame"
    if not np.all(np.isfinite(k + d)):
        raise InvalidInputError(f"{what}: intrinsics and distortion must be finite")
    try:
        return CameraModel(width, height, fx=k[0], fy=k[4], cx=k[2], cy=k[5],
                           distortion=tuple(d), frame_id=frame)
    except InvalidInputError as error:  # e.g. fx <= 0: name the file or topic
        raise InvalidInputError(f"{what}: {error}") from None
