# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Objects given as typed fields (issue 32, item 1): the ROS-free conversion against the YAML
route (same mesh, same plan), frames placed by a pose, the validation messages naming the
message fields, and ``load_object`` on a real planner node with an ``ObjectDescription``.
"""
from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import yaml

from squeeze_grasp_ros.planning import (
    ErrorCode,
    FramePose,
    PlannerError,
    PlannerLimits,
    TypedMaterial,
    TypedObject,
    load_object,
    object_key,
    object_source,
    read_scene,
    squeeze_plan,
    typed_scene,
)

REPO = Path(__file__).resolve().parents[1]
FOAM = (REPO / "config" / "scenes" / "foam_square.yaml").read_text()
FOAM_MATERIAL = TypedMaterial(5.0e4, 0.3, 0.0254)
SQUARE = ((-0.05, -0.05), (0.05, -0.05), (0.05, 0.05), (-0.05, 0.05))
LIMITS = PlannerLimits()


def loaded(source):
    return load_object(source, object_key(source, "x", "", LIMITS), LIMITS)


def foam_like(**fields) -> TypedObject:
    """The foam square scene's object, fingers and friction as typed fields."""
    base = dict(material=FOAM_MATERIAL, outline=SQUARE, mesh_nodes=2000,
                placements=((-0.05, 0.0), (0.05, 0.0)), tip_radius=0.02, mu=0.4)
    return TypedObject(**{**base, **fields})


def test_a_typed_square_meshes_and_plans_like_the_yaml_scene():
    """The foam square as an outline polygon and as a named shape: same nodes, same contact
    nodes and the same squeeze forces as config/scenes/foam_square.yaml (which names a square).
    """
    yaml_object = loaded(read_scene(FOAM, ""))
    polygon = loaded(typed_scene(foam_like()))
    shape = loaded(typed_scene(foam_like(outline=(), shape="square",
                                         shape_parameters={"side": (0.1,)})))
    reference = squeeze_plan(yaml_object, [], "stable", 0.003)
    for typed in (polygon, shape):
        assert typed.num_nodes == yaml_object.num_nodes
        assert typed.finger_nodes == yaml_object.finger_nodes
        np.testing.assert_allclose(typed.body.mesh.nodes, yaml_object.body.mesh.nodes,
                                   atol=1e-12)
        assert typed.scene.mu == 0.4
        plan = squeeze_plan(typed, [], "stable", 0.003)
        np.testing.assert_allclose(plan.boundary_displacement, reference.boundary_displacement,
                                   rtol=1e-9, atol=1e-15)


def test_an_outline_in_another_frame_lands_where_its_pose_puts_it():
    """The square given in a frame turned 30 degrees and shifted, with the pose of that frame
    (z of the pose dropped): the scene's outline and placements are the object-frame square's
    to float rounding, and it meshes and plans like it (the mesher sees points 1e-17 m apart
    from the direct ones, so its refinement may differ by a few nodes: forces within 1 %).
    """
    angle, shift = math.radians(30.0), np.array([0.2, -0.1])
    R = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    local = (np.asarray(SQUARE) - shift) @ R  # object = R local + shift
    fingers = (np.array([[-0.05, 0.0], [0.05, 0.0]]) - shift) @ R
    pose = FramePose((0.2, -0.1, 0.7), (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)))
    source = typed_scene(foam_like(outline=local, placements=fingers, frame_id="camera_plane",
                                   frame_pose=pose))
    np.testing.assert_allclose(source.scene.object.shape["points"], SQUARE, atol=1e-15)
    np.testing.assert_allclose([f.placement.point for f in source.scene.fingers.values()],
                               [[-0.05, 0.0], [0.05, 0.0]], atol=1e-15)
    moved, direct = loaded(source), loaded(typed_scene(foam_like()))
    assert abs(moved.num_nodes - direct.num_nodes) <= 0.02 * direct.num_nodes
    for obj in (moved, direct):
        np.testing.assert_allclose(obj.body.mesh.nodes[list(obj.finger_nodes)],
                                   [[-0.05, 0.0], [0.05, 0.0]], atol=1e-12)
    forces = [np.linalg.norm(squeeze_plan(o, [], "stable", 0.003).squeeze.forces)
              for o in (moved, direct)]
    assert forces[0] == pytest.approx(forces[1], rel=0.01)


def test_holes_make_a_ring_like_solid():
    hole = [(0.02 * math.cos(t), 0.02 * math.sin(t)) for t in np.linspace(0, 2 * math.pi, 24,
                                                                          endpoint=False)]
    ring = loaded(typed_scene(foam_like(holes=[hole], mesh_nodes=800)))
    inner = np.linalg.norm(ring.body.mesh.nodes, axis=1)
    assert inner.min() == pytest.approx(0.02, rel=0.05)
    mesh = ring.body.mesh
    corners = mesh.nodes[mesh.triangles]
    edges = corners[:, 1:] - corners[:, :1]
    area = 0.5 * np.abs(edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0]).sum()
    assert area == pytest.approx(0.01 - math.pi * 0.02**2, rel=0.01)


@pytest.mark.parametrize("fields, words", [
    (dict(material=TypedMaterial(-1.0, 0.3, 0.01)),
     ["object.material.youngs_modulus", "Pa", "[0.001, 1e+13]"]),
    (dict(material=TypedMaterial(5e4, 0.7, 0.01)), ["object.material.poisson_ratio", "0.5"]),
    (dict(material=TypedMaterial(5e4, 0.3, 0.0)), ["object.material.thickness", "m"]),
    (dict(material=TypedMaterial(5e4, 0.3, 0.01, "rubbery")), ["object.material.model",
                                                                "neo_hookean"]),
    (dict(outline=((0, 0), (0.1, 0.1), (0.1, 0), (0, 0.08))),
     ["object.outline.polygon.points", "self-intersect"]),
    (dict(outline=((0, 0), (0.1, 0))), ["object.outline.polygon.points", "at least 3"]),
    (dict(outline=((0, 0), (0.1, 0.1), (0.1, 0), (0, 0.1))),
     ["object.outline.polygon.points", "self-intersecting"]),
    (dict(outline=((0, 0), (0.05, 0), (0.1, 0))), ["object.outline.polygon.points", "degenerate"]),
    (dict(outline=((0.1, 0.1),) * 3),
     ["object.outline.polygon.points", "distinct vertices, got 1"]),
    (dict(outline=((0, 0), (0.1, 0), (float("nan"), 0.1))),
     ["object.outline.polygon.points[2]", "finite"]),
    (dict(outline=((0, 0, 0), (0.1, 0, 0), (0.1, 0.1, 0), (0, 0.1, 0))),
     ["object.outline.polygon.points[0]", "(x, y) pair"]),
    (dict(outline=((0, 0), (0.1,), (0.1, 0.1))), ["object.outline.polygon.points[1]", "pair"]),
    (dict(outline=((0, 0), (0.1, "a"), (0.1, 0.1))), ["object.outline.polygon.points", "numbers"]),
    (dict(placements=((0.0, 0.0, 0.0), (0.1, 0.0, 0.0))), ["object.placements[0]", "pair"]),
    # coordinates beyond 2**53 m (a float32 Point32 holds up to 3.4e38) were named
    # 'object.shape_parameters points' / 'holes[0]', with no range
    (dict(outline=((0, 0), (1e16, 0), (0.1, 0.1))),
     ["object.outline.polygon.points[1] lies at [1e+16, 0.0] m", "+-9.007e+15 m (2^53)"]),
    (dict(holes=[((0.01, 0.01), (1e16, 0.01), (0.01, 0.02))]),
     ["object.holes[0].points[1] lies at [1e+16, 0.01] m", "(2^53)"]),
    (dict(holes=[((0.5, 0.5), (0.6, 0.5), (0.6, 0.6))]), ["object.holes", "inside"]),
    (dict(outline=(), shape="disk", shape_parameters={"radius": (-0.05,)}),
     ["object.shape_parameters radius", "m"]),
    (dict(outline=(), shape="disk", shape_parameters={"side": (0.05,)}),
     ["object.shape_parameters", "'side'", "radius"]),
    (dict(outline=(), shape="file"), ["object.shape", "disk"]),
    (dict(shape="disk"), ["either object.outline", "not both"]),
    (dict(mesh_nodes=5), ["object.mesh_nodes", "10"]),
    (dict(mesh_max_area=-1.0), ["object.mesh_max_area", "m^2"]),
    (dict(placements=((0.0, 0.0),)), ["object.placements", "2 points"]),
    (dict(tip_radius=-0.01), ["object.tip_radius", "m"]),
    (dict(mu=-0.2), ["object.mu"]),
    (dict(frame_id="tilted", frame_pose=FramePose((0, 0, 0), (0.1, 0.0, 0.0, 0.995))),
     ["object.frame_pose", "rad", "z axis"]),
    # placed beyond the scenes' range by the pose: before, "object.shape_parameters points must
    # be a list of [x, y] number pairs (m)", naming a field the request did not give
    (dict(frame_id="camera", frame_pose=FramePose((1e308, 0, 0), (0, 0, 0, 1))),
     ["object.placements[0] lies at [1e+308, 0.0] m", "object.frame_pose", "2^53"]),
    (dict(frame_id="camera", placements=(), frame_pose=FramePose((1e300, 0, 0), (0, 0, 0, 1))),
     ["object.outline.polygon.points[0] lies at", "object.frame_pose", "2^53"]),
])
def test_bad_typed_objects_name_the_message_field(fields, words):
    with pytest.raises(PlannerError) as caught:
        typed_scene(foam_like(**fields))
    assert caught.value.code == ErrorCode.INVALID_ARGUMENT
    for word in words:
        assert word in str(caught.value), str(caught.value)


def test_exactly_one_source_of_the_object():
    with pytest.raises(PlannerError, match="exactly one of scene_yaml, scene_path and object"):
        object_source(FOAM, "", foam_like())
    with pytest.raises(PlannerError, match="exactly one of scene_yaml, scene_path and object"):
        object_source("", "", TypedObject(material=FOAM_MATERIAL))
    assert object_source(FOAM, "", TypedObject(material=FOAM_MATERIAL)).scene.name == \
        "foam_square"


def test_the_planner_limits_apply_to_typed_objects():
    source = typed_scene(foam_like(mesh_nodes=50_000))
    small = PlannerLimits(max_nodes=5_000)
    with pytest.raises(PlannerError, match="oversized factorized mesh: 50000 nodes"):
        load_object(source, object_key(source, "x", "", small), small)


def test_the_digest_follows_the_object_not_the_field_order():
    a, b = typed_scene(foam_like()), typed_scene(foam_like(mu=0.4, tip_radius=0.02))
    assert object_key(a, "", "", LIMITS).digest == object_key(b, "", "", LIMITS).digest
    c = typed_scene(foam_like(material=TypedMaterial(6.0e4, 0.3, 0.0254)))
    assert object_key(a, "", "", LIMITS).digest != object_key(c, "", "", LIMITS).digest
    assert yaml.safe_load(a.text)["object"]["material"]["E"] == 5.0e4


# --------------------------------------------------------------------------- on the node


@pytest.fixture
def planner(ros_context) -> Iterator:
    from planner_support import Harness

    harness = Harness(ros_context)
    try:
        yield harness
    finally:
        harness.close()


def test_load_object_takes_an_object_description(planner):
    """``load_object`` with a PolygonStamped outline, typed material and mesh size: the same
    object as the YAML route (nodes, contact nodes, plan), and refusals name the field.
    """
    from squeeze_grasp_interfaces.srv import LoadObject, PlanSqueeze
    from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
    from squeeze_grasp_ros.ros.messages.objects import object_description

    by_yaml = planner.load(FOAM, object_id="yaml")
    description = object_description(
        Outline(np.asarray(SQUARE)), "object", youngs_modulus=5.0e4, poisson_ratio=0.3,
        thickness=0.0254, placements=((-0.05, 0.0), (0.05, 0.0)), tip_radius=0.02, mu=0.4,
        mesh_nodes=2000)
    typed = planner.call(LoadObject, "load_object",
                         LoadObject.Request(object=description, object_id="typed"))
    assert typed.success, typed.message
    # the polygon's points travel as float32 (geometry_msgs/Point32, 0.05 m -> 0.05 + 7e-10 m):
    # the mesher refines a little differently, the squeeze stays within 1 %
    assert abs(typed.num_nodes - by_yaml.num_nodes) <= 0.02 * by_yaml.num_nodes
    assert typed.mu == by_yaml.mu
    plans = [planner.call(PlanSqueeze, "plan_squeeze",
                          PlanSqueeze.Request(object_id=i, squeeze_type="stable", depth=0.003))
             for i in ("yaml", "typed")]
    forces = [np.linalg.norm(np.asarray(p.forces)) for p in plans]
    assert forces[1] == pytest.approx(forces[0], rel=0.01)
    description.material.youngs_modulus = 0.0
    refused = planner.call(LoadObject, "load_object", LoadObject.Request(object=description))
    assert not refused.success and refused.error_code == LoadObject.Response.INVALID_ARGUMENT
    assert "object.material.youngs_modulus must be in [0.001, 1e+13] Pa" in refused.message
    both = planner.call(LoadObject, "load_object",
                        LoadObject.Request(object=description, scene_yaml=FOAM))
    assert not both.success and "exactly one of scene_yaml, scene_path and object" in both.message


def test_the_frame_pose_comes_from_a_pose_topic(ros_context):
    """Planner parameters ``frame_pose_topic``/``frame_pose_frame``: an outline in frame
    ``table`` without ``frame_pose`` is placed by the newest latched ``PoseStamped`` there,
    landing on the same object (same digest) as the request that carries that pose itself.
    No pose yet, a stale pose (beyond ``frame_pose_max_age`` of the outline's stamp) and a pose
    in another parent frame are refused with what to do; a pose in the request wins.
    """
    from geometry_msgs.msg import PoseStamped
    from planner_support import Harness
    from rclpy.parameter import Parameter

    from squeeze_grasp_interfaces.srv import LoadObject
    from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
    from squeeze_grasp_ros.ros import messages
    from squeeze_grasp_ros.ros.messages.objects import object_description
    from squeeze_grasp_ros.ros.nodes import pipeline

    harness = Harness(ros_context, parameter_overrides=[
        Parameter("frame_pose_topic", value="table/pose"),
        Parameter("frame_pose_frame", value="table"),
        Parameter("frame_pose_max_age", value=1.0)])
    try:
        # the square in the table frame, whose origin is at (0.2, 0.1) m turned by 90 deg
        local = Outline(np.asarray(SQUARE) + [0.01, 0.0])
        quarter = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))

        def request(stamp_s: float, frame: str = "table", pose=None) -> LoadObject.Request:
            description = object_description(
                local, frame, youngs_modulus=5.0e4, poisson_ratio=0.3, thickness=0.0254,
                mesh_nodes=400)
            description.outline.header.stamp = messages.header(int(stamp_s * 1e9)).stamp
            if pose is not None:
                description.frame_pose.position.x, description.frame_pose.position.y = pose
                (description.frame_pose.orientation.x, description.frame_pose.orientation.y,
                 description.frame_pose.orientation.z,
                 description.frame_pose.orientation.w) = quarter
            return LoadObject.Request(object=description)

        def load(req: LoadObject.Request) -> LoadObject.Response:
            return harness.call(LoadObject, "load_object", req)

        missing = load(request(10.0))
        assert not missing.success and missing.error_code == LoadObject.Response.INVALID_ARGUMENT
        assert "object.frame_pose is unset, so its pose comes from table/pose" in missing.message
        assert "nothing has arrived yet" in missing.message

        publisher = harness.node.create_publisher(PoseStamped, "table/pose", pipeline.LATCHED)

        def publish(stamp_s: float, parent: str = "object") -> None:
            pose = PoseStamped(header=messages.header(int(stamp_s * 1e9), parent))
            pose.pose.position.x, pose.pose.position.y = 0.2, 0.1
            (pose.pose.orientation.x, pose.pose.orientation.y, pose.pose.orientation.z,
             pose.pose.orientation.w) = quarter
            publisher.publish(pose)
            harness.spin_until(lambda: harness.planner.frame_poses.latest is not None and (
                messages.stamp_ns(harness.planner.frame_poses.latest.header.stamp)
                == int(stamp_s * 1e9)))

        publish(10.0)
        by_topic = load(request(10.4))
        assert by_topic.success, by_topic.message
        by_request = load(request(10.4, pose=(0.2, 0.1)))
        in_object = load(request(10.4, frame="object"))
        assert by_request.success and in_object.success
        assert by_topic.object_digest == by_request.object_digest != in_object.object_digest

        stale = load(request(12.0))
        assert not stale.success and "2.000 s from the outline's stamp" in stale.message
        assert "frame_pose_max_age = 1 s): stale" in stale.message
        assert load(request(12.0, pose=(0.2, 0.1))).success  # the request's pose wins
        assert load(request(12.0, frame="shelf")).success  # other frames: as before

        publish(12.0, parent="map")
        wrong = load(request(12.0))
        assert not wrong.success and "whose pose is in frame 'map'" in wrong.message
    finally:
        harness.close()
