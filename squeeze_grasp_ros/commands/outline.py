# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp outline``: an object's outline in metres from a top-down mask or depth image."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import yaml

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.commands.camera_args import add_camera_arguments, load_camera
from squeeze_grasp_ros.commands.common import add_plot_argument, output_file
from squeeze_grasp_ros.inputs import InputError, read_bytes
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ImageEncoding, ShapeType
from squeeze_grasp_ros.outputs import write_atomically
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.extract import ObjectOutline, extract_outline
from squeeze_grasp_ros.perception.image_files import decode_image

MAX_IMAGE_BYTES = 256 * 1024 * 1024
"""Largest image file read (256 MiB)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """IMAGE, the camera, extraction options, --output, --plot."""
    parser.add_argument("image", metavar="IMAGE",
                        help="mask (8-bit PNG/NPY, object > 0) or depth (16-bit PNG/NPY in mm, "
                             "float NPY in m)")
    add_camera_arguments(parser)
    parser.add_argument("--encoding", choices=ImageEncoding.values(),
                        help="override the encoding read from the file type")
    parser.add_argument("--object-height", type=float, default=0.0, metavar="M",
                        help="mask: height of the object's top face above the plane (its "
                             "thickness), m (default 0)")
    parser.add_argument("--min-height", type=float, default=0.004, metavar="M",
                        help="depth: pixels higher than this above the support are object, m "
                             "(default 0.004)")
    parser.add_argument("--plane-tolerance", type=float, default=0.002, metavar="M",
                        help="depth: largest offset and unevenness of the support, m "
                             "(default 0.002)")
    parser.add_argument("--max-tilt", type=float, default=2.0, metavar="DEG",
                        help="depth: largest tilt of the support against the pose (default 2)")
    parser.add_argument("--tolerance", type=float, default=None, metavar="M",
                        help="simplification tolerance, m (default: 0.15 of the pixel "
                             "footprint at the object)")
    parser.add_argument("--frame-id", default="plane", help="name of the plane frame "
                                                            "(default plane)")
    parser.add_argument("--output", metavar="FILE", type=output_file,
                        help="write the outline: .yaml = a scene's object.shape (the "
                             "recognised disk, ellipse or annulus when it is centred at the "
                             "frame's origin, else a polygon, or a spline when it has no "
                             "corners, with holes), .json = an outline file ({\"outline\", "
                             "\"holes\"}) for shape type file")
    add_plot_argument(parser)


def _write(path: str, found: ObjectOutline, source: str) -> str:
    suffix = Path(path).suffix.lower()
    if suffix in (".yaml", ".yml"):
        text = (f"# squeeze-grasp outline {source}: frame {found.frame_id}, m; use as a scene's "
                "object.shape\n" + yaml.safe_dump({"shape": found.to_scene_shape()},
                                                  default_flow_style=None, sort_keys=False))
    elif suffix == ".json":
        text = json.dumps({"outline": found.outline.points.tolist(),
                           "holes": [h.tolist() for h in found.outline.holes],
                           "frame_id": found.frame_id}) + "\n"
    else:
        raise InvalidInputError(f"--output {path}: give a .yaml (scene shape) or .json "
                                "(outline file) name")
    write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"), "the outline")
    return path


def run(args: argparse.Namespace) -> dict:
    """Read the image and camera, extract, write and plot."""
    camera, pose = load_camera(args)
    try:
        data = read_bytes(args.image, what="image", max_bytes=MAX_IMAGE_BYTES)
    except InputError as exc:
        raise InvalidInputError(str(exc)) from None
    image, encoding = decode_image(data, Path(args.image).suffix)
    encoding = ImageEncoding(args.encoding) if args.encoding else encoding
    found = extract_outline(image, encoding, camera, pose, tolerance_m=args.tolerance,
                            object_height_m=args.object_height, min_height_m=args.min_height,
                            plane_tolerance_m=args.plane_tolerance, max_tilt_deg=args.max_tilt,
                            frame_id=args.frame_id)
    out = {"image": args.image, **found.to_json()}
    if args.output:
        out["output"] = _write(args.output, found, args.image)
    if args.plot:
        out["plot"] = plot(image, found, camera, pose, args.plot)
    return out


def plot(image: np.ndarray, found: ObjectOutline, camera: CameraModel, pose: CameraPose,
         path: str) -> str:
    """The image around the object with the outline projected back onto it (other blobs
    marked x), and the outline in metres.
    """
    fig, (ax, ax_m) = plots.figure(2, size=5.0)
    shown = np.where(np.isfinite(image.astype(float)), image, np.nan)
    ax.imshow(shown, cmap="gray" if found.encoding == ImageEncoding.MONO8 else "viridis",
              interpolation="nearest")
    for k, loop in enumerate((found.outline.points, *found.outline.holes)):
        xyz = np.column_stack([loop, np.full(len(loop), found.plane_height)])
        uv = camera.project(pose, np.vstack([xyz, xyz[:1]]))
        ax.plot(uv[:, 0], uv[:, 1], "-", color="C1", lw=0.9,
                label="outline" if k == 0 else None)
        ax.plot(uv[:-1, 0], uv[:-1, 1], ".", color="C3", ms=2.5)
        closed = np.vstack([loop, loop[:1]])
        ax_m.plot(closed[:, 0], closed[:, 1], ".-", color="C1", lw=0.9, ms=3)
        if k == 0:  # zoom onto the object, with a margin
            lo, hi = uv.min(axis=0), uv.max(axis=0)
            pad = max(20.0, 0.25 * float((hi - lo).max()))
            ax.set_xlim(lo[0] - pad, hi[0] + pad)
            ax.set_ylim(hi[1] + pad, lo[1] - pad)
    for blob in found.others:
        ax.plot(*blob.centroid_px, "x", color="C3", ms=6)
    ax.set_title(f"{found.encoding}: outline ({len(found.outline.points)} vertices, "
                 f"{len(found.outline.holes)} holes)", fontsize=9)
    ax.set_xlabel("u [px]")
    ax.set_ylabel("v [px]")
    ax_m.set_aspect("equal")
    ax_m.set_xlabel(f"x [m] ({found.frame_id})")
    ax_m.set_ylabel("y [m]")
    ax_m.set_title(f"area {1e4 * found.outline.area:.4g} cm^2, tolerance "
                   f"{1e3 * found.tolerance_m:.2g} mm", fontsize=9)
    return plots.save(fig, path)


def summary(result: dict) -> str:
    """Human-readable report."""
    blob = result["blob"]
    lines = [f"{result['encoding']} image {result['image']}: object blob {blob['area_px']} px at "
             f"({blob['centroid_px'][0]:.1f}, {blob['centroid_px'][1]:.1f}) px"
             + (f"; {len(result['others'])} other blobs" if result["others"] else ""),
             f"outline in frame {result['frame_id']} at z = {1e3 * result['plane_height']:.4g} "
             f"mm: {result['vertices']} vertices, {result['holes']} holes, area "
             f"{1e4 * result['area_m2']:.5g} cm^2",
             f"pixel {1e3 * result['pixel_size_m']:.4g} mm at the object; simplified to "
             f"{1e3 * result['tolerance_m']:.3g} mm from {result['contour_points']} contour "
             "points"]
    primitive = result["primitive"]
    if primitive is None:
        corners = len(result["shape"].get("corners", []))
        lines.append(f"shape: {result['recognised']} ("
                     + ("corners kept" if result["recognised"] == ShapeType.POLYGON
                        else f"smooth{f' between {corners} corners' if corners else ''}, no "
                             "primitive fits") + ")")
    else:
        parameters = ", ".join(f"{k} {1e3 * v:.4g} mm" for k, v in primitive.items()
                               if k not in ("type", "centre", "residual_m", "theta"))
        lines.append(f"shape: {primitive['type']} at ({1e3 * primitive['centre'][0]:.4g}, "
                     f"{1e3 * primitive['centre'][1]:.4g}) mm, {parameters}"
                     + (f", theta {primitive['theta']:.4g} rad" if "theta" in primitive else "")
                     + f"; fitted within {1e3 * primitive['residual_m']:.3g} mm")
    if result["support"]:
        s = result["support"]
        lines.append(f"support plane: tilt {s['tilt_deg']:.3g} deg, flatness "
                     f"{1e3 * s['flatness_m']:.3g} mm")
    for key in ("output", "plot"):
        if key in result:
            lines.append(f"{key}: {result[key]}")
    return "\n".join(lines)
