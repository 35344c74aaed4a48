# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner node on real rclpy, in one process: every service and action against the
mechanics API (exact equality: both run the same deterministic code), bad requests, a long
action beside a quick service, cancel, parameters from YAML and a clean shutdown.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rclpy
import yaml
from action_msgs.msg import GoalStatus
from geometry_msgs.msg import Vector3
from planner_support import (
    BLOB,
    RING,
    Harness,
    big_disk,
    flat,
    planner_threads,
    scene_of,
    solid_of,
)
from rclpy.context import Context
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future

from squeeze_grasp_interfaces.action import EventSqueeze as EventSqueezeAction
from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.msg import EventSqueezeData
from squeeze_grasp_interfaces.srv import (
    EventSqueeze,
    GraspMap,
    LoadObject,
    PlanResistance,
    PlanSqueeze,
    RingGraspTest,
)
from squeeze_grasp_ros.mechanics.elastic.reduced import boundary_displacement, reduced_stiffness
from squeeze_grasp_ros.mechanics.resistance.frictional import add_adversary, frictional_resistance
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    contact_segments,
    optimal_resistance,
    resistance_grasp,
    sweep_directions,
)
from squeeze_grasp_ros.mechanics.ring.squeeze import ring_grasp
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.graspmap import grasp_map
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel
from squeeze_grasp_ros.planning import ErrorCode
from squeeze_grasp_ros.ros.nodes.planner import PARAMETERS
from squeeze_grasp_ros.scene import build_ring, event_squeeze_scene, finger_nodes, placement_node

REPO = Path(__file__).resolve().parents[1]
RESIST_FIG10 = (REPO / "config" / "scenes" / "resist_fig10.yaml").read_text()


def variant(text: str, path: tuple[str, ...], value: object) -> str:
    """The YAML scene ``text`` with the entry at ``path`` replaced by ``value``."""
    data = yaml.safe_load(text)
    entry = data
    for key in path[:-1]:
        entry = entry[key]
    entry[path[-1]] = value
    return yaml.safe_dump(data)


# --------------------------------------------------------------------------- good requests


def test_load_object_reports_mesh_fingers_and_caches(planner: Harness) -> None:
    obj = solid_of(BLOB)
    scene = scene_of(BLOB)
    first = planner.load(BLOB, return_model=True)
    assert (first.object_id, first.model) == ("blob", "solid")
    assert first.num_nodes == obj.mesh.n and first.num_boundary_nodes == len(obj.mesh.boundary)
    assert tuple(first.finger_nodes) == finger_nodes(scene, obj.mesh)
    assert first.mu == scene.mu and first.precompute_time > 0
    model = first.model_data
    assert np.array_equal(flat(model.node_xy), obj.mesh.nodes.reshape(-1))
    assert np.array_equal(np.asarray(model.triangles), obj.mesh.triangles.reshape(-1))
    assert np.array_equal(np.asarray(model.boundary), obj.mesh.boundary)
    assert (model.youngs_modulus, model.poisson_ratio) == (5.0e4, 0.3)
    again = planner.load(BLOB)
    assert again.precompute_time == 0.0 and len(again.model_data.node_xy) == 0
    assert planner.load(BLOB, object_id="copy").object_id == "copy"
    assert planner.load((REPO / "config/scenes/convex_blob.yaml").read_text()).num_nodes > 0
    by_path = planner.call(
        LoadObject,
        "load_object",
        LoadObject.Request(scene_path=str(REPO / "config/scenes/convex_blob.yaml")),
    )
    assert by_path.success and by_path.object_id == "convex_blob"


@pytest.mark.parametrize("kind", ["stable", "pure"])
@pytest.mark.parametrize("depth", [0.0, 0.003])
def test_plan_squeeze_equals_the_mechanics(planner: Harness, kind: str, depth: float) -> None:
    fingers = list(planner.load(BLOB).finger_nodes)
    obj = solid_of(BLOB)
    red = reduced_stiffness(obj, fingers)
    sq = plan_squeeze(obj, fingers, kind=kind, red=red)
    rho = depth or 1.0
    response = planner.call(
        PlanSqueeze,
        "plan_squeeze",
        PlanSqueeze.Request(object_id="blob", squeeze_type=kind, depth=depth),
    )
    assert response.success and response.error_code == ErrorCode.OK and response.message == ""
    assert np.array_equal(flat(response.displacement), rho * sq.displacement)
    assert np.array_equal(flat(response.forces), rho * sq.forces)
    assert response.energy_per_unit_depth2 == sq.energy_per_unit_depth2
    assert response.stiffness == sq.stiffness
    assert response.rigid_rotation == rho * sq.rigid_rotation
    assert response.inward == sq.inward
    assert response.relative_depth == sq.relative_depth(rho)
    assert np.array_equal(
        flat(response.boundary_displacement),
        boundary_displacement(obj, red, rho * sq.displacement).reshape(-1),
    )
    assert response.force_closure


def test_plan_squeeze_at_three_contacts(planner: Harness) -> None:
    boundary = solid_of(BLOB).mesh.boundary
    nodes = [int(boundary[k]) for k in (0, 11, 23)]
    planner.load(BLOB)
    sq = plan_squeeze(solid_of(BLOB), nodes, kind="stable")
    response = planner.call(
        PlanSqueeze,
        "plan_squeeze",
        PlanSqueeze.Request(object_id="blob", contacts=nodes, squeeze_type="stable"),
    )
    assert response.success, response.message
    assert np.array_equal(flat(response.forces), sq.forces) and not response.force_closure


def test_grasp_map_service_equals_the_mechanics(planner: Harness) -> None:
    planner.load(BLOB)
    gmap = grasp_map(solid_of(BLOB), 0.3)
    response = planner.call(
        GraspMap,
        "grasp_map",
        GraspMap.Request(object_id="blob", mu=0.3, best_count=4, full_matrices=True),
    )
    assert response.success, response.message
    data = response.map
    summary = gmap.to_json()
    assert (data.pairs, data.feasible_pairs, data.inward_pairs, data.force_closure_pairs) == (
        summary["pairs"],
        summary["feasible_pairs"],
        summary["inward_pairs"],
        summary["force_closure_pairs"],
    )
    assert [data.stiffness_min, data.stiffness_max] == summary["stiffness_range"]
    assert [(list(c.contacts), c.quality) for c in data.best] == [
        ([i, j], k) for i, j, k in gmap.best(4)
    ]
    assert np.array_equal(flat(data.stiffness), gmap.stiffness.reshape(-1))
    assert list(data.inward) == gmap.inward.reshape(-1).tolist()
    assert list(data.force_closure) == gmap.force_closure.reshape(-1).tolist()
    default = planner.call(GraspMap, "grasp_map", GraspMap.Request(object_id="blob", mu=0.3))
    assert len(default.map.best) == len(gmap.best(PARAMETERS["best_count"][0]))
    assert len(default.map.stiffness) == 0


@pytest.mark.parametrize("model", ["point", "segment"])
@pytest.mark.parametrize("mode", ["stable", "pure"])
def test_plan_resistance_equals_the_mechanics(planner: Harness, model: str, mode: str) -> None:
    i, j = planner.load(BLOB).finger_nodes
    obj = solid_of(BLOB)
    boundary = obj.mesh.boundary.tolist()
    k = boundary[(boundary.index(i) + boundary.index(j)) // 2]
    sets = [[i], [j], [k]] if model == "point" else contact_segments(obj.mesh, [i, j, k], None)
    grasp = resistance_grasp(obj, dict(zip(("F1", "F2", "A"), sets)))
    res = optimal_resistance(grasp, (-0.004, 0.001), mode=mode)
    sweep = sweep_directions(grasp, mode, 12)
    response = planner.call(
        PlanResistance,
        "plan_resistance",
        PlanResistance.Request(
            object_id="blob",
            contacts=[i, j, k],
            a=Vector3(x=-0.004, y=0.001),
            mode=mode,
            contact_model=model,
            directions=12,
        ),
    )
    assert response.success == res.success, response.message
    if not res.success:
        assert response.error_code == ErrorCode.NOT_FEASIBLE and response.message == res.reason
        return
    assert [response.d1.x, response.d1.y, response.d2.x, response.d2.y] == [*res.d1, *res.d2]
    assert (response.work_f1, response.work_f2, response.work_a, response.work_total) == (
        res.work["F1"],
        res.work["F2"],
        res.work["A"],
        res.work["total"],
    )
    assert (response.unit_work, response.energy, response.rigid_rotation) == (
        res.unit_work,
        res.energy,
        res.rigid_rotation,
    )
    assert [response.force_a.x, response.force_a.y] == list(res.forces["A"])
    assert [(n.finger, n.node) for n in response.nodes] == [
        (f, n) for f in ("F1", "F2", "A") for n in res.segments[f]
    ]
    assert np.array_equal([[n.force.x, n.force.y] for n in response.nodes], res.node_forces)
    assert np.array_equal(flat(response.sweep_angles), sweep.angles)
    assert np.array_equal(flat(response.sweep_unit_work), sweep.unit_work, equal_nan=True)


def test_frictional_resistance_equals_the_mechanics(planner: Harness) -> None:
    """Algorithm 2 after the scene's event-driven squeeze (Sec. 6.3), as in the resist verb."""
    scene = scene_of(RESIST_FIG10)
    i, j = planner.load(RESIST_FIG10).finger_nodes
    obj = solid_of(RESIST_FIG10)
    k = placement_node(obj.mesh, scene.adversary.placement, "adversary")
    squeeze = event_squeeze_scene(scene, obj, (i, j))
    model = ContactModel(obj, scene.mu, max_events_per_depth=scene.squeeze.max_events_per_depth)
    state = add_adversary(squeeze.state, model, squeeze.displacement, k, 0.02)
    expected = frictional_resistance(
        model,
        state,
        scene.adversary.a,
        mode="stable",
        step=squeeze.step,
        event_tol=squeeze.event_tol,
        contacts=[i, j, k],
    )
    response = planner.call(
        PlanResistance,
        "plan_resistance",
        PlanResistance.Request(
            object_id="resist_fig10",
            contacts=[i, j, k],
            a=Vector3(x=0.0024, y=0.0044),
            mode="stable",
            contact_model="friction",
        ),
    )
    assert response.success == expected.success and response.message in ("", expected.reason)
    assert response.error_code == (ErrorCode.OK if expected.success else ErrorCode.NOT_FEASIBLE)
    assert [response.d1.x, response.d1.y, response.d2.x, response.d2.y] == [
        *expected.d1,
        *expected.d2,
    ]
    assert (response.work_total, response.travelled) == (
        expected.work["total"],
        expected.travelled,
    )
    assert [(e.type, e.node, e.finger) for e in response.events] == [
        (e.type.value, e.node, e.finger) for e in expected.events
    ]
    assert [(n.finger, n.node, n.polar_angle) for n in response.nodes] == [
        (f, c.node, c.theta) for f in ("F1", "F2", "A") for c in expected.state.segment(f)
    ]
    assert np.isnan(response.energy)
    refused = planner.call(
        PlanResistance,
        "plan_resistance",
        PlanResistance.Request(
            object_id="resist_fig10",
            contacts=[i, j, k],
            a=Vector3(x=0.0024, y=0.0044),
            mode="stable",
            contact_model="friction",
            directions=8,
        ),
    )
    assert refused.error_code == ErrorCode.INVALID_ARGUMENT and "directions" in refused.message


@pytest.mark.parametrize("kind", ["stable", "pure"])
def test_ring_grasp_test_equals_the_mechanics(planner: Harness, kind: str) -> None:
    loaded = planner.load(RING)
    assert loaded.model == "ring" and loaded.num_nodes == loaded.num_boundary_nodes
    ring = build_ring(scene_of(RING)).precompute()
    grasp = ring_grasp(ring, list(loaded.finger_nodes), 0.5, epsilon=0.03, kind=kind)
    depth = grasp.depth_for_relative(0.1)
    response = planner.call(
        RingGraspTest,
        "ring_grasp_test",
        RingGraspTest.Request(
            object_id="ring",
            squeeze_type=kind,
            mu=0.5,
            strain_limit=0.03,
            relative_depth=0.1,
            all_pairs=True,
            best_count=3,
        ),
    )
    assert response.success, response.message
    assert (response.max_depth, response.max_relative_depth, response.limit) == (
        grasp.max_depth,
        grasp.max_relative_depth,
        grasp.limit.value,
    )
    assert (response.depth, response.feasible) == (depth, grasp.feasible_at(depth))
    assert np.array_equal(flat(response.forces), grasp.forces_at(depth).reshape(-1))
    assert response.max_strain == grasp.max_strain_at(depth)
    assert response.pairs == ring.n * (ring.n - 1) // 2 and len(response.best) == 3
    assert response.best[0].quality >= response.best[-1].quality


def test_event_squeeze_service_and_action_equal_the_mechanics(planner: Harness) -> None:
    fingers = tuple(planner.load(BLOB).finger_nodes)
    obj = solid_of(BLOB)
    expected = event_squeeze_scene(scene_of(BLOB), obj, fingers)
    response = planner.call(EventSqueeze, "event_squeeze", EventSqueeze.Request(object_id="blob"))
    assert response.success, response.message
    fractions: list[float] = []
    _, outcome = planner.goal(
        EventSqueezeAction,
        "event_squeeze",
        EventSqueezeAction.Goal(object_id="blob"),
        lambda message: fractions.append(message.feedback.fraction),
    )
    planner.spin_until(outcome.done)
    result = outcome.result()
    assert result.status == GoalStatus.STATUS_SUCCEEDED
    for data in (response.squeeze, result.result.squeeze):
        assert data.termination == expected.termination
        assert (data.depth, data.relative_depth, data.energy) == (
            expected.depth,
            expected.relative_depth,
            expected.energy,
        )
        assert [(e.type, e.node, e.finger, e.depth) for e in data.events] == [
            (e.type.value, e.node, e.finger, e.depth) for e in expected.events
        ]
        final = data.final_state
        assert list(
            zip(final.nodes, final.fingers, final.polar_angles, final.forces_x, final.forces_y)
        ) == [(c.node, c.finger, c.theta, *c.force) for c in expected.state.contacts]
        assert (data.work_f1, data.work_f2) == (expected.work["F1"], expected.work["F2"])
        assert data.max_strain == expected.health.max_strain
        assert (data.material_model, data.strain_measure, data.stress_measure) == (
            "linear", EventSqueezeData.STRAIN_SMALL, EventSqueezeData.STRESS_SMALL_STRAIN)
    planner.spin_until(lambda: bool(fractions) and fractions[-1] >= 1.0, timeout=10.0)
    assert fractions == sorted(fractions) and fractions[-1] == 1.0  # the depth reached: exactly 1


def test_event_squeeze_of_a_neo_hookean_object_names_its_measures(planner: Harness) -> None:
    """A neo-Hookean object's squeeze reports its log strain and Cauchy stress, and says so."""
    text = BLOB.replace("thickness: 0.0254}", "thickness: 0.0254, model: neo_hookean}")
    fingers = tuple(planner.load(text, object_id="blob_nh").finger_nodes)
    expected = event_squeeze_scene(scene_of(text), solid_of(text), fingers)
    response = planner.call(EventSqueeze, "event_squeeze",
                            EventSqueeze.Request(object_id="blob_nh"))
    assert response.success, response.message
    data = response.squeeze
    assert (data.material_model, data.strain_measure, data.stress_measure) == (
        "neo_hookean", EventSqueezeData.STRAIN_LOG, EventSqueezeData.STRESS_CAUCHY)
    assert (data.max_strain, data.max_von_mises) == (expected.health.max_strain,
                                                     expected.health.max_von_mises)


def test_the_message_constants_are_the_vocabulary() -> None:
    """EventSqueezeData's STRAIN_*/STRESS_* constants are the measures the models report."""
    assert {EventSqueezeData.STRAIN_SMALL, EventSqueezeData.STRAIN_BIOT,
            EventSqueezeData.STRAIN_LOG} == {str(m.strain_measure) for m in MaterialModel}
    assert {EventSqueezeData.STRESS_SMALL_STRAIN, EventSqueezeData.STRESS_CAUCHY} == {
        str(m.stress_measure) for m in MaterialModel}


def test_grasp_map_action_loads_with_stages_and_equals_the_service(planner: Harness) -> None:
    stages: list[tuple[str, int, int]] = []
    _, outcome = planner.goal(
        GraspMapAction,
        "grasp_map",
        GraspMapAction.Goal(scene_yaml=BLOB, object_id="mapped", mu=0.4, full_matrices=True),
        lambda message: stages.append(
            (message.feedback.stage, message.feedback.stage_index, message.feedback.stage_count)
        ),
    )
    planner.spin_until(outcome.done)
    result = outcome.result()
    assert result.status == GoalStatus.STATUS_SUCCEEDED, result.result.message
    planner.spin_until(lambda: len(stages) >= 5, timeout=10.0)
    every = [
        ("mesh", 0, 5),
        ("stiffness", 1, 5),
        ("factorisation", 2, 5),
        ("boundary compliance", 3, 5),
        ("grasp map", 4, 5),
    ]
    assert stages == every
    service = planner.call(
        GraspMap, "grasp_map", GraspMap.Request(object_id="mapped", mu=0.4, full_matrices=True)
    )
    assert result.result.map == service.map
    assert np.array_equal(
        flat(service.map.stiffness), grasp_map(solid_of(BLOB), 0.4).stiffness.reshape(-1)
    )


# --------------------------------------------------------------------------- bad requests

BOWTIE = [[0.0, 0.0], [0.1, 0.08], [0.1, 0.0], [0.0, 0.1]]
BAD_SCENES = [
    ("empty shape", ("object", "shape"), {}, "object.shape.type"),
    ("empty outline", ("object", "shape"), {"type": "polygon", "points": []}, "polygon"),
    (
        "self-intersecting outline",
        ("object", "shape"),
        {"type": "polygon", "points": BOWTIE},
        "self-intersecting",
    ),
    ("nu out of range", ("object", "material", "nu"), 0.7, "object.material.nu"),
    ("NaN modulus", ("object", "material", "E"), float("nan"), "object.material.E"),
    ("oversized mesh", ("object", "mesh"), {"nodes": 100_000}, "oversized"),
    (
        "mesh beyond the core limit",
        ("object", "mesh"),
        {"nodes": 10_000_000},
        "mesh.nodes must be in [10, 250000]",
    ),
    ("oversized by max_area", ("object", "mesh"), {"max_area": 1e-12}, "oversized"),
    ("unknown key", ("object", "colour"), "red", "object.colour"),
]


@pytest.mark.parametrize("name,path,value,reason", BAD_SCENES, ids=[b[0] for b in BAD_SCENES])
def test_bad_scenes_are_refused_with_the_reason(
    planner: Harness, name: str, path: tuple, value: object, reason: str
) -> None:
    response = planner.call(
        LoadObject, "load_object", LoadObject.Request(scene_yaml=variant(BLOB, path, value))
    )
    assert not response.success and response.error_code == ErrorCode.INVALID_ARGUMENT
    assert reason in response.message


def bad_requests(fingers: list[int], interior: int) -> list[tuple[str, object, object, int, str]]:
    """(service, type, request, expected code, reason substring) of one bad field each."""
    squeeze = PlanSqueeze.Request
    return [
        (
            "load_object",
            LoadObject,
            LoadObject.Request(),
            ErrorCode.INVALID_ARGUMENT,
            "exactly one of scene_yaml, scene_path and object",
        ),
        (
            "load_object",
            LoadObject,
            LoadObject.Request(scene_yaml="object: ["),
            ErrorCode.INVALID_ARGUMENT,
            "invalid YAML",
        ),
        (
            "load_object",
            LoadObject,
            LoadObject.Request(scene_path=str(REPO / "config/scenes/nonexistent.yaml")),
            ErrorCode.INVALID_ARGUMENT,
            "not found",
        ),
        (
            "load_object",
            LoadObject,
            LoadObject.Request(scene_path="/etc/passwd"),
            ErrorCode.INVALID_ARGUMENT,
            "outside the allowed folders",
        ),
        (
            "load_object",
            LoadObject,
            LoadObject.Request(scene_yaml=BLOB, solver_route="magic"),
            ErrorCode.INVALID_ARGUMENT,
            "solver_route",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="nope", squeeze_type="stable"),
            ErrorCode.UNKNOWN_OBJECT,
            "unknown object_id 'nope'",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="blob", squeeze_type="stable", depth=float("nan")),
            ErrorCode.INVALID_ARGUMENT,
            "depth must be finite",
        ),
        (  # the request's own fields before the lookup: the same answer loaded or not
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="nope", squeeze_type="stable", depth=float("nan")),
            ErrorCode.INVALID_ARGUMENT,
            "depth must be finite",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="blob", squeeze_type="stable", depth=-1e-3),
            ErrorCode.INVALID_ARGUMENT,
            "depth must be >= 0",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="blob", squeeze_type="tight"),
            ErrorCode.INVALID_ARGUMENT,
            "squeeze_type",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="blob", squeeze_type="stable", contacts=[fingers[0], interior]),
            ErrorCode.INVALID_ARGUMENT,
            f"contact node {interior} is not on the outer boundary",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="blob", squeeze_type="stable", contacts=[fingers[0]] * 2),
            ErrorCode.INVALID_ARGUMENT,
            "distinct",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="blob", squeeze_type="stable", contacts=[-5, fingers[1]]),
            ErrorCode.INVALID_ARGUMENT,
            "contact node -5",
        ),
        (
            "plan_squeeze",
            PlanSqueeze,
            squeeze(object_id="ring", squeeze_type="stable"),
            ErrorCode.INVALID_ARGUMENT,
            "ring model",
        ),
        (
            "grasp_map",
            GraspMap,
            GraspMap.Request(object_id="blob", mu=-0.1),
            ErrorCode.INVALID_ARGUMENT,
            "mu must be >= 0",
        ),
        (
            "grasp_map",
            GraspMap,
            GraspMap.Request(object_id="blob", mu=float("inf")),
            ErrorCode.INVALID_ARGUMENT,
            "mu must be finite",
        ),
        (
            "plan_resistance",
            PlanResistance,
            PlanResistance.Request(
                object_id="blob",
                contacts=fingers,
                a=Vector3(x=0.01),
                mode="stable",
                contact_model="point",
            ),
            ErrorCode.INVALID_ARGUMENT,
            "exactly 3 nodes",
        ),
        (
            "plan_resistance",
            PlanResistance,
            PlanResistance.Request(
                object_id="blob",
                contacts=[*fingers, interior],
                a=Vector3(x=0.01, z=1.0),
                mode="stable",
                contact_model="point",
            ),
            ErrorCode.INVALID_ARGUMENT,
            "a.z must be 0",
        ),
        (
            "plan_resistance",
            PlanResistance,
            PlanResistance.Request(
                object_id="blob",
                contacts=[*fingers, interior],
                a=Vector3(x=0.01),
                mode="stable",
                contact_model="glue",
            ),
            ErrorCode.INVALID_ARGUMENT,
            "contact_model",
        ),
        (
            "ring_grasp_test",
            RingGraspTest,
            RingGraspTest.Request(object_id="ring", squeeze_type="stable", mu=-1.0),
            ErrorCode.INVALID_ARGUMENT,
            "mu must be >= 0",
        ),
        (
            "ring_grasp_test",
            RingGraspTest,
            RingGraspTest.Request(
                object_id="ring", squeeze_type="stable", mu=0.5, relative_depth=1.5
            ),
            ErrorCode.INVALID_ARGUMENT,
            "relative_depth must be in [0.0, 1.0]",
        ),
        (
            "ring_grasp_test",
            RingGraspTest,
            RingGraspTest.Request(object_id="blob", squeeze_type="stable", mu=0.5),
            ErrorCode.INVALID_ARGUMENT,
            "not a ring",
        ),
        (
            "event_squeeze",
            EventSqueeze,
            EventSqueeze.Request(object_id="blob", depth=-0.01),
            ErrorCode.INVALID_ARGUMENT,
            "depth must be >= 0",
        ),
        (
            "event_squeeze",
            EventSqueeze,
            EventSqueeze.Request(object_id="blob", step=1e-9),
            ErrorCode.INVALID_ARGUMENT,
            "min_step",
        ),
        (
            "event_squeeze",
            EventSqueeze,
            EventSqueeze.Request(object_id="blob", depth=0.001, relative_depth=0.1),
            ErrorCode.INVALID_ARGUMENT,
            "at most one of depth and relative_depth",
        ),
    ]


def test_bad_requests_get_the_reason_and_the_node_keeps_serving(planner: Harness) -> None:
    fingers = list(planner.load(BLOB).finger_nodes)
    planner.load(RING)
    mesh = solid_of(BLOB).mesh
    interior = int(np.setdiff1d(np.arange(mesh.n), mesh.boundary)[0])
    for name, srv_type, request, code, reason in bad_requests(fingers, interior):
        response = planner.call(srv_type, name, request)
        assert not response.success, (name, request)
        assert response.error_code == code and reason in response.message, response.message
    good = planner.call(
        PlanSqueeze, "plan_squeeze", PlanSqueeze.Request(object_id="blob", squeeze_type="stable")
    )
    assert np.array_equal(flat(good.forces), plan_squeeze(solid_of(BLOB), fingers).forces)


def test_a_failed_goal_is_aborted_with_the_reason(planner: Harness) -> None:
    _, outcome = planner.goal(GraspMapAction, "grasp_map", GraspMapAction.Goal(object_id="nope"))
    planner.spin_until(outcome.done)
    result = outcome.result()
    assert result.status == GoalStatus.STATUS_ABORTED
    assert result.result.error_code == ErrorCode.UNKNOWN_OBJECT and "nope" in result.result.message


def test_an_empty_grasp_map_goal_names_what_to_give(planner: Harness) -> None:
    """``ros2 action send_goal /planner/grasp_map ... "{}"`` ended "unknown object_id '': load
    it first with load_object", though the action loads a scene itself; now it says what a goal
    gives.
    """
    _, outcome = planner.goal(GraspMapAction, "grasp_map", GraspMapAction.Goal())
    planner.spin_until(outcome.done)
    result = outcome.result()
    assert result.status == GoalStatus.STATUS_ABORTED
    assert (result.result.error_code, result.result.message) == (
        ErrorCode.INVALID_ARGUMENT, "give scene_yaml or scene_path (the action loads it), or the "
                                    "object_id of a loaded object")


# --------------------------------------------------------------------------- concurrency


def test_a_long_grasp_map_goal_does_not_block_plan_squeeze(planner: Harness) -> None:
    """While a worker factors a large mesh, plan_squeeze is answered: callback order."""
    planner.load(BLOB)
    order: list[str] = []
    client = planner.client(PlanSqueeze, "plan_squeeze")

    def on_feedback(message: GraspMapAction.Impl.FeedbackMessage) -> None:
        order.append(message.feedback.stage)
        if message.feedback.stage == "factorisation":
            request = PlanSqueeze.Request(object_id="blob", squeeze_type="stable")
            client.call_async(request).add_done_callback(lambda _: order.append("plan_squeeze"))

    _, outcome = planner.goal(
        GraspMapAction,
        "grasp_map",
        GraspMapAction.Goal(scene_yaml=big_disk(15_000), mu=0.3),
        on_feedback,
    )
    outcome.add_done_callback(lambda _: order.append("grasp map result"))
    planner.spin_until(outcome.done, timeout=120)
    assert outcome.result().status == GoalStatus.STATUS_SUCCEEDED
    assert (
        order.index("factorisation")
        < order.index("plan_squeeze")
        < order.index("boundary compliance")
        < order.index("grasp map result")
    )


def test_a_grasp_map_goal_can_be_cancelled(planner: Harness) -> None:
    """Cancel on the first feedback: the worker stops at its next stage, the goal is canceled."""
    stages: list[str] = []
    cancels: list[Future] = []

    def on_feedback(message: GraspMapAction.Impl.FeedbackMessage) -> None:
        stages.append(message.feedback.stage)
        if accepted.done() and not cancels:
            cancels.append(accepted.result().cancel_goal_async())

    accepted, outcome = planner.goal(
        GraspMapAction,
        "grasp_map",
        GraspMapAction.Goal(scene_yaml=big_disk(15_000), object_id="cancelled", mu=0.3),
        on_feedback,
    )
    planner.spin_until(outcome.done, timeout=120)
    result = outcome.result()
    assert result.status == GoalStatus.STATUS_CANCELED
    assert result.result.error_code == ErrorCode.CANCELLED and "grasp map" not in stages
    assert cancels[0].result().goals_canceling
    response = planner.call(
        PlanSqueeze,
        "plan_squeeze",
        PlanSqueeze.Request(object_id="cancelled", squeeze_type="stable"),
    )
    assert response.error_code == ErrorCode.UNKNOWN_OBJECT


def test_shutdown_joins_the_workers_while_a_goal_runs(ros_context: Context) -> None:
    harness = Harness(ros_context)
    started: list[str] = []
    _, outcome = harness.goal(
        GraspMapAction,
        "grasp_map",
        GraspMapAction.Goal(scene_yaml=big_disk(8_000), mu=0.3),
        lambda message: started.append("feedback"),
    )
    harness.spin_until(lambda: bool(started))
    assert planner_threads()
    harness.close()
    assert planner_threads() == [] and not outcome.done()


# --------------------------------------------------------------------------- parameters


def parameters_of(path: Path) -> dict[str, object]:
    """The planner's parameters in a --params-file YAML."""
    return yaml.safe_load(path.read_text())["/**"]["ros__parameters"]


def test_the_shipped_parameter_file_declares_every_parameter() -> None:
    shipped = parameters_of(REPO / "config" / "planner.yaml")
    assert set(shipped) == set(PARAMETERS)
    for name, value in shipped.items():
        assert value == PARAMETERS[name][0], name


def test_parameters_load_from_a_yaml_file(tmp_path: Path) -> None:
    params = tmp_path / "planner.yaml"
    params.write_text(
        yaml.safe_dump(
            {
                "/**": {
                    "ros__parameters": {
                        "max_nodes": 400,
                        "cache_size": 2,
                        "best_count": 3,
                        "worker_threads": 1,
                        "min_step": 1,
                        "default_solver_route": "spectral",
                    }
                }
            }
        )
    )
    context = Context()
    rclpy.init(
        args=["--ros-args", "--params-file", str(params)],
        context=context,
        signal_handler_options=SignalHandlerOptions.NO,
    )
    harness = Harness(context)
    try:
        node = harness.planner
        assert (node.limits.max_nodes, node.cache.capacity, node.limits.best_count) == (400, 2, 3)
        assert node.limits.min_step == 1.0 and node.limits.default_route == "spectral"
        refused = harness.call(
            LoadObject,
            "load_object",
            LoadObject.Request(
                scene_yaml=variant(BLOB, ("object", "mesh"), {"nodes": 500}),
                solver_route="factorized",
            ),
        )
        assert "oversized" in refused.message and "limit of 400" in refused.message
        for object_id in ("a", "b", "c"):
            harness.load(BLOB, object_id=object_id)
        assert node.cache.ids() == ["b", "c"]
        answer = harness.call(GraspMap, "grasp_map", GraspMap.Request(object_id="c", mu=0.4))
        assert len(answer.map.best) == 3
        assert (
            harness.call(
                EventSqueeze, "event_squeeze", EventSqueeze.Request(object_id="c", step=0.5)
            ).error_code
            == ErrorCode.INVALID_ARGUMENT
        )
    finally:
        harness.close()
        context.try_shutdown()
