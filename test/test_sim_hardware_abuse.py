# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated hardware under garbage setpoints, on real rclpy: a setpoint that is not
finite is refused, the world waits for a finite one and steps on it.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from pipeline_support import sim_and_client

from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import pipeline


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_setpoint_that_is_not_finite_is_refused_and_the_world_waits(bad, capfd):
    """F1's setpoint for tick 1 is (bad, 0) and F2's is good: before, the world's step raised
    "InvalidInputError: finger translations must be finite" in the setpoint callback and the
    sim_hardware process ended. Now the NaN is refused with a warning line, tick 1 waits, and
    a finite setpoint of F1 steps the world.
    """
    with sim_and_client(str(scene_file("foam_square"))) as (executor, sim, client):
        pubs = {finger: client.create_publisher(
            PoseStamped, pipeline.device_topic(device, "setpoint"), pipeline.loop_qos(100))
            for finger, device in sim.devices.items()}
        pipeline.Participant(client, "hostile", [], list(pubs.values()))

        def spin_until(condition, timeout=10.0):
            deadline = time.monotonic() + timeout
            while not condition() and time.monotonic() < deadline:
                executor.spin_once(timeout_sec=0.05)
            return condition()

        assert spin_until(lambda: sim.now_ns >= 0)
        start = {f: sim.world.positions[f].copy() for f in pubs}
        stamp = sim.world.dt_ns
        pubs["F1"].publish(messages.pose_msg((bad, 0.0), stamp, pipeline.FRAME))
        pubs["F2"].publish(messages.pose_msg(tuple(start["F2"]), stamp, pipeline.FRAME))
        assert not spin_until(lambda: sim.now_ns > 0, 1.0), "the world stepped on the NaN"
        pubs["F1"].publish(messages.pose_msg(tuple(start["F1"] + [1e-5, 0.0]), stamp,
                                             pipeline.FRAME))
        assert spin_until(lambda: sim.now_ns == stamp), "the good setpoint never stepped it"
        np.testing.assert_allclose(sim.world.positions["F1"], start["F1"] + [1e-5, 0.0],
                                   atol=1e-12)
    assert "refused (F1 setpoint): the setpoint of 0.001000000 s is not finite" in \
        capfd.readouterr().err
