# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Runs that go wrong: the exit code and the summary say so, and every message printed is true.

Exit codes (``squeeze_grasp_ros.exit_codes``): 0 the grasp held, 1 the world says the grasp
failed (the executor is stopped), 2 user error, 4 internal error.
"""
from __future__ import annotations

import json
from pathlib import Path

from squeeze_grasp_ros.cli import main

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"


def test_a_failed_grasp_exits_1_and_stops_the_executor(capfd, tmp_path):
    code = main(["run", str(SCENES / "disk_finger_slip.yaml"), "--json", "--record",
                 str(tmp_path / "bag")])
    out = json.loads(capfd.readouterr().out)
    assert code == 1
    assert out["success"] is False and out["world_termination"] == "finger_slip"
    assert "grasp failed" in out["outcome"] and "finger_slip" in out["outcome"]
    assert out["termination"] == "canceled"
    slip_ns = out["world_end"]["stamp_ns"]
    dt_ns = 1_000_000
    assert out["ticks"] * dt_ns <= slip_ns + 50 * dt_ns  # stopped within 50 ticks of the slip
    assert out["measured_depth"] < 0.5 * out["target_depth"]
    assert (tmp_path / "bag" / "metadata.yaml").is_file()


def test_a_held_grasp_exits_0(capfd):
    assert main(["run", str(SCENES / "foam_square.yaml"), "--json", "--quiet"]) == 0
    out = json.loads(capfd.readouterr().out)
    assert out["success"] is True and out["outcome"] == "grasp held"
