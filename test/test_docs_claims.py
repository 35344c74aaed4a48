# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""What README.md and docs/ state in prose and in blocks that are not console transcripts
(those are run by test_docs.py): shipped files they reproduce, the options they give a verb,
the columns, parameters, topics and values they list, the constants and defaults they quote.

Each check reads the page, so a page edited away from the product fails here; each compares
with the product's own objects (files, parsers, declarations, constants), so a product changed
away from the page fails here too. Results the pages state (forces, events, depths) are
compared with runs in test_docs_results.py.
"""
from __future__ import annotations

import re

import pytest
import yaml
from doc_claims import page_text, shipped, stated, yaml_block
from doc_transcripts import PAGES, REPO, blocks

from squeeze_grasp_ros.cli import add_verb_arguments, build_parser

SHIPPED_COPIES = [
    # (page, the block's first line, the file it reproduces, its keys the block leaves out)
    ("scenes.md", "name: foam_square", "scenes/foam_square.yaml", {"description"}),
    ("sweep.md", "base: ../scenes/foam_square.yaml", "sweeps/example.yaml",
     {"name", "description"}),
    ("grippers.md", "name: generic_85mm", "devices/generic_85mm.yaml", {"description"}),
    ("grippers.md", "controller: {type: joint_trajectory, name: gripper_controller",
     "scenes/sponge_gripper.yaml", None),
    ("grippers.md", "controller: {type: parallel_gripper", "scenes/sponge_gripper_parallel.yaml",
     None),
    ("grippers.md", "controller: {type: joint_trajectory, name: hand_controller",
     "scenes/foam_square_barrett_jtc.yaml", None),
]


@pytest.mark.parametrize("page, first, path, left_out", SHIPPED_COPIES,
                         ids=[f"{c[0]}:{c[2]}" for c in SHIPPED_COPIES])
def test_a_yaml_block_that_shows_a_shipped_file_is_that_file(page, first, path, left_out):
    block, file = yaml_block(page, first), shipped(path)
    if left_out is None:
        assert block == {key: file[key] for key in block}
    else:
        assert block == {key: value for key, value in file.items() if key not in left_out}


def test_the_scene_example_names_every_shape_type():
    """docs/scenes.md's example comments the shape types: every one the parser takes."""
    from squeeze_grasp_ros.scene.specs import SHAPES

    block = next(b for b in blocks(REPO / "docs" / "scenes.md") if b.language == "yaml")
    comment = " ".join(line.partition("#")[2] for line in block.lines[2:5])
    assert re.findall(r"\w+", comment) == [t.value for t in SHAPES], comment


def test_the_camera_section_perception_md_shows_is_valid_and_at_its_defaults():
    """docs/perception.md's ``camera:`` section parses as a scene's camera, and its values are
    the defaults ``scene-help`` lists, but for the distortion and the pose of the shipped
    camera scene (which its comments describe as examples).
    """
    import dataclasses

    from squeeze_grasp_ros.scene import parse_scene
    from squeeze_grasp_ros.scene.specs import CameraSpec

    section = yaml_block("perception.md", "camera:")["camera"]
    scene = shipped("scenes/foam_square.yaml")
    scene.update(camera=section, effects=[*scene["effects"], "camera"])
    camera = parse_scene(scene).camera
    defaults = {f.name: f.default for f in dataclasses.fields(CameraSpec)}
    camera_scene = shipped("scenes/foam_square_camera.yaml")["camera"]
    for key, value in section.items():
        expected = camera_scene[key] if key in ("distortion", "pose") else defaults[key]
        assert getattr(camera, key) == pytest.approx(expected), key


def verb_options() -> dict[str, set[str]]:
    """Every verb of ``squeeze-grasp`` and its option strings."""
    parser = build_parser()
    verbs = next(a for a in parser._actions if a.dest == "verb")._name_parser_map
    return {verb: {o for action in add_verb_arguments(sub)._actions
                   for o in action.option_strings} for verb, sub in verbs.items()}


VERB_SPAN = re.compile(r"`(?:squeeze-grasp )?([a-z][\w-]*) ([^`]*?--[^`]*)`")


def misgiven_options(text: str, options: dict[str, set[str]]) -> list[str]:
    """The ``verb --option`` pairs of ``text``'s inline spans whose verb has no such option."""
    wrong = []
    for span in VERB_SPAN.finditer(text):
        verb, rest = span.groups()
        if verb in options:
            wrong += [f"{verb} {o}" for o in re.findall(r"(?<![\w-])--[a-z][\w-]*", rest)
                      if o not in options[verb]]
    return wrong


def test_an_inline_verb_with_options_has_those_options():
    """An inline span such as `` `ring --map --best 3` `` or `` `squeeze --compare-models` ``,
    or a usage line of a block, names options its verb has (test_docs.py checks the converse,
    and the transcripts).
    """
    options = verb_options()
    wrong, checked = [], 0
    for page in PAGES:
        text = page.read_text(encoding="utf-8") + "".join(  # and the usage lines of blocks
            f"`{line.split('#')[0].strip()}`" for b in blocks(page) if b.language != "console"
            for line in b.lines if line.startswith("squeeze-grasp "))
        checked += len(VERB_SPAN.findall(text))
        wrong += [f"{page.name}: {w}" for w in misgiven_options(text, options)]
    assert checked >= 50 and wrong == [], wrong
    assert misgiven_options("`sweep --large`", options) == ["sweep --large"]


def test_the_records_table_of_sweep_md_is_the_parquet_schema():
    """docs/sweep.md's table of a sweep's columns lists the Parquet schema's columns, in its
    order (``a`` … ``b`` standing for the columns between), and the values it gives for
    ``termination``, ``strain_measure`` and ``stress_measure`` are the ones a row can hold.
    """
    from squeeze_grasp_ros.mechanics.vocabulary import StrainMeasure, StressMeasure, Termination
    from squeeze_grasp_ros.sweep.parts import SCHEMA

    page = (REPO / "docs" / "sweep.md").read_text(encoding="utf-8")
    table = page[page.index("| columns | what |"):]
    rows = {}
    for row in table[:table.index("\n\n")].splitlines()[2:]:
        first, what = row.strip("|").split(" | ", 1)
        rows[first.strip()] = what
    names = list(SCHEMA.names)
    listed: list[str] = []
    for first in rows:
        for k, piece in enumerate(first.split(" … ")):
            shown = re.findall(r"`(\w+)`", piece)
            if k:  # a range: every schema column up to the first one shown after the ellipsis
                start = names.index(listed[-1]) + 1
                listed += names[start:names.index(shown[0])]
            listed += shown
    assert listed == names

    def values(column: str) -> list[str]:
        what = next(w for first, w in rows.items() if f"`{column}`" in first)
        return re.findall(r"`(\w+)`", what)
    # a sweep squeezes with no controller: weight_slip is the simulated lift's only
    assert sorted(values("termination")) == sorted(t.value for t in Termination
                                                   if t != Termination.WEIGHT_SLIP)
    measures = [m.value for m in StrainMeasure if m != StrainMeasure.GREEN_LAGRANGE]
    assert [v for v in values("strain_measure") if v in measures] == measures
    assert [m.value for m in StressMeasure] == [v for v in values("max_von_mises")
                                                if v in {m.value for m in StressMeasure}]


def _constant(dotted: str) -> float:
    import importlib

    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(f"squeeze_grasp_ros.{module}"), name)


CONSTANTS = [
    ("sweep.md", r"at most ([\d,]+) evaluations, ([\d,]+) parameter sets per placement, "
     r"([\d,]+) tasks and ([\d,]+) objects",
     ["sweep.limits.MAX_EVALUATIONS", "sweep.limits.MAX_TASK_EVALUATIONS",
      "sweep.limits.MAX_TASKS", "sweep.limits.MAX_OBJECTS"], 1),
    ("sweep.md", r"Each worker process keeps the last (\d+) prepared groups",
     ["sweep.evaluate.CACHE_GROUPS"], 1),
    ("sweep.md", r"at most (\d+) per core", ["commands.sweep.WORKERS_PER_CORE"], 1),
    ("sweep.md", r"read only as regular files, bounded \((\d+) MiB and (\d+) MiB\)",
     ["sweep.store.MAX_MANIFEST_BYTES", "sweep.parts.MAX_PART_BYTES"], 2 ** 20),
    ("sweep.md", r"a sweep of at least ([\d,]+) evaluations \(`COMPILED_FROM_EVALUATIONS`\)",
     ["mechanics.squeeze.fixed_set_kernel.COMPILED_FROM_EVALUATIONS"], 1),
    ("README.md", r"fixed-set Newton for a `sweep` of ([\d,]+) evaluations or more",
     ["mechanics.squeeze.fixed_set_kernel.COMPILED_FROM_EVALUATIONS"], 1),
    ("README.md", r"for objects of ([\d,]+) nodes or more",
     ["mechanics.squeeze.nonlinear_model.COMPILED_ASSEMBLY_NODES"], 1),
    ("materials.md", r"default for objects under ([\d,]+) nodes",
     ["mechanics.squeeze.nonlinear_model.COMPILED_ASSEMBLY_NODES"], 1),
    ("events.md", r"The substep grows by up to (\d+)x from one substep to the next, to at most "
     r"(\d+) grid steps, while the slope of the contact forces changes by less than (\d+) %",
     ["mechanics.squeeze.stepper.substeps.ADAPTIVE_GROWTH",
      "mechanics.squeeze.stepper.substeps.ADAPTIVE_MAX_STEPS",
      "mechanics.squeeze.stepper.substeps.ADAPTIVE_SLOPE_CHANGE"], [1, 1, 0.01]),
    ("events.md", r"all combinations for up to (\w+) nodes",
     ["mechanics.squeeze.stepper.modes.MAX_JOINT_NODES"], 1),
    ("events.md", r"all combinations\s+again for up to (\w+) nodes",
     ["mechanics.squeeze.stepper.modes.MAX_SEARCHED_NODES"], 1),
    ("events.md", r"the response keeps the last (\d+) evaluated states",
     ["mechanics.elastic.contact_response.KEPT_STATES"], 1),
    ("materials.md", r"a contact set's response keeps its last (\d+) evaluated states",
     ["mechanics.elastic.contact_response.KEPT_STATES"], 1),
    ("materials.md", r"must clear zero by ([\d.]+) of the change the slope makes",
     ["mechanics.squeeze.stepper.location.SURE_MARGIN"], 1),
    ("materials.md", r"`MAX_BORDERED_DOFS` \((\d+) DOFs, two nodes\)",
     ["mechanics.elastic.interior.MAX_BORDERED_DOFS"], 1),
    ("materials.md", r"an element squashed to (\d+) % of its area \(det F = ([\d.]+),",
     ["mechanics.squeeze.contact_model.INVERSION_AREA_RATIO",
      "mechanics.squeeze.contact_model.INVERSION_AREA_RATIO"], [0.01, 1]),
    ("README.md", r"the first run after an install spends about (\d+) s of CPU compiling",
     ["mechanics.squeeze.fixed_set_kernel.COMPILE_CPU_S"], 1),
    ("sweep.md", r"each worker spends about (\d+) s of CPU compiling the kernels",
     ["mechanics.squeeze.fixed_set_kernel.COMPILE_CPU_S"], 1),
    ("design.md", r"beyond `SHARED_SET_BYTES`, (\d+) MiB\)",
     ["mechanics.squeeze.contact_model.SHARED_SET_BYTES"], 2 ** 20),
    ("reliability.md", r"\| nodes \(interior, boundary and thin features\) \| ([\d,]+) "
     r"\(`MAX_MESH_NODES`\)", ["mechanics.elastic.mesh_size.MAX_MESH_NODES"], 1),
    ("reliability.md", r"\| boundary nodes \(outer and holes\) \| ([\d,]+) "
     r"\(`MAX_BOUNDARY_NODES`\)", ["mechanics.elastic.mesh_size.MAX_BOUNDARY_NODES"], 1),
    ("reliability.md", r"at most max\(the nodes asked for, ([\d,]+)\) nodes \(`THIN_ALLOWANCE`\)",
     ["mechanics.elastic.mesh_size.THIN_ALLOWANCE"], 1),
    ("reliability.md", r"`ring --elements` in \[8, ([\d,]+)\]",
     ["mechanics.ring.model.MAX_RING_ELEMENTS"], 1),
    ("events.md", r"`RATE_NOISE` \(([\de.-]+)\)", ["mechanics.squeeze.stepper.modes.RATE_NOISE"],
     1),
    ("events.md", r"one solve with two right-hand sides, at most (\d+) MiB per object\)",
     ["mechanics.elastic.compliance.GRADIENT_BOUND_BYTES"], 2 ** 20),
    ("events.md", r"clears every element whose bound is below ([\d.]+)",
     ["mechanics.squeeze.contact_model.GRADIENT_BOUND_EXACT"], 1),
    ("perception.md", r"Douglas-Peucker to `--tolerance` \(default ([\d.]+) of the pixel "
     r"footprint",
     ["perception.extract.DEFAULT_TOLERANCE_PX"], 1),
    ("perception.md", r"heights above the declared plane are averaged over (\d+) x (\d+) px "
     r"blocks", ["perception.support.BLOCK", "perception.support.BLOCK"], 1),
    ("perception.md", r"within (\d+) px \(`STRAIGHT_PX`", ["perception.extract.STRAIGHT_PX"], 1),
    ("README.md", r"an ellipse or a ring fits within ([\d.]+) pixel",
     ["perception.extract.PRIMITIVE_TOLERANCE_PX"], 1),
    ("perception.md", r"within \*\*([\d.]+) pixel footprints\*\* \(`PRIMITIVE_TOLERANCE_PX`\)",
     ["perception.extract.PRIMITIVE_TOLERANCE_PX"], 1),
]


@pytest.mark.parametrize("page, pattern, constants, unit", CONSTANTS,
                         ids=[f"{c[0]}:{c[2][0].rpartition('.')[2]}" for c in CONSTANTS])
def test_a_stated_constant_is_the_code_s(page, pattern, constants, unit):
    units = unit if isinstance(unit, list) else [unit] * len(constants)
    numbers = [_constant(c) / u for c, u in zip(constants, units)]
    words = {"two": 2, "three": 3, "four": 4, "five": 5}
    found = re.search(pattern, page_text(page))
    assert found, f"{page} no longer states {pattern!r}"
    shown = [float(words.get(x, x.replace(",", ""))) for x in found.groups()]
    assert shown == pytest.approx(numbers, rel=1e-12), (shown, numbers)


def test_the_readme_s_extras_are_the_package_s():
    """Every ``pip install -e '.[extra,...]'`` of README.md and docs/ names extras of
    setup.py.
    """
    import ast

    tree = ast.parse((REPO / "setup.py").read_text(encoding="utf-8"))
    call = next(n for n in ast.walk(tree) if isinstance(n, ast.keyword)
                and n.arg == "extras_require")
    extras = {ast.literal_eval(k) for k in call.value.keys}
    named = {e for page in PAGES for group in re.findall(
        r"pip install (?:-e )?'\.\[([\w,]+)\]'", page.read_text(encoding="utf-8"))
        for e in group.split(",")}
    assert {"ros", "test", "sweep", "cholmod", "fast", "perception"} <= named
    assert named - extras == set()


CLI_DEFAULTS = [
    # (page, pattern capturing the stated default, verb, option, the page's unit in SI)
    ("perception.md", r"higher than `--min-height`, default (\d+) mm", "outline", "--min-height",
     1e-3),
    ("perception.md", r"`--frame-id` names the plane frame \(default `(\w+)`\)", "outline",
     "--frame-id", None),
    ("perception.md", r"seeded by `--seed` \(default (\d+)\)", "render", "--seed", 1),
    ("grippers.md", r"the jaw force times `--margin` \(default ([\d.]+)", "gripper-plan",
     "--margin", 1),
    ("pipeline.md", r"`--max-attempts N` \| with `resqueeze`: squeezes in all, the first "
     r"included \(default (\d+)\)", "run", "--max-attempts", 1),
    ("README.md", r"squeezes again to ([\d.]+) of the alarm's depth", "run",
     "--resqueeze-margin", None),
]


@pytest.mark.parametrize("page, pattern, verb, option, unit", CLI_DEFAULTS,
                         ids=[f"{c[0]}:{c[2]} {c[3]}" for c in CLI_DEFAULTS])
def test_a_default_the_docs_state_is_the_option_s(page, pattern, verb, option, unit):
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "verb")._name_parser_map[verb]
    action = next(a for a in add_verb_arguments(sub)._actions if option in a.option_strings)
    found = re.search(pattern, page_text(page))
    assert found, f"{page} no longer states {pattern!r}"
    if option == "--resqueeze-margin":  # the README states the depth it leaves: 1 - margin
        assert float(found.group(1)) == pytest.approx(1 - action.default)
    elif unit is None:
        assert found.group(1) == action.default
    else:
        assert float(found.group(1)) * unit == pytest.approx(action.default)


def test_the_ros_setup_tests_ci_md_says_skip_on_the_colcon_route():
    """docs/ci.md: "On the colcon route the N `ros-setup` tests ... skip": the tests of
    test/test_ros_setup.py marked ``pip_route_only``.
    """
    import ast

    tree = ast.parse((REPO / "test" / "test_ros_setup.py").read_text(encoding="utf-8"))
    marked = [f.name for f in tree.body if isinstance(f, ast.FunctionDef) and any(
        isinstance(d, ast.Name) and d.id == "pip_route_only" for d in f.decorator_list)]
    assert stated("ci.md", r"On the colcon route the (\d+) `ros-setup` tests") == [len(marked)]


def test_the_planner_parameter_table_of_ros_md_is_the_node_s():
    """docs/ros.md's table of the planner's parameters lists every parameter the node declares,
    each with its default (as config/planner.yaml sets it too).
    """
    from squeeze_grasp_ros.ros.nodes.planner import PARAMETERS

    page = (REPO / "docs" / "ros.md").read_text(encoding="utf-8")
    table = page[page.index("| name | default | meaning |"):]
    rows = [row.split(" | ")[:2] for row in table[:table.index("\n\n")].splitlines()[2:]]

    def value(text: str):
        parsed = yaml.safe_load(text.strip("`"))  # YAML 1.1 reads 1e-5 as text
        return float(parsed) if re.fullmatch(r"[-+]?\d+(\.\d*)?e[-+]?\d+", str(parsed)) else parsed
    shown = {name.strip("|` "): value(default) for name, default in rows}
    assert shown == {name: default for name, (default, _) in PARAMETERS.items()}
    assert shipped("planner.yaml")["/**"]["ros__parameters"] == shown


NODE_DEFAULTS = [
    # (page, pattern capturing the stated default, node module, parameter, the page's unit)
    ("reliability.md", r"at most `max_pending` of them \(default (\d+)\)", "planner",
     "max_pending", 1),
    ("reliability.md", r"`stale_budget` seconds \(executor parameter, default ([\d.]+) s",
     "executor", "stale_budget", 1),
    ("perception.md", r"`min_area_px` \(default (\d+):", "outline", "min_area_px", 1),
    ("perception.md", r"`ambiguous_ratio` \(default ([\d.]+):", "outline", "ambiguous_ratio", 1),
    ("perception.md", r"`qos_depth` \(default (\d+)\), the history depth of the image",
     "outline", "qos_depth", 1),
    ("perception.md", r"whose frame must be the node's `frame_id`, default `(\w+)`", "outline",
     "frame_id", None),
    ("grippers.md", r"`weight_margin` w \(default ([\d.]+),", "monitor", "weight_margin", 1),
    ("grippers.md", r"over the last `joint_slip_window` \(([\d.]+) mm\)", "monitor",
     "joint_slip_window", 1e-3),
    ("grippers.md", r"less than `joint_slip_ratio` \(([\d.]+)\)", "monitor", "joint_slip_ratio",
     1),
    ("grippers.md", r"its grace of (\d+) cycles later", "executor", "redirect_grace", 1),
    ("pipeline.md", r"Ticks before `force_min_fraction` \((\d+) %\)", "monitor",
     "force_min_fraction", 0.01),
    ("pipeline.md", r"beyond `force_tolerance` \((\d+) %\)", "monitor", "force_tolerance", 0.01),
    ("design.md", r"The world runs at most (\d+) ticks \(a report every \d+\) ahead of the "
     r"recorder", "sim_hardware", "recorder_window", 1),
    ("design.md", r"The world runs at most \d+ ticks \(a report every (\d+)\) ahead of the "
     r"recorder", "recorder", "progress_every", 1),
    ("grippers.md", r"\| `stall_timeout`, `gripper_timeout` \| (\d+) s each by default",
     "executor", "stall_timeout", 1),
    ("grippers.md", r"\| `stall_timeout`, `gripper_timeout` \| (\d+) s each by default",
     "executor", "gripper_timeout", 1),
]


@pytest.mark.parametrize("page, pattern, node, parameter, unit", NODE_DEFAULTS,
                         ids=[f"{c[0]}:{c[2]}.{c[3]}" for c in NODE_DEFAULTS])
def test_a_node_parameter_default_the_docs_state_is_the_node_s(page, pattern, node, parameter,
                                                               unit):
    import importlib

    default = importlib.import_module(
        f"squeeze_grasp_ros.ros.nodes.{node}").PARAMETERS[parameter][0]
    found = re.search(pattern, page_text(page))
    assert found, f"{page} no longer states {pattern!r}"
    if unit is None:
        assert found.group(1) == default
    else:
        assert float(found.group(1)) * unit == pytest.approx(default)


def test_the_run_json_keys_pipeline_md_lists_are_the_summary_s():
    """docs/pipeline.md's ``--json`` row names keys of ``run``'s JSON summary, in its order (the
    keys of the dict ``run_summary`` returns, read from its source: a run takes seconds).
    """
    import ast
    import inspect

    from squeeze_grasp_ros.ros.run import summary

    tree = ast.parse(inspect.getsource(summary.run_summary))
    returned = next(n.value for n in ast.walk(tree) if isinstance(n, ast.Return)
                    and isinstance(n.value, ast.Dict))
    keys = [ast.literal_eval(k) for k in returned.keys]
    page = (REPO / "docs" / "pipeline.md").read_text(encoding="utf-8")
    row = next(line for line in page.splitlines() if line.startswith("| `--json` | the summary"))
    listed = re.findall(r"`(\w+)`", row.split(" | ")[1])
    assert len(listed) >= 10 and [k for k in keys if k in listed] == listed, (listed, keys)


def test_the_exit_statuses_the_readme_and_the_help_list_are_the_codes():
    """README.md's "Exit status of every verb" and ``squeeze-grasp --help``'s epilog give every
    exit code and no other; docs/sweep.md's status table and ``sweep --help``'s epilog give the
    same codes as each other.
    """
    from squeeze_grasp_ros.cli import EPILOG
    from squeeze_grasp_ros.commands.sweep import EPILOG as SWEEP_EPILOG
    from squeeze_grasp_ros.exit_codes import ExitCode

    def codes(text: str) -> list[int]:
        return sorted({int(c) for c in re.findall(r"(?:^|[:;,] )(\d+) ", text)})
    readme = page_text("README.md")
    sentence = readme[readme.index("Exit status of every verb:"):]
    sentence = sentence[:sentence.index("SIGTERM") + 8]
    assert codes(sentence) == codes(EPILOG) == sorted(int(c) for c in ExitCode), sentence
    page = (REPO / "docs" / "sweep.md").read_text(encoding="utf-8")
    table = page[page.index("| status | when |"):]
    rows = [row.split(" | ")[0].strip("| ") for row in
            table[:table.index("\n\n")].splitlines()[2:]]
    listed = sorted(int(c) for row in rows for c in row.split(", "))
    assert listed == codes(SWEEP_EPILOG) == [0, 1, 2, 4, 130, 143], (listed, SWEEP_EPILOG)


def test_perception_md_names_every_parameter_of_the_outline_node():
    """docs/perception.md's section on the ``outline`` node names each parameter the node
    declares.
    """
    from squeeze_grasp_ros.ros.nodes.outline import PARAMETERS

    page = (REPO / "docs" / "perception.md").read_text(encoding="utf-8")
    section = page[page.index("## The `outline` node"):]
    section = section[:section.index("\n## ", 4)]
    assert [name for name in PARAMETERS if not re.search(rf"\b{name}\b", section)] == []


def launch_arguments(name: str) -> dict:
    """The arguments ``launch/NAME.launch.py`` declares and their default values (source)."""
    import ast

    tree = ast.parse((REPO / "launch" / f"{name}.launch.py").read_text(encoding="utf-8"))
    return {ast.literal_eval(call.args[0]): next(
        (ast.unparse(k.value) for k in call.keywords if k.arg == "default_value"), None)
        for call in ast.walk(tree) if isinstance(call, ast.Call)
        and getattr(call.func, "id", "") == "DeclareLaunchArgument"}


def test_ros_md_gives_every_argument_of_the_launch_files():
    """docs/ros.md's paragraph on the launch files gives each argument they declare, as
    ``name:=``, and sim_pipeline's ``sigterm_timeout`` default as the file's.
    """
    text = page_text("ros.md")
    paragraph = text[text.index("`sim_pipeline.launch.py` with no arguments"):]
    paragraph = paragraph[:paragraph.index("Data and configuration files")]
    for name in ("sim_pipeline", "hardware", "planner"):
        declared = launch_arguments(name)
        assert declared and [a for a in declared if f"{a}:=" not in paragraph] == [], name
    timeout = launch_arguments("sim_pipeline")["sigterm_timeout"].strip("'\"")
    assert f"`sigterm_timeout:={timeout}`" in paragraph


def test_every_constant_the_docs_name_is_the_package_s():
    """Each ``UPPER_CASE`` name in backticks in the docs (``MAX_BORDERED_DOFS``,
    ``SQUEEZE_GRASP_KERNEL``, ...) occurs in the package's source, but for the environment
    variables of ROS 2 and Fast DDS the docs name.
    """
    source = "\n".join(p.read_text(encoding="utf-8")
                       for p in (REPO / "squeeze_grasp_ros").rglob("*.py"))
    outside = {"ROS_DOMAIN_ID", "FASTRTPS_DEFAULT_PROFILES_FILE"}
    named = {name for page in PAGES for name in re.findall(
        r"`([A-Z][A-Z0-9]*_[A-Z0-9_]+)`", page.read_text(encoding="utf-8"))}
    assert len(named) >= 20
    assert [n for n in sorted(named - outside) if not re.search(rf"\b{n}\b", source)] == []


def test_the_npm_packages_and_caches_the_readme_names_are_the_tests():
    """README.md: the tests fetch four npm packages into ~/.cache/squeeze_grasp_ros/foxglove-js
    and cache the colcon test's interface build in .../colcon-interfaces.
    """
    import json

    words = {"two": 2, "three": 3, "four": 4, "five": 5}
    count = re.search(r"The tests fetch (\w+) npm packages", page_text("README.md")).group(1)
    dependencies = json.loads((REPO / "test" / "js" / "package.json").read_text())["dependencies"]
    assert words[count] == len(dependencies)
    for cache, module in (("foxglove-js", "foxglove_support.py"),
                          ("colcon-interfaces", "test_colcon_route.py")):
        assert f"`~/.cache/squeeze_grasp_ros/{cache}`" in page_text("README.md")
        assert f'"{cache}"' in (REPO / "test" / module).read_text(encoding="utf-8")


def test_the_error_kinds_the_readme_names_are_the_package_s():
    """README.md: "Errors come in four kinds (...) under `SqueezeGraspError`": the direct
    subclasses of SqueezeGraspError in the package's error module, all of them.
    """
    import inspect

    from squeeze_grasp_ros.mechanics import errors

    text = page_text("README.md")
    sentence = re.search(r"Errors come in (\w+) kinds \((.*?)\) under `SqueezeGraspError`",
                         text)
    named = re.findall(r"`(\w+)`", sentence.group(2))
    kinds = [name for name, cls in inspect.getmembers(errors, inspect.isclass)
             if errors.SqueezeGraspError in cls.__bases__]
    assert sorted(named) == sorted(kinds)
    assert {"two": 2, "three": 3, "four": 4, "five": 5}[sentence.group(1)] == len(kinds)


def test_the_measure_table_of_events_md_is_the_models():
    """docs/events.md's table of each material model's strain and stress measure is what
    ``MaterialModel.strain_measure`` and ``stress_measure`` give.
    """
    from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

    page = (REPO / "docs" / "events.md").read_text(encoding="utf-8")
    table = page[page.index("| model | strain (`strain_measure`"):]
    rows = [re.findall(r"`(\w+)`", row) for row in
            table[:table.index("\n\n")].splitlines()[2:]]
    assert [(m.value, str(m.strain_measure), str(m.stress_measure)) for m in MaterialModel] == [
        tuple(row) for row in rows]


def test_the_controller_manager_examples_of_grippers_md_fit_the_shipped_scenes():
    """docs/grippers.md's ``controller_manager`` examples (not run: the simulated hardware
    stands in for them) name the shipped scenes' controller, the device's joints (the Barrett
    hand's eight), and for the parallel gripper the scene's goal tolerance, stall timeout,
    speed limit and the device's largest effort.
    """
    from squeeze_grasp_ros.control.barrett import JOINTS

    found = [yaml.safe_load("\n".join(b.lines)) for b in blocks(REPO / "docs" / "grippers.md")
             if b.language == "yaml" and b.lines[0] == "controller_manager:"]
    assert len(found) == 4
    device = shipped("devices/generic_85mm.yaml")
    parallel = shipped("scenes/sponge_gripper_parallel.yaml")["controller"]
    for example in found:
        (name,) = [k for k in example if k not in ("controller_manager",
                                                   "joint_state_broadcaster")]
        parameters = example[name]["ros__parameters"]
        joints = parameters.get("joints", [parameters.get("joint")])
        if name == "hand_controller":
            assert shipped("scenes/foam_square_barrett_jtc.yaml")["controller"]["name"] == name
            assert joints == list(JOINTS)
            continue
        assert shipped("scenes/sponge_gripper.yaml")["controller"]["name"] == name
        assert joints == device["transmission"]["joints"]
        if "goal_tolerance" in parameters:
            assert {k: parameters[k] for k in ("goal_tolerance", "stall_timeout",
                                               "max_velocity")} == {
                k: parallel[k] for k in ("goal_tolerance", "stall_timeout", "max_velocity")}
            assert parameters["max_effort"] == (device["max_force"]
                                                * device["transmission"]["effort_per_force"])


def test_the_api_help_shows_what_the_readme_says():
    """README.md: ``help(squeeze_grasp_ros.api)`` shows ``polygon(points)``,
    ``generate_mesh(polygon(points), max_area)`` and a squeeze at nodes of your choosing, as
    examples (test_doctests.py runs them).
    """
    import doctest

    from squeeze_grasp_ros import api

    assert "`help(squeeze_grasp_ros.api)` shows this, and a squeeze at nodes of your choosing" \
        in page_text("README.md")
    source = "".join(e.source for e in doctest.DocTestParser().get_examples(api.__doc__))
    for call in (r"\bpolygon\(", r"\bgenerate_mesh\(", r"\bevent_squeeze\(obj, \("):
        assert re.search(call, source), call


def test_the_planner_interface_table_of_ros_md_is_the_node_s():
    """docs/ros.md's table of the planner's services and actions lists each one the node
    creates, with its type, and no other.
    """
    source = (REPO / "squeeze_grasp_ros" / "ros" / "nodes" / "planner.py").read_text(
        encoding="utf-8")
    created = {("srv", kind, name) for kind, name in
               re.findall(r"\((\w+), \"(\w+)\", self\._\w+\)", source)}
    created |= {("action", kind.removesuffix("Action"), name) for kind, name in
                re.findall(r"ActionServer\(self, (\w+),\s+pipeline\.action_name\(self, "
                           r"\"~/(\w+)\"\)", source)}
    page = (REPO / "docs" / "ros.md").read_text(encoding="utf-8")
    table = page[page.index("| name | type | computes | where |"):]
    listed = {(kind, typ, name) for name, kind, typ in re.findall(
        r"^\| `~/(\w+)` \| (srv|action) `(\w+)` \|", table[:table.index("\n\n")], re.M)}
    assert len(created) == 9 and listed == created, (listed ^ created)


def test_the_node_table_of_pipeline_md_is_the_console_scripts():
    """docs/pipeline.md's table of the nodes names every node console script of setup.py (all
    but ``squeeze-grasp``), and each parameter file it names is shipped.
    """
    import ast

    tree = ast.parse((REPO / "setup.py").read_text(encoding="utf-8"))
    scripts = next(ast.literal_eval(k.value)["console_scripts"] for k in ast.walk(tree)
                   if isinstance(k, ast.keyword) and k.arg == "entry_points")
    nodes = sorted(s.split("=")[0].strip() for s in scripts)
    nodes.remove("squeeze-grasp")
    page = (REPO / "docs" / "pipeline.md").read_text(encoding="utf-8")
    table = page[page.index("| node (console script) |"):]
    rows = table[:table.index("\n\n")].splitlines()[2:]
    assert sorted(re.match(r"\| `(\w+)` \|", row).group(1) for row in rows) == nodes
    files = re.findall(r"`(config/\w+\.yaml)`", "\n".join(rows))
    assert len(files) >= 5 and all((REPO / f).exists() for f in files), files


def test_every_topic_of_the_pipeline_is_documented_and_the_table_names_real_ones():
    """Each topic name of ``ros/nodes/pipeline.py`` appears in the docs (in backticks), and each
    fixed name in docs/pipeline.md's topic table is one of them.
    """
    source = (REPO / "squeeze_grasp_ros" / "ros" / "nodes" / "pipeline.py").read_text(
        encoding="utf-8")
    topics = set(re.findall(r'^[A-Z_]+ = "(/?[a-z_]+(?:/[a-z_]+)*)"$', source, re.M))
    topics -= {"object"}  # FRAME: the object frame's name, not a topic
    text = "\n".join(page.read_text(encoding="utf-8") for page in PAGES)
    assert len(topics) >= 25
    assert [t for t in sorted(topics) if f"`{t}`" not in text] == []
    page = (REPO / "docs" / "pipeline.md").read_text(encoding="utf-8")
    table = page[page.index("| topic | type | direction |"):]
    rows = table[:table.index("\n\n")].splitlines()[2:]
    named = [t for row in rows for t in re.findall(r"`([^`<>]+)`", row.split(" | ")[0])]
    assert len(named) >= 15 and [t for t in named if t not in topics] == []


def test_the_readme_s_ci_line_is_what_ci_runs():
    """README.md's second quick-start line is "exactly what CI runs, `.ci/run`": its commands
    are the script's, in order (and CONTRIBUTING.md's set-up line is the same without the
    tests; docs/ci.md names the same extras).
    """
    script = [line for line in (REPO / ".ci" / "run").read_text(encoding="utf-8").splitlines()
              if line and not line.startswith(("#", "set ", "cd "))]
    readme = next(b for b in blocks(REPO / "README.md") if b.language == "bash"
                  and "pytest" in "\n".join(b.lines))
    assert "exactly what CI runs, `.ci/run`" in readme.before
    assert [c.strip() for c in " ".join(readme.lines).split("&&")] == script
    contributing = next(b for b in blocks(REPO / "CONTRIBUTING.md") if b.language == "bash")
    assert [c.strip() for c in " ".join(contributing.lines).split("&&")] == script[:-1]
    extras = re.search(r"pip install -e '\.\[([\w,]+)\]'", script[2]).group(1)
    assert f"`pip install -e '.[{extras}]'`" in page_text("ci.md")


def test_the_readme_s_pictures_are_schematics_captioned_as_such():
    """CONTRIBUTING.md: the README's pictures in docs/img/ are hand-drawn schematics, captioned
    as such beside the command that draws the computed picture: each embedded picture says so
    in its own description and in the caption under it, which names a ``squeeze-grasp``
    command or the commands of its section.
    """
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    embedded = re.findall(r"!\[[^\]]*\]\((docs/img/[\w.]+)\)\n\n(\*[^\n]*(?:\n[^\n]+)*)", readme)
    assert sorted(path for path, _ in embedded) == sorted(
        f"docs/img/{p.name}" for p in (REPO / "docs" / "img").iterdir())
    for path, caption in embedded:
        assert "(hand-drawn, not a result)" in (REPO / path).read_text(encoding="utf-8"), path
        assert "drawn by hand" in caption and ("squeeze-grasp " in caption
                                               or "commands below" in caption), caption
    assert "are hand-drawn schematics, captioned as such" in page_text("CONTRIBUTING.md")


def test_every_named_section_a_page_points_to_exists():
    """A reference such as ``docs/grippers.md, "The lift"`` or ``docs/design.md §4`` names a
    heading (or a bold paragraph title) of that page.
    """
    checked, missing = 0, []
    for page in PAGES:
        flat = " ".join(page.read_text(encoding="utf-8").split())
        for name, section, number in re.findall(
                r'(?:docs/)?(\w+)\.md(?:, "([^"]+)"| §(\d+))', flat):
            target = REPO / "docs" / f"{name}.md"
            text = target.read_text(encoding="utf-8") if target.exists() else ""
            found = (re.search(rf"^## {number}\. ", text, re.M) if number else
                     re.search(rf"^#+ {re.escape(section)}", text, re.M)
                     or f"**{section}" in " ".join(text.split()))
            checked += 1
            if not found:
                missing.append(f"{page.name}: {name}.md {section or '§' + number}")
    assert checked >= 25 and missing == [], missing


def test_every_bench_section_the_docs_name_is_one():
    """Each ``bench [--quick] --only SECTION ...`` of the docs names sections of the bench."""
    from squeeze_grasp_ros.bench import SECTIONS

    named = [s for page in PAGES for run in re.findall(
        r"bench (?:--quick )?--only ((?:[a-z_]+ ?)+)", page.read_text(encoding="utf-8"))
        for s in run.split()]
    assert len(named) >= 50 and sorted(set(named) - set(SECTIONS)) == []


def test_the_default_taxels_pipeline_md_states_are_the_scene_s():
    """docs/pipeline.md: "the default 96 taxels over 150°" are ``sensors.taxels`` and
    ``sensors.taxel_span_deg``'s defaults.
    """
    import dataclasses

    from squeeze_grasp_ros.scene.specs import SensorsSpec

    taxels, span = stated("pipeline.md", r"with the default (\d+) taxels over (\d+)°")
    defaults = {f.name: f.default for f in dataclasses.fields(SensorsSpec)}
    assert (defaults["taxels"], defaults["taxel_span_deg"]) == (taxels, span)


def test_the_corner_turn_perception_md_states_is_the_outline_file_s():
    """docs/perception.md: an outline file's vertices are samples of the curve and only turns of
    more than 20 degrees are kept (as mesh corners): ``shapes._turning_corners``' default.
    """
    import inspect

    from squeeze_grasp_ros.mechanics.elastic import shapes

    (turn,) = stated("perception.md", r"only turns of more than (\d+) degrees are kept")
    default = inspect.signature(shapes._turning_corners).parameters["threshold_deg"].default
    assert turn == default
