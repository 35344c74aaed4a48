# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Jaw setpoints as joint trajectories, and a JointTrajectoryController's following of them.

Both sides of the stock ``joint_trajectory`` interface (docs/grippers.md) work on the jaw line:
the jaws close symmetrically along the line through their tips' reference points, so a pair of
fingertip setpoints is one aperture (the distance between the pad faces) and back.

:class:`TrajectoryFollower` is the simulated controller's core, with the semantics of
ros2_controllers' JointTrajectoryController (position interface, linear interpolation):

- a trajectory must name exactly the controller's joints (in any order), its points
  ``time_from_start`` strictly increasing, each point one finite position per joint; it starts
  at ``header.stamp`` (zero: on receipt);
- a new trajectory replaces the old one at receipt: when its first point lies ahead the
  command interpolates linearly from the measured position at receipt (the stock default; the
  command with ``interpolate_from_desired_state``) to that point; when it
  began in the past the command follows the trajectory's own segments from where it is at
  receipt (Jazzy's ``Trajectory::sample``); then between points, holding the last point; a
  trajectory that ends in the past is refused (a point at the time of receipt, as a zero stamp
  with ``time_from_start`` 0 gives, is taken at once);
- refusals leave the active trajectory untouched. Beyond the stock controller, this one also
  refuses positions whose aperture lies outside the gripper's opening range or whose joints
  disagree on the aperture (the joints of a parallel gripper move together).

>>> line = JawLine.between(np.array([0.0, -0.03]), np.array([0.0, 0.03]), reach=0.002)
>>> round(line.aperture(np.array([0.0, -0.025]), np.array([0.0, 0.025])), 12)
0.046
>>> follower = TrajectoryFollower(0.05, opening=(0.0, 0.085))
>>> follower.accept([(1_000_000, (0.04,))], now_ns=0, to_aperture=lambda p: p)
>>> follower.sample(500_000), follower.sample(1_000_000), follower.sample(9_000_000)
(0.045, 0.04, 0.04)
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["JawLine", "JointFollower", "TrajectoryFollower", "TrajectoryRefused"]

APERTURE_AGREEMENT = 1e-9
"""Largest spread of the apertures a trajectory point's joints stand for, m."""


class TrajectoryRefused(ValueError):
    """A trajectory the controller does not follow; the message says why."""


def checked_points(points: Sequence[tuple[int, Sequence[float]]]
                   ) -> list[tuple[int, np.ndarray]]:
    """``points`` (time ns, positions) with their positions as arrays, checked as every
    JointTrajectoryController checks them.

    Raises
    ------
    TrajectoryRefused
        No points, times not strictly increasing, non-finite positions.
    """
    if not points:
        raise TrajectoryRefused("it has no points")
    times = [t for t, _ in points]
    if any(b <= a for a, b in zip(times, times[1:])):
        raise TrajectoryRefused("its points' time_from_start are not strictly increasing")
    out = []
    for k, (t, positions) in enumerate(points):
        values = np.asarray(positions, float)
        if not np.all(np.isfinite(values)):
            raise TrajectoryRefused(f"point {k} has non-finite positions {values.tolist()}")
        out.append((int(t), values))
    return out


def replacing_knots(knots: list, now_ns: int, command) -> list:
    """The knots (time ns first) a JointTrajectoryController follows once it has taken the new
    trajectory ``knots`` at ``now_ns``, its command then ``command``, as Jazzy's
    ``Trajectory::sample`` does: from ``command`` at ``now_ns`` to the first point when that
    lies ahead; otherwise the message's own points (the command goes to where the trajectory is
    at ``now_ns``, between its points, and holds the last).

    Raises
    ------
    TrajectoryRefused
        The trajectory ends before ``now_ns`` (a point at ``now_ns`` is taken).
    """
    if knots[-1][0] < now_ns:
        raise TrajectoryRefused("it ends in the past (all its points lie in the past)")
    if knots[0][0] > now_ns:
        return [(int(now_ns), command)] + knots
    return knots


@dataclass(frozen=True)
class JawLine:
    """The line the two jaws close on.

    Attributes
    ----------
    centre : ndarray (2,)
        Midway between the jaws' tip reference points, m (object frame).
    direction : ndarray (2,)
        Unit closing direction of F1's jaw (from its tip toward the other's).
    reach : float
        Distance from a tip's reference point to its face along the line, m (a pad's edge
        radius, a circle's radius).
    """

    centre: np.ndarray
    direction: np.ndarray
    reach: float

    @classmethod
    def between(cls, first: np.ndarray, second: np.ndarray, *, reach: float) -> JawLine:
        """The line through the tip reference points ``first`` (F1's jaw) and ``second`` (m)."""
        first, second = np.asarray(first, float), np.asarray(second, float)
        gap = second - first
        length = float(np.hypot(*gap))
        if not length > 2.0 * reach:
            raise ValueError(f"the jaws' tips are {length:g} m apart: their faces overlap "
                             f"(reach {reach:g} m each)")
        return cls(0.5 * (first + second), gap / length, float(reach))

    @classmethod
    def at_pose(cls, centre: np.ndarray, yaw: float, *, reach: float) -> JawLine:
        """The line of a gripper whose centre (midway between the pad faces, m) is ``centre``
        and whose closing direction (F1's jaw's motion, the x axis of ``plan_gripper_grasp``'s
        pose) is at ``yaw`` (rad) from the object frame's x axis.
        """
        centre = np.asarray(centre, float)
        if not (centre.shape == (2,) and np.all(np.isfinite(centre)) and np.isfinite(yaw)):
            raise ValueError(f"the gripper's pose must be a finite centre (x, y) m and yaw rad, "
                             f"got {centre.tolist()}, {yaw}")
        return cls(centre, np.array([np.cos(yaw), np.sin(yaw)]), float(reach))

    def aperture(self, first: np.ndarray, second: np.ndarray) -> float:
        """The distance between the pad faces (m) of tips at ``first`` and ``second`` (m),
        measured along the line.
        """
        return float(np.dot(np.asarray(second, float) - first, self.direction)) - 2 * self.reach

    def positions(self, aperture: float) -> tuple[np.ndarray, np.ndarray]:
        """The tips' reference points (m) at ``aperture`` (m), symmetric about the centre."""
        half = 0.5 * float(aperture) + self.reach
        return self.centre - half * self.direction, self.centre + half * self.direction


class TrajectoryFollower:
    """A JointTrajectoryController's command for one parallel gripper, as an aperture (m).

    Parameters
    ----------
    aperture : float
        The commanded aperture before any trajectory (the jaws' initial aperture), m.
    opening : (float, float)
        The gripper's opening range (min, max), m.
    """

    def __init__(self, aperture: float, *, opening: tuple[float, float]) -> None:
        self.opening = (float(opening[0]), float(opening[1]))
        self.knots: list[tuple[int, float]] = [(0, float(aperture))]
        """(time ns, aperture m) of the active trajectory, its anchor first."""

    def sample(self, t_ns: int) -> float:
        """The commanded aperture (m) at sim time ``t_ns``: linear between knots, held after
        the last.
        """
        times = [t for t, _ in self.knots]
        values = [a for _, a in self.knots]
        if t_ns >= times[-1]:
            return values[-1]
        return float(np.interp(t_ns, times, values))

    def accept(self, points: Sequence[tuple[int, Sequence[float]]], *, now_ns: int,
               to_aperture: Callable[[float], float], measured: float | None = None) -> None:
        """Replace the active trajectory by ``points`` (absolute time ns, joint positions),
        at ``now_ns`` (:func:`replacing_knots`), starting from ``measured`` (the measured
        aperture at ``now_ns``, m: the stock controller's start, ``interpolate_from_desired_state``
        false, its default) or, when None, from the command (that parameter true).

        Raises
        ------
        TrajectoryRefused
            Saying why; the active trajectory is kept.
        """
        knots = []
        lo, hi = self.opening
        for k, (t, values) in enumerate(checked_points(points)):
            apertures = [to_aperture(v) for v in values]
            if max(apertures) - min(apertures) > APERTURE_AGREEMENT:
                raise TrajectoryRefused(f"point {k}'s joints stand for different apertures "
                                        f"{apertures} m (the jaws move together)")
            if not lo <= apertures[0] <= hi:
                raise TrajectoryRefused(f"point {k}'s aperture {apertures[0]:g} m is outside "
                                        f"the opening range [{lo:g}, {hi:g}] m")
            knots.append((t, float(np.mean(apertures))))
        start = self.sample(now_ns) if measured is None else float(measured)
        self.knots = replacing_knots(knots, now_ns, start)


class JointFollower:
    """A JointTrajectoryController's command for several independent joints (a hand), rad.

    The semantics of :class:`TrajectoryFollower` in joint space: linear interpolation of every
    joint between knots, the last knot held, a new trajectory replacing the old at receipt
    (:func:`replacing_knots`); refused: unordered times, non-finite positions, a position
    outside its joint's range, a trajectory that ends in the past.

    Parameters
    ----------
    positions : sequence of float
        The commanded joint positions before any trajectory (the hand's initial joints).
    limits : sequence of (float, float)
        Each joint's range (min, max).
    names : sequence of str
        The joints' names (for the refusals' messages).
    """

    def __init__(self, positions: Sequence[float], *, limits: Sequence[tuple[float, float]],
                 names: Sequence[str]) -> None:
        self.limits = np.asarray(limits, float)
        self.names = tuple(names)
        self.knots: list[tuple[int, np.ndarray]] = [(0, np.asarray(positions, float))]

    def sample(self, t_ns: int) -> np.ndarray:
        """The commanded joint positions at sim time ``t_ns``."""
        times = [t for t, _ in self.knots]
        if t_ns >= times[-1]:
            return self.knots[-1][1].copy()
        values = np.array([v for _, v in self.knots])
        return np.array([np.interp(t_ns, times, values[:, j]) for j in range(values.shape[1])])

    def accept(self, points: Sequence[tuple[int, Sequence[float]]], *, now_ns: int,
               measured: Sequence[float] | None = None) -> None:
        """Replace the active trajectory by ``points`` (absolute time ns, joint positions in
        the order of ``names``) at ``now_ns`` (:func:`replacing_knots`), starting from
        ``measured`` (the measured joint positions at ``now_ns``, rad: the stock controller's
        start, ``interpolate_from_desired_state`` false, its default) or, when None, from the
        command (that parameter true).

        Raises
        ------
        TrajectoryRefused
            Saying why; the active trajectory is kept.
        """
        knots = []
        for k, (t, values) in enumerate(checked_points(points)):
            outside = [f"{self.names[j]} {values[j]:g} (range [{lo:g}, {hi:g}])"
                       for j, (lo, hi) in enumerate(self.limits)
                       if not lo - 1e-12 <= values[j] <= hi + 1e-12]
            if outside:
                raise TrajectoryRefused(f"point {k} has positions outside the joint limits: "
                                        f"{', '.join(outside)} rad")
            knots.append((t, values))
        start = self.sample(now_ns) if measured is None else np.asarray(measured, float)
        self.knots = replacing_knots(knots, now_ns, start)
