# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Parallel-jaw grippers: the device file and its transmission, ``plan_gripper_grasp`` against
the grasp map, analytic first-contact geometry, the event squeeze called directly and the
closed-form jaw force of a block between wide pads, and the ``gripper-plan`` verb.
"""
from __future__ import annotations

import functools
import json
import re

import numpy as np
import pytest
import yaml
from doc_transcripts import REPO, blocks

from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.errors import InfeasibleError
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.graspmap import grasp_map
from squeeze_grasp_ros.mechanics.squeeze.gripper_grasp import (
    evaluate_candidate,
    gripper_candidates,
)
from squeeze_grasp_ros.mechanics.vocabulary import Finger
from squeeze_grasp_ros.resources import device_file, scene_file
from squeeze_grasp_ros.scene import GraspSetup, SceneError, load_scene
from squeeze_grasp_ros.scene.gripper import GripperError, load_gripper, parse_gripper
from squeeze_grasp_ros.scene.gripper_plan import plan_gripper_grasp

E, THICKNESS = 5e4, 0.01
W, H = 0.06, 0.03


def device(**changes) -> dict:
    """The generic 85 mm gripper's document with ``changes`` (nested keys with dots)."""
    data = {"name": "test_gripper", "opening": {"min": 0.0, "max": 0.085}, "max_force": 235.0,
            "pad": {"shape": "pad", "width": 0.022, "edge_radius": 0.002},
            "transmission": {"joints": ["finger_joint"], "position_per_aperture": -0.8 / 0.085,
                             "position_offset": 0.8}}
    for key, value in changes.items():
        *path, last = key.split(".")
        node = data
        for part in path:
            node = node[part]
        node[last] = value
    return data


@functools.lru_cache(maxsize=None)
def sponge():
    setup = GraspSetup.build(load_scene(scene_file("sponge_gripper")))
    return setup, grasp_map(setup.solid, setup.scene.mu)


@functools.lru_cache(maxsize=None)
def block():
    outline = shapes.rectangle(W, H)
    return ElasticObject(generate_mesh(outline, target_max_area(outline, 400)),
                         Material(E, 0.0, THICKNESS)).precompute()


# --- the device -------------------------------------------------------------------------------

def test_shipped_device_transmission_round_trips():
    g = load_gripper(device_file("generic_85mm"))
    assert g.joint_positions(0.085) == pytest.approx((0.0,), abs=1e-12)  # open
    assert g.joint_positions(0.0) == (0.8,)  # closed
    for aperture in np.linspace(0, 0.085, 7):
        assert g.aperture(g.joint_positions(aperture)[0]) == pytest.approx(aperture, abs=1e-15)
    assert g.jaw_force(g.joint_efforts(12.5)[0]) == 12.5
    franka = parse_gripper(device(**{"transmission.joints": ["j1", "j2"],
                                     "transmission.position_per_aperture": 0.5,
                                     "transmission.position_offset": 0.0}))
    assert franka.joint_positions(0.06) == (0.03, 0.03)  # each finger half the aperture


@pytest.mark.parametrize(("changes", "message"), [
    ({"opening.max": 0.0}, r"gripper\.opening\.max must be in \(0\.0, 1\.0\] m"),
    ({"opening.min": 0.09}, r"gripper\.opening\.max must be > gripper\.opening\.min"),
    ({"max_force": -1.0}, r"gripper\.max_force"),
    ({"pad.width": 0.003}, r"gripper\.pad\.width must be >= 2 gripper\.pad\.edge_radius"),
    ({"transmission.position_per_aperture": 0.0},
     r"gripper\.transmission\.position_per_aperture must be a nonzero"),
    ({"transmission.joints": []}, r"gripper\.transmission\.joints must name"),
    ({"transmission.joints": ["a", "a"]}, r"gripper\.transmission\.joints repeats"),
    ({"colour": "red"}, r"colour"),
    # a user's unit mistakes, which planned silently (mm: "no placement fits [0, 85] m" after
    # the meshing; an 8 m pad, a speed in mm/s, a joint in degrees: planned and commanded)
    ({"opening.max": 85.0}, r"gripper\.opening\.max must be in \(0\.0, 1\.0\] m \(a gripper's "
                            r"stroke is below 1 m: a length in mm\?\), got 85\.0"),
    ({"opening.min": 2.0, "opening.max": 0.085},
     r"gripper\.opening\.min must be in \[0\.0, 1\.0\]"),
    ({"pad.width": 22.0, "pad.edge_radius": 2.0},
     r"gripper\.pad\.width must be <= 1 m .*got 22 m"),
    ({"max_speed": 150.0}, r"gripper\.max_speed must be in \(0\.0, 10\.0\] m/s, got 150\.0"),
    ({"max_speed": 0.0}, r"gripper\.max_speed must be in \(0\.0, 10\.0\] m/s, got 0\.0"),
    ({"transmission.position_per_aperture": -45.84 / 0.085, "transmission.position_offset": 45.84},
     r"gripper\.transmission\.position_offset \+ position_per_aperture \* aperture puts the "
     r"joints at 45\.84 closed and 0 open \(opening \[0, 0\.085\] m\), beyond \+-6\.283: joint "
     r"positions are in rad or m, not degrees or mm"),
    # the sign closing the wrong way: 0.8 rad open, 1.6 rad closed, outside the joint's limits
    ({"transmission.position_per_aperture": 0.8 / 0.085, "transmission.position_limits": [0, 0.8]},
     r"puts the joints at 0\.8 closed and 1\.6 open \(opening \[0, 0\.085\] m\), outside "
     r"gripper\.transmission\.position_limits \[0, 0\.8\]: position_per_aperture's sign"),
    ({"transmission.position_limits": [0.8, 0.0]},
     r"gripper\.transmission\.position_limits must be \[lower, upper\] with lower < upper"),
    ({"transmission.position_limits": [0.0, float("nan")]},
     r"gripper\.transmission\.position_limits\[1\] must be a finite number"),
    ({"transmission.position_limits": [0.0]},
     r"gripper\.transmission\.position_limits must have 2 entries"),
])
def test_bad_device_files_name_the_field(changes, message):
    with pytest.raises(GripperError, match=message):
        parse_gripper(device(**changes))


@pytest.mark.parametrize("changes", [
    # a Franka Hand-like: two prismatic finger joints at half the aperture each, in m
    {"opening.max": 0.08, "transmission.joints": ["finger_joint1", "finger_joint2"],
     "transmission.position_per_aperture": 0.5, "transmission.position_offset": 0.0,
     "transmission.position_limits": [0.0, 0.04]},
    # a Robotiq 2F-140-like: one revolute joint, 0.7 rad closed, 0 rad open
    {"opening.max": 0.14, "transmission.position_per_aperture": -5.0,
     "transmission.position_offset": 0.7, "transmission.position_limits": [0.0, 0.7],
     "pad.width": 0.03, "pad.edge_radius": 0.003},
    # a small servo gripper of 20 mm stroke in m, its pads wider than its stroke
    {"opening.min": 0.002, "opening.max": 0.022, "max_speed": 0.02, "pad.width": 0.03,
     "pad.edge_radius": 0.0005, "transmission.position_per_aperture": 0.5,
     "transmission.position_offset": -0.001, "transmission.position_limits": [0.0, 0.01]},
    # a joint of a full turn (rad) is still a joint
    {"transmission.position_per_aperture": -6.2 / 0.085, "transmission.position_offset": 6.2},
])
def test_a_labs_own_devices_are_accepted(changes):
    g = parse_gripper(device(**changes))
    lo, hi = g.transmission.position_limits or (-np.inf, np.inf)
    for aperture in (g.opening.min, g.opening.max):
        assert all(lo - 1e-12 <= p <= hi + 1e-12 for p in g.joint_positions(aperture))
        assert g.aperture(g.joint_positions(aperture)[0]) == pytest.approx(aperture, abs=1e-15)


def test_a_device_file_error_names_the_file_before_any_work(tmp_path, monkeypatch, capsys):
    """docs/grippers.md's error line: a device file in mm is refused, exit 2, naming the file
    (before: "no inward, force-closing placement of the object fits franka_mm's opening
    [0, 80] m", exit 1, after meshing the object and computing its grasp map).
    """
    (tmp_path / "lab").mkdir()
    (tmp_path / "lab" / "franka_mm.yaml").write_text(
        "name: franka_mm\nopening: {min: 0, max: 80}\nmax_force: 70\n"
        "pad: {shape: pad, width: 18, edge_radius: 1}\n"
        "transmission: {joints: [j1, j2], position_per_aperture: 0.5}\n")
    monkeypatch.chdir(tmp_path)
    code = main(["gripper-plan", str(scene_file("sponge_gripper")), "--gripper",
                 "lab/franka_mm.yaml"])
    err = capsys.readouterr().err
    assert code == 2
    (shown,) = [b.lines for b in blocks(REPO / "docs" / "grippers.md")
                if b.language == "text" and b.lines[0].startswith("gripper device ")]
    assert err == f"squeeze-grasp gripper-plan: error: {shown[0]}\n"


def test_a_scenes_device_file_error_names_the_scene_field_and_the_file(tmp_path):
    data = yaml.safe_load(scene_file("sponge_gripper").read_text())
    data["controller"]["device"] = "franka_deg.yaml"
    bad = device(**{"transmission.position_per_aperture": -45.84 / 0.085,
                    "transmission.position_offset": 45.84})
    (tmp_path / "franka_deg.yaml").write_text(yaml.safe_dump(bad))
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(data))
    with pytest.raises(SceneError, match=re.escape(
            f"controller.device: gripper device {tmp_path / 'franka_deg.yaml'}: "
            "gripper.transmission.position_offset + position_per_aperture")):
        load_scene(tmp_path / "scene.yaml")


# --- candidates against the grasp map and geometry -------------------------------------------

def test_candidates_are_the_grasp_maps_best_placements_the_pads_make():
    setup, gmap = sponge()
    jaws = load_gripper(device_file("generic_85mm")).jaws()
    found = gripper_candidates(setup.solid, gmap, jaws, count=50)
    assert len(found) == 50
    index = {int(n): k for k, n in enumerate(gmap.boundary)}
    k = [gmap.stiffness[index[c.first_contacts[0]], index[c.first_contacts[1]]] for c in found]
    assert np.array_equal(k, [c.stiffness for c in found])
    assert all(np.diff(k) <= 0)  # ranked by work quality k / 2
    for c in found:
        i, j = (index[n] for n in c.first_contacts)
        assert gmap.feasible[i, j]  # the pads' own placement is inward and force closing
        assert 0 < c.aperture <= jaws.max_aperture
    # no feasible placement the pads make is better than the best candidate
    all_found = gripper_candidates(setup.solid, gmap, jaws, count=100000)
    assert max(c.stiffness for c in all_found) == found[0].stiffness


def test_first_contact_geometry_on_a_block():
    """Pads wider than the block's side closing along x: the aperture is W and the centre is on
    the closing line midway, whatever the line's height.
    """
    obj = block()
    wide = parse_gripper(device(**{"pad.width": 0.05, "pad.edge_radius": 0.003})).jaws()
    gmap = grasp_map(obj, 0.3)
    found = gripper_candidates(obj, gmap, wide, count=1000, yaw_range=(-1e-9, 1e-9))
    assert found
    for c in found:
        assert abs(np.sin(c.yaw)) < 1e-9
        assert c.aperture == pytest.approx(W, abs=1e-12)
        assert c.center[0] == pytest.approx(0.0, abs=1e-12)
    # a narrow pad on a tilted line touches with its rounded edge: the clearance is the
    # distance along the line to the nearest node within the swath, by brute force
    narrow = load_gripper(device_file("generic_85mm")).jaws()
    nodes = obj.mesh.nodes[obj.mesh.boundary]
    for c in gripper_candidates(obj, gmap, narrow, count=40):
        d = c.closing_direction
        t = np.array([-d[1], d[0]])
        face = c.center - 0.5 * c.aperture * d  # F1's face middle
        s = (nodes - face) @ d
        lat = np.abs((nodes - face) @ t)
        a, r = narrow.pad.half_flat, narrow.pad.radius
        recede = np.where(lat <= a, 0.0, r - np.sqrt(np.maximum(r * r - (lat - a) ** 2, 0)))
        ahead = np.where(lat < a + r, s + recede, np.inf)
        assert ahead.min() == pytest.approx(0.0, abs=1e-12)  # touching, nothing inside


def test_yaw_range_is_modulo_pi():
    setup, gmap = sponge()
    jaws = load_gripper(device_file("generic_85mm")).jaws()
    lo, hi = np.radians(80), np.radians(100)
    found = gripper_candidates(setup.solid, gmap, jaws, count=30, yaw_range=(lo, hi))
    assert found
    assert all(np.mod(c.yaw - lo, np.pi) <= hi - lo + 1e-12 for c in found)


def test_a_too_large_object_has_no_gripper_grasp():
    setup = GraspSetup.build(load_scene(scene_file("foam_square")))  # 100 mm > 85 mm
    with pytest.raises(InfeasibleError, match="fits test_gripper's opening"):
        plan_gripper_grasp(setup.solid, parse_gripper(device()), 0.4, relative_closing=0.1,
                           count=3, evaluate=0)


# --- evaluation against the event squeeze -----------------------------------------------------

def test_evaluation_is_the_event_squeeze_with_pads_and_matches_the_block_closed_form():
    """A block with nu = 0 between pads covering its sides.

    The jaw force at closing c is E H h c / W (uniform compression), and equals the event
    squeeze called directly.
    """
    obj = block()
    wide = parse_gripper(device(**{"pad.width": 0.05, "pad.edge_radius": 0.003})).jaws()
    gmap = grasp_map(obj, 0.3)
    c = min(gripper_candidates(obj, gmap, wide, count=1000, yaw_range=(-1e-9, 1e-9)),
            key=lambda c: abs(c.center[1]))
    assert abs(c.center[1]) + wide.pad.half_flat > H / 2  # the pads cover the sides
    closing = 0.002
    ev = evaluate_candidate(obj, c, wide, 0.3, closing=closing, weight=0.5)
    assert ev.jaw_force == pytest.approx(E * H * THICKNESS * closing / W, rel=1e-8)
    assert ev.aperture == pytest.approx(W - closing, rel=1e-12)
    d = c.closing_direction
    direct = event_squeeze(obj, c.first_contacts, wide.pad, 0.3, depth=closing / np.sqrt(2),
                           directions={Finger.F1: d, Finger.F2: -d},
                           facing={Finger.F1: c.yaw, Finger.F2: c.yaw + np.pi},
                           origins={Finger.F1: c.center - W * d, Finger.F2: c.center + W * d})
    assert ev.jaw_force == pytest.approx(
        0.5 * sum(direct.finger_force[f][1] for f in (Finger.F1, Finger.F2)), rel=1e-12)
    assert ev.command_force == pytest.approx(1.25 * ev.jaw_force)
    assert ev.lift_force == pytest.approx(0.5 / (2 * 0.3))
    assert ev.holds_weight == (ev.jaw_force >= ev.lift_force)


def test_plan_commands_joint_positions_and_efforts_through_the_transmission():
    setup, gmap = sponge()
    gripper = load_gripper(device_file("generic_85mm"))
    plan = plan_gripper_grasp(setup.solid, gripper, 0.6, relative_closing=0.15, count=4,
                              evaluate=2, gmap=gmap)
    out = plan.to_json()
    assert [c["rank"] for c in out["candidates"]] == [0, 1, 2, 3]
    for row, ev in zip(out["candidates"], plan.evaluations):
        cmd = row["command"]
        assert gripper.aperture(cmd["positions"][0]) == pytest.approx(ev.aperture, abs=1e-12)
        assert cmd["efforts"][0] == pytest.approx(1.25 * ev.jaw_force)
        assert ev.closing == pytest.approx(0.15 * ev.candidate.aperture, rel=1e-9)
        # symmetric jaws: each jaw's force along its motion is the same
        f = ev.squeeze.finger_force
        assert f[Finger.F1][1] == pytest.approx(f[Finger.F2][1], rel=1e-9)
    assert "command" not in out["candidates"][2]


# --- the verb ---------------------------------------------------------------------------------

def test_gripper_plan_verb_json_and_plot(tmp_path, capsys):
    png = tmp_path / "plan.png"
    code = main(["gripper-plan", str(scene_file("sponge_gripper")), "--count", "3",
                 "--evaluate", "1", "--yaw-range", "80", "100", "--weight", "0.2", "--json",
                 "--plot", str(png)])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["gripper"] == "generic_85mm" and len(out["candidates"]) == 3
    best = out["candidates"][0]
    assert best["lift_force"] == pytest.approx(0.2 / (2 * 0.6))
    assert best["command"]["joints"] == ["finger_joint"]
    assert png.stat().st_size > 10000


@pytest.mark.parametrize(("args", "message"), [
    (["--gripper", "no_such_gripper"], "--gripper: no shipped device 'no_such_gripper'"),
    (["--relative-closing", "1.5"], "relative closing must be in (0, 1)"),
    (["--margin", "0.5"], "force margin must be finite and >= 1"),
    # a reversed or NaN range was shown in radians as numpy reprs, after the object's meshing:
    # "got (np.float64(0.17453292519943295), np.float64(-0.17453292519943295))"
    (["--yaw-range", "10", "-10"],
     "--yaw-range MIN MAX must be finite, in deg, with MIN <= MAX, got 10 -10"),
    (["--yaw-range", "nan", "0"],
     "--yaw-range MIN MAX must be finite, in deg, with MIN <= MAX, got nan 0"),
])
def test_gripper_plan_verb_rejects_bad_input_with_exit_2(args, message, capsys):
    code = main(["gripper-plan", str(scene_file("sponge_gripper")), *args])
    assert code == 2
    assert message in capsys.readouterr().err


def test_the_evaluated_jaws_sit_where_the_candidate_put_them():
    """An off-centre candidate on the sponge, whose pads touch with an edge: the evaluated
    squeeze's pads start at the candidate's first contacts and on its closing line.
    """
    setup, gmap = sponge()
    jaws = load_gripper(device_file("generic_85mm")).jaws()
    c = gripper_candidates(setup.solid, gmap, jaws, count=1)[0]
    ev = evaluate_candidate(setup.solid, c, jaws, 0.6, closing=0.002)
    assert ev.squeeze.contacts == c.first_contacts
    d = c.closing_direction
    t = np.array([-d[1], d[0]])
    for name, sign in ((Finger.F1, -1.0), (Finger.F2, 1.0)):
        finger = ev.squeeze.state.finger(name)
        start = finger.center - finger.translation  # the reference point at first contact
        assert (start - c.center) @ t == pytest.approx(0.0, abs=1e-12)  # on the line
        face = (start - c.center) @ d - sign * jaws.pad.radius  # F1's face is r ahead of it
        assert face == pytest.approx(sign * 0.5 * c.aperture, abs=1e-12)


def test_a_closing_capped_by_the_jaws_travel_is_named_on_its_line(tmp_path, capsys):
    """The header's closing (15 % of the aperture at first contact) is what was asked; a
    gripper whose opening.min leaves less travel closes only that far. Before, the candidate's
    line said nothing of it: the header read "closing 15.0 %" over a 2.4 % squeeze.
    """
    device = yaml.safe_load(device_file("generic_85mm").read_text())
    device["opening"]["min"], device["name"] = 0.044, "narrow_travel"
    path = tmp_path / "narrow_travel.yaml"
    path.write_text(yaml.safe_dump(device))
    argv = ["gripper-plan", str(scene_file("sponge_gripper")), "--count", "1", "--evaluate",
            "1", "--yaw-range", "80", "100"]
    assert main([*argv, "--gripper", str(path), "--json"]) == 0
    c = json.loads(capsys.readouterr().out)["candidates"][0]
    travel = c["aperture_at_contact"] - 0.044
    assert c["closing"] == pytest.approx(travel, rel=1e-9) and c["termination"] == "depth_reached"
    assert main([*argv, "--gripper", str(path)]) == 0
    out = capsys.readouterr().out
    assert "closing 15.0 % beyond first contact" in out
    assert (f"(depth_reached), closing {1e3 * travel:.2f} mm "
            f"({100 * travel / c['aperture_at_contact']:.1f} %) of the "
            f"{150 * c['aperture_at_contact']:.2f} mm asked, capped by the jaws' travel to "
            "opening.min; limit closing") in out
    assert main(argv) == 0   # the shipped device's travel holds the 15 %: nothing added
    assert "mm asked" not in capsys.readouterr().out
