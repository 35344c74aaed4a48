# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""What a node that reads camera images knows of the camera: the newest usable ``camera_info``
and ``camera/pose``, why the newest of each was refused, and whether an image can be read with
them. The outline node and the monitor's shape watch read images alike through it.

The rules:

- a ``camera_info`` that gives no pinhole model (uncalibrated, fx = 0, ...) is refused, and
  images are refused until a usable one arrives;
- a ``camera/pose`` must be in the plane frame (the frame the outline, or the prediction it is
  matched against, is in) and a rotation; after a refused one images are refused until a
  usable one arrives: the camera may have moved;
- an image whose ``header.frame_id`` is not its ``camera_info``'s comes from another camera
  than the calibration (either one naming no frame is taken).
"""
from __future__ import annotations

from dataclasses import dataclass

from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import CameraInfo, Image

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.ros.messages.images import camera_model, camera_pose

__all__ = ["CameraInputs"]


@dataclass
class CameraInputs:
    """The camera model and pose a node reads its images with (mutable: updated as the
    messages arrive).

    Parameters
    ----------
    frame_id : str
        The plane frame a ``camera/pose`` must be in.
    pose : CameraPose, optional
        The camera's pose until a ``camera/pose`` arrives (a node parameter); None: wait for
        one.
    pose_source : str, optional
        Where a pose comes from, for the refusal of an image read before one came.

    Examples
    --------
    >>> inputs = CameraInputs("object")
    >>> msg = PoseStamped()
    >>> msg.header.frame_id = "world"
    >>> inputs.take_pose(msg)
    "camera/pose is in frame 'world', not the plane frame 'object'"
    >>> inputs.image_problem(Image())
    'no camera_info yet'
    """

    frame_id: str
    pose: CameraPose | None = None
    pose_source: str = "camera/pose"
    camera: CameraModel | None = None
    camera_frame: str = ""
    """``header.frame_id`` of the camera_info in use ("" when it names none)."""
    camera_refused: str = ""
    """Why the newest camera_info was refused ("" when it was not)."""
    pose_refused: str = ""
    """Why the newest camera/pose was refused ("" when it was not)."""

    def take_info(self, msg: CameraInfo) -> str:
        """Take ``msg`` as the camera's model; return why it was refused ("" when it was not)."""
        try:
            self.camera, self.camera_frame = camera_model(msg), msg.header.frame_id
            self.camera_refused = ""
        except InvalidInputError as error:
            self.camera, self.camera_refused = None, str(error)
        return self.camera_refused

    def take_pose(self, msg: PoseStamped) -> str:
        """Take ``msg`` as the camera's pose; return why it was refused ("" when it was not)."""
        if msg.header.frame_id != self.frame_id:
            self.pose_refused = (f"camera/pose is in frame {msg.header.frame_id!r}, not the "
                                 f"plane frame {self.frame_id!r}")
        else:
            try:
                self.pose, self.pose_refused = camera_pose(msg.pose), ""
            except InvalidInputError as error:
                self.pose_refused = f"camera/pose: {error}"
        return self.pose_refused

    def image_problem(self, msg: Image) -> str:
        """Why ``msg`` cannot be read with the camera's model and pose ("" when it can)."""
        if self.camera is None:
            return ("no usable camera_info: the newest was refused "
                    f"({self.camera_refused})" if self.camera_refused
                    else "no camera_info yet")
        if self.pose is None or self.pose_refused:
            return (f"no usable camera pose: the newest was refused ({self.pose_refused})"
                    if self.pose_refused else f"no camera pose yet ({self.pose_source})")
        frame = msg.header.frame_id
        if frame and self.camera_frame and frame != self.camera_frame:
            return (f"image header.frame_id {frame!r} is not the camera_info's "
                    f"{self.camera_frame!r}: the image and the calibration come from different "
                    "cameras (publish both in the camera's optical frame)")
        return ""
