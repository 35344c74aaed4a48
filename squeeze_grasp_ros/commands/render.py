# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp render``: a scene's object as the simulated top-down camera sees it."""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from squeeze_grasp_ros.commands.camera_args import add_camera_arguments, load_camera
from squeeze_grasp_ros.commands.common import add_scene_argument, output_file
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.outputs import write_atomically
from squeeze_grasp_ros.perception.image_files import encode_png
from squeeze_grasp_ros.perception.render import (
    MAX_16UC1_M,
    MAX_NOISE,
    CameraViews,
    render_views,
    ring_band,
)
from squeeze_grasp_ros.scene import build_outline, load_scene


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, the camera, the images to write, blur and noise."""
    add_scene_argument(parser)
    add_camera_arguments(parser)
    parser.add_argument("--mask", metavar="FILE.png", type=output_file,
                        help="write the mono8 mask (PNG, or NPY by suffix)")
    parser.add_argument("--depth", metavar="FILE.png", type=output_file,
                        help="write the depth: .png = 16UC1 in mm, .npy = 32FC1 in m")
    parser.add_argument("--blur", type=float, default=0.0, metavar="PX",
                        help="Gaussian blur of the coverage, std in px (default 0)")
    parser.add_argument("--depth-noise", type=float, default=0.0, metavar="M",
                        help="Gaussian depth noise, std in m, at most "
                             f"{MAX_NOISE['depth_noise_m']:g} (default 0)")
    parser.add_argument("--mask-noise", type=float, default=0.0, metavar="F",
                        help="Gaussian noise on the coverage before quantisation, std as a "
                             f"fraction of full scale, at most {MAX_NOISE['mask_noise']:g} "
                             "(default 0)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the noise (default 0)")


def _save_npy(path: Path, image: np.ndarray) -> None:
    with open(path, "wb") as fh:  # a file object: np.save would append .npy to the name
        np.save(fh, image, allow_pickle=False)


def _write(path: str, image: np.ndarray) -> str:
    if Path(path).suffix.lower() == ".npy":
        write_atomically(path, lambda tmp: _save_npy(tmp, image), "the image")
    elif Path(path).suffix.lower() == ".png":
        write_atomically(path, lambda tmp: tmp.write_bytes(encode_png(image)), "the image")
    else:
        raise InvalidInputError(f"{path}: images are written as .png or .npy")
    return path


def _depth_image(views: CameraViews, path: str) -> np.ndarray:
    """The depth as written to ``path``: in m for .npy (``32FC1``), in mm for a PNG
    (``16UC1``, :meth:`~squeeze_grasp_ros.perception.render.CameraViews.depth_mm`).

    Raises
    ------
    InvalidInputError
        For a PNG when some depth does not fit 16UC1 (65.535 m at most): it would be written as
        0, invalid.
    """
    if Path(path).suffix.lower() == ".npy":
        return views.depth
    deepest = float(np.max(views.depth))
    if not deepest < MAX_16UC1_M:
        raise InvalidInputError(f"--depth {path}: the depth reaches {deepest:.4g} m, beyond "
                                f"what 16UC1 holds (mm in uint16, below {MAX_16UC1_M} m); "
                                "write .npy (32FC1, m) or bring the camera closer")
    return views.depth_mm()


def run(args: argparse.Namespace) -> dict:
    """Render and write the images; report what the camera sees."""
    scene = load_scene(args.scene)
    camera, pose = load_camera(args)
    height = scene.object.material.thickness
    outline = build_outline(scene.object.shape)
    if scene.object.ring is not None:  # the shape is the wall's middle curve
        outline = ring_band(outline, scene.object.ring.wall_thickness)
    views = render_views(outline, camera, pose, top_height=height,
                         blur_px=args.blur, depth_noise_m=args.depth_noise,
                         mask_noise=args.mask_noise, seed=args.seed)
    out = {"scene": args.scene, "camera": camera.to_camera_info(), "pose": pose.to_json(),
           "top_height": height, "object_pixels": float(views.coverage.sum()),
           "touches_border": bool(views.coverage[[0, -1], :].any()
                                  or views.coverage[:, [0, -1]].any())}
    if args.mask:
        out["mask"] = _write(args.mask, views.mask)
    if args.depth:
        out["depth"] = _write(args.depth, _depth_image(views, args.depth))
    return out


def summary(result: dict) -> str:
    """Human-readable report."""
    cam = result["camera"]
    lines = [f"{cam['width']} x {cam['height']} px camera at "
             f"{', '.join(f'{v:.4g}' for v in result['pose']['position'])} m; top face "
             f"{1e3 * result['top_height']:.4g} mm above the plane covers "
             f"{result['object_pixels']:.1f} px"
             + (" (it touches the image border)" if result["touches_border"] else "")
             + (" (the object is out of view: the images show only the plane)"
                if result["object_pixels"] == 0 else "")]
    for key in ("mask", "depth"):
        if key in result:
            lines.append(f"{key}: {result[key]}")
    return "\n".join(lines)
