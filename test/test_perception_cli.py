# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ``render`` and ``outline`` verbs as a user runs them: a scene's object rendered into
PNG/NPY files with the shipped camera calibration, read back as a scene polygon that meshes,
and bad input ending in one line with exit code 2.
"""
from __future__ import annotations

import json

import numpy as np
import pytest
import yaml
from perception_support import skimage_or_skip

from squeeze_grasp_ros import cli
from squeeze_grasp_ros.mechanics.elastic.shapes import load_outline
from squeeze_grasp_ros.resources import config_dir, scene_file
from squeeze_grasp_ros.scene import build_mesh, build_outline, load_scene, parse_scene

CAMERA = ["--camera-info", str(config_dir() / "examples" / "camera_top.yaml"),
          "--camera-pose", "0.004", "-0.003", "0.5", "3.1", "0.03", "0.4"]


def run_json(capsys, argv):
    code = cli.main([*argv, "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_render_then_outline_gives_back_the_scene_object(tmp_path, capsys):
    skimage_or_skip()
    mask, depth = tmp_path / "mask.png", tmp_path / "depth.png"
    scene = scene_file("nonconvex_blob")
    code, rendered = run_json(capsys, ["render", str(scene), *CAMERA, "--mask", str(mask),
                                       "--depth", str(depth)])
    assert code == 0 and not rendered["touches_border"]
    true = build_outline(load_scene(scene).object.shape)
    for image, extra in ((mask, ["--object-height", "0.0254"]), (depth, [])):
        out = tmp_path / f"{image.stem}.yaml"
        code, found = run_json(capsys, ["outline", str(image), *CAMERA, *extra,
                                        "--output", str(out), "--plot",
                                        str(tmp_path / f"{image.stem}_plot.png")])
        assert code == 0
        assert found["area_m2"] == pytest.approx(true.area, rel=0.005)
        assert (tmp_path / f"{image.stem}_plot.png").stat().st_size > 10_000
        shape = yaml.safe_load(out.read_text())["shape"]
        data = yaml.safe_load(scene.read_text())
        data["object"]["shape"] = shape
        data["fingers"] = {"F1": {"tip_radius": 0.015, "placement": {"angle_deg": 180}},
                           "F2": {"tip_radius": 0.015, "placement": {"angle_deg": 0}}}
        mesh = build_mesh(parse_scene(data))
        assert mesh.n > 500


def test_a_d_shape_comes_back_as_a_spline_with_its_two_corners(tmp_path, capsys):
    """A user's D (a half disk as a spline with its two corners) through render and outline:
    the report names the corners, the scene shape keeps exactly two, within 0.5 mm (half a
    pixel) of the true ones.
    """
    skimage_or_skip()
    a = np.linspace(-np.pi / 2, np.pi / 2, 81)
    points = np.c_[0.04 * np.cos(a) - 0.02, 0.04 * np.sin(a)]
    data = yaml.safe_load(scene_file("nonconvex_blob").read_text())
    data["object"]["shape"] = {"type": "spline", "points": points.tolist(), "corners": [0, 80]}
    data["fingers"] = {"F1": {"tip_radius": 0.015, "placement": {"point": [-0.02, 0.0]}},
                       "F2": {"tip_radius": 0.015, "placement": {"point": [0.02, 0.0]}}}
    scene, mask, out = tmp_path / "d.yaml", tmp_path / "d.png", tmp_path / "d_seen.yaml"
    scene.write_text(yaml.safe_dump(data))
    assert cli.main(["render", str(scene), *CAMERA, "--mask", str(mask)]) == 0
    height = str(data["object"]["material"]["thickness"])
    capsys.readouterr()
    assert cli.main(["outline", str(mask), *CAMERA, "--object-height", height,
                     "--output", str(out)]) == 0
    assert "shape: spline (smooth between 2 corners, no primitive fits)" in \
        capsys.readouterr().out
    shape = yaml.safe_load(out.read_text())["shape"]
    corners = np.array(shape["points"])[shape["corners"]]
    assert len(corners) == 2
    offset = np.linalg.norm(corners[:, None] - points[[0, -1]][None], axis=2).min(axis=1)
    assert offset.max() < 5e-4, offset


def test_a_ring_comes_back_with_its_hole_as_json_outline_file(tmp_path, capsys):
    skimage_or_skip()
    depth = tmp_path / "ring.npy"
    assert cli.main(["render", str(scene_file("ring_ring")), *CAMERA, "--depth",
                     str(depth)]) == 0
    assert "depth: " in capsys.readouterr().out
    assert np.load(depth).dtype == np.float32
    out = tmp_path / "ring.json"
    code, found = run_json(capsys, ["outline", str(depth), *CAMERA, "--output", str(out)])
    assert code == 0 and found["holes"] == 1 and found["encoding"] == "32FC1"
    assert len(load_outline(out).holes) == 1  # the outline file keeps the hole


@pytest.mark.parametrize("argv, message", [
    (["--camera-pose", "0", "0", "0.5"], "--camera-pose takes 6 numbers"),
    (["--camera-pose", "0", "0", "-0.5", "3.1", "0", "0"], "above the support plane"),
    (["--encoding", "16UC1"], "must hold uint16"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv, message):
    mask = tmp_path / "mask.npy"
    np.save(mask, np.zeros((480, 640), np.uint8))
    pose = argv if argv[0] == "--camera-pose" else CAMERA[2:]
    extra = [] if argv[0] == "--camera-pose" else argv
    code = cli.main(["outline", str(mask), *CAMERA[:2], *pose, *extra])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("option, message", [
    (["--seed", "-1"], "seed must be an integer >= 0, got -1"),
    (["--blur", "1e9"], "blur_px must be at most the image's larger side (640 px)"),
    (["--depth-noise", "1e308"], "depth_noise_m must be in [0, 0.1], got 1e+308"),
    (["--mask-noise", "1e308"], "mask_noise must be in [0, 1], got 1e+308"),
])
def test_render_refuses_a_negative_seed_and_a_blur_wider_than_the_image(tmp_path, capsys,
                                                                        option, message):
    """Both were tracebacks: numpy's seed ValueError, a 60 GiB kernel's MemoryError. A noise
    of 1e308 wrote an image of overflowed noise with exit 0 and numpy RuntimeWarnings (a depth
    of inf at every pixel, 0 in a 16UC1 PNG); its bounds are the scene camera's.
    """
    mask = tmp_path / "mask.png"
    code = cli.main(["render", str(scene_file("foam_square")), *CAMERA, "--mask", str(mask),
                     *option])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not mask.exists()


def test_render_says_when_the_object_is_out_of_view(tmp_path, capsys):
    """A camera pointed beside the object rendered an empty mask and said only '0.0 px'."""
    away = ["--camera-info", CAMERA[1], "--camera-pose", "1.5", "0", "0.5", "3.1", "0", "0"]
    mask = tmp_path / "mask.png"
    assert cli.main(["render", str(scene_file("foam_square")), *away, "--mask", str(mask)]) == 0
    out = capsys.readouterr().out
    assert "covers 0.0 px (the object is out of view: the images show only the plane)" in out
    far = [*away[:3], "1e9", *away[4:]]  # was a ValueError traceback, exit 1
    assert cli.main(["render", str(scene_file("foam_square")), *far, "--mask", str(mask)]) == 0
    assert "the object is out of view" in capsys.readouterr().out
    assert cli.main(["render", str(scene_file("foam_square")), *CAMERA, "--mask", str(mask)]) == 0
    assert "out of view" not in capsys.readouterr().out


def test_render_refuses_a_png_depth_beyond_16uc1(tmp_path, capsys):
    """A camera 70 m up wrote a 16UC1 PNG of zeros (every pixel invalid) and exit 0."""
    high = ["--camera-info", CAMERA[1], "--camera-pose", "0", "0", "70", "3.14159265", "0", "0"]
    png, npy = tmp_path / "depth.png", tmp_path / "depth.npy"
    code = cli.main(["render", str(scene_file("foam_square")), *high, "--depth", str(png)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "the depth reaches 70 m, beyond what 16UC1 holds" in err and "write .npy" in err
    assert not png.exists()
    assert cli.main(["render", str(scene_file("foam_square")), *high, "--depth", str(npy)]) == 0
    assert np.load(npy).max() == pytest.approx(70.0)  # the plane; the object 25.4 mm nearer


def test_an_npy_name_on_another_format_is_refused_with_one_line(tmp_path, capsys):
    """An .npz archive named .npy ended in an AttributeError traceback; a PNG or text file
    named .npy was called 'pickled (object) data'.
    """
    archive, text = tmp_path / "archive.npy", tmp_path / "text.npy"
    with open(archive, "wb") as fh:
        np.savez(fh, mask=np.zeros((480, 640), np.uint8))
    text.write_text("hello\n")
    for path in (archive, text):
        assert cli.main(["outline", str(path), *CAMERA]) == 2
        err = capsys.readouterr().err
        assert "not an NPY array file" in err and len(err.strip().splitlines()) == 1, err


def test_an_empty_mask_and_a_colour_png_are_refused(tmp_path, capsys):
    skimage_or_skip()
    from PIL import Image

    empty, colour = tmp_path / "empty.png", tmp_path / "colour.png"
    Image.fromarray(np.zeros((480, 640), np.uint8)).save(empty)
    Image.fromarray(np.zeros((480, 640, 3), np.uint8)).save(colour)
    assert cli.main(["outline", str(empty), *CAMERA]) == 2
    assert "no object in view" in capsys.readouterr().err
    assert cli.main(["outline", str(colour), *CAMERA]) == 2
    assert "mode RGB" in capsys.readouterr().err


def test_scene_polygons_take_holes_and_refuse_bad_ones():
    """A non-convex hole (its vertex mean lies outside it) meshes to the exact area; a hole
    crossing the polygon is refused naming it.
    """
    base = yaml.safe_load(scene_file("foam_square").read_text())
    hole = [[-0.03, -0.03], [0.03, -0.03], [0.03, 0.03], [0.0, -0.01], [-0.03, 0.03]]
    base["object"]["shape"] = {"type": "polygon",
                               "points": [[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05],
                                          [-0.05, 0.05]], "holes": [hole]}
    mesh = build_mesh(parse_scene(base))
    a, b, c = (mesh.nodes[mesh.triangles[:, k]] for k in range(3))
    area = 0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]).sum()
    assert len(mesh.inner_boundaries) == 1 and area == pytest.approx(0.01 - 0.0024, rel=1e-9)
    base["object"]["shape"]["holes"] = [[[0.04, 0.0], [0.07, 0.0], [0.05, 0.02]]]
    with pytest.raises(Exception, match=r"polygon.holes\[0\] must lie strictly inside"):
        build_mesh(parse_scene(base))
    base["object"]["shape"]["holes"] = [[1, 2]]
    with pytest.raises(Exception, match=r"object.shape.holes\[0\] must be a list of \[x, y\]"):
        parse_scene(base)
