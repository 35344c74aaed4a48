# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The checks ``ros2 pkg create`` sets up for a Python package: code style (flake8's checks,
line length 99), pep257 docstrings and copyright headers, plus sorted imports (isort's rules);
settings in ``ruff.toml``.
"""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
CHECKED = ("squeeze_grasp_ros", "test", "launch", "setup.py")
HEADER = ("# Copyright 2026 squeeze_grasp_ros developers\n"
          "# SPDX-License-Identifier: Apache-2.0\n")


def python_files() -> list[Path]:
    files = [REPO / "setup.py"]
    for folder in CHECKED[:-1]:
        files += sorted(p for p in (REPO / folder).rglob("*.py") if "node_modules" not in p.parts)
    return files


def ruff_findings() -> list[str]:
    """Every finding of ``ruff check`` with the repository's settings (ruff.toml)."""
    result = subprocess.run([sys.executable, "-m", "ruff", "check", "--output-format", "concise",
                             *CHECKED], cwd=REPO, capture_output=True, text=True)
    assert result.returncode in (0, 1), result.stderr
    return [line for line in result.stdout.splitlines() if ".py:" in line]


@pytest.mark.parametrize("codes", [("E", "W", "F"), ("D",), ("I",)],
                         ids=["flake8", "pep257", "isort"])
def test_ruff(codes):
    found = [f for f in ruff_findings() if f.split(": ", 1)[1].startswith(codes)]
    assert found == [], "\n".join(found)


def test_the_line_length_is_the_stated_one():
    assert "line-length = 99" in (REPO / "ruff.toml").read_text()


def test_copyright_headers():
    missing = [str(p.relative_to(REPO)) for p in python_files()
               if not p.read_text(encoding="utf-8").startswith(HEADER)]
    assert len(python_files()) > 100 and missing == []


STEPPER = ("squeeze_grasp_ros/mechanics/squeeze/stepper",
           "squeeze_grasp_ros/mechanics/squeeze/event_key.py")
MAX_STEPPER_COMPLEXITY = 15
MAX_MECHANICS_CLASS_LINES = 300


def complexity_findings(limit: int) -> list[str]:
    """The findings of ruff's C901 (McCabe complexity above ``limit``) in the stepper."""
    result = subprocess.run([sys.executable, "-m", "ruff", "check", "--select", "C901",
                             "--config", f"lint.mccabe.max-complexity={limit}",
                             "--output-format", "concise", *STEPPER],
                            cwd=REPO, capture_output=True, text=True)
    assert result.returncode in (0, 1), result.stderr
    return [line for line in result.stdout.splitlines() if ".py:" in line]


def test_no_stepper_function_is_too_complex():
    """Every function of the stepper stays within McCabe complexity 15, and the check sees
    them: at a limit of 5 it flags some.
    """
    assert complexity_findings(MAX_STEPPER_COMPLEXITY) == []
    assert len(complexity_findings(5)) >= 3


def test_no_mechanics_class_is_over_300_lines():
    """No class in ``mechanics/`` spans more than 300 lines (docstring included)."""
    sizes = {}
    for path in sorted((REPO / "squeeze_grasp_ros" / "mechanics").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef):
                name = f"{path.relative_to(REPO)}:{node.name}"
                sizes[name] = node.end_lineno - node.lineno + 1
    assert len(sizes) > 50 and max(sizes.values()) > 100
    assert {k: v for k, v in sizes.items() if v > MAX_MECHANICS_CLASS_LINES} == {}
