# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Every console transcript in README.md, docs/ and CONTRIBUTING.md is run and its output compared.

How a transcript is compared, and the masks: ``test/doc_transcripts.py`` (and docs/ci.md).
A command runs as the user would type it, from a scratch folder in which ``config`` is a copy
of the repository's and ``launch`` and ``msg_defs`` link to it (so relative paths in the docs
resolve and files the commands write land in the scratch folder). A command of the colcon
route runs as its equivalent without ros2cli, which is not on PyPI:

- ``ros2 run squeeze_grasp_ros squeeze-grasp ARGS`` is ``squeeze-grasp ARGS``, and ``$SHARE``
  (the package's share folder) is the repository, which has the same ``config/`` and
  ``launch/``;
- ``ros2 pkg executables squeeze_grasp_ros`` lists the console scripts of the installed
  distribution;
- ``ros2 launch squeeze_grasp_ros FILE --show-args`` prints the launch file's declared
  arguments, read from its source;
- ``ros2 launch squeeze_grasp_ros sim_pipeline.launch.py [scene:=F] [record:=D]`` is
  ``squeeze-grasp run F [--record D]``: its ``[run-N]`` lines are the run's summary, compared
  as a subsequence of the transcript's lines (the launch system's own lines need ros2launch);
- ``ros2 interface show PKG/srv/T`` prints ``msg_defs/srv/T.srv``;
- ``/tmp/user/`` (the docs' folder outside the repository) is a folder in the scratch folder.

Mechanics verbs run in this process (``cli.main``), the ROS verbs (``run``, ``replay``,
``sweep``) as processes; each distinct command runs once per session. Transcripts whose
commands take more than a few seconds are in the slow suite (``-m slow``).
"""
from __future__ import annotations

import ast
import contextlib
import importlib.metadata
import io
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import doc_ros_session
import numpy as np
import pytest
import yaml
from doc_transcripts import (
    MASKS,
    PAGES,
    REPO,
    Command,
    Transcript,
    abridged_json,
    abridged_json_matches,
    blocks,
    compare,
    json_matches,
    line_matches,
    number_matches,
    transcripts,
)
from executables import script

from squeeze_grasp_ros.commands.launch_checks import RUN_ARGUMENTS, run_arguments
from squeeze_grasp_ros.exit_codes import ExitCode
from squeeze_grasp_ros.extras import install_hint

LINKED = ("launch", "msg_defs")
SLOW_VERBS = ("run", "replay", "sweep", "bench")
PROCESS_VERBS = ("run", "replay", "sweep", "sweep-report", "bench", "ros-setup")
SLOW_OPTIONS = ("--compare-models",)
RUN_LINE = re.compile(r"^\[run-\d+\] ")
USER_FOLDER = "/tmp/user/"
"""The transcripts' working folder outside the repository; a scratch folder stands in for it."""

ALL = transcripts()
PLANNER_COMMANDS = ("ros2 service", "ros2 param", "ros2 action")
PLANNER_PAGE, PLANNER_START = REPO / "docs" / "ros.md", "## Parameters"


def by_planner_session(transcript: Transcript) -> bool:
    """Whether the planner session of docs/ros.md runs this transcript (test below)."""
    return all(c.text.startswith(PLANNER_COMMANDS) for c in transcript.commands)


TESTED = [t for t in ALL if t.untested is None and not by_planner_session(t)]


def is_slow(transcript: Transcript) -> bool:
    """Whether a transcript runs a pipeline, a sweep, a benchmark or the model comparison."""
    for command in transcript.commands:
        words = squeeze_grasp_words(command.text)
        if words and (words[0] in SLOW_VERBS or any(o in words for o in SLOW_OPTIONS)):
            return True
        if command.text.startswith("ros2 launch") and "--show-args" not in command.text:
            return True
    return False


def squeeze_grasp_words(text: str) -> list[str] | None:
    """The arguments of a ``squeeze-grasp`` command (also through ``ros2 run``), else None."""
    words = shlex.split(text.replace("$SHARE", str(REPO)), comments=True)
    if words[:3] == ["ros2", "run", "squeeze_grasp_ros"]:
        words = words[3:]
    return words[1:] if words and words[0] == "squeeze-grasp" else None


@pytest.fixture(scope="session")
def scratch(tmp_path_factory) -> Path:
    """The folder the transcripts run in: config/, launch/, msg_defs/ link to the repository."""
    folder = tmp_path_factory.mktemp("docs")
    # a copy of config/: a planner reads scene files only inside its share folder and its
    # working folder, symlinks resolved (on the colcon route the share folder is not REPO)
    shutil.copytree(REPO / "config", folder / "config")
    for name in LINKED:
        (folder / name).symlink_to(REPO / name)
    (folder / "tmp_user").mkdir()
    return folder


OUTPUTS: dict[str, list[str]] = {}
"""Each distinct command's output, run once per session."""


def run_command(command: Command, folder: Path, again: bool = False) -> list[str]:
    """The output of ``command`` (or its equivalent, see the module docstring) in ``folder``;
    ``again``: run it even if it ran before (a transcript repeating a command shows what the
    repetition does, e.g. a sweep resuming).
    """
    if again or command.text not in OUTPUTS:
        # a terminal shows what follows the last carriage return of a line (progress lines)
        OUTPUTS[command.text] = [line.rsplit("\r", 1)[-1]
                                 for line in _run(command.text, folder).split("\n")]
    return OUTPUTS[command.text]


def _run(text: str, folder: Path) -> str:
    text = text.replace(USER_FOLDER, f"{folder / 'tmp_user'}/")
    words = squeeze_grasp_words(text)
    if words is not None:
        if words and words[0] in PROCESS_VERBS:
            return _process([script("squeeze-grasp"), *words], folder)
        return _in_process(words, folder)
    words = shlex.split(text.replace("$SHARE", str(REPO)), comments=True)
    if words[0] == "cat":
        return (folder / words[1]).read_text(encoding="utf-8")
    if words[0] == "ls":
        return "  ".join(sorted(p.name for p in (folder / words[1]).iterdir()))
    if words[0].startswith("SHARE="):
        return ""
    if words[0] == "python":
        return _process([sys.executable, *words[1:]], folder)
    if words[:3] == ["ros2", "pkg", "executables"]:
        return executables(words[3])
    if words[:2] == ["ros2", "launch"] and words[-1] == "--show-args":
        return show_args(REPO / "launch" / words[3])
    if words[:2] == ["ros2", "launch"] and words[3] == "sim_pipeline.launch.py":
        return launched_run(dict(w.split(":=", 1) for w in words[4:]), folder)
    if words[:3] == ["ros2", "interface", "show"]:
        package, kind, name = words[3].split("/")
        return (REPO / "msg_defs" / kind / f"{name}.{kind}").read_text(encoding="utf-8")
    raise AssertionError(f"no way to run {text!r}: mark the transcript <!-- untested: ... -->")


def _cli(words: list[str], folder: Path) -> tuple[int, str]:
    """``squeeze-grasp WORDS`` run in this process from ``folder``: its exit code and its
    output (stdout and stderr together).
    """
    from squeeze_grasp_ros import cli

    out = io.StringIO()
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            code = cli.main(words)
    finally:
        os.chdir(cwd)
    return code, out.getvalue()


def _in_process(words: list[str], folder: Path) -> str:
    code, output = _cli(words, folder)
    missing = re.search(r"needs (\S+), which is not installed: (.*)", output)
    if code == ExitCode.INTERNAL and missing and install_hint(missing.group(1)):
        pytest.skip(f"squeeze-grasp {words[0]} needs {missing.group(1)}: {missing.group(2)}")
    assert code in (0, 1), f"squeeze-grasp {' '.join(words)} exited {code}:\n{output}"
    return output


def _process(argv: list[str], folder: Path) -> str:
    """The output of a process, stdout and stderr interleaved as on a terminal."""
    done = subprocess.run(argv, cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=900, stdin=subprocess.DEVNULL,
                          env={**os.environ, "PYTHONUNBUFFERED": "1"})
    assert done.returncode in (0, 1), f"{argv} exited {done.returncode}:\n{done.stdout}"
    return done.stdout


def executables(package: str) -> str:
    """What ``ros2 pkg executables PACKAGE`` lists: the console scripts, sorted."""
    scripts = importlib.metadata.distribution(package).entry_points.select(
        group="console_scripts")
    return "\n".join(f"{package} {name}" for name in sorted(e.name for e in scripts))


def show_args(launch_file: Path) -> str:
    """``ros2 launch ... --show-args``: every ``DeclareLaunchArgument`` of the file, in order.

    A default computed from the package's share folder (``get_package_share_directory``) is
    evaluated with that folder as ``<install prefix>/share/<package>``.
    """
    tree = ast.parse(launch_file.read_text(encoding="utf-8"))
    values = {"Path": Path, "str": str,
              "get_package_share_directory": lambda p: f"<install prefix>/share/{p}"}
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and len(node.targets) == 1 \
                and isinstance(node.targets[0], ast.Name):
            with contextlib.suppress(Exception):
                values[node.targets[0].id] = eval(  # noqa: S307 (the repository's own file)
                    compile(ast.Expression(node.value), str(launch_file), "eval"), values)
    lines = ["Arguments (pass arguments as '<name>:=<value>'):"]
    for call in ast.walk(tree):
        if not (isinstance(call, ast.Call) and getattr(call.func, "id", "")
                == "DeclareLaunchArgument"):
            continue
        keywords = {k.arg: k.value for k in call.keywords}
        default = eval(compile(ast.Expression(keywords["default_value"]), str(launch_file),
                               "eval"), values)
        lines += ["", f"    {ast.literal_eval(call.args[0])!r}:",
                  f"        {ast.literal_eval(keywords['description'])}",
                  f"        (default: {default!r})"]
    return "\n".join(lines)


def launched_run(arguments: dict[str, str], folder: Path) -> str:
    """``sim_pipeline.launch.py``'s run, as the run's own lines prefixed by ``[run-N] ``."""
    scene = arguments.get("scene") or str(REPO / "config" / "scenes" / "foam_square.yaml")
    argv = [script("squeeze-grasp"), "run", scene]
    if arguments.get("record"):
        argv += ["--record", arguments["record"]]
    argv += run_arguments(**{name: arguments.get(name, "") for name in RUN_ARGUMENTS})
    return _process(argv, folder)


def check(transcript: Transcript, folder: Path) -> None:
    """Run every command of ``transcript`` and compare its output."""
    problems, seen = [], set()
    for command in transcript.commands:
        output = run_command(command, folder, again=command.text in seen)
        seen.add(command.text)
        if command.text.startswith("ros2 launch") and "--show-args" not in command.text:
            problem = compare_subsequence(command.output, output)
        else:
            problem = compare(command.output, output)
        if problem:
            problems.append(f"$ {command.text}\n  {problem}")
    assert not problems, f"{transcript.name}:\n" + "\n".join(problems)


def compare_subsequence(expected: tuple[str, ...], actual: list[str]) -> str | None:
    """The ``[run-N]`` lines of a launch transcript, in order, against the run's lines."""
    wanted = [RUN_LINE.sub("", line) for line in expected if RUN_LINE.match(line)]
    assert wanted, "a launch transcript without [run-N] lines cannot be compared"
    k = 0
    for line in actual:
        if k < len(wanted) and line_matches(wanted[k], line):
            k += 1
    if k == len(wanted):
        return None
    shown = "\n".join(f"    {line}" for line in actual)
    return f"no run line matches {wanted[k]!r}\n  actual output:\n{shown}"


@pytest.mark.parametrize(
    "transcript",
    [pytest.param(t, id=t.name, marks=[pytest.mark.slow] if is_slow(t) else [])
     for t in TESTED])
def test_transcript(transcript, scratch):
    check(transcript, scratch)


def test_planner_examples(scratch):
    """docs/ros.md's snippets and ros2 commands against a real planner process."""
    problems = []
    for step, output in doc_ros_session.run(PLANNER_PAGE, PLANNER_START, scratch):
        if step.expected is not None:
            problem = compare(step.expected, output)
            if problem:
                problems.append(f"docs/ros.md:{step.block.line}:\n{step.source}\n  {problem}")
    assert not problems, "\n".join(problems)


def test_every_transcript_is_tested_or_says_why_not():
    assert len(ALL) >= 20
    for t in ALL:
        assert t.commands, f"{t.name}: a console block without a '$ command' line"
        if t.untested is not None:
            assert len(t.untested) > 15, f"{t.name}: say why it is untested"
        elif by_planner_session(t):
            assert t.page == PLANNER_PAGE and t.line > PLANNER_PAGE.read_text(
                encoding="utf-8")[:PLANNER_PAGE.read_text(encoding="utf-8").index(
                    PLANNER_START)].count("\n"), f"{t.name}: no planner session runs it"


def test_command_outputs_are_console_blocks():
    """A block of another language that shows ``$ command`` lines is a transcript in
    disguise: it would escape the test.
    """
    disguised = [f"{b.page.relative_to(REPO)}:{b.line}" for page in PAGES
                 for b in blocks(page) if b.language != "console"
                 and any(line.startswith("$ ") for line in b.lines)]
    assert disguised == []


def test_untested_markers_stand_right_before_a_transcript():
    marked = {(t.page, t.line) for t in ALL if t.untested is not None}
    for page in PAGES:
        inside = {k for b in blocks(page) for k in range(b.line, b.line + len(b.lines) + 1)}
        lines = page.read_text(encoding="utf-8").splitlines()
        for k, line in enumerate(lines, start=1):
            if line.strip().startswith("<!-- untested:") and k not in inside:
                fence = next(j for j in range(k + 1, len(lines) + 1) if lines[j - 1].strip())
                assert (page, fence) in marked, f"{page.name}:{k}: not right before a transcript"


def test_the_comparison_can_fail():
    """The comparison itself: numbers at the printed precision, masks, ellipses."""
    assert number_matches("8.485", "8.48528")
    assert not number_matches("8.489", "8.48528")
    assert number_matches("-5.214e-15", "3e-17")
    assert number_matches("0", "-2.95e-17")
    assert not number_matches("0.01277", "0.012559")
    assert number_matches("467.15707834831113", "467.1570783483")
    assert not number_matches("467.15707834831113", "467.157")
    assert line_matches("time: precompute 0.049 s, squeeze 0.127 s",
                        "time: precompute 1.5 s, squeeze 12 s")
    assert not line_matches("after 701 ticks = 0.700 s sim time", "after 700 ticks = 0.699 s "
                            "sim time")
    assert not line_matches("  t=   0.1040 s   A F1", "  t=   0.1050 s   A F1")
    assert line_matches("contacts: nodes ..., 49", "contacts: nodes 114, 49")
    assert not line_matches("contacts: nodes 115, 49", "contacts: nodes 114, 49")
    assert compare(("a 1", "...", "z 2"), ["a 1", "b", "c", "z 2"]) is None
    assert compare(("a 1", "z 2"), ["a 1", "b", "z 2"]) is not None
    assert compare(("a 1",), ["a 1", "more"]) is not None
    assert {m.name for m in MASKS} >= {"seconds", "pid", "goal id", "temporary path"}


def heading_anchor(heading: str) -> str:
    """GitHub's anchor of a Markdown heading."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_every_relative_link_and_anchor_exists():
    broken = []
    for page in PAGES:
        for found in re.finditer(r"\]\(([^)#\s]*)(#[^)\s]*)?\)", page.read_text(encoding="utf-8")):
            target, anchor = found.groups()
            if target.startswith(("http://", "https://")):
                continue
            path = page.parent / target if target else page
            if not path.exists():
                broken.append(f"{page.name}: {target}")
            elif anchor and path.suffix == ".md":
                headings = [heading_anchor(line.lstrip("#")) for line in
                            path.read_text(encoding="utf-8").splitlines() if line.startswith("#")]
                if anchor[1:] not in headings:
                    broken.append(f"{page.name}: {target}{anchor}")
    assert broken == []


def test_the_abridged_json_example_is_what_the_verb_prints(scratch):
    """docs/events.md's ``--json`` example (abridged: ``...``) is what ``squeeze --json`` of the
    scene it names prints: every key shown in the verb's order (all of them where nothing is
    elided), every value shown at its printed precision.
    """
    page = REPO / "docs" / "events.md"
    block = next(b for b in blocks(page) if b.language == "json")
    scene = re.search(r"`--json` prints \(abridged; `([\w.]+)`\)", block.before).group(1)
    command = Command(f"squeeze-grasp squeeze config/scenes/{scene} --json", ())
    actual = json.loads("\n".join(run_command(command, scratch)))
    problem = abridged_json_matches(abridged_json("\n".join(block.lines)), actual)
    assert problem is None, f"{page.name}:{block.line}: {problem}"


def test_the_abridged_json_comparison_can_fail():
    example = abridged_json('{"a": 1.5, "b": [1, 2, ...], "c": {...}, "d": {"x": 1, ...}}')
    actual = {"a": 1.46, "b": [1, 2, 3], "c": {"y": 0}, "d": {"w": 0, "x": 1, "z": 2}}
    assert abridged_json_matches(example, actual) is None
    assert abridged_json_matches(example, {**actual, "a": 1.44}) is not None
    assert abridged_json_matches(example, {"b": actual["b"], **actual}) is not None  # key order
    assert abridged_json_matches(example, {**actual, "e": 0}) is not None  # a key not shown
    assert abridged_json_matches(example, {**actual, "b": [1]}) is not None
    assert abridged_json_matches(example, {**actual, "d": {"w": 0}}) is not None


def test_the_executor_goal_example_is_the_foam_squares_plan():
    """docs/pipeline.md's ``ros2 action send_goal`` example is the planned goal of the shipped
    foam square, to its printed precision.
    """
    from squeeze_grasp_ros.api import load_scene, scene_file
    from squeeze_grasp_ros.scene.goal import plan_scene

    page = REPO / "docs" / "pipeline.md"
    block = next(b for b in blocks(page) if b.language == "bash"
                 and "/executor/execute_grasp" in "\n".join(b.lines))
    text = " ".join(block.lines)
    printed = [re.search(rf"{key}: ([-0-9.e]+)", text).group(1)
               for key in ("depth", "relative_per_depth")]
    printed += re.findall(r"[xy]: ([-0-9.e]+)", text)
    goal = plan_scene(load_scene(scene_file("foam_square"))).goal
    actual = [goal.depth, goal.relative_per_depth, *np.asarray(goal.directions).ravel()]
    assert len(printed) == len(actual) == 6
    assert all(number_matches(p, repr(float(a))) for p, a in zip(printed, actual)), \
        (printed, actual)


def test_the_scene_error_the_docs_quote_is_the_one_a_scene_gets():
    """scenes.md and ros.md quote the error of a Poisson's ratio out of range: it is the one
    loading such a scene raises (the range included); scenes.md quotes that of a misspelt key
    (line breaks aside).
    """
    from squeeze_grasp_ros.scene import SceneError, parse_scene

    doc = yaml.safe_load((REPO / "config" / "scenes" / "foam_square.yaml").read_text())
    doc["object"]["material"]["nu"] = 0.7
    with pytest.raises(SceneError) as refused:
        parse_scene(doc)
    quoted = f"`{refused.value}`"
    assert quoted == "`object.material.nu must be in [-0.9, 0.5], got 0.7`"
    for page in ("scenes.md", "ros.md"):
        assert quoted in (REPO / "docs" / page).read_text(encoding="utf-8"), page
    doc["object"]["materal"] = doc["object"].pop("material")
    with pytest.raises(SceneError) as misspelt:
        parse_scene(doc)
    scenes = " ".join((REPO / "docs" / "scenes.md").read_text(encoding="utf-8").split())
    assert f"`{misspelt.value}`" in scenes, misspelt.value


def _refusal(words: list[str], folder: Path) -> str:
    """The one line ``squeeze-grasp WORDS`` prints when it refuses its input (exit 2)."""
    code, output = _cli(words, folder)
    assert code == ExitCode.USAGE, (words, code, output)
    return output.strip()


def _quoted_block(page: Path, starts: str) -> str:
    """The text of the plain fenced block of ``page`` that starts with ``starts``, its
    wrapped lines joined.
    """
    block = next(b for b in blocks(page) if b.language == "" and b.lines
                 and b.lines[0].startswith(starts))
    return " ".join(line.strip() for line in block.lines)


def test_the_size_refusals_reliability_md_quotes_are_the_ones_printed(scratch):
    """docs/reliability.md quotes the refusal of a 0.1 m x 1e-7 m rectangle with
    ``mesh.nodes: 500`` (the case of test/test_mesh_bounds.py) and of a sweep of 3,000
    frictions, tip radii and depths (test/test_hostile_core.py): each is the line printed.
    """
    page = REPO / "docs" / "reliability.md"
    scene = yaml.safe_load((REPO / "config" / "scenes" / "foam_square.yaml").read_text())
    scene["object"].update(shape={"type": "rectangle", "width": 0.1, "height": 1e-7},
                           mesh={"nodes": 500})
    (scratch / "tmp_user" / "thin.yaml").write_text(yaml.safe_dump(scene))
    assert _refusal(["mesh", "tmp_user/thin.yaml"], scratch) == _quoted_block(
        page, "squeeze-grasp mesh: error:")
    pytest.importorskip("distributed", reason="sweep needs the sweep extra")
    spec = {"base": str(REPO / "config" / "scenes" / "foam_square.yaml"),
            "friction": [k * 1e-4 for k in range(3000)],
            "tip_radius": [0.001 + k * 1e-6 for k in range(3000)],
            "relative_depth": [0.001 + k * 1e-4 for k in range(3000)]}
    (scratch / "tmp_user" / "huge.yaml").write_text(yaml.safe_dump(spec))
    assert _refusal(["sweep", "tmp_user/huge.yaml", "--dry-run"], scratch) == _quoted_block(
        page, "squeeze-grasp sweep: error:")


def test_the_refused_views_perception_md_lists_are_the_messages():
    """docs/perception.md's table of refused views quotes, for each, the message of its case in
    test/test_perception_extract.py, whole.
    """
    pytest.importorskip("skimage", reason="outline extraction needs the perception extra")
    import test_perception_extract as cases

    from squeeze_grasp_ros.mechanics.errors import InvalidInputError

    page = (REPO / "docs" / "perception.md").read_text(encoding="utf-8")
    table = page[page.index("| view | message (excerpt) |"):]
    table = table[:table.index("\n\n", table.index("|---|"))]
    quoted = [q for q in re.findall(r"`([^`]+)`", table) if "..." not in q]
    messages = []
    for _, image, encoding, options, expected in cases.hostile_views():
        if expected is None:
            continue
        view = options.pop("pose", cases.pose())
        with pytest.raises(InvalidInputError) as refused:
            cases.extract_outline(image, encoding, cases.CAMERA, view, **options)
        messages.append(str(refused.value))
    assert len(quoted) >= 8 and [q for q in quoted if q not in messages] == [], messages


def test_the_oversized_refusal_ros_md_quotes_is_the_planners():
    """docs/ros.md quotes the planner's refusal of the foam square with ``mesh: {max_area:
    1.0e-9}`` at its default limits, whole (its line breaks aside).
    """
    from squeeze_grasp_ros.planning.objects import PlannerLimits, check_requested
    from squeeze_grasp_ros.scene import parse_scene

    doc = yaml.safe_load((REPO / "config" / "scenes" / "foam_square.yaml").read_text())
    doc["object"]["mesh"] = {"max_area": 1.0e-9}
    with pytest.raises(Exception, match="oversized") as refused:
        check_requested(parse_scene(doc), "factorized", PlannerLimits())
    page = " ".join((REPO / "docs" / "ros.md").read_text(encoding="utf-8").split())
    assert "`mesh: {max_area: 1.0e-9}`" in page and f"`{refused.value}`" in page, refused.value


def test_the_docs_doctests_run():
    """Every ``>>>`` example in a ```python block of the docs runs and prints what it shows
    (docs/perception.md's seen-against-predicted outline needs the perception extra).
    """
    import doctest

    pytest.importorskip("skimage", reason="docs/perception.md's example extracts an outline")
    examples = [(page, block) for page in PAGES for block in blocks(page)
                if block.language == "python"
                and any(line.lstrip().startswith(">>>") for line in block.lines)]
    assert examples
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for page, block in examples:
        test = doctest.DocTestParser().get_doctest(
            "\n".join(block.lines), {}, f"{page.name}:{block.line}", str(page), block.line)
        runner.run(test)
    assert runner.summarize(verbose=False).failed == 0


def test_the_ring_diameter_example_prints_what_ring_md_shows():
    """docs/ring.md's ``ring_diameter_changes`` call and the value its comment shows (a full
    repr: to 1e-8 relative, as in the transcripts).
    """
    page = REPO / "docs" / "ring.md"
    block = next(b for b in blocks(page) if b.language == "python"
                 and "ring_diameter_changes(" in "\n".join(b.lines))
    code, comment = block.lines[:-1], block.lines[-1]
    shown = re.fullmatch(r"# (\(.*?\))\s+.*", comment).group(1)
    *setup, call = code
    namespace: dict = {}
    exec("\n".join(setup), namespace)  # noqa: S102 (the repository's own page)
    actual = eval(call, namespace)  # noqa: S307
    assert json_matches(list(ast.literal_eval(shown)), list(actual)) is None, (shown, actual)


def _package_calls(code: str) -> list[tuple[str, ast.Call, object]]:
    """The calls in ``code`` of the names it imports from the package: (name, call, object)."""
    import importlib

    tree, imported = ast.parse(code), {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
                "squeeze_grasp_ros"):
            module = importlib.import_module(node.module)
            for alias in node.names:
                imported[alias.asname or alias.name] = getattr(module, alias.name)
    return [(node.func.id, node, imported[node.func.id]) for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
            and node.func.id in imported and callable(imported[node.func.id])]


def test_the_docs_python_blocks_call_the_package_as_its_signatures_allow():
    """Every call in a ```python block of the docs to a function the block imports from the
    package binds to that function's signature: as many positional arguments as it takes,
    keyword-only ones by name, no name it does not have (the bodies' variables need not
    exist: only the call's shape is checked).
    """
    import inspect

    checked, wrong = 0, []
    for page in PAGES:
        for block in blocks(page):
            if block.language != "python":
                continue
            lines = block.lines
            if any(line.lstrip().startswith(">>>") for line in lines):  # a doctest: its source
                lines = [line.lstrip()[4:] for line in lines
                         if line.lstrip().startswith((">>>", "..."))]
            for name, call, function in _package_calls("\n".join(lines)):
                if any(isinstance(a, ast.Starred) for a in call.args) or any(
                        k.arg is None for k in call.keywords):
                    continue
                try:
                    signature = inspect.signature(function)
                except (TypeError, ValueError):
                    continue
                try:
                    signature.bind(*call.args, **{k.arg: k.value for k in call.keywords})
                except TypeError as error:
                    wrong.append(f"{page.name}:{block.line + call.lineno} {name}: {error}")
                checked += 1
    assert checked >= 10 and not wrong, wrong


def test_every_option_of_every_verb_is_described_in_the_docs():
    """Each ``--option`` that a verb's ``--help`` lists appears in README.md or docs/ (or
    CONTRIBUTING.md), so that what the help names a user can read more about.
    """
    from squeeze_grasp_ros.cli import add_verb_arguments, build_parser

    text = "\n".join(page.read_text(encoding="utf-8") for page in PAGES)
    parser = build_parser()
    verbs = next(a for a in parser._actions if a.dest == "verb")._name_parser_map
    options = [(verb, option) for verb, sub in verbs.items()
               for action in add_verb_arguments(sub)._actions
               for option in action.option_strings if option.startswith("--")
               and option != "--help"]
    missing = [f"{verb} {option}" for verb, option in options
               if not re.search(re.escape(option) + r"(?![\w-])", text)]
    assert len(options) >= 100 and not missing, missing


def test_contributing_lists_every_linter_test():
    """CONTRIBUTING.md's linter table names every test of test/test_lint.py (ruff's three
    groups by their ids).
    """
    source = (REPO / "test" / "test_lint.py").read_text(encoding="utf-8")
    tests = [node.name for node in ast.parse(source).body
             if isinstance(node, ast.FunctionDef) and node.name.startswith("test_")]
    names = [f"test_ruff[{group}]" for group in ("flake8", "pep257", "isort")] + [
        name for name in tests if name != "test_ruff"]
    contributing = (REPO / "CONTRIBUTING.md").read_text(encoding="utf-8")
    assert "test_ruff" in tests and len(names) >= 7
    assert [name for name in names if f"test_lint.py::{name}`" not in contributing] == []


def _shown_keys(text: str) -> dict:
    """The keys of a JSON shape written as docs/mechanics.md writes one: ``{"key": value,
    "bare_key", "nested": {...}}``; a nested object's value is its own dict of keys, ``...``
    (an elided object) the key ``"..."``, every other value None.
    """
    root, stack, last = None, [], None
    for key, bracket, ellipsis in re.findall(r'"(\w+)"|([{}\[\]])|(\.\.\.)', text):
        top = stack[-1] if stack else None
        if bracket == "{":
            shape: dict = {}
            if isinstance(top, dict) and last is not None:
                top[last] = shape
            root = shape if root is None else root
            stack.append(shape)
        elif bracket == "[":
            stack.append([])
        elif bracket:
            stack.pop()
        elif isinstance(top, dict):
            top[key or "..."] = None
        last = key if isinstance(top, dict) and bracket == "" else None
    return root


def _keys_match(shown: dict, actual: dict, path: str = "") -> str | None:
    """None if ``actual`` has the keys ``shown`` lists, in their order (all of them unless
    ``...`` elides the rest), and so for every nested object shown; else what differs.
    """
    keys = [k for k in shown if k != "..."]
    listed = [k for k in actual if k in keys] if "..." in shown else list(actual)
    if listed != keys:
        return f"{path or 'top level'}: shown {keys}, printed {list(actual)}"
    for key in keys:
        if isinstance(shown[key], dict):
            if not isinstance(actual[key], dict):
                return f"{path}{key}: shown as an object, printed {type(actual[key]).__name__}"
            problem = _keys_match(shown[key], actual[key], f"{path}{key}.")
            if problem:
                return problem
    return None


def test_the_plan_json_keys_mechanics_md_lists_are_what_plan_prints(scratch):
    """docs/mechanics.md lists the keys of ``plan --json`` inline: they are the keys the verb
    prints, in its order, nested objects included (``{...}`` elides one).
    """
    page = (REPO / "docs" / "mechanics.md").read_text(encoding="utf-8")
    text = re.search(r"`plan --json` gives `(\{.*?\})`:", page, re.S).group(1)
    command = Command("squeeze-grasp plan config/scenes/foam_square.yaml --json", ())
    actual = json.loads("\n".join(run_command(command, scratch)))
    shown = _shown_keys(text)
    assert len(shown) >= 10 and isinstance(shown["stable"], dict)
    assert _keys_match(shown, actual) is None, _keys_match(shown, actual)
    assert _keys_match(_shown_keys('{"a": 1, "b": {"x", "y"}}'),
                       {"a": 1, "b": {"y": 0, "x": 0}}) is not None  # the order counts


SIGNATURE_SPAN = re.compile(r"`((?:[\w.]+\.)?(\w+)\(([^`]*?)\)\s*->\s*(\w+))`", re.S)
"""An inline signature in the docs: ``name(params) -> Result``, the name dotted from the
package or bare."""
BARE_NAMES = {"advance": "mechanics.squeeze.stepper"}
"""Where a bare name of an inline signature lives, from the package."""


def _signature_problem(text: str, name: str, returned: str) -> str | None:
    """None if ``text`` (``f(a, b=1, ...) -> R``) agrees with the function it names: its
    positional names are the first parameters, in order; each keyword is a parameter with
    that default unless shown as ``...``; the return annotation is ``R``; without a ``...``
    every required parameter is shown.
    """
    import importlib
    import inspect

    call = ast.parse(text.split("->")[0].strip(), mode="eval").body
    dotted = ast.unparse(call.func)
    module, _, attribute = (dotted if "." in dotted else
                            f"{BARE_NAMES[name]}.{name}").rpartition(".")
    function = getattr(importlib.import_module(f"squeeze_grasp_ros.{module}"), attribute)
    parameters = inspect.signature(function).parameters
    names = list(parameters)
    elided = any(isinstance(a, ast.Constant) and a.value is Ellipsis for a in call.args)
    shown = [a.id for a in call.args if isinstance(a, ast.Name)]
    if shown != names[:len(shown)]:
        return f"{dotted}: positional {shown}, the function's {names[:len(shown)]}"
    for keyword in call.keywords:
        if keyword.arg not in parameters:
            return f"{dotted}: no parameter {keyword.arg!r}"
        value = ast.literal_eval(keyword.value)
        if value is not Ellipsis and value != parameters[keyword.arg].default:
            return (f"{dotted}: {keyword.arg}={value!r}, the function's default "
                    f"{parameters[keyword.arg].default!r}")
    required = [n for n in names if parameters[n].default is inspect.Parameter.empty]
    missing = [n for n in required if n not in shown + [k.arg for k in call.keywords]]
    if not elided and missing:
        return f"{dotted}: does not show the required {missing}"
    annotation = inspect.signature(function).return_annotation
    if getattr(annotation, "__name__", annotation) != returned:
        return f"{dotted}: returns {annotation}, shown {returned}"
    return None


def test_the_inline_signatures_are_the_functions():
    """Every inline ``name(params) -> Result`` of the docs (docs/events.md's ``advance``,
    docs/design.md's perception calls) names a function of the package with those parameters,
    defaults and return type.
    """
    found, wrong = 0, []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for span in SIGNATURE_SPAN.finditer(text):
            whole, name, _, returned = span.groups()
            problem = _signature_problem(" ".join(whole.split()), name, returned)
            found += 1
            if problem:
                wrong.append(f"{page.name}:{text[:span.start()].count(chr(10)) + 1}: {problem}")
    assert found >= 4 and not wrong, wrong
    assert _signature_problem("advance(model, state, translations, step=1e-2) -> StepResult",
                              "advance", "StepResult") is not None  # a default can differ


def test_the_readme_verb_table_names_every_verb_and_only_verbs():
    """README.md's table of the CLI lists each verb of ``squeeze-grasp`` once (the first word
    of each backticked usage in its first column), and no verb the CLI does not have; every
    verb has ``--json``, as the sentence above the table says.
    """
    from squeeze_grasp_ros.cli import add_verb_arguments, build_parser

    readme = (REPO / "README.md").read_text(encoding="utf-8")
    table = readme[readme.index("| verb | what it does"):]
    table = table[:table.index("\n\n")]
    listed = [usage.split()[0] for row in table.splitlines()[2:]
              for usage in re.findall(r"`([^`]+)`", row.split(" | ")[0])]
    parser = build_parser()
    verbs = next(a for a in parser._actions if a.dest == "verb")._name_parser_map
    assert sorted(listed) == sorted(verbs) and len(listed) == len(set(listed)), listed
    assert "Every verb has `--help`, `--json`" in readme
    without = [v for v, sub in verbs.items()
               if "--json" not in {o for a in add_verb_arguments(sub)._actions
                                   for o in a.option_strings}]
    assert without == []
