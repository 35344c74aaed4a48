# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``--camera-info`` and ``--camera-pose``, shared by the ``render`` and ``outline`` verbs."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from squeeze_grasp_ros.inputs import InputError, load_yaml, read_text
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.camera_info import camera_from_info


def add_camera_arguments(parser: argparse.ArgumentParser) -> None:
    """The camera's calibration file and its pose above the support plane."""
    parser.add_argument("--camera-info", metavar="FILE", required=True,
                        help="camera calibration: camera_calibration YAML or CameraInfo fields "
                             "(width, height, k, d, distortion_model) in YAML or JSON")
    parser.add_argument("--camera-pose", metavar="V", nargs="+", type=float, required=True,
                        help="the optical frame in the plane frame (z up, plane z = 0): "
                             "X Y Z ROLL PITCH YAW (m, rad, fixed axes as tf2) or "
                             "X Y Z QX QY QZ QW; straight down from 0.5 m: 0 0 0.5 3.14159265 0 0")


def load_camera(args: argparse.Namespace) -> tuple[CameraModel, CameraPose]:
    """The camera model and pose named by ``--camera-info`` and ``--camera-pose``."""
    path = Path(args.camera_info)
    try:
        text = read_text(path, what="camera info")
        data = json.loads(text) if path.suffix.lower() == ".json" else load_yaml(
            text, what="camera info")
    except InputError as exc:
        raise InvalidInputError(str(exc)) from None
    except json.JSONDecodeError as exc:
        raise InvalidInputError(f"camera info {path.name}: invalid JSON at line {exc.lineno}, "
                                f"column {exc.colno}") from None
    camera = camera_from_info(data, what=f"camera info {path.name}")
    values = args.camera_pose
    if len(values) == 6:
        pose = CameraPose.from_xyz_rpy(*values)
    elif len(values) == 7:
        pose = CameraPose.from_xyz_quaternion(*values)
    else:
        raise InvalidInputError(f"--camera-pose takes 6 numbers (x y z roll pitch yaw) or 7 "
                                f"(x y z qx qy qz qw), got {len(values)}")
    return camera, pose
