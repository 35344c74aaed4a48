# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The Barrett BH8's joint kinematics in the object plane (control/barrett.py): the forward
kinematics against an independent chain of homogeneous transforms, the open hand's closed
form, inverse-forward round trips with their residual, the coupling, a straight squeeze line
followed exactly, and the errors out of reach.
"""
from __future__ import annotations

import numpy as np
import pytest
from doc_transcripts import REPO, blocks
from hypothesis import example, given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.control.barrett import (
    JOINTS,
    BarrettFinger,
    BarrettHand,
    HandPose,
    ReachError,
)

F1, F2, F3 = BarrettFinger.F1, BarrettFinger.F2, BarrettFinger.F3


def transform(rotation_axis: str, angle: float, offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    """A 4x4 homogeneous rotation about x, y or z followed by nothing, translated by offset."""
    c, s = np.cos(angle), np.sin(angle)
    r = {"z": [[c, -s, 0], [s, c, 0], [0, 0, 1]],
         "y": [[c, 0, s], [0, 1, 0], [-s, 0, c]]}[rotation_axis]
    out = np.eye(4)
    out[:3, :3] = r
    out[:3, 3] = offset
    return out


def chain_tip(hand: BarrettHand, base_xy, heading, proximal, distal) -> np.ndarray:
    """The fingertip in the palm frame by a chain of 3D transforms: turn to the finger's
    heading about the palm normal at its spread axis, out A1 to the knuckle, curl up by the
    proximal angle (about the finger's horizontal axis), out A2, curl by distal + Phi3, out
    A3; the top view drops the height.
    """
    t = transform("z", heading, (*base_xy, 0.0))
    t = t @ transform("y", 0.0, (hand.knuckle, 0.0, 0.0))
    t = t @ transform("y", -proximal) @ transform("y", 0.0, (hand.proximal_link, 0.0, 0.0))
    t = t @ transform("y", -(distal + hand.distal_offset))
    tip = t @ np.array([hand.distal_link, 0.0, 0.0, 1.0])
    return tip[:2]


def joints_of(spread, q1, q2, q3, d1=None, d2=None, d3=None) -> dict[str, float]:
    c = 1.0 / 3.0
    return {"bh_j11_joint": spread, "bh_j12_joint": q1, "bh_j13_joint": c * q1 if d1 is None
            else d1, "bh_j21_joint": spread, "bh_j22_joint": q2,
            "bh_j23_joint": c * q2 if d2 is None else d2, "bh_j32_joint": q3,
            "bh_j33_joint": c * q3 if d3 is None else d3}


def test_the_open_hand_is_the_closed_form():
    """All joints at zero: every finger straight out, its tip A1 + A2 + A3 cos(Phi3) from its
    spread axis, fingers 1 and 2 on the -y side, the thumb on +y.
    """
    hand = BarrettHand()
    reach = 0.050 + 0.070 + 0.050 * np.cos(np.deg2rad(42.0))
    tips = hand.forward(joints_of(0.0, 0.0, 0.0, 0.0))
    np.testing.assert_allclose(tips[F1], [-0.025, -reach], atol=1e-15)
    np.testing.assert_allclose(tips[F2], [0.025, -reach], atol=1e-15)
    np.testing.assert_allclose(tips[F3], [0.0, reach], atol=1e-15)


@settings(max_examples=60, deadline=None)
@given(spread=st.floats(0.0, np.pi), q=st.lists(st.floats(0.0, 2.44), min_size=3, max_size=3),
       d=st.lists(st.floats(0.0, 0.84), min_size=3, max_size=3),
       x=st.floats(-0.2, 0.2), y=st.floats(-0.2, 0.2), yaw=st.floats(-np.pi, np.pi))
def test_forward_kinematics_equals_a_chain_of_transforms(spread, q, d, x, y, yaw):
    hand = BarrettHand(pose=HandPose((x, y), yaw))
    tips = hand.forward(joints_of(spread, *q, *d))
    headings = {F1: -np.pi / 2 - spread, F2: -np.pi / 2 + spread, F3: np.pi / 2}
    bases = {F1: (-0.025, 0.0), F2: (0.025, 0.0), F3: (0.0, 0.0)}
    for k, finger in enumerate((F1, F2, F3)):
        palm = chain_tip(hand, bases[finger], headings[finger], q[k], d[k])
        rotated = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]) @ palm
        np.testing.assert_allclose(tips[finger], rotated + [x, y], atol=1e-14)


@settings(max_examples=80, deadline=None)
@given(spread=st.floats(0.0, np.pi), q1=st.floats(0.0, 2.39), q3=st.floats(0.0, 2.39),
       yaw=st.floats(-np.pi, np.pi))
@example(spread=np.pi, q1=0.0, q3=0.0, yaw=0.0)          # the spread's upper limit
@example(spread=0.0, q1=2.0, q3=0.0, yaw=0.0)            # finger 1's tip behind its axis
def test_inverse_of_forward_gives_the_joints_back_with_zero_residual(spread, q1, q3, yaw):
    hand = BarrettHand(pose=HandPose((0.01, -0.02), yaw))
    joints = joints_of(spread, q1, 0.0, q3)
    tips = hand.forward(joints)
    solution = hand.inverse({F1: tips[F1], F3: tips[F3]})
    assert solution.residual < 1e-12
    again = hand.forward(solution.joints)
    for finger in (F1, F3):
        np.testing.assert_allclose(again[finger], tips[finger], atol=1e-12)
    # the joints themselves where they are unique: the thumb's proximal angle on the branch;
    # finger 1's where its tip is ahead of its spread axis (a tip behind it, rho < 0, is also
    # reached ahead at the spread turned by pi, which the inverse prefers)
    assert solution.joints["bh_j32_joint"] == pytest.approx(q3, abs=1e-7)
    if hand.rho(q1) > 1e-3 and 1e-6 < spread < np.pi - 1e-6:
        assert solution.joints["bh_j12_joint"] == pytest.approx(q1, abs=1e-7)
        assert solution.joints["bh_j11_joint"] == pytest.approx(spread, abs=1e-9)
    # one spread motor, coupled distal joints
    assert solution.joints["bh_j11_joint"] == solution.joints["bh_j21_joint"]
    for finger in (F1, F3):
        assert solution.joints[finger.distal] == pytest.approx(
            solution.joints[finger.proximal] / 3.0, rel=1e-15)


def test_a_straight_pinch_of_fingers_1_and_2_is_followed_exactly():
    """The executor's setpoints close fingers 1 and 2 toward each other on one straight line
    of the object frame (the paper's translational squeeze; the fingers opposed near spread
    90 degrees): the shared spread follows the line, both tips are on their targets at every
    step (the pinch is symmetric about the palm's y axis, as the spread's motor is), and the
    spread moves continuously.
    """
    pose = HandPose((0.01, 0.03), 0.3)
    hand = BarrettHand(pose=pose)
    spreads = []
    for depth in np.linspace(0.0, 0.04, 41):
        targets = {F1: pose.to_object([-0.10 + depth, -0.02]),
                   F2: pose.to_object([0.10 - depth, -0.02])}
        solution = hand.inverse(targets)
        assert solution.residual < 1e-12
        tips = hand.forward(solution.joints)
        for finger, target in targets.items():
            np.testing.assert_allclose(tips[finger], target, atol=1e-12)
        spreads.append(solution.joints["bh_j11_joint"])
        # the spread points finger 1 from its axis (-25 mm, 0) at its target (palm frame)
        heading = np.arctan2(-0.02, -0.10 + depth + 0.025)
        assert spreads[-1] == pytest.approx(-(heading + np.pi / 2), abs=1e-12)
    assert np.all(np.abs(np.diff(spreads)) < 0.02) and 0.2 < np.ptp(spreads) < 0.3


def test_one_finger_follows_any_line_in_its_half_plane():
    """The paper's set-up: one Barrett finger against the arm. Finger 1 follows a slanted line
    through its workspace (spread and proximal together), the thumb and finger 2 at rest.
    """
    hand = BarrettHand(pose=HandPose((0.2, -0.1), -1.0))
    start, end = np.array([-0.13, -0.06]), np.array([-0.06, -0.01])
    for t in np.linspace(0.0, 1.0, 25):
        target = hand.pose.to_object(start + t * (end - start))
        solution = hand.inverse({F1: target})
        np.testing.assert_allclose(hand.forward(solution.joints)[F1], target, atol=1e-12)
        assert solution.joints["bh_j32_joint"] == 0.0 == solution.joints["bh_j22_joint"]


def test_targets_out_of_reach_name_the_finger_the_target_and_the_reach():
    hand = BarrettHand()
    with pytest.raises(ReachError, match=r"barrett_f3: target \(0, 0.3\) m lies 0.3 m from its "
                                         r"spread axis .*beyond its reach \[-0.0367585, "
                                         r"0.157157\] m"):
        hand.inverse({F3: np.array([0.0, 0.3])})
    with pytest.raises(ReachError) as refused:
        hand.inverse({F3: np.array([0.0, 0.3])})
    quoted = [b.lines for b in blocks(REPO / "docs" / "grippers.md")
              if b.language == "text" and "beyond its reach" in "\n".join(b.lines)]
    assert quoted == [(str(refused.value),)], quoted  # as docs/grippers.md quotes it
    with pytest.raises(ReachError, match=r"barrett_f3: target \(0.01, 0.1\) m is 0.01 m off "
                                         r"its closing line"):
        hand.inverse({F3: np.array([0.01, 0.1])})
    # with the spread held, finger 2 is on a fixed line too
    with pytest.raises(ReachError, match="barrett_f2: .* off its closing line"):
        hand.inverse({F2: np.array([0.0, -0.1])}, spread=0.0)


def test_forward_needs_every_joint():
    with pytest.raises(ValueError, match=r"\['bh_j33_joint'\] are missing"):
        BarrettHand().forward({j: 0.0 for j in JOINTS[:-1]})
