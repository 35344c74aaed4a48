# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Errors by meaning: a solver failure is a NumericalError with residuals (CLI exit 3, service
NUMERICAL_FAILURE), never an input error; the mechanics use no exception for control flow.
"""
from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest

from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.exit_codes import ExitCode
from squeeze_grasp_ros.mechanics import errors
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.squeeze import contact_model
from squeeze_grasp_ros.planning import ErrorCode, PlannerError, classify
from squeeze_grasp_ros.scene import (
    build_mesh,
    event_squeeze_scene,
    finger_nodes,
    load_scene,
    scene_material,
)

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


def caught_package_errors(path: Path) -> list[str]:
    """``except`` clauses in ``path`` that catch one of the package's own error kinds."""
    names = {"SqueezeGraspError", "InvalidInputError", "InfeasibleError", "NumericalError",
             "InternalError", "SceneError"}
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ExceptHandler) and node.type is not None:
            caught = {n.id for n in ast.walk(node.type) if isinstance(n, ast.Name)}
            caught |= {n.attr for n in ast.walk(node.type) if isinstance(n, ast.Attribute)}
            if caught & names:
                found.append(f"{path.relative_to(REPO)}:{node.lineno}")
    return found


def test_the_mechanics_use_no_exception_for_control_flow():
    """A failed mode hypothesis or substep is a value (SolveFailure), not a caught error."""
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
