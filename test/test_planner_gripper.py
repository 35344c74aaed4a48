# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner's ``plan_gripper_grasp`` service on real rclpy: equal to the mechanics API's
plan (same deterministic code), poses in the object frame, joint commands through the device's
transmission, and the reasons of bad requests.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from planner_support import Harness

from squeeze_grasp_interfaces.srv import PlanGripperGrasp
from squeeze_grasp_ros.planning import ErrorCode
from squeeze_grasp_ros.resources import device_file, scene_file
from squeeze_grasp_ros.scene import GraspSetup, load_scene
from squeeze_grasp_ros.scene.gripper import load_gripper
from squeeze_grasp_ros.scene.gripper_plan import plan_gripper_grasp

SPONGE = scene_file("sponge_gripper").read_text()


def request(**fields) -> PlanGripperGrasp.Request:
    base = dict(object_id="sponge_gripper", gripper_name="generic_85mm", mu=0.6,
                relative_closing=0.15, count=5, evaluate=2)
    return PlanGripperGrasp.Request(**{**base, **fields})


def test_plan_gripper_grasp_service_equals_the_mechanics(planner: Harness) -> None:
    loaded = planner.load(SPONGE)
    response = planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(weight=0.3))
    assert response.success, response.message
    assert response.object_digest == loaded.object_digest and response.gripper == "generic_85mm"
    setup = GraspSetup.build(load_scene(scene_file("sponge_gripper")))
    gripper = load_gripper(device_file("generic_85mm"))
    plan = plan_gripper_grasp(setup.solid, gripper, 0.6, relative_closing=0.15, count=5,
                              evaluate=2, weight=0.3)
    assert len(response.candidates) == len(plan.candidates) == 5
    for msg, c in zip(response.candidates, plan.candidates):
        assert (msg.rank, list(msg.nodes), list(msg.first_contacts)) == (
            c.rank, list(c.nodes), list(c.first_contacts))
        assert msg.pose.header.frame_id == "object"
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        assert (p.x, p.y) == (c.center[0], c.center[1])
        assert 2 * math.atan2(q.z, q.w) == pytest.approx(c.yaw, abs=1e-12)
        assert (msg.aperture_at_contact, msg.stiffness) == (c.aperture, c.stiffness)
        assert msg.evaluated == (c.rank < 2)
    for msg, e in zip(response.candidates, plan.evaluations):
        assert (msg.jaw_force, msg.aperture_planned, msg.closing) == (
            e.jaw_force, e.aperture, e.closing)
        assert msg.lift_force == pytest.approx(0.3 / 1.2) and msg.holds_weight == e.holds_weight
        assert list(msg.joint_names) == ["finger_joint"]
        assert gripper.aperture(msg.joint_positions[0]) == pytest.approx(e.aperture, abs=1e-12)
        assert np.allclose(msg.joint_efforts, [1.25 * e.jaw_force])


@pytest.mark.parametrize(("fields", "message"), [
    ({"gripper_name": ""}, "give exactly one of gripper_yaml and gripper_name"),
    ({"gripper_name": "../etc/passwd"}, "gripper_name must be a shipped device's name"),
    ({"gripper_name": "nope"}, "no shipped device 'nope'"),
    ({"gripper_name": "", "gripper_yaml": "name: g\nopening: {max: 0.1}\n"},
     "gripper.max_force"),
    ({"relative_closing": 1.5}, "relative_closing must be in [0.0, 1.0]"),
    ({"mu": float("nan")}, "mu must be finite"),
    ({"evaluate": 9}, "evaluate must be in [0, count=5]"),
    ({"force_margin": 0.5, "evaluate": 0}, "force_margin must be >= 1 (0: 1.25), got 0.5"),
    ({"force_margin": 0.5}, "force_margin must be >= 1"),
    ({"object_id": "missing"}, "missing"),
])
def test_bad_gripper_requests_get_the_reason(planner: Harness, fields, message) -> None:
    planner.load(SPONGE)
    response = planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(**fields))
    assert not response.success
    assert message in response.message
    assert response.error_code in (ErrorCode.INVALID_ARGUMENT, ErrorCode.UNKNOWN_OBJECT)


def test_a_count_out_of_range_is_named_as_the_requests_field(planner: Harness) -> None:
    """Before, ``count`` was refused as "best_count must be ...", a field this service lacks."""
    planner.load(SPONGE)
    response = planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(count=2**31 - 1))
    assert (response.success, response.error_code) == (False, ErrorCode.INVALID_ARGUMENT)
    assert response.message == "count must be in [0, 100000], got 2147483647"


def test_a_gripper_too_small_is_not_feasible(planner: Harness) -> None:
    planner.load(SPONGE)
    small = ("name: tiny\nopening: {max: 0.02}\nmax_force: 10\n"
             "pad: {shape: pad, width: 0.01, edge_radius: 0.001}\n"
             "transmission: {joints: [j], position_per_aperture: 1.0}\n")
    response = planner.call(PlanGripperGrasp, "plan_gripper_grasp",
                            request(gripper_name="", gripper_yaml=small))
    assert not response.success and response.error_code == ErrorCode.NOT_FEASIBLE
    assert "fits tiny's opening" in response.message


def candidate_fields(response: PlanGripperGrasp.Response) -> list[tuple]:
    return [(c.rank, list(c.nodes), list(c.first_contacts), c.aperture_at_contact, c.stiffness,
             c.pose.pose.position.x, c.pose.pose.position.y) for c in response.candidates]


def test_the_grasp_map_is_cached_with_the_loaded_object(planner: Harness) -> None:
    planner.load(SPONGE)
    maps = planner.planner.cache.get("sponge_gripper").maps
    first = planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(evaluate=0))
    second = planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(evaluate=0))
    assert first.success and second.success
    assert (maps.misses, maps.hits) == (1, 1)
    assert candidate_fields(second) == candidate_fields(first) and len(first.candidates) == 5
    # the map is of point contacts: another pad, gripper or yaw range is ranked on the same map
    small_pads = load_gripper(device_file("generic_85mm"))
    other = planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(
        evaluate=0, gripper_name="", use_yaw_range=True, yaw_min=1.2, yaw_max=1.9,
        gripper_yaml=device_file("generic_85mm").read_text().replace(
            f"width: {small_pads.pad.width}", "width: 0.01")))
    assert other.success and (maps.misses, maps.hits) == (1, 2)
    assert candidate_fields(other) != candidate_fields(first)
    # another mu is another map, and the answer of the first comes again from the cache
    assert planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(mu=0.2)).success
    again = planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(evaluate=0))
    assert (maps.misses, maps.hits) == (2, 3)
    assert candidate_fields(again) == candidate_fields(first)
    # a reload of the same scene keeps the object and its maps; another object under the id
    # replaces both
    planner.load(SPONGE)
    assert planner.planner.cache.get("sponge_gripper").maps is maps
    planner.load(SPONGE.replace("E: 5.0e4", "E: 6.0e4"), object_id="sponge_gripper", replace=True)
    fresh = planner.planner.cache.get("sponge_gripper").maps
    assert fresh is not maps and (fresh.misses, fresh.hits) == (0, 0)
    planner.call(PlanGripperGrasp, "plan_gripper_grasp", request(evaluate=0))
    assert (fresh.misses, fresh.hits) == (1, 0)
