# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event-driven squeeze on the shipped scenes: each termination in the scene built for it, the
strain and pickup criteria checked independently, the squeeze verb's JSON and plot.
"""
from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from squeeze_grasp_ros import cli
from squeeze_grasp_ros.mechanics.elastic.fem import element_strains, principal_strains
from squeeze_grasp_ros.mechanics.squeeze.contact_model import TerminationLimits
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.scene import (
    GraspSetup,
    SceneError,
    event_squeeze_scene,
    load_scene,
    parse_scene,
)

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"


@functools.lru_cache(maxsize=None)
def scene_run(name: str):
    setup = GraspSetup.build(load_scene(SCENES / f"{name}.yaml")).precompute()
    return setup, setup.event_squeeze()


def test_foam_square_runs_out_of_the_box():
    loaded, res = scene_run("foam_square")
    assert res.termination == "depth_reached"
    assert res.relative_depth == pytest.approx(0.12, rel=1e-12)
    assert res.event_counts["A"] >= 8
    assert all(len(seg) >= 4 for seg in res.segments.values())
    assert res.contacts == loaded.contacts
    for seg in res.segments.values():
        for s in seg:
            assert s.slip_margin >= -1e-9 * abs(s.normal_force)


def test_low_friction_variant_has_sliding_nodes_and_c_d_events():
    _, res = scene_run("foam_square_low_friction")
    assert res.termination == "depth_reached"
    assert res.event_counts["C"] >= 1 and res.event_counts["D"] >= 1
    assert any(s.mode == "slip" for seg in res.segments.values() for s in seg)
    assert sum(res.work.values()) > res.energy  # sliding dissipates


def test_finger_slip_scene_ends_with_one_finger_sliding_one_way():
    _, res = scene_run("disk_finger_slip")
    assert res.termination == "finger_slip"
    assert 0 < res.depth < res.target_depth
    assert res.event_counts["A"] >= 2  # the contacts grew into segments before the slip
    slipping = [name for name, seg in res.segments.items()
                if all(s.mode == "slip" for s in seg) and len({s.slip for s in seg}) == 1]
    assert slipping
    for name in slipping:
        for s in res.segments[name]:
            assert abs(s.slip_margin) < 1e-9 * abs(s.normal_force)


def test_strain_limit_scene_stops_at_the_proportional_limit():
    loaded, res = scene_run("foam_square_strain_limit")
    eps_star = loaded.scene.strain_limit.epsilon
    assert res.termination == "strain_limit"
    assert res.depth < res.target_depth
    # independent: principal strains of the final displacement field from the FEM module
    eps = np.abs(principal_strains(element_strains(loaded.solid.mesh, res.displacement))).max()
    assert eps == pytest.approx(eps_star, rel=1e-6)
    assert res.health.max_strain == pytest.approx(eps_star, rel=1e-6)


def test_componentwise_strain_criterion_allows_at_least_as_deep_a_squeeze():
    loaded, res = scene_run("foam_square_strain_limit")
    eps_star = loaded.scene.strain_limit.epsilon
    literal = event_squeeze(loaded.solid, loaded.contacts, 0.02, 0.4, relative_depth=0.12,
                            limits=TerminationLimits(eps_star, "componentwise"))
    assert literal.depth >= res.depth
    eps = element_strains(loaded.solid.mesh, literal.displacement)
    if literal.termination == "strain_limit":
        assert np.abs(eps[:, :2]).max() == pytest.approx(eps_star, rel=1e-6)
    else:
        assert np.abs(eps[:, :2]).max() < eps_star


def test_pickup_scene_stops_when_friction_carries_the_weight():
    loaded, res = scene_run("foam_square_pickup")
    w, mu = loaded.scene.pickup.weight, loaded.scene.mu
    assert res.termination == "picked_up"
    assert res.depth < res.target_depth
    assert round(100 * res.relative_depth, 3) == 4.154  # docs/events.md, "Scenes"
    supply = {name: sum(np.sqrt(max(mu ** 2 * s.normal_force ** 2 - s.tangential_force ** 2, 0))
                        for s in seg if s.mode == "stick")
              for name, seg in res.segments.items()}
    assert min(supply.values()) == pytest.approx(w / 2, rel=1e-6)
    assert all(v >= w / 2 * (1 - 1e-6) for v in supply.values())


def test_user_given_directions_and_validation():
    data = yaml.safe_load((SCENES / "foam_square.yaml").read_text())
    data["object"]["mesh"] = {"nodes": 600}
    data["fingers"]["F1"]["direction"] = [1.0, 0.0]
    with pytest.raises(SceneError, match="direction"):
        parse_scene(data)
    data["fingers"]["F2"]["direction"] = [-1.0, 0.0]
    scene = parse_scene(data)
    from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
    from squeeze_grasp_ros.scene import build_mesh, finger_nodes, scene_material
    mesh = build_mesh(scene)
    res = event_squeeze_scene(scene, ElasticObject(mesh, scene_material(scene)),
                              finger_nodes(scene, mesh), relative_depth=0.05)
    assert res.kind == "custom"
    assert res.directions["F1"] == pytest.approx([2 ** -0.5, 0.0])
    assert res.relative_depth == pytest.approx(0.05)
    assert res.state.finger("F1").translation[1] == 0.0
    data["fingers"]["F1"]["tip_radius"] = 0.0
    del data["fingers"]["F1"]["direction"], data["fingers"]["F2"]["direction"]
    scene = parse_scene(data)
    with pytest.raises(SceneError, match="tip_radius"):
        event_squeeze_scene(scene, None, (0, 1))
    ring = dict(data, object={**data["object"], "model": "ring",
                              "ring": {"wall_thickness": 0.005}})
    with pytest.raises(SceneError, match="solid"):
        event_squeeze_scene(parse_scene(ring), None, (0, 1))


def run_cli(args, capsys) -> dict:
    assert cli.main(args) == 0
    return json.loads(capsys.readouterr().out)


def test_squeeze_verb_json_keys_and_plot(tmp_path, capsys):
    png = tmp_path / "squeeze.png"
    out = run_cli(["squeeze", str(SCENES / "foam_square_low_friction.yaml"), "--relative-depth",
                   "0.06", "--event-tol", "1e-8", "--json", "--plot", str(png)], capsys)
    for key in ("termination", "depth", "relative_depth", "contacts", "events", "event_counts",
                "segments", "energy", "mu", "tip_radius"):
        assert key in out
    assert out["termination"] == "depth_reached" and out["relative_depth"] == pytest.approx(0.06)
    assert out["mu"] == 0.05 and out["tip_radius"] == 0.02 and len(out["contacts"]) == 2
    assert set(out["event_counts"]) == {"A", "B", "C", "D"}
    assert sum(out["event_counts"].values()) == len(out["events"])
    for e in out["events"]:
        assert {"type", "node", "finger", "depth", "relative_depth"} <= set(e)
        assert e["type"] in "ABCD" and e["finger"] in ("F1", "F2")
    assert set(out["segments"]) == {"F1", "F2"}
    for seg in out["segments"].values():
        for s in seg:
            assert s["mode"] in ("stick", "slip") and len(s["force"]) == 2
    assert out["event_tol"] == 1e-8
    assert png.stat().st_size > 10_000


def test_squeeze_summary_prints_round_off_as_zero(capsys):
    # the force at depth 0 and a sliding node's slip margin are zero by construction: the JSON
    # keeps the computed floats (round-off), the summary prints them as 0, other values as they are
    scene = str(SCENES / "foam_square_low_friction.yaml")
    out = run_cli(["squeeze", scene, "--json"], capsys)
    ends = {name: f["end"] for name, f in out["finger_force"].items()}
    round_off = [(f["start"], ends[name]) for name, f in out["finger_force"].items()]
    round_off += [(v, ends[name]) for name, v in out["health"]["slip_margin"].items()]
    assert all(0 < abs(v) < 1e-12 * end for v, end in round_off)  # what the summary hides
    assert cli.main(["squeeze", scene]) == 0
    text = capsys.readouterr().out
    for name, end in ends.items():
        assert f"{name}: 7 nodes" in text and f"force along motion 0 -> {end:.4g} N" in text
    assert "slip margin F1 0 N, F2 0 N" in text and "e-15" not in text and "e-16" not in text
    out = run_cli(["squeeze", str(SCENES / "foam_square.yaml"), "--json"], capsys)
    assert cli.main(["squeeze", str(SCENES / "foam_square.yaml")]) == 0
    margins = out["health"]["slip_margin"]
    assert min(margins.values()) > 0.01  # sticking nodes: real margins, printed as computed
    assert (f"slip margin F1 {margins['F1']:.4g} N, F2 {margins['F2']:.4g} N"
            in capsys.readouterr().out)


def test_squeeze_verb_reference_mode_and_errors(capsys):
    out = run_cli(["squeeze", str(SCENES / "foam_square.yaml"), "--relative-depth", "0.02",
                   "--reference", "--step", "1e-3", "--json"], capsys)
    assert out["reference"] and out["step"] == 1e-3 and out["event_counts"]["A"] >= 1
    assert cli.main(["squeeze", str(SCENES / "foam_square.yaml"), "--event-tol", "-1"]) == 2
    assert "event_tol" in capsys.readouterr().err


@pytest.mark.parametrize(("model", "percent", "measure"), [("linear", 2.720, "small"),
                                                           ("corotational", 2.748, "biot"),
                                                           ("neo_hookean", 2.601, "log")])
def test_strain_limit_scene_stops_where_the_docs_say_on_each_models_own_strain(model, percent,
                                                                               measure):
    """docs/events.md, "Scenes": epsilon* = 0.1 stops the foam square at 2.720 % (linear),
    2.748 % (corotational) and 2.601 % (neo-Hookean), each on its own strain measure.
    """
    setup = GraspSetup.build(load_scene(SCENES / "foam_square_strain_limit.yaml")).precompute()
    res = setup.event_squeeze(material_model=model)
    assert res.termination == "strain_limit"
    assert round(100 * res.relative_depth, 3) == percent
    assert res.to_json()["health"]["strain_measure"] == measure
