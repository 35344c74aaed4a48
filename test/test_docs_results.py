# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Results README.md and docs/ state outside console transcripts (forces, events, depths,
placements that succeed, suite sizes), compared with the runs that give them; and the API
examples that leave names free, run with a shipped scene's.
"""
from __future__ import annotations

import re

import pytest
import yaml
from doc_claims import FOAM_SQUARE, cli_json, page_text, shipped, stated
from doc_transcripts import REPO, blocks


def test_the_diagnostics_mechanics_md_names_are_plan_s(tmp_path):
    """docs/mechanics.md names the diagnostics ``plan --json`` gives and says it has no solve
    residual; its ConditioningWarning threshold is the code's.
    """
    from squeeze_grasp_ros.mechanics.elastic.compliance import CONDITION_WARN

    text = page_text("mechanics.md")
    bullet = text[text.index("**Diagnostics**"):text.index("**Point contacts")]
    named = re.findall(r"`(\w+)`", bullet)
    diagnostics = cli_json(["plan", FOAM_SQUARE], tmp_path)["diagnostics"]
    assert {"condition_estimate", "rigid_mode_residual", "reduced_condition"} <= set(named)
    assert [k for k in named if k not in ("diagnostics", "plan", "ConditioningWarning")
            and k not in diagnostics] == []
    assert "so its JSON has no residual" in bullet
    assert [k for k in diagnostics if "residual" in k] == ["rigid_mode_residual"]
    assert stated("mechanics.md", r"a `ConditioningWarning` is issued past (1e\d+)") == [
        CONDITION_WARN]


def test_the_yaml_route_the_readme_compares_the_camera_with():
    """README.md: "The YAML route gives 4.9061 N and the same 12 events" (the shipped foam
    square's event squeeze).
    """
    from squeeze_grasp_ros.api import event_squeeze_scene, load_scene, scene_file, scene_solid

    force, events = stated("README.md", r"The YAML route gives ([\d.]+) N and the same (\d+) "
                                        r"events")
    scene = load_scene(scene_file("foam_square"))
    result = event_squeeze_scene(scene, scene_solid(scene))
    assert (round(float(result.finger_force["F1"][1]), 4), len(result.events)) == (force, events)


def test_the_mask_outline_as_a_file_and_as_a_polygon_squeezes_as_perception_md_says(tmp_path):
    """docs/perception.md, "Files": the foam square's mask outline (the example's render), as
    an outline file and as a polygon, meshed and squeezed: boundary nodes, events, the first
    event's relative depth and the final finger force it states, beside the scene's own.
    """
    pytest.importorskip("skimage", reason="outline extraction needs the perception extra")
    camera = ["--camera-info", str(REPO / "config" / "examples" / "camera_top.yaml"),
              "--camera-pose", "0.01", "-0.02", "0.5", "3.1", "0.05", "0.3"]
    cli_json(["render", FOAM_SQUARE, *camera, "--mask", "mask.png"], tmp_path)
    polygon = cli_json(["outline", "mask.png", *camera, "--object-height", "0.0254",
                        "--output", "shape.yaml"], tmp_path)
    cli_json(["outline", "mask.png", *camera, "--object-height", "0.0254",
              "--output", "outline.json"], tmp_path)
    base = shipped("scenes/foam_square.yaml")
    shapes = {"file": {"type": "file", "path": str(tmp_path / "outline.json")},
              "polygon": yaml.safe_load((tmp_path / "shape.yaml").read_text())["shape"]}
    runs = {"scene": cli_json(["squeeze", FOAM_SQUARE], tmp_path)}
    for name, shape in shapes.items():
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(
            {**base, "object": {**base["object"], "shape": shape}}))
        runs[name] = cli_json(["squeeze", f"{name}.yaml"], tmp_path)

    def seen(run: dict) -> tuple:
        return (run["mesh"]["boundary"], len(run["events"]),
                round(100 * run["events"][0]["relative_depth"], 1),
                round(run["finger_force"]["F1"]["end"], 3))
    text = page_text("perception.md")
    as_file = stated("perception.md", r"as an outline file it meshes like the scene's own square "
                     r"\((\d+) boundary nodes, the same (\d+) new-contact events, final finger "
                     r"force ([\d.]+) N against ([\d.]+) N: (-?[\d.]+) %\)")
    as_polygon = stated("perception.md", r"as a polygon its (\d+) vertices give (\d+) boundary "
                        r"nodes, (\d+) events, the first ones at ([\d.]+) % instead of ([\d.]+) % "
                        r"relative depth .{0,80}?, and ([\d.]+) N")
    assert "through the mask, then `squeeze`" in text
    assert seen(runs["file"])[:2] == seen(runs["scene"])[:2] == tuple(as_file[:2])
    assert [seen(runs["file"])[3], seen(runs["scene"])[3]] == as_file[2:4]
    assert round(100 * (as_file[2] / as_file[3] - 1), 1) == as_file[4]
    assert polygon["vertices"] == len(shapes["polygon"]["points"]) == as_polygon[0]
    boundary, events, first, force = seen(runs["polygon"])
    assert [boundary, events, first, seen(runs["scene"])[2], force] == as_polygon[1:]


@pytest.mark.slow
def test_where_an_element_inverts_is_where_materials_md_says(tmp_path):
    """docs/materials.md: ``squeeze --relative-depth 0.95`` of the foam square ends
    ``element_inverted`` at the relative depths it states (the shipped mesh, linear; a
    300-node mesh, linear and corotational), and the neo-Hookean one reaches 95 %.
    """
    text = page_text("materials.md")
    assert "`squeeze --relative-depth 0.95`" in text
    shipped_linear, linear, corotational, reached = stated(
        "materials.md", r"the shipped linear foam square, 2,054 nodes, at ([\d.]+) % relative "
        r"depth; on a 300-node mesh of it the linear one at ([\d.]+) %, the corotational one "
        r"at ([\d.]+) %, and the neo-Hookean one reaches (\d+) % with no element inverted")
    coarse = shipped("scenes/foam_square.yaml")
    coarse["object"]["mesh"] = {"nodes": 300, "min_angle": 30}
    (tmp_path / "coarse.yaml").write_text(yaml.safe_dump(coarse))
    runs = [(FOAM_SQUARE, "linear"), ("coarse.yaml", "linear"),
            ("coarse.yaml", "corotational"), ("coarse.yaml", "neo_hookean")]
    ends = [cli_json(["squeeze", scene, "--model", model, "--relative-depth", "0.95"], tmp_path)
            for scene, model in runs]
    assert ends[0]["mesh"]["nodes"] == 2054
    assert [e["termination"] for e in ends] == ["element_inverted"] * 3 + ["depth_reached"]
    assert [round(100 * e["relative_depth"], 1) for e in ends] == [
        shipped_linear, linear, corotational, reached]


def test_the_quick_bench_s_force_differences_materials_md_quotes():
    """docs/materials.md: in ``bench --only material_models --quick`` (400-node meshes) the
    neo-Hookean foam square's F1 force is +0.25/+1.4/+3.6 % above linear at 2/8/16 % and the
    corotational one -2.0/-3.9/-8.4 % below: the bench's own set-up and squeezes.
    """
    from squeeze_grasp_ros.bench.material_models import _run, _setup
    from squeeze_grasp_ros.mechanics.vocabulary import Finger, MaterialModel

    found = stated("materials.md", r"in its quick mode \((\d+)-node meshes\) the neo-Hookean "
                   r"force is \+([\d.]+)/\+([\d.]+)/\+([\d.]+) % above linear on the foam square "
                   r"at (\d+)/(\d+)/(\d+) % and the corotational one "
                   r"−([\d.]+)/−([\d.]+)/−([\d.]+) % below")
    nodes, neo, depths, corotational = int(found[0]), found[1:4], found[4:7], found[7:]
    setup = _setup("foam_square", nodes)

    def force(model: MaterialModel, depth: float) -> float:
        return _run(setup, model, depth / 100)[0].finger_force[Finger.F1][1]
    for k, depth in enumerate(depths):
        linear = force(MaterialModel.LINEAR, depth)
        for model, shown, sign in ((MaterialModel.NEO_HOOKEAN, neo[k], 1),
                                   (MaterialModel.COROTATIONAL, corotational[k], -1)):
            change = 100 * (force(model, depth) / linear - 1)
            decimals = len(f"{shown}".partition(".")[2])
            assert round(sign * change, decimals) == shown, (model, depth, change)


@pytest.mark.slow
def test_the_suite_sizes_the_docs_state_are_the_collected_ones():
    """README.md and docs/ci.md give the default suite's size (about N tests) and docs/ci.md
    the slow suite's: within 5 % of what pytest collects now (one collection, 10-20 s).
    """
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q",
                           "-p", "no:cacheprovider"], cwd=REPO, capture_output=True, text=True,
                          timeout=600)
    found = re.search(r"(\d+)/(\d+) tests collected \((\d+) deselected\)", done.stdout)
    assert found, done.stdout[-2000:]
    default, slow = int(found.group(1)), int(found.group(3))
    stated_default = (stated("README.md", r"the default test suite \(about ([\d,]+) tests[;)]")
                      + stated("ci.md", r"The default suite grew from 562 tests .*? to about "
                                        r"([\d,]+)"))
    stated_slow = stated("ci.md", r"The slow suite \(`python -m pytest -m slow`, about "
                                  r"([\d,]+) tests")
    assert all(abs(n / default - 1) < 0.05 for n in stated_default), (stated_default, default)
    assert all(abs(n / slow - 1) < 0.05 for n in stated_slow), (stated_slow, slow)


def _foam_square_names() -> dict:
    """What docs/events.md's stepper example leaves free: the shipped foam square's object and
    its finger nodes.
    """
    from squeeze_grasp_ros.api import load_scene, scene_file
    from squeeze_grasp_ros.scene import GraspSetup

    setup = GraspSetup.build(load_scene(scene_file("foam_square"))).precompute()
    i, j = setup.contacts
    return {"obj": setup.solid, "i": int(i), "j": int(j)}


def _resist_fig10_names() -> dict:
    """What docs/resistance.md's API example leaves free, from the Fig. 10 scene: the object,
    F1's, F2's and A's nodes, the squeeze, its contact model, A's tip radius and push.
    """
    from squeeze_grasp_ros.api import load_scene, scene_file
    from squeeze_grasp_ros.scene import GraspSetup

    setup = GraspSetup.build(load_scene(scene_file("resist_fig10"))).precompute()
    i, j = setup.contacts
    return {"obj": setup.solid, "i": int(i), "j": int(j), "k": setup.adversary_node,
            "squeeze": setup.event_squeeze(), "model": setup.contact_model(terminations=False),
            "radius": setup.scene.adversary.tip_radius, "a": setup.scene.adversary.a}


@pytest.mark.parametrize("page, marker, names", [
    ("events.md", "advance(", _foam_square_names),
    ("resistance.md", "optimal_resistance(", _resist_fig10_names)])
def test_a_python_example_with_free_names_runs_and_returns_what_its_comments_name(
        page, marker, names):
    """The API examples of docs/events.md and docs/resistance.md leave the object and its
    nodes free: bound to a shipped scene's, each runs, and a result whose comment names a
    class (``res = ...  # Resistance``) is of that class.
    """
    block = next(b for b in blocks(REPO / "docs" / page)
                 if b.language == "python" and marker in "\n".join(b.lines))
    namespace = names()
    exec("\n".join(block.lines), namespace)  # noqa: S102 (the repository's own page)
    typed = re.findall(r"^(\w+) = .*#\s+([A-Z]\w+)\b", "\n".join(block.lines), re.M)
    assert [(n, type(namespace[n]).__name__) for n, _ in typed] == typed
    assert len(typed) >= (3 if page == "resistance.md" else 0)


def test_the_table_5_scenes_succeed_as_ring_md_says(tmp_path):
    """docs/ring.md's Table 5: each shipped ring scene's ``--map`` at its requested depth, the
    placements succeeding of all; and the steel heart's own placement (where the strain limit
    stops it, its fibre strain at 15 %; without the limit, how many placements reach 15 % and
    how deep this one goes).
    """
    page = (REPO / "docs" / "ring.md").read_text(encoding="utf-8")
    table = page[page.index("| scene | shape | E |"):]
    rows = [row.strip("|").split(" | ") for row in table[:table.index("\n\n")].splitlines()[2:]]
    assert len(rows) == 5
    for row in rows:
        scene = REPO / "config" / "scenes" / f"{row[0].strip()}.yaml"
        found = cli_json(["ring", str(scene), "--map"], tmp_path)
        assert f"{found['feasible_pairs']} of {found['pairs']}" == row[-1].strip(), row[0]
    heart = REPO / "config" / "scenes" / "ring_heart.yaml"
    reached, strain, unlimited, deepest = stated(
        "ring.md", r"the scene's placement reaches `ε\* = 0.005` at ([\d.]+) % relative depth "
        r"and a ([\d.]+) % fibre strain, small strain, at 15 %\)\. Without the strain limit, "
        r"friction alone lets (\d+) placements reach 15 %, this one to (\d+) %")
    single = cli_json(["ring", str(heart)], tmp_path)
    assert (single["limit"], single["strain_measure"]) == ("strain", "small")
    assert [round(100 * single["max_relative_depth"], 1),
            round(100 * single["max_strain"], 1)] == [reached, strain]
    free = shipped("scenes/ring_heart.yaml")
    del free["strain_limit"]
    free["effects"] = ["friction"]
    (tmp_path / "heart.yaml").write_text(yaml.safe_dump(free))
    single = cli_json(["ring", "heart.yaml"], tmp_path)
    assert round(100 * single["max_relative_depth"]) == deepest
    assert cli_json(["ring", "heart.yaml", "--map"], tmp_path)["feasible_pairs"] == unlimited


def test_the_slip_scene_is_what_grippers_md_says():
    """docs/grippers.md: the shipped slip scene grips the sponge N mm off its short axis, where
    the surface leans M degrees from the pads, with its mu; the mechanics API's squeeze ends
    with a jaw slipping at the depth it states.
    """
    import math

    from squeeze_grasp_ros.api import event_squeeze_scene, load_scene, scene_file, scene_solid

    off, lean, mu, depth = stated(
        "grippers.md", r"The shipped slip scene grips the sponge (\d+) mm off its short axis, "
        r"where the surface leans (\d+) degrees from the pads, with mu = ([\d.]+): the mechanics "
        r"API's squeeze ends with a jaw slipping at ([\d.]+) mm of depth")
    scene = load_scene(scene_file("sponge_gripper_slip"))
    shape = scene.object.shape
    x, y = scene.fingers["F2"].placement.point
    assert (round(1e3 * x), scene.friction.mu) == (off, mu)
    normal = math.degrees(math.atan2(shape["b"] ** 2 * x, shape["a"] ** 2 * y))
    assert round(normal) == lean  # the outward normal's tilt from the pads' closing line (y)
    result = event_squeeze_scene(scene, scene_solid(scene))
    assert (result.termination, round(1e3 * result.depth, 2)) == ("finger_slip", depth)


def test_an_outline_file_in_either_orientation_loads_as_scenes_md_says(tmp_path):
    """docs/scenes.md: an outline file's points may run clockwise; they are taken in reverse.
    A clockwise and a counter-clockwise CSV of one square give one counter-clockwise outline.
    """
    from squeeze_grasp_ros.api import load_scene
    from squeeze_grasp_ros.mechanics.elastic.shapes import signed_area
    from squeeze_grasp_ros.scene.build import build_outline

    assert "clockwise points are taken in reverse, as counter-clockwise" in page_text("scenes.md")
    square = [(0.0, 0.0), (0.05, 0.0), (0.05, 0.05), (0.0, 0.05)]
    outlines = []
    for name, points in (("ccw", square), ("cw", square[::-1])):
        (tmp_path / f"{name}.csv").write_text("".join(f"{x},{y}\n" for x, y in points))
        scene = shipped("scenes/foam_square.yaml")
        scene["object"]["shape"] = {"type": "file", "path": f"{name}.csv"}
        for finger, x in (("F1", 0.0), ("F2", 0.05)):
            scene["fingers"][finger]["placement"] = {"point": [x, 0.025]}
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(scene))
        outlines.append(build_outline(load_scene(tmp_path / f"{name}.yaml").object.shape).points)
    assert all(signed_area(p) == pytest.approx(0.0025) for p in outlines)
    assert sorted(map(tuple, outlines[0])) == sorted(map(tuple, outlines[1]))


def test_the_force_curve_pipeline_md_counts_is_the_foam_square_s():
    """docs/pipeline.md: the planner's event squeeze returns its force curve, "each finger's
    force along its motion at every accepted point, N on the foam square".
    """
    from squeeze_grasp_ros.api import event_squeeze_scene, load_scene, scene_file, scene_solid
    from squeeze_grasp_ros.control.force_watch import squeeze_forces

    (points,) = stated("pipeline.md", r"each finger's force along its motion at every accepted "
                                      r"point, (\d+) on the foam square")
    scene = load_scene(scene_file("foam_square"))
    curve = squeeze_forces(event_squeeze_scene(scene, scene_solid(scene)))
    assert len(curve.depths) == points
