# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The measuring instruments of ``bench --only pipeline`` on real rclpy: the bare loop with the
pipeline's messages per tick, and the tick profile timing every callback and publish in place.
"""
from __future__ import annotations

import math
import os

import pytest
from pipeline_support import SMALL_SQUARE, scene_data, write_scene

from squeeze_grasp_ros.bench.lockstep import tick_profile
from squeeze_grasp_ros.ros.bare_loop import bare_loop_rate
from squeeze_grasp_ros.ros.run.tick_profile import SPIN, STAGES


@pytest.mark.parametrize("clock_deliveries", [True, False])
@pytest.mark.parametrize("executor", ["events", "single"])
def test_the_bare_loop_runs_its_ticks_in_lockstep(executor, clock_deliveries):
    rate = bare_loop_rate(200, executor=executor, namespace=f"/test_bare_{os.getpid()}",
                          clock_deliveries=clock_deliveries)
    assert math.isfinite(rate) and rate > 0


def test_the_tick_profile_sees_every_node_and_adds_up_to_the_loop(tmp_path):
    """Every node's stages are measured and non-negative; together with the executor's rest
    and the mechanics they make up the loop's wall time exactly; the recorder's row is there
    with recording on.
    """
    path = write_scene(tmp_path, scene_data(SMALL_SQUARE, name="profiled", squeeze={
        "type": "stable", "relative_depth": 0.02}))
    table, summary = tick_profile(path, tmp_path / "bag")
    assert summary["success"] and summary["ticks"] > 0
    assert {"sim_hardware", "monitor", "executor", "recorder", "run client", SPIN,
            "mechanics"} <= table.keys()
    for name, row in table.items():
        assert set(row) == set(STAGES)
        if name != SPIN:
            assert all(v >= 0.0 for v in row.values()), (name, row)
    for node in ("sim_hardware", "monitor", "recorder"):
        assert table[node]["logic"] > 0.0
    # the monitor and the executor take every loop input raw and, in lockstep, no clock (the
    # executor's clock follows its statuses' stamps)
    assert table["sim_hardware"]["publish"] > 0.0
    assert table["monitor"]["deserialise"] == table["executor"]["deserialise"] == 0.0
    loop_us = 1e6 * summary["timing"]["loop"] / summary["ticks"]
    measured = sum(v for row in table.values() for v in row.values())
    assert measured == pytest.approx(loop_us, rel=1e-9)
    assert table[SPIN]["logic"] > 0.0 and table["executor"]["logic"] > 0.0
