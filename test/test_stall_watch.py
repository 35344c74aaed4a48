# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor program's stall watch (``stall_timeout``): fingers that stand still short of
their setpoints end the goal ``gripper_stalled``, holding where they are. Before, a squeeze
through a JointTrajectoryController that was loaded but not active (it drops every trajectory)
went on "squeezing" at depth 0 for ever: the program waited for the tips to reach their last
setpoints.
"""
from __future__ import annotations

import numpy as np
import pytest

from squeeze_grasp_ros.control.motion import GraspGoal, GraspProgram, MotionLimits, Observation

DT = 0.01
START = {"F1": np.array([0.0, -0.03]), "F2": np.array([0.0, 0.03])}
GOAL = GraspGoal(("F1", "F2"), np.array([[0.0, 1.0], [0.0, -1.0]]) / np.sqrt(2.0), 0.002)


def drive(limits: MotionLimits, follow: bool, ticks: int):
    """Run the program ``ticks`` cycles; the tips stay where they started, or (``follow``)
    reach each cycle's setpoints one cycle late. Its commands, one per cycle.
    """
    program = GraspProgram(GOAL, limits, ("F1", "F2"))
    at, commands = dict(START), []
    zero = {f: np.zeros(2) for f in START}
    for k in range(ticks):
        command = program.step(Observation(k * round(DT * 1e9), at, zero, zero), DT)
        commands.append(command)
        if command.termination is not None:
            break
        if follow:
            at = {f: np.asarray(p, float) for f, p in command.setpoints.items()}
    return commands


def test_tips_that_never_move_end_the_goal_gripper_stalled_after_the_timeout():
    commands = drive(MotionLimits(stall_timeout=0.5), follow=False, ticks=1000)
    end = commands[-1]
    assert end.termination == "gripper_stalled" and end.state == "holding"
    # the first setpoint away from the tips is the second cycle's; then 0.5 s of cycles
    assert len(commands) == 2 + round(0.5 / DT)
    assert end.message.startswith("F1, F2 stood still (within 0.1 mm) for 0.500 s "
                                  "(stall_timeout 0.5 s) short of the setpoints by F1 1.414 mm, "
                                  "F2 1.414 mm: a JointTrajectoryController")
    assert "that is loaded but not active drops every trajectory" in end.message
    for f in START:  # held where they are, not at the setpoints they never reached
        assert np.array_equal(end.setpoints[f], START[f])


def test_without_a_timeout_the_program_waits_as_before():
    commands = drive(MotionLimits(), follow=False, ticks=3000)
    assert all(c.termination is None for c in commands)
    assert commands[-1].state == "squeezing"


@pytest.mark.parametrize("max_velocity", [0.01, 2e-5])
def test_tips_that_follow_are_never_stalled_however_slowly_they_move(max_velocity):
    """At 20 um/s a tip moves 0.1 mm in 5 s, ten times the timeout: the watch's distance is
    a tenth of what max_velocity covers in the timeout (10 nm here), not a fixed 0.1 mm.
    """
    limits = MotionLimits(max_velocity=max_velocity, stall_timeout=0.5)
    assert limits.still_distance() == pytest.approx(min(1e-4, 0.1 * max_velocity * 0.5))
    commands = drive(limits, follow=True, ticks=20000)
    assert commands[-1].termination == "depth_reached", commands[-1].message
