# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner as its own process (console script and ``python -m``), called from this one.

Across processes the first request can be lost even after ``wait_for_service`` (docs/design.md
§5), so requests are re-sent when no answer comes: the planner's requests are idempotent.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import yaml
from executables import script
from planner_support import BLOB, Harness, flat, solid_of
from rcl_interfaces.srv import GetParameters
from rclpy.context import Context
from rclpy.parameter import parameter_value_to_python

from squeeze_grasp_interfaces.srv import LoadObject, PlanSqueeze
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze

REPO = Path(__file__).resolve().parents[1]
COMMANDS = {
    "console script": [script("planner")],
    "python -m": [sys.executable, "-m", "squeeze_grasp_ros.ros.nodes.planner"],
}
ATTEMPTS, TIMEOUT = 3, 20.0


@pytest.fixture(params=sorted(COMMANDS))
def planner_process(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[dict]:
    """A planner process started with a parameter file that differs from the defaults."""
    params = yaml.safe_load((REPO / "config" / "planner.yaml").read_text())
    values = params["/**"]["ros__parameters"]
    values.update(cache_size=3, max_nodes=5000, best_count=4)
    path = tmp_path / "planner.yaml"
    path.write_text(yaml.safe_dump(params))
    log = (tmp_path / "planner.log").open("w")
    process = subprocess.Popen(
        [*COMMANDS[request.param], "--ros-args", "--params-file", str(path)],
        stdout=log,
        stderr=subprocess.STDOUT,
        env=dict(os.environ),
    )
    try:
        yield values
    finally:
        process.send_signal(signal.SIGINT)
        code = process.wait(timeout=30)
        log.close()
        output = (tmp_path / "planner.log").read_text()
        assert code == 0, output


def test_the_planner_process_answers_and_loads_its_parameters(
    ros_context: Context, planner_process: dict
) -> None:
    harness = Harness(ros_context, with_planner=False)
    try:
        names = sorted(planner_process)
        answer = harness.call(
            GetParameters, "get_parameters", GetParameters.Request(names=names), TIMEOUT, ATTEMPTS
        )
        assert {n: parameter_value_to_python(v) for n, v in zip(names, answer.values)} == (
            planner_process
        )
        loaded = harness.call(
            LoadObject, "load_object", LoadObject.Request(scene_yaml=BLOB), TIMEOUT, ATTEMPTS
        )
        assert loaded.success, loaded.message
        fingers = list(loaded.finger_nodes)
        response = harness.call(
            PlanSqueeze,
            "plan_squeeze",
            PlanSqueeze.Request(object_id="blob", squeeze_type="stable", depth=0.002),
            TIMEOUT,
            ATTEMPTS,
        )
        assert response.success, response.message
        expected = plan_squeeze(solid_of(BLOB), fingers, kind="stable")
        assert np.array_equal(flat(response.forces), 0.002 * expected.forces)
        refused = harness.call(
            LoadObject,
            "load_object",
            LoadObject.Request(scene_yaml=BLOB.replace("nodes: 300", "nodes: 9000")),
            TIMEOUT,
            ATTEMPTS,
        )
        assert not refused.success and "limit of 5000" in refused.message
    finally:
        harness.close()
