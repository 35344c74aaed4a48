# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The lift watched on a gripper's joint feedback (docs/grippers.md, "Lifting: the weight on
joint_states"): the monitor's pickup verdict and weight slip against the closed form
2 mu F >= w from the joint efforts, and hostile weights.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from pipeline_support import LogLines
from rclpy.context import Context
from sensor_msgs.msg import JointState

from squeeze_grasp_ros.control.joint_feedback import WeightWatch
from squeeze_grasp_ros.mechanics.vocabulary import Termination
from squeeze_grasp_ros.ros.nodes import ParameterError
from squeeze_grasp_ros.ros.nodes.monitor import JointFeedback

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
SPONGE = SCENES / "sponge_gripper.yaml"
MU, WEIGHT, MARGIN = 0.6, 1.5, 1.25


def jaw_feedback(**extra) -> JointFeedback:
    params = {"controller_scene": str(SPONGE), "load_threshold": 0.002, "mu": MU,
              "joint_slip_window": 1e-4, "joint_slip_ratio": 0.5, "weight": WEIGHT,
              "weight_margin": MARGIN, **extra}
    return JointFeedback.of(params, [])


def test_the_pickup_verdict_is_the_closed_form_from_the_joint_efforts():
    """Joint states whose efforts stand for a jaw force rising, holding, then falling: the
    monitor's jaws report picked_up at the first state with 2 mu F >= margin w, and weight_slip
    for both jaws exactly at the states with 2 mu F < w after it (value 2 mu F / w); the
    force is read back through the device's transmission, not given to the watch.
    """
    jaws = jaw_feedback()
    gripper = jaws.controller.gripper
    poses = {"F1": np.array([0.0, -0.026]), "F2": np.array([0.0, 0.026])}
    rising = np.linspace(0.0, 2.0, 41)
    forces = np.concatenate([rising, np.full(5, 2.0), np.linspace(2.0, 0.5, 31),
                             np.linspace(0.5, 1.6, 12)])
    picked, alarmed, log = [], [], LogLines()
    for k, force in enumerate(forces):
        msg = JointState(name=list(gripper.transmission.joints),
                         position=list(gripper.joint_positions(0.045)),
                         effort=list(gripper.joint_efforts(float(force))))
        msg.header.stamp.nanosec = (k + 1) * 1_000_000
        fields = {f: {"position": p.copy()} for f, p in poses.items()}
        jaws.replace(fields, msg, log)
        picked.append(jaws.take_picked_up())
        weight = [a for a in jaws.alarms if a.type == Termination.WEIGHT_SLIP]
        alarmed.append(weight)
    carried = 2.0 * MU * forces / WEIGHT
    first = int(np.argmax(carried >= MARGIN))
    assert picked == [k == first for k in range(len(forces))]
    assert math.isclose(2.0 * MU * forces[first], MARGIN * WEIGHT, rel_tol=0.05)
    expect = [k > first and carried[k] < 1.0 for k in range(len(forces))]
    assert [bool(a) for a in alarmed] == expect and any(expect)
    for k in np.flatnonzero(expect):
        assert sorted(a.finger for a in alarmed[k]) == ["F1", "F2"]
        assert alarmed[k][0].value == pytest.approx(carried[k], rel=1e-12)
        assert "below the 1.25 N that carries the weight 1.5 N" in alarmed[k][0].message
    # recovering above w / (2 mu) clears the alarm without a second picked_up
    assert not alarmed[-1] and sum(picked) == 1
    assert any(line.startswith("picked up: jaw force") for line in log.lines)


def test_the_watch_starts_again_once_the_object_is_out_of_the_jaws():
    watch = WeightWatch(("F1", "F2"), mu=0.5, weight=1.0, margin=1.0, contact_force=0.01)
    assert watch.update(1.0) == (True, ())
    picked, alarms = watch.update(0.0)  # slipped out: the force falls to nothing
    assert not picked and [a.value for a in alarms] == [0.0, 0.0]
    assert watch.update(0.0) == (False, ()) and watch.update(1.0) == (True, ())


@pytest.mark.parametrize("weight, why", [
    (-1.0, "weight must be a finite number > 0 N (0: no pickup test), got -1.0"),
    (float("nan"), "weight must be a finite number > 0 N (0: no pickup test), got nan"),
    (float("inf"), "weight must be a finite number > 0 N (0: no pickup test), got inf"),
])
def test_a_hostile_weight_is_refused_naming_the_field_and_its_range(weight, why):
    with pytest.raises(ParameterError, match=re.escape(why)):
        jaw_feedback(weight=weight)
    with pytest.raises(ValueError, match=re.escape(why)):
        WeightWatch(("F1", "F2"), mu=MU, weight=weight)


def test_no_weight_no_pickup_test_and_a_bad_margin_or_mu_is_refused():
    assert jaw_feedback(weight=0.0).weight is None
    with pytest.raises(ParameterError, match=r"weight_margin must be a finite number >= 1, "
                                             r"got 0.9"):
        jaw_feedback(weight_margin=0.9)
    with pytest.raises(ParameterError, match=r"mu must be a finite number > 0 to carry a "
                                             r"weight by friction, got 0.0"):
        jaw_feedback(mu=0.0)


@pytest.mark.parametrize("weight", [-1.0, float("nan")])
def test_the_monitor_node_refuses_a_hostile_weight_on_real_rclpy(weight, ros_context: Context):
    """Every route: the monitor's weight parameter, before any joint feedback is built."""
    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode

    with pytest.raises(ParameterError, match=r"weight must be a finite number >= 0 N "
                                             r"\(0: no pickup test\), got "):
        MonitorNode(context=ros_context, parameter_overrides=[Parameter("weight", value=weight)])
