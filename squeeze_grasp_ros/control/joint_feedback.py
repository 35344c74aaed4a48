# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor on a gripper's joint feedback: jaw force and aperture from ``joint_states``.

A parallel gripper under ros2_control reports ``sensor_msgs/JointState`` (joint_state_broadcaster:
position and effort per joint). Without a wrench or tactile sensor on the jaws, that is all the
monitor sees, through the device's transmission (docs/grippers.md):

- the **aperture** a (m) from the joint positions, the **jaw force** F (N, each jaw's push along
  the closing line) from the joint efforts (:meth:`..scene.controller.JawController.reading`);
- the jaws' tip positions on the jaw line (fixed by the gripper's pose) follow from a, so the
  squeeze depth is the stepper's: both jaws close by (a0 - a) / 2, the stacked translation has
  length (a0 - a) / sqrt(2);
- what a scalar force cannot show: which nodes touch, stick or slide (events A-D need taxels),
  and the tangential force on the pad faces.

The **slip watch** (:class:`JointSlipWatch`) is designed from the squeeze's force-closing curve
F(c), c the aperture's closing since the first reading in contact. While the contacts hold,
closing on an elastic object loads it ever faster: the stiffness grows as contacts spread
(events A), so F(c) is convex and its tangent k_t = dF/dc never falls below the chord k_s from
the first reading in contact (the event squeeze's force curves show k_t / k_s between 1 and 1.5,
``test/test_joint_feedback.py``). When the object gives way between the jaws (a finger slips,
Sec. 5.1: its contact nodes all slide one way, the object turns or squirts out), closing no
longer loads it: F stops rising or drops. The watch raises ``slip_imminent`` for both jaws when,
over the last ``window`` m of closing, k_t < ``ratio`` k_s, the chord taken to the start of
that window (value: k_t / k_s, negative when F drops; judged once the jaws have closed two
windows). It is a detection, not a forecast: the finger slip of the paper's quasi-static model
has no precursor in F(c) (k_t / k_s rises toward it); the taxels' cone usage (the tracker's
alarm) is what sees a slip coming. With the planner's prediction, the force watch's
``force_mismatch`` is the other test: F(c) being increasing, "F below the predicted force at
this closing" is "the aperture below the predicted aperture at this force".

The **weight watch** (:class:`WeightWatch`) judges a lift: the object hangs between the pads, each
carrying half its weight w by friction, at most mu F: the grasp holds while 2 mu F >= w.

Contact: a jaw is in contact while F > ``contact_force``; its **first touch** is the aperture
of the last reading without contact (where F starts from zero); a jaw that had contact and has
none raises ``contact_lost``, as the tracker does on taxels.

>>> watch = JointSlipWatch(("F1", "F2"), contact_force=0.01, window=5e-5, ratio=0.5)
>>> readings = [(0.05, 0.0), (0.0499, 0.05), (0.0498, 0.1), (0.0497, 0.15), (0.0496, 0.2)]
>>> [watch.update(a, f) for a, f in readings]
[(), (), (), (), ()]
>>> watch.first_touch
0.05
>>> [alarm.type for alarm in watch.update(0.0495, 0.2)]  # closing, force stopped rising
['slip_imminent', 'slip_imminent']
"""
from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

from squeeze_grasp_ros.control.tracker import TrackedAlarm
from squeeze_grasp_ros.mechanics.vocabulary import AlarmType, Termination

__all__ = ["JointSlipWatch", "WeightWatch", "weight_problem"]

SLIP_IMMINENT = AlarmType.SLIP_IMMINENT
"""The alarm type the executor reacts to (``Alarm.SLIP_IMMINENT``)."""
DEFAULT_WEIGHT_MARGIN = 1.25
"""The weight watch's margin on the weight for ``picked_up`` (the planner's effort margin)."""


class JointSlipWatch:
    """Contact, first touch and slip of a parallel gripper from its aperture and jaw force.

    Parameters
    ----------
    jaws : sequence of str
        The fingers the jaws carry: every alarm is raised for each.
    contact_force : float
        A jaw is in contact above this force, N.
    window : float
        Closing over which the tangent stiffness is measured, m.
    ratio : float
        Tangent over secant stiffness below which ``slip_imminent`` is raised (< 1).
    """

    def __init__(self, jaws: Sequence[str], *, contact_force: float, window: float,
                 ratio: float) -> None:
        if not (contact_force >= 0 and window > 0 and 0 < ratio < 1):
            raise ValueError(f"joint slip watch: contact_force >= 0 N, window > 0 m and ratio in "
                             f"(0, 1) expected, got {contact_force}, {window}, {ratio}")
        self.jaws = tuple(jaws)
        self.contact_force, self.window, self.ratio = contact_force, window, ratio
        self.free: float | None = None
        """The aperture of the newest reading before first touch, m."""
        self.first_touch: float | None = None
        """The aperture at first touch, m (None before): of the last reading without contact
        (where the force starts from zero), or of the first reading if it already touches."""
        self.in_contact = False
        self.origin: tuple[float, float] | None = None
        """(aperture m, force N) of the first reading in contact: the secant's origin."""
        self.history: deque[tuple[float, float]] = deque()
        """(closing since first touch m, force N) of the recent ticks, oldest first."""

    def update(self, aperture: float, force: float) -> tuple[TrackedAlarm, ...]:
        """The alarms of one tick's reading (aperture m, jaw force N), for both jaws."""
        touching = force > self.contact_force
        if not touching and self.first_touch is None:
            self.free = aperture
        elif touching and self.first_touch is None:
            self.first_touch = aperture if self.free is None else self.free
        had, self.in_contact = self.in_contact, touching
        if had and not touching:
            self.history.clear()
            self.origin = None
            return self._alarms(Termination.CONTACT_LOST, force,
                                f"jaw force {force:.4g} N at or below the contact force "
                                f"{self.contact_force:g} N")
        if not touching:
            return ()
        if self.origin is None:
            self.origin = (aperture, force)
        closing = self.origin[0] - aperture
        history = self.history
        history.append((closing, force))
        while len(history) > 1 and closing - history[1][0] >= self.window:
            history.popleft()
        then_closing, then_force = history[0]
        if closing - then_closing < self.window or then_closing < self.window:
            return ()
        tangent = (force - then_force) / (closing - then_closing)
        secant = (then_force - self.origin[1]) / then_closing
        measured = float(tangent / secant)
        if measured >= self.ratio:
            return ()
        return self._alarms(SLIP_IMMINENT, measured,
                            f"the jaws closed {(closing - then_closing) * 1e3:.3g} mm while the "
                            f"jaw force went {then_force:.4g} -> {force:.4g} N: stiffness "
                            f"{measured:.3g} of the secant (slip below {self.ratio:g})")

    def _alarms(self, kind: str, value: float, message: str) -> tuple[TrackedAlarm, ...]:
        return tuple(TrackedAlarm(kind, jaw, value, f"{jaw}: {message}") for jaw in self.jaws)


def weight_problem(weight: float, *, mu: float, margin: float) -> str | None:
    """Why a weight watch cannot be built from ``weight`` (N), ``mu`` and ``margin``, or None.

    >>> weight_problem(float("nan"), mu=0.6, margin=1.25)
    'weight must be a finite number > 0 N (0: no pickup test), got nan'
    """
    if not (math.isfinite(weight) and weight > 0.0):
        return f"weight must be a finite number > 0 N (0: no pickup test), got {weight}"
    if not (math.isfinite(mu) and mu > 0.0):
        return f"mu must be a finite number > 0 to carry a weight by friction, got {mu}"
    if not (math.isfinite(margin) and margin >= 1.0):
        return f"weight_margin must be a finite number >= 1, got {margin}"
    return None


class WeightWatch:
    """Whether the jaw force carries the object's weight by friction on both pads.

    The object hangs between the two pads (closing line horizontal, gravity along the pad
    faces); each pad carries half its weight w by friction, at most mu F with F the jaw force.
    That is the stepper's pickup criterion (:func:`..mechanics.squeeze.stepper.functions.
    pickup_margin`: each finger supplies w / 2 of vertical friction, sum over its sticking
    nodes of sqrt(mu^2 f_n^2 - f_t^2)) with the pads' in-plane tangential forces f_t taken as
    zero: a scalar jaw force cannot show them, and they only lower the supply; ``margin``
    covers them.

    - ``picked_up`` (an event): the first reading with 2 mu F >= margin w;
    - ``weight_slip`` (an alarm for both jaws, active while it holds): after ``picked_up``,
      2 mu F < w: friction no longer carries the weight (the jaw force relaxed or was lowered,
      the object is heavier than the watch's w, or it slipped out of the jaws: F fell to the
      contact force). Its value is 2 mu F / w, the fraction of the weight friction carries.

    Once the jaws have lost contact after ``picked_up`` (the object is out of them), the watch
    starts again: the next grip is a new pickup.

    Parameters
    ----------
    jaws : sequence of str
        The fingers the jaws carry: the alarm is raised for each.
    mu : float
        The pads' friction coefficient (> 0).
    weight : float
        The object's weight w, N (> 0).
    margin : float
        Factor (>= 1) on w that the friction must carry for ``picked_up``.
    contact_force : float
        A jaw is in contact above this force, N.

    >>> watch = WeightWatch(("F1", "F2"), mu=0.5, weight=1.0, margin=1.25, contact_force=0.01)
    >>> watch.update(1.2), watch.update(1.3)[0]  # needs w / (2 mu) = 1 N, with the margin 1.25
    ((False, ()), True)
    >>> [a.type for a in watch.update(0.9)[1]]  # below w / (2 mu): the weight slips
    ['weight_slip', 'weight_slip']
    >>> watch.update(1.1)  # between w and margin w: held, no new event
    (False, ())
    """

    def __init__(self, jaws: Sequence[str], *, mu: float, weight: float,
                 margin: float = DEFAULT_WEIGHT_MARGIN, contact_force: float = 0.0) -> None:
        problem = weight_problem(weight, mu=mu, margin=margin)
        if problem is not None:
            raise ValueError(problem)
        self.jaws = tuple(jaws)
        self.mu, self.weight, self.margin = float(mu), float(weight), float(margin)
        self.contact_force = float(contact_force)
        self.need = self.weight / (2.0 * self.mu)
        """The jaw force that carries the weight, w / (2 mu), N."""
        self.picked_up = False
        """``picked_up`` was reported and the jaws have not lost contact since."""

    def update(self, force: float) -> tuple[bool, tuple[TrackedAlarm, ...]]:
        """(``picked_up`` at this reading, the alarms) of one reading of the jaw force (N)."""
        carried = 2.0 * self.mu * force / self.weight
        if not self.picked_up:
            self.picked_up = carried >= self.margin
            return self.picked_up, ()
        if force <= self.contact_force:
            self.picked_up = False
        if carried >= 1.0:
            return False, ()
        return False, tuple(TrackedAlarm(
            Termination.WEIGHT_SLIP, jaw, carried,
            f"{jaw}: jaw force {force:.4g} N below the {self.need:.4g} N that carries the weight "
            f"{self.weight:g} N by friction (mu {self.mu:g}): 2 mu F / w = {carried:.3g}")
            for jaw in self.jaws)
