# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Joint kinematics of the Barrett BH8 hand in the object plane: fingertip setpoints to the
hand's joint positions and back (docs/grippers.md, "The Barrett hand's joints").

The model (this project's; dimensions from Barrett's published D-H table of the BH8-280, as
the hand's user manual and the common BH8 models give it):

- **Joints** (the names of the hand's ROS drivers): ``bh_j11_joint`` / ``bh_j21_joint`` the
  spread of fingers 1 and 2 (one motor: always equal, 0 .. pi rad), ``bh_jk2_joint`` finger
  k's proximal joint (0 .. 2.44 rad), ``bh_jk3_joint`` its distal joint, driven by the same
  motor at the fixed ratio :data:`COUPLING` of the proximal one (0 .. 0.84 rad; the ranges'
  ratio is 0.344, Barrett states 1/3). Finger 3 (the thumb) has no spread.
- **Geometry** (palm frame, top view: the palm parallel to the object plane, its normal out of
  it, the fingers curling toward it): the spread axes of fingers 1 and 2 at (-``Aw``, 0) and
  (+``Aw``, 0), the thumb's at the palm centre; finger k closes in the vertical plane through
  its spread axis and its direction e_k (angle -pi/2 - spread for finger 1, -pi/2 + spread for
  finger 2, +pi/2 for the thumb). In that plane its tip is at the radial distance
  rho(q) = A1 + A2 cos q + A3 cos((1 + c) q + Phi3) from the spread axis (q the proximal angle,
  c the coupling) and at the height A2 sin q + A3 sin((1 + c) q + Phi3) above the knuckles;
  the top view keeps rho. rho falls from A1 + A2 + A3 cos Phi3 = 157.2 mm (open) to its
  minimum -36.8 mm at q* = 2.40 rad (the tip curled past the spread axis) and rises after:
  the inverse kinematics keeps the branch [0, q*], on which rho is strictly decreasing.
- **The hand's pose** in the object frame: the palm centre (m) and the yaw of the palm's x
  axis (rad); a fingertip p (object frame) is palm = R(yaw)^T (p - centre) in the palm frame.

The tip's height above the object plane is not modelled (the planar contact takes the
fingertip as a disk in the plane: its height must lie within the object's thickness).

>>> hand = BarrettHand()
>>> round(hand.reach(BarrettFinger.F3)[1] * 1e3, 1)            # rho open, mm
157.2
>>> tips = hand.forward({"bh_j11_joint": 0.3, "bh_j12_joint": 1.0, "bh_j13_joint": 1.0 / 3,
...                      "bh_j21_joint": 0.3, "bh_j22_joint": 0.0, "bh_j23_joint": 0.0,
...                      "bh_j32_joint": 1.2, "bh_j33_joint": 0.4})
>>> solution = hand.inverse({BarrettFinger.F1: tips[BarrettFinger.F1],
...                          BarrettFinger.F3: tips[BarrettFinger.F3]})
>>> round(solution.joints["bh_j11_joint"], 9), round(solution.joints["bh_j32_joint"], 9)
(0.3, 1.2)
>>> solution.residual < 1e-12
True
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import Enum

import numpy as np
from scipy.optimize import brentq, minimize_scalar

__all__ = ["COUPLING", "JOINTS", "MAX_CONDITION", "BarrettFinger", "BarrettHand", "HandPose",
           "HandSolution", "ReachError", "SingularPosture", "TipForce"]

MAX_CONDITION = 100.0
"""Largest condition number of a finger's J^T (:meth:`BarrettHand.tip_force`) at which its tip
force is recovered from its joint efforts: an effort error dtau gives a force error up to
condition * |dtau| / |tau| relative."""

COUPLING = 1.0 / 3.0
"""Distal over proximal joint angle of a BH8 finger (Barrett's stated ratio; the joint ranges'
ratio 0.84 / 2.44 = 0.344)."""


class BarrettFinger(str, Enum):
    """A finger of the hand, by its device name (``scene.DEVICES``)."""

    F1 = "barrett_f1"
    F2 = "barrett_f2"
    F3 = "barrett_f3"

    @property
    def index(self) -> int:
        """1, 2 or 3 (the joint names' digit)."""
        return int(self.value[-1])

    @property
    def proximal(self) -> str:
        """The proximal joint's name."""
        return f"bh_j{self.index}2_joint"

    @property
    def distal(self) -> str:
        """The distal joint's name."""
        return f"bh_j{self.index}3_joint"

    @property
    def spread(self) -> str | None:
        """The spread joint's name (None for the thumb)."""
        return None if self is BarrettFinger.F3 else f"bh_j{self.index}1_joint"


JOINTS: tuple[str, ...] = ("bh_j11_joint", "bh_j12_joint", "bh_j13_joint", "bh_j21_joint",
                           "bh_j22_joint", "bh_j23_joint", "bh_j32_joint", "bh_j33_joint")
"""The hand's joints, in the order of its drivers' JointTrajectory."""


class ReachError(ValueError):
    """A fingertip target the finger cannot reach; the message names the finger, the target
    and the reach.
    """


@dataclass(frozen=True)
class HandPose:
    """The palm in the object frame: centre (m) and the yaw of its x axis (rad)."""

    centre: tuple[float, float] = (0.0, 0.0)
    yaw: float = 0.0

    def to_palm(self, point: np.ndarray) -> np.ndarray:
        """An object-frame point (m) in the palm frame."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        d = np.asarray(point, float) - np.asarray(self.centre, float)
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    def to_object(self, point: np.ndarray) -> np.ndarray:
        """A palm-frame point (m) in the object frame."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        p = np.asarray(point, float)
        return np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]]) + np.asarray(self.centre)


class SingularPosture(ValueError):
    """A posture at which a finger's joint efforts do not determine its planar tip force; the
    message names the finger, its joints and the conditioning.
    """


@dataclass(frozen=True)
class TipForce:
    """A fingertip's planar force recovered from its joint efforts (:meth:`BarrettHand.tip_force`).

    Attributes
    ----------
    force : ndarray (2,)
        The finger's push on the object, object frame, N.
    condition : float
        The condition number of the finger's J^T (3 x 2).
    residual : float
        The largest |J^T F - tau| over the finger's three joints, N m (0 for efforts of the
        model: a driver's efforts that break the model's proportions show here).
    """

    force: np.ndarray
    condition: float
    residual: float


@dataclass(frozen=True)
class HandSolution:
    """The inverse kinematics of some fingertip targets.

    Attributes
    ----------
    joints : dict of str to float
        Every joint of :data:`JOINTS`, rad (fingers without a target keep ``rest``'s angles).
    residual : float
        The largest distance between a target and its finger's tip at ``joints``, m.
    """

    joints: dict[str, float]
    residual: float


@dataclass(frozen=True)
class BarrettHand:
    """The BH8's kinematics in the object plane (lengths in m, angles in rad).

    Attributes
    ----------
    pose : HandPose
    palm_offset : float
        Aw: the spread axes of fingers 1 and 2 from the palm centre.
    knuckle, proximal_link, distal_link : float
        A1, A2, A3: spread axis to proximal joint, proximal to distal joint, distal joint to
        the fingertip's centre.
    distal_offset : float
        Phi3: the distal link's fixed angle to the proximal one at a zero distal joint.
    coupling : float
        Distal over proximal joint angle.
    proximal_max, distal_max, spread_max : float
        The proximal, distal and spread joints' upper limits (all start at 0).
    """

    pose: HandPose = field(default_factory=HandPose)
    palm_offset: float = 0.025
    knuckle: float = 0.050
    proximal_link: float = 0.070
    distal_link: float = 0.050
    distal_offset: float = np.deg2rad(42.0)
    coupling: float = COUPLING
    proximal_max: float = 2.44
    distal_max: float = 0.84
    spread_max: float = np.pi

    def limits(self) -> list[tuple[float, float]]:
        """Each joint's range (rad), in the order of :data:`JOINTS`."""
        ranges = {"1": (0.0, self.spread_max), "2": (0.0, self.proximal_max),
                  "3": (0.0, self.distal_max)}
        return [ranges[name[-7]] for name in JOINTS]

    # ----------------------------------------------------------------- one finger's plane
    def rho(self, proximal: float, distal: float | None = None) -> float:
        """The tip's distance from the spread axis along the finger's direction (m) at the
        proximal (and distal; default coupled) joint angles.
        """
        distal = self.coupling * proximal if distal is None else distal
        return float(self.knuckle + self.proximal_link * np.cos(proximal)
                     + self.distal_link * np.cos(proximal + distal + self.distal_offset))

    @property
    def turning(self) -> float:
        """q*: the proximal angle of the smallest rho (the end of the inverse's branch)."""
        found = minimize_scalar(self.rho, bounds=(0.0, self.proximal_max), method="bounded",
                                options={"xatol": 1e-12})
        return float(found.x)

    def reach(self, finger: BarrettFinger) -> tuple[float, float]:
        """(smallest, largest) rho of the inverse's branch, m."""
        del finger                      # the three fingers are alike
        return self.rho(self.turning), self.rho(0.0)

    def base(self, finger: BarrettFinger) -> np.ndarray:
        """The finger's spread axis in the palm frame, m."""
        return np.array({BarrettFinger.F1: (-self.palm_offset, 0.0),
                         BarrettFinger.F2: (self.palm_offset, 0.0),
                         BarrettFinger.F3: (0.0, 0.0)}[finger])

    @staticmethod
    def direction(finger: BarrettFinger, spread: float) -> float:
        """The finger's direction in the palm frame (angle of e_k, rad) at ``spread``."""
        return {BarrettFinger.F1: -np.pi / 2 - spread, BarrettFinger.F2: -np.pi / 2 + spread,
                BarrettFinger.F3: np.pi / 2}[finger]

    # ----------------------------------------------------------------- the hand
    def forward(self, joints: Mapping[str, float]) -> dict[BarrettFinger, np.ndarray]:
        """Each fingertip's centre (object frame, m) at the measured ``joints`` (rad; every
        name of :data:`JOINTS`, others ignored): the distal joints as measured.
        """
        missing = [j for j in JOINTS if j not in joints]
        if missing:
            raise ValueError(f"joint positions of {missing} are missing")
        tips = {}
        for finger in BarrettFinger:
            spread = float(joints[finger.spread]) if finger.spread else 0.0
            angle = self.direction(finger, spread)
            rho = self.rho(float(joints[finger.proximal]), float(joints[finger.distal]))
            palm = self.base(finger) + rho * np.array([np.cos(angle), np.sin(angle)])
            tips[finger] = self.pose.to_object(palm)
        return tips

    # ----------------------------------------------------------------- statics
    def jacobian(self, finger: BarrettFinger, joints: Mapping[str, float]) -> np.ndarray:
        """The fingertip's planar velocity per joint velocity: (2, 3), m/rad, object frame,
        columns the spread, proximal and distal joints each moved alone (the thumb's spread
        column zero: it has none). The tip moves along its line e_k by the proximal and distal
        joints (d rho / dq e_k; the height they also change is not modelled) and across it by
        the spread (rho de_k / dspread).
        """
        spread = float(joints[finger.spread]) if finger.spread else 0.0
        q2, q3 = float(joints[finger.proximal]), float(joints[finger.distal])
        angle = self.direction(finger, spread)
        along = np.array([np.cos(angle), np.sin(angle)])
        across = np.array([-np.sin(angle), np.cos(angle)])
        turn = -1.0 if finger is BarrettFinger.F1 else 1.0      # d angle / d spread
        distal = -self.distal_link * np.sin(q2 + q3 + self.distal_offset)
        columns = np.column_stack([
            (self.rho(q2, q3) * turn * across) if finger.spread else np.zeros(2),
            (-self.proximal_link * np.sin(q2) + distal) * along, distal * along])
        c, s = np.cos(self.pose.yaw), np.sin(self.pose.yaw)
        return np.array([[c, -s], [s, c]]) @ columns

    def efforts(self, joints: Mapping[str, float],
                forces: Mapping[BarrettFinger, np.ndarray]) -> dict[str, float]:
        """Every joint's torque (N m, order of :data:`JOINTS`) holding the fingertips' pushes
        ``forces`` (object frame, N; fingers not given push nothing): tau = J^T F per finger,
        each joint's own torque, as a torque sensor at that joint reads it. The drivetrain
        couples them: one motor drives a finger's proximal and distal joints (distal = 1/3 of
        proximal), so that motor carries tau_proximal + tau_distal / 3; one motor drives both
        spread joints, carrying bh_j11 + bh_j21.
        """
        out = {j: 0.0 for j in JOINTS}
        for finger, force in forces.items():
            finger = BarrettFinger(finger)
            tau = self.jacobian(finger, joints).T @ np.asarray(force, float)
            names = (finger.spread, finger.proximal, finger.distal)
            for name, value in zip(names, tau):
                if name is not None:
                    out[name] = float(value)
        return out

    def tip_force(self, finger: BarrettFinger, joints: Mapping[str, float],
                  efforts: Mapping[str, float], *, max_condition: float = MAX_CONDITION
                  ) -> TipForce:
        """The fingertip's planar push on the object from its joints' efforts (N m): the
        least-squares solution of J^T F = tau over its spread, proximal and distal joints.

        Raises
        ------
        SingularPosture
            The thumb (no spread joint: its force across its line is borne by its structure,
            so its efforts give one component only), or a J^T whose condition number exceeds
            ``max_condition`` (the tip near its spread axis, where the spread hardly moves it).
        """
        finger = BarrettFinger(finger)
        if finger.spread is None:
            raise SingularPosture(
                f"{finger.value}: the thumb has no spread joint, so its joint efforts give its "
                "tip force along its closing line only (the force across it is borne by its "
                "structure); watch it on a force or tactile sensor")
        a = self.jacobian(finger, joints).T
        condition = float(np.linalg.cond(a))
        if not condition <= max_condition:
            rho = self.rho(joints[finger.proximal], joints[finger.distal])
            raise SingularPosture(
                f"{finger.value}: its joint efforts do not determine its tip force at spread "
                f"{joints[finger.spread]:.4g}, proximal {joints[finger.proximal]:.4g}, distal "
                f"{joints[finger.distal]:.4g} rad: J^T has condition number {condition:.3g} > "
                f"{max_condition:g} (the tip {rho * 1e3:.3g} mm from its spread axis, where the "
                "spread hardly moves it)")
        tau = np.array([efforts[finger.spread], efforts[finger.proximal],
                        efforts[finger.distal]], float)
        force = np.linalg.lstsq(a, tau, rcond=None)[0]
        return TipForce(force, condition, float(np.max(np.abs(a @ force - tau))))

    def inverse(self, targets: Mapping[BarrettFinger, np.ndarray], *,
                rest: Mapping[str, float] | None = None, spread: float | None = None,
                tolerance: float = 1e-9) -> HandSolution:
        """The joint positions that put the fingertips' centres on ``targets`` (object frame,
        m), each distal joint coupled to its proximal one.

        The spread is solved from the target of finger 1 (or else 2) unless ``spread`` is
        given; a second spread finger and the thumb then move on their fixed lines, and a
        target off its line is reached as closely as the line allows (the distance is the
        residual). Fingers without a target keep ``rest``'s angles (default: open, zero).

        Raises
        ------
        ReachError
            A target whose distance along its finger's line is beyond the finger's reach, or
            whose residual exceeds ``tolerance`` (m); the message names the finger, the target
            and the reach.
        """
        joints = {j: 0.0 for j in JOINTS} if rest is None else {j: float(rest[j]) for j in JOINTS}
        targets = {BarrettFinger(f): np.asarray(p, float) for f, p in targets.items()}
        spreaders = [f for f in (BarrettFinger.F1, BarrettFinger.F2) if f in targets]
        if spread is None and spreaders:
            spread = self._spread(spreaders[0], targets[spreaders[0]])
        if spread is not None:
            joints["bh_j11_joint"] = joints["bh_j21_joint"] = float(spread)
        low, high = self.reach(BarrettFinger.F1)
        turning = self.turning
        residual = 0.0
        for finger, target in targets.items():
            spread_k = joints["bh_j11_joint"] if finger.spread else 0.0
            angle = self.direction(finger, spread_k)
            d = self.pose.to_palm(target) - self.base(finger)
            along = float(d[0] * np.cos(angle) + d[1] * np.sin(angle))
            if not low - tolerance <= along <= high + tolerance:
                raise ReachError(
                    f"{finger.value}: target ({target[0]:.6g}, {target[1]:.6g}) m lies "
                    f"{along:.6g} m from its spread axis along its closing line, beyond its "
                    f"reach [{low:.6g}, {high:.6g}] m (hand at {self.pose.centre}, yaw "
                    f"{self.pose.yaw:.6g} rad)")
            q = 0.0 if along >= high else turning if along <= low else float(
                brentq(lambda x: self.rho(x) - along, 0.0, turning, xtol=1e-15, rtol=1e-15))
            joints[finger.proximal], joints[finger.distal] = q, self.coupling * q
            reached = self.base(finger) + self.rho(q) * np.array([np.cos(angle), np.sin(angle)])
            error = float(np.hypot(*(self.pose.to_object(reached) - target)))
            if error > tolerance:
                raise ReachError(
                    f"{finger.value}: target ({target[0]:.6g}, {target[1]:.6g}) m is "
                    f"{error:.3g} m off its closing line at spread {spread_k:.6g} rad (its "
                    f"reach: the line through its spread axis, [{low:.6g}, {high:.6g}] m "
                    f"along it; tolerance {tolerance:g} m)")
            residual = max(residual, error)
        return HandSolution(joints, residual)

    def _spread(self, finger: BarrettFinger, target: np.ndarray) -> float:
        """The spread that puts ``target`` on the line of ``finger`` (1 or 2), in [0, pi]:
        the target ahead of the spread axis (rho > 0) if that spread is in range, else behind.
        """
        d = self.pose.to_palm(target) - self.base(finger)
        heading = float(np.arctan2(d[1], d[0]))
        sign = -1.0 if finger is BarrettFinger.F1 else 1.0
        for candidate in (heading, heading + np.pi):      # ahead, then behind the axis
            spread = float(np.mod(sign * (candidate + np.pi / 2), 2 * np.pi))   # [0, 2 pi)
            if spread <= self.spread_max + 1e-12:
                return min(spread, self.spread_max)
            if spread >= 2 * np.pi - 1e-12:
                return 0.0
        raise ReachError(f"{finger.value}: no spread in [0, {self.spread_max:.6g}] rad points "
                         f"its closing line at ({target[0]:.6g}, {target[1]:.6g}) m")
