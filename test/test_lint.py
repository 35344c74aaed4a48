# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The checks ``ros2 pkg create`` sets up for a Python package: code style (flake8's checks,
line length 99), pep257 docstrings and copyright headers; settings in ``ruff.toml``.
"""
from __future__ import annotations

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


@pytest.mark.parametrize("codes", [("E", "W", "F"), ("D",)], ids=["flake8", "pep257"])
def test_ruff(codes):
    found = [f for f in ruff_findings() if f.split(": ", 1)[1].startswith(codes)]
    assert found == [], "\n".join(found)


def test_the_line_length_is_the_stated_one():
    assert "line-length = 99" in (REPO / "ruff.toml").read_text()


def test_copyright_headers():
    missing = [str(p.relative_to(REPO)) for p in python_files()
               if not p.read_text(encoding="utf-8").startswith(HEADER)]
    assert len(python_files()) > 100 and missing == []
