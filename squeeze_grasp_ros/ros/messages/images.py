# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Camera streams: ``sensor_msgs/Image`` <-> numpy, ``CameraInfo`` <-> camera models, poses."""
from __future__ import annotations

import numpy as np
from geometry_msgs.msg import Pose
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import CameraInfo, Image

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ImageEncoding
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.camera_info import camera_from_info
from squeeze_grasp_ros.ros.messages.common import header

PIXEL_TYPES: dict[ImageEncoding, np.dtype] = {
    ImageEncoding.MONO8: np.dtype(np.uint8),
    ImageEncoding.DEPTH_16UC1: np.dtype(np.uint16),
    ImageEncoding.DEPTH_32FC1: np.dtype(np.float32),
}
"""Pixel type of each encoding the outline extraction reads."""

SAME_AS: dict[str, ImageEncoding] = {"8UC1": ImageEncoding.MONO8}
"""Encodings read as one of :class:`ImageEncoding` because their pixels are the same: a
one-channel 8-bit image is a mask, whichever name its segmentation node gives it."""


def image_array(msg: Image) -> tuple[np.ndarray, ImageEncoding]:
    """The pixels of an ``Image`` (rows of ``step`` bytes, either byte order) and its encoding.

    Raises
    ------
    InvalidInputError
        An encoding other than mono8 (or 8UC1, read as mono8), 16UC1, 32FC1, or a size that
        does not match the data.
    """
    try:
        encoding = SAME_AS.get(msg.encoding) or ImageEncoding(msg.encoding)
    except ValueError:
        raise InvalidInputError(f"image encoding must be one of "
                                f"{[*ImageEncoding.values(), *SAME_AS]}, got "
                                f"{msg.encoding!r}") from None
    dtype = PIXEL_TYPES[encoding].newbyteorder(">" if msg.is_bigendian else "<")
    row = msg.width * dtype.itemsize
    if msg.height < 1 or msg.width < 1 or msg.step < row or len(msg.data) != msg.step * msg.height:
        raise InvalidInputError(f"image of {msg.width} x {msg.height} px, step {msg.step} B "
                                f"has {len(msg.data)} B of data (expected step x height, step "
                                f">= {row} B)")
    raw = np.frombuffer(bytes(msg.data), np.uint8).reshape(msg.height, msg.step)[:, :row]
    return np.ascontiguousarray(raw).view(dtype).reshape(msg.height, msg.width).astype(
        PIXEL_TYPES[encoding]), encoding


def image_msg(pixels: np.ndarray, encoding: ImageEncoding, ns: int, frame_id: str) -> Image:
    """An ``Image`` (little-endian, packed rows) of ``pixels`` in ``encoding``, stamped ``ns``."""
    pixels = np.ascontiguousarray(pixels, PIXEL_TYPES[encoding].newbyteorder("<"))
    height, width = pixels.shape
    return Image(header=header(ns, frame_id), height=height, width=width,
                 encoding=encoding.value, is_bigendian=0, step=width * pixels.itemsize,
                 data=pixels.tobytes())


def camera_info_msg(camera: CameraModel, ns: int) -> CameraInfo:
    """The ``CameraInfo`` of a camera model (plumb-bob, no rectification), stamped ``ns``."""
    info = camera.to_camera_info()
    return CameraInfo(header=header(ns, camera.frame_id), height=info["height"],
                      width=info["width"], distortion_model=str(info["distortion_model"]),
                      d=info["d"], k=info["k"], r=info["r"], p=info["p"])


def camera_model(msg: CameraInfo) -> CameraModel:
    """The camera model of a ``CameraInfo`` (pinhole, plumb-bob)."""
    return camera_from_info({"width": msg.width, "height": msg.height, "k": list(msg.k),
                             "d": list(msg.d), "distortion_model": msg.distortion_model,
                             "header": {"frame_id": msg.header.frame_id}},
                            what="camera_info")


def camera_pose(msg: Pose) -> CameraPose:
    """The camera's optical-frame pose in the plane frame from a ``Pose`` (m, quaternion)."""
    p, q = msg.position, msg.orientation
    return CameraPose.from_xyz_quaternion(p.x, p.y, p.z, q.x, q.y, q.z, q.w)


def pose_of_camera(pose: CameraPose) -> Pose:
    """The ``Pose`` of a camera pose (inverse of :func:`camera_pose`)."""
    x, y, z, w = Rotation.from_matrix(pose.matrix).as_quat()
    msg = Pose()
    msg.position.x, msg.position.y, msg.position.z = map(float, pose.position)
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = (
        float(x), float(y), float(z), float(w))
    return msg
