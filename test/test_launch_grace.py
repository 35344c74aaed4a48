# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The launch files give their nodes time to end as designed after SIGINT.

After SIGINT a node drains what has arrived and waits up to ``ACK_TIMEOUT`` s for its readers
to acknowledge what it published (``run_node``). launch's default grace before SIGTERM is 5 s,
the same: a node whose reader left first was killed with SIGTERM (exit -15, seen once in five
``ros2 launch ... record:=`` runs at load 10). The pipeline's launch files declare launch's
``sigterm_timeout`` argument with a longer default.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from squeeze_grasp_ros.ros.nodes import ACK_TIMEOUT

LAUNCH = Path(__file__).resolve().parents[1] / "launch"


def declared_defaults(path: Path) -> dict[str, str]:
    """``DeclareLaunchArgument`` name -> literal default of a launch file."""
    out = {}
    for call in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(call, ast.Call) and getattr(call.func, "id", "") == "DeclareLaunchArgument":
            keywords = {k.arg: k.value for k in call.keywords}
            out[ast.literal_eval(call.args[0])] = ast.literal_eval(keywords["default_value"])
    return out


@pytest.mark.parametrize("name", ["sim_pipeline.launch.py", "hardware.launch.py"])
def test_sigterm_comes_after_the_longest_designed_shutdown(name):
    grace = float(declared_defaults(LAUNCH / name)["sigterm_timeout"])
    assert grace >= 2 * ACK_TIMEOUT
