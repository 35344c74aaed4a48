# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``sim_pipeline.launch.py``'s checks and exit status (:mod:`..commands.launch_checks`).

Before, ``on_slip_alarm:=bogus`` started every node, the run client refused the option, and
``ros2 launch`` exited 0; ``record:=/proc/nope`` ended the recorder (exit 2) while sim_hardware
waited for it for ever, so the launch hung; a grasp that did not hold ended the launch with 0.
The launch file itself needs ``launch`` (not on PyPI), so here its use of the checks is read
from its source; the checks are plain functions.
"""
from __future__ import annotations

import argparse
import ast
from pathlib import Path
from types import SimpleNamespace

import pytest

from squeeze_grasp_ros.commands import run
from squeeze_grasp_ros.commands.launch_checks import (
    RUN_ARGUMENTS,
    LaunchEnded,
    flag,
    node_ended,
    required,
    run_arguments,
    run_ended,
)
from squeeze_grasp_ros.exit_codes import ExitCode

LAUNCH = Path(__file__).resolve().parents[1] / "launch" / "sim_pipeline.launch.py"
HARDWARE = LAUNCH.with_name("hardware.launch.py")


def refused_by_run(option: str) -> bool:
    """Whether ``squeeze-grasp run``'s own parser refuses ``option``."""
    parser = argparse.ArgumentParser(exit_on_error=False)
    run.add_arguments(parser)
    try:
        parser.parse_args(["scene.yaml", option])
    except argparse.ArgumentError:
        return True
    return False


@pytest.mark.parametrize("name, text", [
    ("on_slip_alarm", "bogus"), ("on_slip_alarm", "HOLD"), ("max_attempts", "abc"),
    ("max_attempts", "0"), ("max_attempts", "101"), ("max_attempts", "2.5"),
    ("resqueeze_margin", "2"), ("resqueeze_margin", "0"), ("resqueeze_margin", "nan"),
    ("resqueeze_margin", "x" * 100),
])
def test_a_run_argument_run_would_refuse_is_refused_before_any_node_starts(name, text):
    with pytest.raises(ValueError) as refused:
        run_arguments(**{name: text})
    message = str(refused.value)
    assert message.startswith(f"{name}:={text[:40]}: ") and len(message) < 200
    assert refused_by_run(f"--{name.replace('_', '-')}={text}")


@pytest.mark.parametrize("name, text", [
    ("on_slip_alarm", "resqueeze"), ("on_slip_alarm", "normals"), ("max_attempts", "100"),
    ("resqueeze_margin", "0.25"),
])
def test_a_run_argument_run_takes_becomes_its_option(name, text):
    option = f"--{name.replace('_', '-')}={text}"
    assert run_arguments(**{name: text}) == [option] and not refused_by_run(option)


def test_empty_run_arguments_leave_run_its_defaults_and_unknown_ones_are_refused():
    assert run_arguments(**dict.fromkeys(RUN_ARGUMENTS, "")) == []
    with pytest.raises(ValueError, match="scene is not a launch argument of the run"):
        run_arguments(scene="x.yaml")


def test_the_statuses_say_which_process_and_why():
    assert run_ended(0) is None
    assert run_ended(1) == ("the run exited 1 (OUTCOME: the grasp did not hold in the simulated "
                            "world; its summary is above)")
    assert run_ended(-9) == "the run exited -9 (killed by signal 9)"
    assert run_ended(7) == "the run exited 7"
    assert node_ended("recorder", ExitCode.USAGE) == (
        "the recorder node exited 2 (USAGE: invalid input; its message is above) while the "
        "launch ran")


def test_the_launch_file_checks_its_run_arguments_and_requires_its_nodes():
    """Every Node of the launch file has ``on_exit=required(name)``; the run's end goes through
    ``run_exited`` (which fails on ``run_ended``); the run arguments through ``run_arguments``
    before the scene is read.
    """
    tree = ast.parse(LAUNCH.read_text(encoding="utf-8"))
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)]
    nodes = [c for c in calls if getattr(c.func, "id", "") == "Node"]
    assert len(nodes) == 2  # the planner, and one per node of node_parameters
    for node in nodes:
        on_exit = {k.arg: k.value for k in node.keywords}["on_exit"]
        assert isinstance(on_exit, ast.Call) and on_exit.func.id == "required"
    handlers = [c for c in calls if getattr(c.func, "id", "") == "OnProcessExit"]
    assert [ast.unparse({k.arg: k.value for k in h.keywords}["on_exit"])
            for h in handlers] == ["run_exited"]
    functions = {f.name: f for f in tree.body if isinstance(f, ast.FunctionDef)}
    called = {name: {getattr(c.func, "id", "") for c in ast.walk(functions[name])
                     if isinstance(c, ast.Call)} for name in ("nodes", "run_exited")}
    assert "run_arguments" in called["nodes"] and "run_ended" in called["run_exited"]
    line = {getattr(c.func, "id", ""): c.lineno for c in ast.walk(functions["nodes"])
            if isinstance(c, ast.Call)}
    assert line["run_arguments"] < line["load_scene"]


@pytest.mark.parametrize("text, value", [("true", True), ("True", True), ("1", True),
                                         ("on", True), ("false", False), ("OFF", False),
                                         ("0", False), ("no", False)])
def test_a_yes_no_argument_takes_launch_words(text, value):
    assert flag("run", text) is value


@pytest.mark.parametrize("text", ["perhaps", "ture", "", "2", "y"])
def test_a_yes_no_argument_refuses_other_words(text):
    """Before, any other word was false: ``run:=ture`` started the nodes without a run, and
    they waited for a goal nobody sent.
    """
    with pytest.raises(ValueError, match=rf"^run:={text}: must be true or false \(or 1, yes, "
                                         r"on, 0, no, off\)$"):
        flag("run", text)


def test_the_launch_file_reads_every_yes_no_argument_with_flag():
    tree = ast.parse(LAUNCH.read_text(encoding="utf-8"))
    flagged = {c.args[0].value for c in ast.walk(tree) if isinstance(c, ast.Call)
               and getattr(c.func, "id", "") == "flag"}
    declared = {c.args[0].value for c in ast.walk(tree) if isinstance(c, ast.Call)
                and getattr(c.func, "id", "") == "DeclareLaunchArgument"
                and getattr(c.keywords[0].value, "value", None) in ("true", "false")}
    assert flagged == declared == {"run", "rviz", "include_hidden_topics"}


def test_a_required_node_that_ends_ends_the_launch_unless_it_is_shutting_down():
    """``required(name)`` is launch's ``on_exit(event, context)`` (ProcessExited has
    ``returncode``, LaunchContext ``is_shutdown``).
    """
    on_exit = required("monitor")
    with pytest.raises(LaunchEnded, match=r"^the monitor node exited 2 \(USAGE: "):
        on_exit(SimpleNamespace(returncode=2), SimpleNamespace(is_shutdown=False))
    with pytest.raises(LaunchEnded, match=r"^the monitor node exited 0 \(OK\) while"):
        on_exit(SimpleNamespace(returncode=0), SimpleNamespace(is_shutdown=False))
    assert on_exit(SimpleNamespace(returncode=-2), SimpleNamespace(is_shutdown=True)) is None


def test_the_planner_launch_requires_its_planner():
    tree = ast.parse(LAUNCH.with_name("planner.launch.py").read_text(encoding="utf-8"))
    [node] = [c for c in ast.walk(tree) if isinstance(c, ast.Call)
              and getattr(c.func, "id", "") == "Node"]
    assert ast.unparse({k.arg: k.value for k in node.keywords}["on_exit"]) == \
        "required('planner')"


def test_the_hardware_launch_requires_its_nodes_and_evaluates_no_python():
    """Before, a monitor that refused ``mu:=abc`` left the executor commanding the fingers
    without it, and ``record:=/data/bob's run`` failed in launch's PythonExpression
    ("unterminated string literal").
    """
    tree = ast.parse(HARDWARE.read_text(encoding="utf-8"))
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)]
    nodes = [c for c in calls if getattr(c.func, "id", "") == "Node"]
    names = [{k.arg: k.value for k in n.keywords}["name"].value for n in nodes]
    assert names == ["planner", "monitor", "executor", "recorder"]
    for node, name in zip(nodes, names):
        on_exit = {k.arg: k.value for k in node.keywords}["on_exit"]
        assert ast.unparse(on_exit) == f"required('{name}')"
    assert "PythonExpression" not in {getattr(c.func, "id", "") for c in calls}
