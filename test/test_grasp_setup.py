# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""One place where a scene becomes mechanics (``scene.setup.GraspSetup``): every front end gets
the same object, contacts, finger motion and Algorithm 2 from it, and every route to the
adversary refuses an adversary on F1's or F2's node with the same error (issue 30 §1); a ring
scene with a nonlinear material model is refused (issue 34 item 3).
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from squeeze_grasp_ros import planning
from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.elastic.shapes import fourier_blob, with_boundary_points
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.scene import GraspSetup, SceneError, load_scene, parse_scene
from squeeze_grasp_ros.scene.goal import plan_scene, resistance_goal
from squeeze_grasp_ros.scene.studies import resistance_study
from squeeze_grasp_ros.sim.world import SimWorld

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
FIG10 = SCENES / "resist_fig10.yaml"


LIMITS = planning.PlannerLimits()


def load(source: planning.SceneSource) -> planning.LoadedObject:
    """The planner's object of ``source`` (no ROS: the request layer)."""
    return planning.load_object(source, planning.object_key(source, "", "", LIMITS), LIMITS)


def raw(name: str) -> dict:
    return yaml.safe_load((SCENES / f"{name}.yaml").read_text())


def test_the_setup_meshes_what_an_independent_build_meshes():
    """The solid is the scene's outline with the point placements as vertices, meshed at the
    scene's node count, of the scene's material: built here from the mechanics alone.
    """
    scene = load_scene(FIG10)
    setup = GraspSetup.build(scene)
    shape = raw("resist_fig10")["object"]["shape"]
    points = [scene.fingers[f].placement.point for f in ("F1", "F2")]
    outline = with_boundary_points(fourier_blob(shape["radius"], shape["cos"], shape["sin"]),
                                   points + [scene.adversary.placement.point])
    mesh = generate_mesh(outline, target_max_area(outline, 1200), min_angle=30.0)
    assert np.array_equal(setup.solid.mesh.nodes, mesh.nodes)
    assert setup.solid.material == Material(5.0e4, 0.3, 0.0254)
    corners = outline.points[outline.corners]
    for node, point in zip([*setup.contacts, setup.adversary_node],
                           points + [scene.adversary.placement.point]):
        assert np.min(np.linalg.norm(corners - mesh.nodes[node], axis=1)) < 1e-15
        assert np.linalg.norm(mesh.nodes[node] - point) < 1e-3


def test_finger_motion_follows_the_definitions():
    """Relative depth per depth: sqrt(2)/|p_i - p_j| for a stable squeeze (docs/design.md §2);
    the given directions' approach along the chord over |p_i - p_j|^2 (Fig. 10's scene).
    """
    stable = GraspSetup.build(load_scene(SCENES / "foam_square.yaml"))
    p = stable.solid.mesh.nodes[list(stable.contacts)]
    assert stable.motion.kind == "stable"
    assert stable.motion.relative_per_depth == pytest.approx(
        np.sqrt(2) / np.linalg.norm(p[1] - p[0]), rel=1e-12)
    custom = GraspSetup.build(load_scene(FIG10))
    q = custom.solid.mesh.nodes[list(custom.contacts)]
    d = np.array([[0.0, 0.0], [-0.00068, 0.002]]) / np.hypot(0.00068, 0.002)
    chord = q[1] - q[0]
    assert custom.motion.kind == "custom"
    assert custom.motion.relative_per_depth == pytest.approx(
        (d[0] - d[1]) @ chord / (chord @ chord), rel=1e-12)
    squeeze = custom.event_squeeze()
    assert squeeze.relative_depth / squeeze.depth == pytest.approx(
        custom.motion.relative_per_depth, rel=1e-12)


def test_front_ends_share_the_setup():
    """The simulated world, the planner and the CLI's squeeze see the same contacts, finger
    motion and squeeze (one GraspSetup behind each).
    """
    scene = load_scene(FIG10)
    world = SimWorld(GraspSetup.build(scene))
    source = planning.read_scene("", str(FIG10))
    loaded = load(source)
    assert world.contacts == loaded.finger_nodes == GraspSetup.build(scene).contacts
    assert world.relative_per_depth == loaded.setup.motion.relative_per_depth
    for f in ("F1", "F2"):
        assert np.array_equal(world.directions[f], loaded.setup.motion.directions[f])
    planned = planning.event_squeeze_run(loaded, [], "", 0.0, 0.0, 0.0, 0.0, LIMITS)
    out = json.loads(json.dumps(loaded.setup.event_squeeze().to_json()))
    assert json.loads(json.dumps(planned.to_json())) == out


def test_algorithm_2_is_one_computation_for_every_front_end():
    """The CLI's ``resist`` (friction), the planner's frictional resistance and the executor's
    resistance waypoints are the same run of Algorithm 2 after the same squeeze.
    """
    setup = GraspSetup.build(load_scene(FIG10))
    study = resistance_study(setup)
    source = planning.read_scene("", str(FIG10))
    loaded = load(source)
    adv = setup.scene.adversary
    planned = planning.friction_resistance(loaded, np.array([*setup.contacts,
                                                             setup.adversary_node]),
                                           adv.a, adv.mode, 0.0, LIMITS)
    assert planned.work == study.resistance.work and planned.reason == study.resistance.reason
    goal = resistance_goal(setup, study.squeeze)
    travel = [s.end for s in study.resistance.stages]
    assert goal["resist_travel"][-1] == pytest.approx(max(travel))
    assert np.allclose(goal["resist_waypoints"][-1],
                       [study.resistance.trajectories[f][-1] for f in ("F1", "F2")])


def adversary_on_f1(tmp_path: Path) -> Path:
    data = raw("resist_fig10")
    data["adversary"]["placement"] = copy.deepcopy(data["fingers"]["F1"]["placement"])
    path = tmp_path / "on_f1.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_every_route_refuses_an_adversary_on_a_squeezing_finger(tmp_path, capsys):
    """The check is written once (``check_adversary_node``) and every route to the adversary
    runs it: the resist verb (exit 2, one line), the simulated world, the mechanics planning of
    ``run --no-planner`` and the resistance waypoints, and the planner's requests.
    """
    path = adversary_on_f1(tmp_path)
    message = "adversary.placement is on the same boundary node as F1 or F2"
    for contacts in ("point", "segment", "friction"):
        assert main(["resist", str(path), "--contacts", contacts]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [f"squeeze-grasp resist: error: {message}"]
    scene = load_scene(path)
    for route in (lambda: SimWorld(GraspSetup.build(scene)),
                  lambda: plan_scene(scene),
                  lambda: resistance_goal(GraspSetup.build(scene))):
        with pytest.raises(SceneError, match=message):
            route()
    source = planning.read_scene("", str(path))
    loaded = load(source)
    i, j = loaded.finger_nodes
    with pytest.raises(InvalidInputError, match="same boundary node as F1 or F2"):
        loaded.setup.resistance_grasp("point", nodes=(i, j, j))
    with pytest.raises(planning.PlannerError, match="distinct"):
        planning.resistance_plan(loaded, [i, j, i], (0.001, 0.0, 0.0), "stable", "point", 0.0,
                                 0, 0.0, LIMITS)


def test_a_setup_moves_to_another_scene_of_the_same_object_only():
    setup = GraspSetup.build(load_scene(SCENES / "disk.yaml"))
    data = raw("disk")
    data["fingers"]["F1"]["placement"] = {"angle_deg": 90}
    moved = setup.on(parse_scene(data))
    assert moved.body is setup.body and moved.contacts != setup.contacts
    data["object"]["material"]["E"] = 1.0e5
    with pytest.raises(SceneError, match="same object"):
        setup.on(parse_scene(data))


def test_the_mesh_verb_needs_no_valid_placement(tmp_path, capsys):
    """``squeeze-grasp mesh`` lists the nodes a placement may name, so a bad placement must not
    stop it (the setup places the fingers only when asked).
    """
    data = raw("disk")
    data["fingers"]["F1"]["placement"] = {"node": 10**6}
    path = tmp_path / "bad_node.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["mesh", str(path), "--json"]) == 0
    assert len(json.loads(capsys.readouterr().out)["boundary"]) > 50
    with pytest.raises(SceneError, match="fingers.F1.placement.node 1000000"):
        _ = GraspSetup.build(load_scene(path)).contacts


@pytest.mark.parametrize("model", ["neo_hookean", "corotational"])
def test_a_ring_refuses_a_nonlinear_material_model(tmp_path, capsys, model):
    """Issue 34 item 3: the ring is the linear curved-beam model (Sec. 7); a material model
    that it would silently ignore is refused, naming the key, by the scene and by the verbs.
    """
    data = raw("ring_ring")
    data["object"]["material"]["model"] = model
    with pytest.raises(SceneError, match=f"object.material.model is {model}, but a ring"):
        parse_scene(data)
    path = tmp_path / "ring.yaml"
    path.write_text(yaml.safe_dump(data))
    for verb in ("ring", "graspmap"):
        assert main([verb, str(path)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "object.material.model" in err[0]
    data["object"]["material"]["model"] = "linear"
    assert parse_scene(data).object.material.model == "linear"


def test_a_ring_and_a_solid_answer_their_own_kind_only():
    ring = GraspSetup.build(load_scene(SCENES / "ring_ring.yaml"))
    with pytest.raises(SceneError, match="has no solid mesh"):
        _ = ring.solid
    with pytest.raises(SceneError, match="needs a solid object"):
        ring.event_squeeze()
    solid = GraspSetup.build(load_scene(SCENES / "disk.yaml"))
    with pytest.raises(SceneError, match="needs a ring"):
        _ = solid.ring
    assert isinstance(solid.body, ElasticObject)
