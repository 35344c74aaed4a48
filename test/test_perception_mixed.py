# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Mixed outlines (issue 32): straight edges and curved stretches, a stadium, a rounded
rectangle and a D shape, seen in anti-aliased synthetic masks.

A mixed outline is a smoothing spline fitted to the trace, pinned only at its real corners (the
D's two, rebuilt where its diameter meets its arc); tangent joins are no mesh corners. Before,
the joins were declared corners (the mesh's boundary nodes anchored there), the spline ran
through Douglas-Peucker vertices (0.04-0.07 px outside the trace, areas up to 0.55 % large)
and the D's corners were cut by up to 0.76 px. The truths here are independent of the
product's curve code: arcs and lines sampled densely.
"""
from __future__ import annotations

import copy

import numpy as np
import pytest
from perception_support import CAMERA, hausdorff_px, pose, skimage_or_skip

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.mesh import vertex_normals
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ShapeType
from squeeze_grasp_ros.perception.render import render_views
from squeeze_grasp_ros.planning.errors import PlannerError
from squeeze_grasp_ros.planning.typed_objects import TypedMaterial, TypedObject, typed_scene
from squeeze_grasp_ros.scene import GraspSetup, build_outline, parse_scene

HEIGHT = 0.02
"""Top face height, m."""


def arc(centre, radius, start, stop, n):
    """``n`` points of a circular arc from angle ``start`` to ``stop`` (rad), m."""
    t = np.linspace(start, stop, n)
    return np.c_[centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)]


def stadium(length=0.06, radius=0.025):
    """Two half disks joined by straight sides (tangent-continuous)."""
    return np.vstack([arc((length / 2, 0), radius, -np.pi / 2, np.pi / 2, 200),
                      arc((-length / 2, 0), radius, np.pi / 2, 1.5 * np.pi, 200)])


def rounded_rectangle(width=0.08, height=0.05, radius=0.012):
    """A rectangle with quarter-circle corners (tangent-continuous)."""
    cx, cy = width / 2 - radius, height / 2 - radius
    quarters = [((cx, cy), 0.0), ((-cx, cy), 0.5 * np.pi), ((-cx, -cy), np.pi),
                ((cx, -cy), 1.5 * np.pi)]
    return np.vstack([arc(c, radius, a, a + 0.5 * np.pi, 60) for c, a in quarters])


def d_shape(radius=0.04):
    """A half disk: an arc closed by its diameter, two right-angle corners."""
    return arc((0.0, 0.0), radius, -np.pi / 2, np.pi / 2, 400)


MIXED = {"stadium": stadium(), "rounded_rectangle": rounded_rectangle(), "d_shape": d_shape()}


def seen(points, view):
    from squeeze_grasp_ros.perception.extract import extract_outline

    truth = Outline(shapes.validate_polyline(points))
    views = render_views(truth, CAMERA, view, top_height=HEIGHT)
    return truth, extract_outline(views.mask, "mono8", CAMERA, view, object_height_m=HEIGHT)


TRUE_CORNERS = {"stadium": 0, "rounded_rectangle": 0, "d_shape": 2}
"""Corners of each truth (tangent discontinuities): the D's two, where its diameter meets the
arc; the stadium's and the rounded rectangle's straight edges run into their arcs tangentially."""

VIEWS = [(0.0, 0.0, 0.0), (0.37e-3, -0.81e-3, 0.3), (-1.3e-3, 0.55e-3, -1.1),
         (0.21e-3, 0.13e-3, 2.0)]
"""Camera offsets (m) and yaw (rad): sub-pixel shifts and rotations."""


@pytest.mark.parametrize("name", sorted(MIXED))
@pytest.mark.parametrize("scale", [0.7, 1.0, 1.4])
def test_mixed_outlines_within_half_a_pixel_corners_included(name, scale):
    """At three scales and four views: the seen outline is a spline whose declared corners are
    the truth's real corners only (tangent joins are no mesh corners), each within 0.5 px of
    the true corner; the outline built from its scene shape is within 0.5 px of the truth
    everywhere (Hausdorff, image plane; the D's corners included) and its area within 0.5 %.
    """
    skimage_or_skip()
    for dx, dy, yaw in VIEWS:
        view = pose(dx=dx, dy=dy, yaw=yaw)
        truth, found = seen(MIXED[name] * scale, view)
        shape = found.to_scene_shape()
        assert found.shape == ShapeType.SPLINE and shape["type"] == "spline"
        corners = np.array(shape["points"])[shape.get("corners", [])]
        assert len(corners) == TRUE_CORNERS[name], (scale, yaw, len(corners))
        if len(corners):
            true_corners = truth.points[[0, -1]]
            offset = np.linalg.norm(corners[:, None] - true_corners[None], axis=2).min(axis=1)
            assert offset.max() <= 0.5 * found.pixel_size_m, (scale, yaw, offset)
        built = build_outline(shape)
        assert hausdorff_px(truth, built, CAMERA, view, HEIGHT) <= 0.5, (scale, yaw)
        assert built.area == pytest.approx(truth.area, rel=0.005), (scale, yaw)


def densified(points, step=4e-4):
    """``points`` with every edge longer than ``step`` (m) split evenly: the true shape's
    straight edges sampled too, so that a spline through them is straight there (a periodic
    spline through the arcs' points alone bows a rounded rectangle's sides by 0.1 mm).
    """
    out = []
    for a, b in zip(points, np.roll(points, -1, axis=0)):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        out.append(a + np.outer(np.arange(n) / n, b - a))
    return np.vstack(out)


def true_shape(name):
    """The true shape as a scene's spline: dense, with the D's two corners declared."""
    points = densified(MIXED[name])
    shape = {"type": "spline", "points": points.tolist()}
    if name == "d_shape":
        ends = MIXED[name][[0, -1]]
        shape["corners"] = [int(np.argmin(np.linalg.norm(points - e, axis=1))) for e in ends]
    return shape


FINGERS = {
    ("stadium", "across"): ([0.004, -0.025], [0.004, 0.025]),
    ("stadium", "along"): ([-0.055, 0.004], [0.055, 0.004]),
    ("rounded_rectangle", "across"): ([0.004, -0.025], [0.004, 0.025]),
    ("rounded_rectangle", "along"): ([-0.04, 0.004], [0.04, 0.004]),
    ("d_shape", "flat"): ([0.0, 0.004], [0.04, 0.004]),
    ("d_shape", "corners"): ([0.012, -0.03816], [0.012, 0.03816]),
}
"""Finger placements (m) of each shape's two squeezes: the stadium and the rounded rectangle
across their long sides and along their long axis, 4 mm off the symmetry line; the D from its
flat to its arc, and across its two corners (1 mm inside the arc's ends)."""


def squeezer(name, direction, nodes, depth):
    """A function squeezing a scene shape as ``name`` is squeezed in ``direction`` (E = 50 kPa,
    nu = 0.3, mu = 0.4, fingertips of 2 cm, ``nodes`` mesh nodes, a stable squeeze to relative
    ``depth``); it returns the mesh and the event-driven squeeze.
    """
    first, second = FINGERS[name, direction]
    base = {"name": name,
            "object": {"material": {"E": 5.0e4, "nu": 0.3, "thickness": HEIGHT},
                       "mesh": {"nodes": nodes, "min_angle": 30}},
            "fingers": {"F1": {"tip_radius": 0.02, "placement": {"point": first}},
                        "F2": {"tip_radius": 0.02, "placement": {"point": second}}},
            "squeeze": {"type": "stable", "relative_depth": depth}, "friction": {"mu": 0.4},
            "effects": ["friction"]}

    def squeezed(shape):
        scene = parse_scene({**copy.deepcopy(base), "object": {**base["object"],
                                                              "shape": shape}})
        setup = GraspSetup.build(scene).precompute()
        return setup.solid.mesh, setup.event_squeeze()

    return squeezed


def seen_shapes(name):
    """The scene shapes of ``name`` seen in the first three views."""
    return [seen(MIXED[name], pose(dx=dx, dy=dy, yaw=yaw))[1].to_scene_shape()
            for dx, dy, yaw in VIEWS[:3]]


def counts(squeeze):
    """The squeeze's event counts, e.g. ``'10A1C3D'``."""
    return "".join(f"{n}{kind}" for kind, n in sorted(squeeze.event_counts.items()) if n)


def assert_same_contact_and_forces(true_mesh, truth, seen_mesh, squeeze):
    """The issue's target beside the events: every final contact node of either squeeze within
    one boundary spacing of one of the other's, and the finger forces within 1 %.
    """
    loop = true_mesh.nodes[true_mesh.boundary]
    spacing = np.median(np.linalg.norm(np.diff(loop, axis=0), axis=1))
    a = true_mesh.nodes[[c.node for c in truth.state.contacts]]
    b = seen_mesh.nodes[[c.node for c in squeeze.state.contacts]]
    for p, q in ((a, b), (b, a)):
        assert np.linalg.norm(p[:, None] - q[None], axis=2).min(axis=1).max() <= 1.01 * spacing
    forces = [[np.linalg.norm(s.finger_force[f]) for f in sorted(s.finger_force)]
              for s in (truth, squeeze)]
    np.testing.assert_allclose(forces[1], forces[0], rtol=0.01)


def along_normals(shape, offset):
    """``shape`` (a scene spline) with each point moved by ``offset`` (m, an array over the
    points, or one value) along the outward normal of its polyline.
    """
    points = np.array(shape["points"])
    moved = points + np.reshape(offset, (-1, 1)) * vertex_normals(points)
    return {**shape, "points": moved.tolist()}


@pytest.mark.parametrize("name, direction, nodes, depth", [
    ("stadium", "across", 1000, 0.10),
    ("stadium", "along", 1000, 0.10),
    ("rounded_rectangle", "across", 1000, 0.10),
    ("d_shape", "flat", 1000, 0.10),
    pytest.param("stadium", "across", 2000, 0.12, marks=pytest.mark.slow),
    pytest.param("rounded_rectangle", "across", 2000, 0.12, marks=pytest.mark.slow),
    pytest.param("rounded_rectangle", "along", 2000, 0.12, marks=pytest.mark.slow),
    pytest.param("d_shape", "flat", 2000, 0.12, marks=pytest.mark.slow),
])
def test_the_seen_mixed_outline_predicts_the_true_shapes_events(name, direction, nodes, depth):
    """The issue's camera-loop target for a mixed outline, at the camera scenes' resolution
    (1 mm pixels) and in three views: the seen shape and the true one (a dense spline, the D's
    corners declared) have the same number of boundary nodes and give the same event counts,
    their final contact nodes lie within one boundary spacing of each other's, and the finger
    forces agree within 1 %.

    These squeezes are no ties: the true shape moved by 10 um (shifted, turned at its ends, or
    moved along its normals by 10 um times cos(k theta) or sin(k theta), k = 0..4) gives its
    own events, but for the D across its flat at 1,000 nodes, whose one move of the 24
    (-10 um cos(4 theta)) gives 9 A instead of 8 (docs/perception.md). Before splines kept
    their resampled boundary, Triangle's boundary splits gave the seen meshes up to 5 boundary
    nodes more (or 2 fewer) than the true ones, and 7 of these 24 squeezes other event counts.
    """
    skimage_or_skip()
    squeezed = squeezer(name, direction, nodes, depth)
    true_mesh, truth = squeezed(true_shape(name))
    for view, shape in enumerate(seen_shapes(name)):
        seen_mesh, squeeze = squeezed(shape)
        assert len(seen_mesh.boundary) == len(true_mesh.boundary), view
        assert counts(squeeze) == counts(truth), view
        assert_same_contact_and_forces(true_mesh, truth, seen_mesh, squeeze)


def test_ties_the_d_across_its_corners():
    """A tie in itself: the D squeezed across its corners (1,000 nodes, 10 %) gives 10 A and 2 D
    events, and 1 C and 3 D when its true outline is moved 10 um inwards (its stick-slip
    events are decided below the outline's accuracy, a few hundredths of a pixel). So the
    seen outlines' events are compared at that sensitivity: each view gives the truth's events
    or the moved truth's; contact nodes and forces agree as the target asks.
    """
    skimage_or_skip()
    squeezed = squeezer("d_shape", "corners", 1000, 0.10)
    true_mesh, truth = squeezed(true_shape("d_shape"))
    moved = {sign: counts(squeezed(along_normals(true_shape("d_shape"), sign * 1e-5))[1])
             for sign in (1, -1)}
    assert counts(truth) == "10A2D" and moved[-1] == "10A1C3D", (counts(truth), moved)
    for view, shape in enumerate(seen_shapes("d_shape")):
        seen_mesh, squeeze = squeezed(shape)
        assert counts(squeeze) in {counts(truth), *moved.values()}, view
        assert_same_contact_and_forces(true_mesh, truth, seen_mesh, squeeze)


def test_ties_the_rounded_rectangle_along_its_axis():
    """A tie in itself: the rounded rectangle squeezed along its long axis (1,000 nodes, 10 %)
    gives 12 A events, 11 when its true outline is moved by 10 um sin(2 theta) along its normals
    (the short sides skewed by 10 um; its last two new contacts come within 1.5 % of the final
    depth, so micrometres decide whether they come before it). Each seen view gives the truth's
    events or the moved truth's; contact nodes within one spacing, forces within 1 %.
    """
    skimage_or_skip()
    squeezed = squeezer("rounded_rectangle", "along", 1000, 0.10)
    true_mesh, truth = squeezed(true_shape("rounded_rectangle"))
    points = np.array(true_shape("rounded_rectangle")["points"])
    theta = np.arctan2(points[:, 1], points[:, 0])
    skewed = counts(squeezed(along_normals(true_shape("rounded_rectangle"),
                                           1e-5 * np.sin(2 * theta)))[1])
    assert (counts(truth), skewed) == ("12A", "11A")
    for view, shape in enumerate(seen_shapes("rounded_rectangle")):
        seen_mesh, squeeze = squeezed(shape)
        assert counts(squeeze) in {"12A", "11A"}, view
        assert_same_contact_and_forces(true_mesh, truth, seen_mesh, squeeze)


@pytest.mark.slow
def test_ties_the_stadium_along_its_axis_stick_slip():
    """A tie in itself: the stadium squeezed along its long axis (2,000 nodes, 12 %) gives 12 A
    events, and its true outline moved by 10 um gives 1-2 C and 1-3 D events more (moved along
    its normals by 10 um cos(theta): 2 C 3 D, by -10 um cos(theta): 1 C 2 D, by 10 um
    sin(3 theta): 2 D; turned by 10 um at its ends, 1 D or 1 C 2 D, the turn's last digits
    decide): its stick-slip events are decided below the outline's accuracy. Each seen view
    gives the events of the truth or of one of these moved truths; the new contacts (A), the
    final contact nodes and the forces are the truth's.
    """
    skimage_or_skip()
    squeezed = squeezer("stadium", "along", 2000, 0.12)
    shape = true_shape("stadium")
    true_mesh, truth = squeezed(shape)
    points = np.array(shape["points"])
    theta = np.arctan2(points[:, 1], points[:, 0])
    moved = {counts(squeezed(along_normals(shape, offset))[1]) for offset in (
        1e-5 * np.cos(theta), -1e-5 * np.cos(theta), 1e-5 * np.sin(3 * theta))}
    assert counts(truth) == "12A" and moved - {"12A"}, moved
    for view, shape in enumerate(seen_shapes("stadium")):
        seen_mesh, squeeze = squeezed(shape)
        assert counts(squeeze) in {counts(truth), *moved}, view
        assert squeeze.event_counts["A"] == 12, view
        assert_same_contact_and_forces(true_mesh, truth, seen_mesh, squeeze)


def test_spline_corners_in_scenes_and_typed_requests():
    """A half disk as a spline with its two corners declared: the area of the half disk
    within 0.1 %, the corners kept; clockwise points give the same corners; the typed request
    carries corners as the spline's ``corners`` shape parameter; bad indices are refused with
    the field named.
    """
    a = np.linspace(-np.pi / 2, np.pi / 2, 9)
    points = 0.04 * np.c_[np.cos(a), np.sin(a)]
    for pts, corners in ((points, [0, 8]), (points[::-1], [0, 8])):
        d = shapes.spline(pts, corners=corners)
        assert d.area == pytest.approx(0.5 * np.pi * 0.04 ** 2, rel=1e-3)
        np.testing.assert_allclose(np.sort(d.points[d.corners][:, 1]), [-0.04, 0.04],
                                   atol=1e-12)
    with pytest.raises(InvalidInputError, match="spline.corners must be indices"):
        shapes.spline(points, corners=[0, 9])
    typed = typed_scene(TypedObject(outline=points.tolist(), shape="spline",
                                    shape_parameters={"corners": (0.0, 8.0)},
                                    material=TypedMaterial(5e4, 0.3, 0.02))).scene
    assert typed.object.shape["corners"] == [0, 8]
    with pytest.raises(PlannerError, match="shape_parameters corners"):
        typed_scene(TypedObject(outline=points.tolist(), shape="spline",
                                shape_parameters={"corners": (0.5,)},
                                material=TypedMaterial(5e4, 0.3, 0.02)))
    with pytest.raises(PlannerError, match="does not go with object.outline"):
        typed_scene(TypedObject(outline=points.tolist(), shape="",
                                shape_parameters={"corners": (0.0,)},
                                material=TypedMaterial(5e4, 0.3, 0.02)))
