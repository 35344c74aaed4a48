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

from collections import deque
from collections.abc import Sequence

from squeeze_grasp_ros.control.tracker import TrackedAlarm
from squeeze_grasp_ros.mechanics.vocabulary import Termination

__all__ = ["JointSlipWatch"]

SLIP_IMMINENT = "slip_imminent"
"""The alarm type the executor reacts to (``Alarm.SLIP_IMMINENT``)."""


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
