# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Errors by meaning: a solver failure is a NumericalError with residuals (CLI exit 3, service
NUMERICAL_FAILURE), never an input error; the mechanics use no exception for control flow.
"""
from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import pytest

from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.exit_codes import ExitCode
from squeeze_grasp_ros.mechanics import errors
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.squeeze import contact_model
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode
from squeeze_grasp_ros.planning import ErrorCode, PlannerError, classify
from squeeze_grasp_ros.scene import (
    GraspSetup,
    build_mesh,
    event_squeeze_scene,
    finger_nodes,
    load_scene,
    scene_material,
)
from squeeze_grasp_ros.sweep.evaluate import run_task
from squeeze_grasp_ros.sweep.plan import plan_tasks
from squeeze_grasp_ros.sweep.spec import parse_sweep_spec

REPO = Path(__file__).resolve().parents[1]
MECHANICS = REPO / "squeeze_grasp_ros" / "mechanics"
SLIPPING = str(REPO / "config" / "scenes" / "foam_square_low_friction.yaml")


@pytest.fixture
def newton_without_iterations(monkeypatch):
    """Newton on the sliding angles may take no iteration: the first sliding contact fails."""
    monkeypatch.setattr(contact_model, "NEWTON_MAX_ITERATIONS", 0)


def test_a_solver_failure_reaches_the_cli_as_numerical(newton_without_iterations, capfd):
    assert main(["squeeze", SLIPPING, "--json"]) == ExitCode.NUMERICAL == 3
    error = json.loads(capfd.readouterr().out)
    assert error["code"] == 3 and error["code_name"] == "NUMERICAL"
    assert "did not converge" in error["error"] and "residuals: cone" in error["error"]
    assert error["error"].startswith(f"at depth {error['depth']:.6g} m (relative depth "
                                     f"{error['relative_depth']:.6g}): Newton on the sliding")
    assert error["depth"] > 0 and error["residuals"]["cone"] >= 0


def _first_sliding_point() -> tuple[float, float]:
    """(depth m, relative depth) of the low-friction foam square's first event with a sliding
    contact, from its squeeze with Newton: where the squeeze without Newton iterations fails.
    """
    squeeze = GraspSetup.build(load_scene(SLIPPING)).event_squeeze()
    first = next(e for e in squeeze.events if e.mode == ContactMode.SLIP)
    return first.depth, first.relative_depth


def test_a_squeeze_failure_says_where_it_failed(monkeypatch):
    """The error of a squeeze that fails starts with the depth and relative depth of the last
    point it solved (here the event whose sliding contact Newton cannot solve), keeps its
    reason and residuals, and chains the stepper's error (which knows the depth in metres only).
    """
    depth, relative = _first_sliding_point()
    monkeypatch.setattr(contact_model, "NEWTON_MAX_ITERATIONS", 0)
    with pytest.raises(errors.NumericalError) as info:
        GraspSetup.build(load_scene(SLIPPING)).event_squeeze()
    error = info.value
    assert (error.depth, error.relative_depth) == (depth, relative) and depth > 0
    assert str(error) == (f"at depth {depth:.6g} m (relative depth {relative:.6g}): Newton on the "
                          f"sliding angles did not converge in 0 iterations (residuals: cone "
                          f"{error.residuals['cone']:.3g})")
    assert error.reason == "Newton on the sliding angles did not converge in 0 iterations"
    cause = error.__cause__
    assert isinstance(cause, errors.NumericalError) and cause.depth == depth
    assert cause.relative_depth is None and str(cause).startswith(f"at depth {depth:.6g} m: ")


def test_a_failed_evaluation_s_row_says_where(monkeypatch, tmp_path):
    """The dataset route: the row of a squeeze that fails carries its error as the API raises
    it, with the depth and the relative depth of the point where the squeeze failed.
    """
    spec = {"name": "where", "base": SLIPPING, "objects": [{"scene": SLIPPING}],
            "placements": {"mode": "graspmap", "count": 2}}
    tasks = list(plan_tasks(parse_sweep_spec(spec, tmp_path)))
    monkeypatch.setattr(contact_model, "NEWTON_MAX_ITERATIONS", 0)
    rows = [row for task in tasks for row in run_task(task)["rows"]]
    assert len(rows) == 2
    for row in rows:
        where = re.match(r"NumericalError: at depth (\S+) m \(relative depth (\S+)\): Newton "
                         r"on the sliding angles did not converge", row["error"])
        depth, relative = float(where[1]), float(where[2])
        assert depth > 0 and 0 < relative < row["target_relative_depth"]


def test_the_same_scene_succeeds_with_newton(capfd):
    """The failure above is the solver's: with its iterations the scene runs (exit 0)."""
    assert main(["squeeze", SLIPPING, "--json"]) == 0
    assert json.loads(capfd.readouterr().out)["event_counts"]["C"] > 0


def test_the_planner_reports_a_numerical_failure(newton_without_iterations):
    from squeeze_grasp_interfaces.srv import EventSqueeze

    assert EventSqueeze.Response.NUMERICAL_FAILURE == ErrorCode.NUMERICAL_FAILURE == 7
    scene = load_scene(SLIPPING)
    mesh = build_mesh(scene)
    obj = ElasticObject(mesh, scene_material(scene))
    with pytest.raises(errors.NumericalError) as info:
        event_squeeze_scene(scene, obj, finger_nodes(scene, mesh))
    assert info.value.residuals["cone"] >= 0 and not isinstance(info.value, ValueError)
    code, message = classify(info.value)
    assert code == ErrorCode.NUMERICAL_FAILURE and "residuals" in message


@pytest.mark.parametrize("exc, code", [
    (errors.InvalidInputError("x"), ErrorCode.INVALID_ARGUMENT),
    (errors.InfeasibleError("x"), ErrorCode.NOT_FEASIBLE),
    (errors.NumericalError("x"), ErrorCode.NUMERICAL_FAILURE),
    (errors.InternalError("x"), ErrorCode.INTERNAL_ERROR),
    (PlannerError(ErrorCode.BUSY, "x"), ErrorCode.BUSY),
    (KeyError("x"), ErrorCode.INTERNAL_ERROR),
])
def test_every_error_kind_has_its_service_code(exc, code):
    assert classify(exc)[0] == code


@pytest.mark.parametrize("kind, exit_code", [
    (errors.InvalidInputError, ExitCode.USAGE), (errors.InfeasibleError, ExitCode.OUTCOME),
    (errors.NumericalError, ExitCode.NUMERICAL), (errors.InternalError, ExitCode.INTERNAL)])
def test_every_error_kind_has_its_exit_code(kind, exit_code, monkeypatch, capfd):
    from squeeze_grasp_ros.commands import mesh

    def failing(args):
        raise kind("what failed")
    monkeypatch.setattr(mesh, "run", failing)
    assert main(["mesh", SLIPPING]) == exit_code
    assert "what failed" in capfd.readouterr().err


def _reraises(handler: ast.ExceptHandler) -> bool:
    """Whether the clause only adds context and raises again: assignments, then a raise."""
    *before, last = handler.body
    return isinstance(last, ast.Raise) and all(isinstance(s, ast.Assign) for s in before)


def caught_package_errors(path: Path) -> list[str]:
    """``except`` clauses in ``path`` that catch one of the package's own error kinds and do
    more than raise it again with context (:func:`_reraises`).
    """
    names = {"SqueezeGraspError", "InvalidInputError", "InfeasibleError", "NumericalError",
             "InternalError", "SceneError"}
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ExceptHandler) and node.type is not None:
            caught = {n.id for n in ast.walk(node.type) if isinstance(n, ast.Name)}
            caught |= {n.attr for n in ast.walk(node.type) if isinstance(n, ast.Attribute)}
            if caught & names and not _reraises(node):
                found.append(f"{path.relative_to(REPO)}:{node.lineno}")
    return found


def test_the_mechanics_use_no_exception_for_control_flow():
    """A failed mode hypothesis or substep is a value (SolveFailure), not a caught error (a
    squeeze's failure is caught only to be raised again with where it failed).
    """
    offenders = [hit for p in MECHANICS.rglob("*.py") for hit in caught_package_errors(p)]
    assert offenders == []
    assert caught_package_errors(REPO / "squeeze_grasp_ros" / "cli.py")  # the check can fail


def test_help_lists_every_exit_code():
    """``squeeze-grasp --help`` names every exit status the program can return."""
    import re

    from squeeze_grasp_ros.cli import build_parser
    from squeeze_grasp_ros.exit_codes import ExitCode

    epilog = build_parser().epilog
    listed = {int(n) for n in re.findall(r"(?:^|; |: )(\d+) ", epilog)}
    assert listed == {int(code) for code in ExitCode}


def _exit(argv: list[str]) -> int:
    """The CLI's exit status for ``argv``: argparse's refusals exit, the verbs' return."""
    try:
        return main(argv)
    except SystemExit as done:
        return done.code


def test_a_usage_error_under_json_is_a_json_object_too(capfd):
    """Before, a run-time refusal under ``--json`` printed a JSON object on stdout and a mistyped
    option printed nothing there; the README quotes the object of the second.
    """
    scene = str(REPO / "config" / "scenes" / "foam_square.yaml")
    for depth in ("abc", "-1"):
        assert _exit(["plan", scene, "--json", "--depth", depth]) == 2
        out = capfd.readouterr().out
        error = json.loads(out)
        assert (error["field"], error["code"], error["code_name"]) == ("depth", 2, "USAGE")
    quoted = " ".join((REPO / "README.md").read_text().split())
    _exit(["plan", scene, "--json", "--depth", "abc"])
    assert f"`plan SCENE --json --depth abc` prints `{capfd.readouterr().out.strip()}`" in quoted
    assert _exit(["plan", "--json"]) == 2
    assert json.loads(capfd.readouterr().out)["field"] is None
    assert _exit(["plan", scene, "--depth", "abc"]) == 2   # without --json stdout stays empty
    assert capfd.readouterr().out == ""
