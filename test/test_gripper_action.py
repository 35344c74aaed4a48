# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The stock gripper action controllers' goal semantics, ROS-free (control/gripper_action.py):
goal tolerance, stall detection, the speed limit and the force-controlled stop, against the
rules of ros2_controllers' Jazzy sources and a spring closed in by the jaws.
"""
from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.control.gripper_action import (
    GoalEnd,
    GoalRefused,
    GripperGoal,
    GripperParameters,
    GripperServo,
    gripper_goal,
)

DT = 1e-3
REPO = Path(__file__).resolve().parents[1]
SPONGE = REPO / "config" / "scenes" / "sponge_gripper.yaml"


@settings(max_examples=60, deadline=None)
@given(target=st.floats(-1.0, 1.0), position=st.floats(-1.0, 1.0),
       tolerance=st.floats(1e-6, 0.1))
def test_reached_exactly_within_the_goal_tolerance(target, position, tolerance):
    """check_for_success: the goal succeeds with reached_goal iff |command - position| <
    goal_tolerance, whatever the velocity.
    """
    servo = GripperServo(GripperParameters(goal_tolerance=tolerance), position=0.0)
    servo.accept(GripperGoal(target, 5.0, 0.1), now=0.0)
    outcome = servo.update(now=0.001, position=position, velocity=0.5)
    if abs(target - position) < tolerance:
        assert outcome is not None and outcome.reached_goal and not outcome.stalled
        assert outcome.end is GoalEnd.SUCCEEDED and outcome.position == position
        assert outcome.effort == 5.0          # the computed command of a position interface
        assert servo.goal is None
    else:
        assert outcome is None and servo.goal is not None


@pytest.mark.parametrize("allow_stalling, end", [(False, GoalEnd.ABORTED),
                                                  (True, GoalEnd.SUCCEEDED)])
def test_stall_after_the_timeout_below_the_velocity_threshold(allow_stalling, end):
    """Standing still (|v| <= threshold) for more than stall_timeout s short of the goal is a
    stall: aborted, or succeeded with allow_stalling; any faster tick restarts the timer.
    """
    p = GripperParameters(stall_velocity_threshold=0.001, stall_timeout=0.05,
                          allow_stalling=allow_stalling)
    servo = GripperServo(p, position=0.0)
    servo.accept(GripperGoal(0.5, 5.0, 0.1), now=0.0)
    for k in range(1, 51):                       # 0.05 s, not more: no stall yet
        assert servo.update(now=k * DT, position=0.1, velocity=0.001) is None
    assert servo.update(now=0.0505, position=0.1, velocity=0.0011) is None   # moved: reset
    for k in range(1, 51):
        assert servo.update(now=0.0505 + k * DT, position=0.1, velocity=0.0) is None
    outcome = servo.update(now=0.0505 + 51 * DT, position=0.1, velocity=0.0)
    assert outcome is not None and outcome.stalled and not outcome.reached_goal
    assert outcome.end is end and outcome.position == 0.1


def test_command_speed_limit_and_jump():
    """The parallel controller's speed limit moves the command by velocity dt per tick; the
    GripperActionController's (no limit) jumps to the goal.
    """
    servo = GripperServo(GripperParameters(), position=0.0)
    servo.accept(GripperGoal(0.01, 5.0, 2.0), now=0.0)
    steps = [servo.command(0.0, 0.0, dt=DT) for _ in range(6)]
    assert steps == pytest.approx([0.002, 0.004, 0.006, 0.008, 0.01, 0.01], abs=1e-15)
    jump = GripperServo(GripperParameters(max_velocity=math.inf), position=0.0)
    jump.accept(GripperGoal(0.7, 5.0, math.inf), now=0.0)
    assert jump.command(0.0, 0.0, dt=DT) == 0.7


def test_cancel_holds_the_measured_position():
    servo = GripperServo(GripperParameters(max_effort=3.0), position=0.0)
    servo.accept(GripperGoal(0.5, 5.0, 1.0), now=0.0)
    servo.command(0.0, 0.0, dt=DT)
    servo.cancel(0.0007)
    assert servo.goal is None and servo.effort == 3.0
    assert servo.command(0.0007, 0.0, dt=DT) == 0.0007
    assert servo.update(now=1.0, position=0.0, velocity=0.0) is None


def spring_close(stiffness: float, contact: float, effort: float, *, stall_timeout: float,
                 ticks: int) -> tuple[list[float], object]:
    """Jaws (joint = aperture, m; effort = jaw force, N) closing from 0.05 m on a spring that
    pushes back k (contact - a) below the aperture ``contact``; the joint follows its command
    exactly. Returns (apertures, outcome).
    """
    p = GripperParameters(goal_tolerance=1e-6, stall_timeout=stall_timeout)
    servo = GripperServo(p, position=0.05)
    servo.accept(gripper_goal(0.0, effort, 0.02, parameters=p, joint_range=(0.0, 0.085),
                              effort_limit=235.0), now=0.0)
    position, force, apertures = 0.05, 0.0, []
    for k in range(1, ticks):
        new = servo.command(position, force, dt=DT)
        velocity, position = (new - position) / DT, new
        force = stiffness * max(contact - position, 0.0)
        apertures.append(position)
        outcome = servo.update(now=k * DT, position=position, velocity=velocity)
        if outcome is not None:
            return apertures, outcome
    return apertures, None


def test_force_controlled_stop_stalls_at_the_effort_limit():
    """With max effort F on a spring k, the jaws stop where the force first reaches F (within
    one tick's closing, 20 um at 0.02 m/s), stand still, and the goal stalls stall_timeout
    later: aborted, reached_goal false, effort = F.
    """
    k, contact, f_max = 1000.0, 0.04, 5.0
    apertures, outcome = spring_close(k, contact, f_max, stall_timeout=0.05, ticks=5000)
    stop = contact - f_max / k
    assert outcome is not None and outcome.stalled and outcome.end is GoalEnd.ABORTED
    assert stop - 0.02 * DT - 1e-12 <= outcome.position <= stop + 1e-12
    assert outcome.effort == f_max
    first_stop = next(i for i, a in enumerate(apertures) if a <= stop + 1e-12)
    assert len(apertures) - 1 - first_stop == pytest.approx(51, abs=1)   # ticks standing still


def test_a_strong_enough_effort_reaches_the_goal():
    apertures, outcome = spring_close(1000.0, 0.04, 235.0, stall_timeout=0.05, ticks=5000)
    assert outcome is not None and outcome.reached_goal and not outcome.stalled
    assert outcome.position == pytest.approx(0.0, abs=1e-6)
    assert len(apertures) == pytest.approx(0.05 / 0.02 / DT, abs=1)


@pytest.mark.parametrize("position, effort, velocity, field", [
    (math.nan, 1.0, None, "position nan is not finite"),
    (0.9, 1.0, None, "position 0.9 is outside the joint range [0, 0.8]"),
    (-0.1, 1.0, None, "outside the joint range"),
    (0.4, 300.0, None, "effort 300 is outside (0, 235]"),
    (0.4, -1.0, None, "effort -1 is outside"),
    (0.4, math.inf, None, "effort inf is outside"),
    (0.4, 1.0, 0.0, "velocity 0 must be finite and > 0"),
    (0.4, 1.0, math.nan, "velocity nan must be"),
])
def test_goal_refusals_name_the_field(position, effort, velocity, field):
    with pytest.raises(GoalRefused, match=field.replace("(", r"\(").replace("[", r"\[")
                       .replace(")", r"\)").replace("]", r"\]")):
        gripper_goal(position, effort, velocity, parameters=GripperParameters(),
                     joint_range=(0.8, 0.0), effort_limit=235.0)


def test_goal_defaults_from_the_parameters():
    p = GripperParameters(max_effort=7.0, max_velocity=0.3)
    assert gripper_goal(0.4, None, None, parameters=p, joint_range=(0.0, 0.8),
                        effort_limit=235.0) == GripperGoal(0.4, 7.0, 0.3)
    assert gripper_goal(0.4, 0.0, 0.1, parameters=p, joint_range=(0.0, 0.8),
                        effort_limit=235.0) == GripperGoal(0.4, 7.0, 0.1)


# --------------------------------------------------------------------------- without control_msgs
def test_without_control_msgs_the_ros_tests_skip_saying_how_to_build_it():
    """A fresh machine has no control_msgs: the action tests skip with the ros-setup line and
    the doctest sweep skips the two modules that import it, nothing fails.
    """
    hide = "import sys; sys.modules['control_msgs'] = None; import pytest; "
    tests = ["test/test_gripper_action_ros.py", "test/test_doctests.py::test_examples"]
    result = subprocess.run(
        [sys.executable, "-c", hide + f"sys.exit(pytest.main(['-q', '-rs', *{tests!r}, "
         "'-k', 'action_ros or jaw_action or sim_gripper_action', '-p', 'no:cacheprovider']))"],
        cwd=REPO, capture_output=True, text=True, timeout=300)
    out = result.stdout
    assert result.returncode == 0, out + result.stderr
    assert "control_msgs is not built: squeeze-grasp ros-setup --control-msgs DIR" in out
    assert "SKIPPED [2] test/test_doctests.py" in out
    assert "needs control_msgs.action, which is not installed: squeeze-grasp ros-setup " \
           "--control-msgs DIR" in out
    assert "3 skipped" in out and "failed" not in out


def test_an_action_controller_without_control_msgs_is_a_parameter_error(monkeypatch):
    from squeeze_grasp_ros.ros.nodes import ParameterError
    from squeeze_grasp_ros.ros.nodes.sim_hardware import sim_controller
    from squeeze_grasp_ros.scene import parse_scene
    from squeeze_grasp_ros.scene.controller import scene_controller

    data = yaml.safe_load(SPONGE.read_text())
    data["controller"]["type"] = "parallel_gripper"
    jaws = scene_controller(parse_scene(data), SPONGE)
    for name in ("control_msgs", "control_msgs.action", "control_msgs.msg"):
        monkeypatch.setitem(sys.modules, name, None)     # as on a fresh machine
    monkeypatch.delitem(sys.modules, "squeeze_grasp_ros.ros.nodes.sim_gripper_action",
                        raising=False)
    with pytest.raises(ParameterError, match="controller.type parallel_gripper needs "
                       "control_msgs .*squeeze-grasp ros-setup --control-msgs DIR"):
        sim_controller(jaws)


def test_the_force_stop_outlasts_the_goal():
    """After a stall ends the goal the command and its effort limit stay (stock: the command
    struct is unchanged): the jaws still do not close while at the limit.
    """
    servo = GripperServo(GripperParameters(stall_timeout=0.0), position=0.05)
    servo.accept(GripperGoal(0.0, 5.0, 0.02), now=0.0)
    assert servo.command(0.05, 5.0, dt=DT) == 0.05
    assert servo.update(now=DT, position=0.05, velocity=0.0).stalled
    assert servo.goal is None
    assert servo.command(0.05, 5.0, dt=DT) == 0.05
    assert servo.command(0.05, 4.0, dt=DT) == pytest.approx(0.05 - 0.02 * DT)


@pytest.mark.parametrize("gain", [-0.8 / 0.085, 0.5, 1.0])
@pytest.mark.parametrize("closing", [0.0024, 0.0075])
def test_a_goal_tolerance_the_squeeze_ends_within_at_once_is_named(gain, closing, tmp_path):
    """The controller section's goal_tolerance is in joint units: on a joint at half the
    aperture in m (a Franka-like finger) the stock 0.01 is 20 mm of aperture. The stock rule
    (|goal - position| < goal_tolerance) ends a squeeze of ``closing`` where it starts exactly
    when JawController.tolerance_problem names it.
    """
    from squeeze_grasp_ros.scene import parse_scene
    from squeeze_grasp_ros.scene.controller import scene_controller

    device = yaml.safe_load((REPO / "config" / "devices" / "generic_85mm.yaml").read_text())
    device["transmission"] = {"joints": ["finger_joint"], "position_per_aperture": gain,
                              "position_offset": 0.8 if gain < 0 else 0.0}
    (tmp_path / "device.yaml").write_text(yaml.safe_dump(device))
    for tolerance in (0.99 * closing * abs(gain), 1.01 * closing * abs(gain), 0.01):
        data = yaml.safe_load(SPONGE.read_text())
        data["controller"] = {"type": "parallel_gripper", "name": "gripper_controller",
                              "device": "device.yaml", "goal_tolerance": tolerance}
        jaws = scene_controller(parse_scene(data), tmp_path / "scene.yaml")
        start = jaws.joint_positions(0.05)[0]
        servo = GripperServo(jaws.parameters(), position=start)
        servo.accept(GripperGoal(jaws.joint_positions(0.05 - closing)[0], 5.0, 0.1), now=0.0)
        at_once = servo.update(now=0.001, position=start, velocity=0.0) is not None
        problem = jaws.tolerance_problem(closing)
        assert at_once == (problem is not None), (tolerance, problem)
        if problem is not None:
            assert problem.startswith(f"controller.goal_tolerance {tolerance:g} (joint units) "
                                      f"is {tolerance / abs(gain) * 1e3:.4g} mm of aperture")
            assert f"below {closing * abs(gain):.4g}" in problem
        assert jaws.tolerance_problem(0.0) is None   # a depth-0 goal is reached where it starts
