# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor's logic: a grasp goal -> rate-limited fingertip setpoints, one observation at a
time.

A goal is a squeeze (each squeezing finger f moves along d_f per unit depth rho, to depth rho*)
and optionally a resistance (the adversary moves by a along a straight line while the squeezing
fingers follow piecewise-linear waypoints in the adversary's travel). Each phase is a path
p_f(s) in a progress variable s (depth, or the adversary's travel). Every control cycle the
progress speed v follows an online trapezoid: v <- min(v + a_s dt, v_s, v_b(s* - s)) with
v_s = v_max / g and a_s = a_max / g, where g = max over fingers and segments of |dp_f/ds|, and
v_b(R) the largest speed from which the remaining progress R can still be covered exactly while
slowing by at most a_s dt per cycle (:func:`braking_speed`); so no fingertip exceeds
``max_velocity`` (m/s) or ``max_acceleration`` (m/s^2), also in discrete time, and the last step
lands exactly on the end. A phase ends when the progress is at its end and every moving
fingertip is measured within ``position_tolerance`` of its setpoint (devices may lag).

Reactions (checked in this order every cycle):

1. cancel -> hold the measured positions, end ``canceled``;
2. ``picked_up`` event -> hold, end ``picked_up``; ``contact_lost`` alarm of a moving finger ->
   hold, end ``contact_lost``;
3. ``slip_imminent`` alarm of a squeezing finger -> with ``on_slip_alarm`` = "hold": hold, end
   ``slip_alarm``; with "pure" / "normals": once, continue the remaining depth from the current
   setpoints along the pure-squeeze directions / along each finger's measured contact normal
   (scaled so the stacked direction has unit norm), ignoring the alarm for ``redirect_grace``
   cycles; an alarm after that ends the goal as with "hold"; with "resqueeze": release and
   squeeze again (below), at most ``max_attempts`` squeezes in all, then as with "hold". In the
   resistance phase an alarm of the adversary ends it successfully (the adversary slips, as in
   Algorithm 2);
4. ``stale_sensor`` alarm of a moving finger -> hold the current setpoints (v = 0) until fresh.

**Re-squeeze** ("resqueeze"). At the alarm the squeeze's measured depth rho_s is noted (the
monitor's depth less its depth when the current squeeze passed first contact). The squeezing
fingers then open along straight lines to their *release positions* x0_f - c d_f / g (x0_f the
first-contact position, where the goal started; c = ``release_clearance``; g = max_f |d_f|, so
the finger with the longest direction opens c past first contact and the others in
proportion). The phase ends when they are there and the monitor has reported every squeezing
finger free (a ``contact_lost`` alarm since the release began); if that does not come within
``stale_budget`` of reaching the release positions the goal ends ``slip_alarm``. The next squeeze
runs the same placement and directions from the release positions, through first contact, to
the depth (1 - ``resqueeze_margin``) rho_s: the depth the plan reached with the slip measured
``resqueeze_margin`` short of it. During the release ``slip_imminent`` and ``contact_lost``
are ignored; in a re-squeeze a finger's ``contact_lost`` counts only after the monitor has seen
it loaded again (a cycle with a non-zero force and no such alarm), since the approach to first
contact is free by design.

**The lift** (``lift_watch`` > 0). A ``picked_up`` event (friction carries the weight) does not
end the goal at once: the fingers hold their measured positions while the lab's arm lifts, and
the goal watches the monitor for ``lift_watch`` s. Without alarm it then ends ``picked_up``.
A ``weight_slip`` alarm (friction no longer carries the weight) is a slip alarm under weight:
with "resqueeze" (attempts left) the fingers release as above and squeeze again *deeper*, to
(1 + ``resqueeze_margin``) times the depth measured at the alarm (a larger jaw force carries
more weight; a shallower squeeze could not), ignoring ``picked_up`` on the way, and at that
depth hold and watch the lift again; else the goal ends ``slip_alarm`` (every other reaction
holds: a redirection cannot add force). A ``contact_lost`` alarm without it ends the goal
``contact_lost``.

Fingers the goal does not move hold the positions measured at the start. Work is integrated
from measurements: W_f += (F_prev + F_cur)/2 . (x_cur - x_prev), forces of the finger on the
object (N), positions in m; a re-squeeze starts it again from zero (the work of the last
squeeze).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from squeeze_grasp_ros.inputs import shown
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_relative_depth
from squeeze_grasp_ros.mechanics.vocabulary import AlarmType, Finger, SqueezeKind, Termination

RESQUEEZE = "resqueeze"
"""The reaction that releases and squeezes again (``ExecuteGrasp.Goal.REACT_RESQUEEZE``)."""
REACTIONS: tuple[str, ...] = ("hold", SqueezeKind.PURE.value, "normals", RESQUEEZE)
DEFAULT_ATTEMPTS = 2
"""Squeezes in all, the first included, of a "resqueeze" goal that gives none."""
DEFAULT_MARGIN = 0.25
"""Fraction of the alarm depth a re-squeeze stays below, when the goal gives none."""
DEFAULT_CLEARANCE = 0.002
"""How far a released finger opens past first contact (m), when the goal gives none: 2 mm,
clear of the object at rest for the shipped pads and circles while a gripper opens in 0.2 s at
the default ``max_velocity``."""
MAX_TRAVEL = 10.0
"""m: the longest fingertip travel a goal may ask for (its depth times its longest direction or
pure direction, the adversary's translation, a resistance waypoint, the release clearance).
Before, a depth of 1e308 m was accepted and its first control cycle overflowed the motion
profile ("OverflowError: cannot convert float infinity to integer"), which ended the executor
process."""
_NO_FORCE = np.zeros(2)
_NO_FORCE.flags.writeable = False
"""A finger's force while it has no reading (N; one array, not one per tick)."""
STILL = 1e-4
"""m: a finger measured within this of where it stood counts as standing still (the stall
watch; less at a low ``max_velocity``: :meth:`MotionLimits.still_distance`)."""


def _distance(a: Sequence[float], b: Sequence[float]) -> float:
    """|a - b| of two planar points, m (scalar arithmetic: cheaper than numpy on 2-vectors)."""
    return math.hypot(float(a[0]) - float(b[0]), float(a[1]) - float(b[1]))


@dataclass(frozen=True)
class MotionLimits:
    """Limits and tolerances of the executor.

    Attributes
    ----------
    max_velocity : float
        Largest fingertip speed, m/s.
    max_acceleration : float
        Largest fingertip acceleration, m/s^2.
    position_tolerance : float
        A phase ends when every moving tip is measured this close to its setpoint, m.
    redirect_grace : int
        Cycles after a redirection during which the slip alarm is ignored.
    stale_budget : float
        Longest uninterrupted hold for stale sensor data, s of (sim) time; past it the goal
        ends ``stale_data`` holding position.
    lift_watch : float
        After ``picked_up``, how long the fingers hold watching for ``weight_slip`` before the
        goal ends ``picked_up``, s (0: it ends at ``picked_up``).
    stall_timeout : float
        Longest the moving fingers may stand still short of their setpoints, s of (sim) time;
        past it the goal ends ``gripper_stalled`` holding the measured positions (0: no limit).
        Standing still: no moving finger measured more than :func:`still_distance` from where
        it stood when the watch began.
    """

    max_velocity: float = 0.01
    max_acceleration: float = 0.1
    position_tolerance: float = 1e-7
    redirect_grace: int = 20
    stale_budget: float = 0.1
    lift_watch: float = 0.0
    stall_timeout: float = 0.0

    def still_distance(self) -> float:
        """How far a finger may move and still stand still for the stall watch, m: 0.1 mm, or
        a tenth of what ``max_velocity`` covers in ``stall_timeout`` if that is less.
        """
        return min(STILL, 0.1 * self.max_velocity * self.stall_timeout)


@dataclass(frozen=True)
class GraspGoal:
    """A squeeze and an optional resistance (object frame, SI).

    Attributes
    ----------
    fingers : tuple of str
        Squeezing fingers.
    directions : (f, 2) ndarray
        Translation of each squeezing finger per unit depth, m/m.
    depth : float
        Squeeze depth to reach, m.
    relative_per_depth : float
        1/m, for reports.
    on_slip_alarm : {"hold", "pure", "normals", "resqueeze"}
    pure_directions : (f, 2) ndarray or None
        For "pure".
    max_attempts : int
        For "resqueeze": squeezes in all, the first included (>= 1).
    resqueeze_margin : float
        For "resqueeze": a re-squeeze's depth is (1 - margin) times the measured depth of the
        alarm, in (0, 1).
    release_clearance : float
        For "resqueeze": how far the fingers open past first contact, m (> 0; see the module).
    adversary : str
        Adversary finger of the resistance ("" = no resistance).
    adversary_translation : (2,) ndarray
        Total translation a of the adversary, m.
    resist_travel : (k,) ndarray
        Adversary travel at each waypoint, m, increasing, last = |a|.
    resist_waypoints : (k, f, 2) ndarray
        Translation of each squeezing finger since the resistance start at each waypoint, m.
    """

    fingers: tuple[str, ...]
    directions: np.ndarray
    depth: float
    relative_per_depth: float = 0.0
    on_slip_alarm: str = "hold"
    pure_directions: np.ndarray | None = None
    max_attempts: int = DEFAULT_ATTEMPTS
    resqueeze_margin: float = DEFAULT_MARGIN
    release_clearance: float = DEFAULT_CLEARANCE
    adversary: str = ""
    adversary_translation: np.ndarray = field(default_factory=lambda: np.zeros(2))
    resist_travel: np.ndarray = field(default_factory=lambda: np.zeros(0))
    resist_waypoints: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 2)))

    @property
    def resist(self) -> bool:
        """True if the goal has a resistance phase."""
        return bool(self.adversary)


def _longest_travel(depth: float, directions: np.ndarray) -> float:
    """The longest fingertip travel (m) of ``depth`` along ``directions`` (m/m)."""
    return float(depth * np.max(np.hypot(directions[:, 0], directions[:, 1])))


def goal_problem(goal: GraspGoal, known: Sequence[str]) -> str | None:
    """Why ``goal`` cannot be executed with fingers ``known``, or None if it can."""
    f = len(goal.fingers)
    if f == 0 or len(set(goal.fingers)) != f:
        return "fingers must be non-empty and distinct"
    unknown = sorted(set(goal.fingers) - set(known))
    if unknown:
        return f"finger {shown(unknown[0])} is not mapped to a device (known: {sorted(known)})"
    if goal.directions.shape != (f, 2) or not np.all(np.isfinite(goal.directions)):
        return f"directions must be {f} finite vectors"
    if not np.any(goal.directions):
        return "directions are all zero"
    if not (np.isfinite(goal.depth) and goal.depth >= 0):
        return f"depth must be finite and >= 0, got {goal.depth}"
    travel = _longest_travel(goal.depth, goal.directions)
    if not travel <= MAX_TRAVEL:
        return (f"depth times the longest direction must be at most {MAX_TRAVEL:g} m of "
                f"fingertip travel, got {travel:.6g} m (depth {goal.depth:.6g} m)")
    if not (np.isfinite(goal.relative_per_depth) and goal.relative_per_depth >= 0):
        return f"relative_per_depth must be finite and >= 0 (1/m), got {goal.relative_per_depth}"
    try:  # the fingers would meet or cross (0: the goal gives no finger distance to check)
        require_relative_depth(goal.depth * goal.relative_per_depth, goal.depth)
    except InvalidInputError as exc:
        return str(exc)
    if goal.on_slip_alarm not in REACTIONS:
        return f"on_slip_alarm must be one of {REACTIONS}, got {shown(goal.on_slip_alarm)}"
    if goal.on_slip_alarm == SqueezeKind.PURE and (
        goal.pure_directions is None
        or goal.pure_directions.shape != (f, 2)
        or not np.all(np.isfinite(goal.pure_directions))
        or not np.any(goal.pure_directions)
        or not _longest_travel(goal.depth, goal.pure_directions) <= MAX_TRAVEL
    ):
        return (f"on_slip_alarm 'pure' needs {f} finite, not all zero pure_directions, at most "
                f"{MAX_TRAVEL:g} m of fingertip travel at the goal's depth")
    if goal.on_slip_alarm == RESQUEEZE:
        if not goal.max_attempts >= 1:
            return f"max_attempts must be >= 1, got {goal.max_attempts}"
        if not 0.0 < goal.resqueeze_margin < 1.0:
            return f"resqueeze_margin must be in (0, 1), got {goal.resqueeze_margin}"
        if not 0.0 < goal.release_clearance <= MAX_TRAVEL:
            return (f"release_clearance must be in (0, {MAX_TRAVEL:g}] m, got "
                    f"{goal.release_clearance}")
        if goal.resist:
            return ("on_slip_alarm 'resqueeze' cannot be combined with a resistance: its "
                    "waypoints are planned for the goal's depth, not a re-squeeze's")
    if goal.resist:
        return _resistance_problem(goal, known)
    return None


def _resistance_problem(goal: GraspGoal, known: Sequence[str]) -> str | None:
    f = len(goal.fingers)
    if goal.adversary not in known or goal.adversary in goal.fingers:
        return (f"adversary {shown(goal.adversary)} must be a mapped finger other than the "
                "squeezing ones")
    a = goal.adversary_translation
    travel = goal.resist_travel
    k = len(travel)
    if a.shape != (2,) or not 0 < np.hypot(*a) <= MAX_TRAVEL:
        return f"adversary_translation must be a nonzero vector of at most {MAX_TRAVEL:g} m"
    if (
        k == 0
        or np.any(np.diff(travel) <= 0)
        or travel[0] <= 0
        or not np.isclose(travel[-1], np.hypot(*a), rtol=1e-9, atol=0.0)
    ):
        return "resist_travel must increase from > 0 to |adversary_translation|"
    if goal.resist_waypoints.shape != (k, f, 2) or not np.all(
            np.abs(goal.resist_waypoints) <= MAX_TRAVEL):
        return f"resist_waypoints must hold {k} x {f} vectors of at most {MAX_TRAVEL:g} m"
    return None


class Observation(NamedTuple):
    """What the executor knows at a control cycle (the monitor's status; object frame, SI; a
    named tuple: one is built per cycle).

    Attributes
    ----------
    stamp_ns : int
    positions, forces, normals : mapping of str to (2,) ndarray
        Measured tip centres (m), forces on the object (N), unit contact normals.
    alarms : tuple of (str, str)
        Active (type, finger) alarms.
    events : tuple of str
        Types of the events detected at this cycle.
    depth : float
        Measured depth, m.
    """

    stamp_ns: int
    positions: Mapping[str, np.ndarray]
    forces: Mapping[str, np.ndarray]
    normals: Mapping[str, np.ndarray]
    alarms: tuple[tuple[str, str], ...] = ()
    events: tuple[str, ...] = ()
    depth: float = 0.0


@dataclass(frozen=True)
class Command:
    """The executor's output for one cycle.

    Attributes
    ----------
    setpoints : dict of str to (2,) ndarray
        Tip-centre setpoint of every finger, m, object frame.
    state : str
        ExecutorStatus state ("squeezing", "resisting", "holding").
    termination : str or None
        Set on the last cycle of the goal.
    message : str
    """

    setpoints: Mapping[Finger, np.ndarray]
    state: str
    termination: str | None = None
    message: str = ""


def braking_speed(remaining: float, accel: float, dt: float) -> float:
    """Largest speed v for this cycle after which ``remaining`` progress can still be covered
    exactly, slowing by at most ``accel * dt`` per cycle.

    With m later cycles, each slower by accel dt, the progress covered from speed v is
    g(v) = dt ((m + 1) v - accel dt m (m + 1) / 2) for v in (m accel dt, (m + 1) accel dt];
    g is continuous and increasing, and v_b = g^-1(remaining).
    """
    if remaining <= 0.0:
        return 0.0
    x = remaining / (accel * dt * dt)
    m = max(int(np.ceil((np.sqrt(1.0 + 8.0 * x) - 1.0) / 2.0)) - 1, 0)
    return (remaining / dt + accel * dt * m * (m + 1) / 2.0) / (m + 1)


@dataclass(frozen=True)
class PolylinePath:
    """p_f(s) = start_f + piecewise-linear offsets through knots (s_k, offsets_k)."""

    knots: np.ndarray  # (K+1,), s_0 = 0
    offsets: np.ndarray  # (K+1, f, 2)
    start: np.ndarray  # (f, 2)

    @property
    def end(self) -> float:
        """Progress at the end of the path."""
        return float(self.knots[-1])

    @cached_property
    def gain(self) -> float:
        """Largest fingertip speed per unit progress speed, max |dp_f/ds|."""
        if self.end == 0.0:
            return 1.0
        slopes = np.diff(self.offsets, axis=0) / np.diff(self.knots)[:, None, None]
        return max(float(np.linalg.norm(slopes, axis=2).max()), 1e-300)

    def at(self, s: float) -> np.ndarray:
        """Positions (f, 2) at progress s."""
        if self.end == 0.0:
            return self.start.copy()
        k = min(max(int(self.knots.searchsorted(s, side="right")) - 1, 0), len(self.knots) - 2)
        w = (s - self.knots[k]) / (self.knots[k + 1] - self.knots[k])
        return self.start + self.offsets[k] + w * (self.offsets[k + 1] - self.offsets[k])


def straight_path(start: np.ndarray, directions: np.ndarray, length: float) -> PolylinePath:
    """Every finger from ``start`` (f, 2) along ``directions`` (f, 2) per unit s, s in [0,
    length].
    """
    return PolylinePath(
        np.array([0.0, length]), np.stack([np.zeros_like(directions), directions * length]), start
    )


class GraspProgram:
    """Online execution of one :class:`GraspGoal`.

    Parameters
    ----------
    goal : GraspGoal
        A goal for which :func:`goal_problem` returned None.
    limits : MotionLimits
    fingers : sequence of str
        Every finger with a device; those the goal does not move hold still.
    """

    def __init__(self, goal: GraspGoal, limits: MotionLimits, fingers: Sequence[str]) -> None:
        self.goal = goal
        self.limits = limits
        self.fingers = tuple(fingers)
        self.phase = "squeeze"
        self.moving: tuple[str, ...] = goal.fingers
        self.path: PolylinePath | None = None
        self.s = 0.0
        self.v = 0.0
        self.commanded: dict[str, np.ndarray] = {}
        self.redirected = False
        self.grace = 0
        self.hold_ticks = 0
        self.stale_time = 0.0
        self.still: dict[str, np.ndarray] | None = None
        """Where the moving fingers stood when the stall watch began (None: not watching)."""
        self.still_time = 0.0
        self.ticks = 0
        self.cancel_requested = False
        self.work = {f: 0.0 for f in self.fingers}
        self._last: Observation | None = None
        self.attempts = 1
        """Squeezes started (re-squeezes after slip alarms included)."""
        self.planned_depth = goal.depth
        """Depth the current squeeze aims at, m."""
        self.first_contact: np.ndarray | None = None
        """(f, 2) positions of the squeezing fingers at the goal's start, m."""
        self.depth_offset = 0.0
        """The monitor's depth when the current squeeze passed first contact, m."""
        self.approaching = False
        """A re-squeeze has not yet passed first contact."""
        self.armed = set(goal.fingers)
        """Fingers whose ``contact_lost`` alarm counts (see the module)."""
        self.freed: set[str] = set()
        self.release_wait = 0.0
        self.lift_time = 0.0
        """Time held since the lift began, s."""
        self.under_weight = False
        """The current squeeze follows a weight slip: it ignores ``picked_up`` and lifts at its
        depth."""

    def depth(self, obs: Observation) -> float:
        """The current squeeze's measured depth (m): the monitor's depth past this squeeze's
        first contact; while releasing, and while a re-squeeze approaches, the fingers' travel
        past their first-contact positions along the squeeze directions, negative while open.
        """
        if self.phase != "release" and not self.approaching:
            return obs.depth - self.depth_offset
        return self._travel(obs)

    def _travel(self, obs: Observation) -> float:
        """The fingers' travel past their first-contact positions (m, the length of all their
        displacements together), negative when it is against the squeeze directions.
        """
        past = np.array([obs.positions[f] for f in self.goal.fingers]) - self.first_contact
        travel = float(np.linalg.norm(past))
        return travel if float(np.sum(past * np.asarray(self.goal.directions, float))) >= 0.0 \
            else -travel

    def cancel(self) -> None:
        """Request a cancel: the next cycle holds the measured positions and ends the goal."""
        self.cancel_requested = True

    # ----------------------------------------------------------------- the cycle
    def step(self, obs: Observation, dt: float) -> Command:
        """One control cycle of ``dt`` s from observation ``obs``."""
        self.ticks += 1
        self._integrate_work(obs)
        if self.path is None:
            self.commanded = {f: np.asarray(obs.positions[f], float) for f in self.fingers}
            self._start_squeeze(self.goal.directions)
            self.first_contact = self.path.start.copy()
        if self.phase == "release":
            return self._release_step(obs, dt)
        if self.phase == "lift":
            return self._lift_step(obs, dt)
        if self.attempts > 1:
            self._approach(obs)
        terminal = self._terminal(obs)
        if terminal is not None:
            return terminal
        alarmed = {finger for kind, finger in obs.alarms if kind == AlarmType.SLIP_IMMINENT}
        if self.grace > 0:
            self.grace -= 1
        elif self.phase == "resist" and self.goal.adversary in alarmed:
            return self._finish(obs, "resisted", "the adversary slips", measured=True)
        elif alarmed & set(self.goal.fingers):
            if (self.goal.on_slip_alarm == RESQUEEZE and self.phase == "squeeze"
                    and self.attempts < self.goal.max_attempts):
                return self._release(obs, dt)
            if self.goal.on_slip_alarm in ("hold", RESQUEEZE) or self.redirected \
                    or self.phase != "squeeze":
                return self._finish(
                    obs,
                    "slip_alarm",
                    "imminent slip of " + ", ".join(sorted(alarmed & set(self.goal.fingers))),
                    measured=True,
                )
            self._redirect(obs)
        stale = {finger for kind, finger in obs.alarms if kind == AlarmType.STALE_SENSOR}
        if stale & set(self.moving):
            self.v = 0.0
            self.hold_ticks += 1
            self.stale_time += dt
            if self.stale_time > self.limits.stale_budget:
                return self._finish(
                    obs,
                    "stale_data",
                    f"sensor data of "
                    f"{', '.join(sorted(stale & set(self.moving)))} stale for "
                    f"{self.stale_time:.3f} s (stale_budget "
                    f"{self.limits.stale_budget} s)",
                )
            return Command(
                self._setpoints(),
                "holding",
                None,
                "stale sensor data: " + ", ".join(sorted(stale & set(self.moving))),
            )
        self.stale_time = 0.0
        stalled = self._stalled(obs, dt)
        if stalled is not None:
            return self._finish(obs, "gripper_stalled", stalled, measured=True)
        if self.s >= self.path.end and self._settled(obs):
            done = self._phase_done(obs)
            if done is not None:
                return done
        self._advance(dt)
        return Command(self._setpoints(), "squeezing" if self.phase == "squeeze" else "resisting")

    # ----------------------------------------------------------------- pieces
    def _terminal(self, obs: Observation) -> Command | None:
        if self.cancel_requested:
            return self._finish(obs, "canceled", "goal canceled", measured=True)
        if Termination.PICKED_UP in obs.events and self.phase == "squeeze" \
                and not self.under_weight:
            if self.limits.lift_watch > 0.0:
                return self.lift(obs)
            return self._finish(
                obs, Termination.PICKED_UP, "friction can lift the object", measured=True
            )
        lost = {finger for kind, finger in obs.alarms if kind == Termination.CONTACT_LOST} & set(
            self.moving
        ) & self.armed
        if lost:
            return self._finish(
                obs,
                Termination.CONTACT_LOST,
                "no contact on " + ", ".join(sorted(lost)),
                measured=True,
            )
        return None

    def _start_squeeze(self, directions: np.ndarray) -> None:
        start = np.array([self.commanded[f] for f in self.goal.fingers])
        self.path = straight_path(start, np.asarray(directions, float), self.goal.depth)
        self.s, self.v = 0.0, 0.0

    def _redirect(self, obs: Observation) -> None:
        """Continue the remaining depth along the pure directions or the contact normals."""
        goal = self.goal
        if goal.on_slip_alarm == SqueezeKind.PURE:
            directions = np.asarray(goal.pure_directions, float)
        else:
            old = self.path.offsets[-1] / max(self.path.end, 1e-300)
            directions = np.array(
                [
                    obs.normals[f] if np.any(obs.normals.get(f, 0.0)) else old[k]
                    for k, f in enumerate(goal.fingers)
                ],
                float,
            )
            directions /= np.linalg.norm(directions)
        remaining = self.path.end - self.s
        start = np.array([self.commanded[f] for f in goal.fingers])
        self.path = straight_path(start, directions, remaining)
        self.s, self.v = 0.0, 0.0
        self.redirected = True
        self.grace = self.limits.redirect_grace

    def _release(self, obs: Observation, dt: float, *, deeper: bool = False) -> Command:
        """A slip alarm to re-squeeze: note the depth, open toward the release positions (a
        weight slip, ``deeper``: to squeeze again deeper).
        """
        goal = self.goal
        sign = 1.0 if deeper else -1.0
        self.planned_depth = (1.0 + sign * goal.resqueeze_margin) * self.depth(obs)
        self.under_weight = deeper
        self.commanded = {f: np.asarray(obs.positions[f], float) for f in self.fingers}
        start = np.array([self.commanded[f] for f in goal.fingers])
        self.path = straight_path(start, self.release_positions() - start, 1.0)
        self.s, self.v = 0.0, 0.0
        self.phase, self.armed, self.release_wait = "release", set(), 0.0
        self.freed = {finger for kind, finger in obs.alarms
                      if kind == Termination.CONTACT_LOST} & set(goal.fingers)
        self._advance(dt)
        what = "slip under the weight" if deeper else "imminent slip"
        return Command(self._setpoints(), "releasing", None,
                       f"{what} at depth {self.depth(obs) * 1e3:.4g} mm: "
                       f"releasing to squeeze again to {self.planned_depth * 1e3:.4g} mm")

    def lift(self, obs: Observation) -> Command:
        """Picked up (or a squeeze under weight at its depth): hold the measured positions
        while the arm lifts (see the module).
        """
        self.commanded = {f: np.asarray(obs.positions[f], float) for f in self.fingers}
        self.phase, self.lift_time, self.v = "lift", 0.0, 0.0
        return Command(self._setpoints(), "holding", None,
                       f"picked up at depth {self.depth(obs) * 1e3:.4g} mm: holding while "
                       f"lifted, watching for a weight slip for {self.limits.lift_watch:g} s")

    def _lift_step(self, obs: Observation, dt: float) -> Command:
        """A cycle of the lift: a weight slip, a lost contact, or held long enough."""
        goal = self.goal
        if self.cancel_requested:
            return self._finish(obs, "canceled", "goal canceled", measured=True)
        alarms = set(obs.alarms)
        slipped = sorted(f for f in goal.fingers if (Termination.WEIGHT_SLIP, f) in alarms)
        if slipped:
            if goal.on_slip_alarm == RESQUEEZE and self.attempts < goal.max_attempts:
                return self._release(obs, dt, deeper=True)
            return self._finish(obs, "slip_alarm", "slip under the weight of "
                                + ", ".join(slipped), measured=True)
        lost = sorted(f for f in goal.fingers if (Termination.CONTACT_LOST, f) in alarms)
        if lost:
            return self._finish(obs, Termination.CONTACT_LOST, "no contact on "
                                + ", ".join(lost), measured=True)
        self.lift_time += dt
        if self.lift_time >= self.limits.lift_watch - 1e-12:
            return self._finish(obs, Termination.PICKED_UP,
                                f"friction carries the object's weight (held "
                                f"{self.lift_time:.4g} s after the pickup)")
        return Command(self._setpoints(), "holding")

    def release_positions(self) -> np.ndarray:
        """(f, 2) first-contact positions moved back by ``release_clearance`` (see the module),
        m, in the order of the goal's fingers.
        """
        directions = np.asarray(self.goal.directions, float)
        gain = float(np.linalg.norm(directions, axis=1).max())
        return self.first_contact - (self.goal.release_clearance / gain) * directions

    def _release_step(self, obs: Observation, dt: float) -> Command:
        """A cycle of the release: open, then squeeze again once every finger is free."""
        goal = self.goal
        if self.cancel_requested:
            return self._finish(obs, "canceled", "goal canceled", measured=True)
        self.freed |= {finger for kind, finger in obs.alarms
                       if kind == Termination.CONTACT_LOST} & set(goal.fingers)
        if self.s < self.path.end or not self._settled(obs):
            self._advance(dt)
            return Command(self._setpoints(), "releasing")
        if self.freed != set(goal.fingers):
            self.release_wait += dt
            if self.release_wait > self.limits.stale_budget:
                return self._finish(obs, "slip_alarm", "released for a re-squeeze, but the "
                                    "monitor reported no contact loss of " + ", ".join(
                                        sorted(set(goal.fingers) - self.freed))
                                    + f" within stale_budget {self.limits.stale_budget} s")
            return Command(self._setpoints(), "releasing")
        directions = np.asarray(goal.directions, float)
        gain = float(np.linalg.norm(directions, axis=1).max())
        start = np.array([self.commanded[f] for f in goal.fingers])
        self.path = straight_path(start, directions,
                                  goal.release_clearance / gain + self.planned_depth)
        self.s, self.v = 0.0, 0.0
        self.phase, self.attempts, self.approaching = "squeeze", self.attempts + 1, True
        self.work = {f: 0.0 for f in self.fingers}
        self._advance(dt)
        return Command(self._setpoints(), "squeezing")

    def _approach(self, obs: Observation) -> None:
        """In a re-squeeze: the depth offset at first contact, and which fingers are loaded."""
        goal = self.goal
        lost = {finger for kind, finger in obs.alarms if kind == Termination.CONTACT_LOST}
        self.armed |= {f for f in goal.fingers
                       if f not in lost and np.any(obs.forces.get(f, 0.0))}
        if not self.approaching:
            return
        travel = self._travel(obs)
        if travel >= 0.0:
            self.approaching = False
            self.depth_offset = obs.depth - travel

    def _stalled(self, obs: Observation, dt: float) -> str | None:
        """Why the moving fingers count as stalled after this cycle of ``dt`` s (standing
        still short of their setpoints for longer than ``stall_timeout``), or None (a few
        scalar distances a cycle: it runs at every control cycle).
        """
        timeout = self.limits.stall_timeout
        if not timeout:
            return None
        where, commanded = obs.positions, self.commanded
        tol = self.limits.position_tolerance
        short = [f for f in self.moving if _distance(where[f], commanded[f]) > tol]
        still = self.limits.still_distance()
        if not short or self.still is None or any(
                _distance(where[f], self.still[f]) > still for f in self.moving):
            # copies: an observation's arrays may be refilled in place for the next cycle
            self.still = {f: np.array(where[f], float) for f in self.moving} if short else None
            self.still_time = 0.0
            return None
        self.still_time += dt
        if self.still_time <= timeout:
            return None
        gaps = ", ".join(f"{f} {_distance(where[f], commanded[f]) * 1e3:.4g} mm" for f in short)
        return (f"{', '.join(short)} stood still (within {still * 1e3:.3g} mm) for "
                f"{self.still_time:.3f} s (stall_timeout {timeout:g} s) short of the setpoints "
                f"by {gaps}: a JointTrajectoryController that is loaded but not active drops "
                "every trajectory (ros2 control list_controllers shows its state), or the drive "
                "stalled")

    def _settled(self, obs: Observation) -> bool:
        tol = self.limits.position_tolerance
        return all(
            np.linalg.norm(np.asarray(obs.positions[f]) - self.commanded[f]) <= tol
            for f in self.moving
        )

    def _phase_done(self, obs: Observation) -> Command | None:
        if self.phase == "resist":
            return self._finish(obs, "resisted", "the adversary completed its translation")
        if self.under_weight:
            return self.lift(obs)
        if not self.goal.resist:
            return self._finish(obs, Termination.DEPTH_REACHED, "squeeze depth reached")
        goal = self.goal
        self.phase = "resist"
        self.moving = goal.fingers + (goal.adversary,)
        a = goal.adversary_translation
        knots = np.concatenate([[0.0], goal.resist_travel])
        unit_a = a / np.hypot(*a)
        adv = knots[:, None] * unit_a[None, :]
        offsets = np.concatenate(
            [
                np.concatenate([np.zeros((1, len(goal.fingers), 2)), goal.resist_waypoints]),
                adv[:, None, :],
            ],
            axis=1,
        )
        start = np.array([self.commanded[f] for f in self.moving])
        self.path = PolylinePath(knots, offsets, start)
        self.s, self.v = 0.0, 0.0
        return None

    def _advance(self, dt: float) -> None:
        path = self.path
        gain = path.gain
        speed = self.limits.max_velocity / gain
        accel = self.limits.max_acceleration / gain
        remaining = path.end - self.s
        if remaining <= 0.0:
            return
        self.v = min(self.v + accel * dt, speed, braking_speed(remaining, accel, dt))
        self.s = min(self.s + self.v * dt, path.end)
        for f, p in zip(self.moving, path.at(self.s)):
            self.commanded[f] = p

    def _setpoints(self) -> dict:
        return {f: self.commanded[f].copy() for f in self.fingers}

    def _finish(
        self, obs: Observation, termination: str, message: str, measured: bool = False
    ) -> Command:
        """End the goal holding the measured (or the commanded) positions."""
        if measured:
            self.commanded = {f: np.asarray(obs.positions[f], float) for f in self.fingers}
        self.phase = "done"
        return Command(self._setpoints(), "holding", termination, message)

    def _integrate_work(self, obs: Observation) -> None:
        last = self._last
        if last is not None:
            for f in self.fingers:
                if f in obs.positions and f in last.positions:
                    force = 0.5 * (
                        np.asarray(obs.forces.get(f, _NO_FORCE))
                        + np.asarray(last.forces.get(f, _NO_FORCE))
                    )
                    self.work[f] += float(
                        force @ (np.asarray(obs.positions[f]) - np.asarray(last.positions[f]))
                    )
        self._last = obs
