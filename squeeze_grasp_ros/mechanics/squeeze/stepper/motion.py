# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The fingertips of one stepper call: where they are at s, and their shape.

Within a call finger f moves from c_f to c_f + s d_f, s in [0, 1]. The tips are rigid circles
or flat pads with rounded edges (:mod:`..tip_shapes`); their shape enters the stepper only
through :meth:`FingerMotion.gaps`, :meth:`FingerMotion.gap_slopes` and
:meth:`FingerMotion.touch_angle` (and the fixed-set solve's
:class:`~..contact_model.Configuration`). Dimensionless (lengths / L).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, tip_geometry
from squeeze_grasp_ros.mechanics.squeeze.kept import kept_property
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry

__all__ = ["ContactTips", "FingerMotion"]

CONTACT_TIPS_KEPT = 16
"""Contact sets' finger arrays whose :class:`ContactTips` a motion keeps (a call has a few)."""


@dataclass(frozen=True)
class ContactTips:
    """The motion's per-finger data taken at a contact set's finger indices (m contacts).

    Attributes
    ----------
    tip : TipGeometry
        Each contact's tip (m), lengths / L.
    start, translation : (m, 2) ndarray
        Each contact's finger's start and translation, / L.
    masks : tuple of (m,) ndarray of bool
        Per finger of the motion, its contacts.
    present : tuple of bool
        Per finger, whether it has contacts.
    """

    tip: TipGeometry
    start: np.ndarray
    translation: np.ndarray
    masks: tuple[np.ndarray, ...]
    present: tuple[bool, ...]


@dataclass(frozen=True)
class FingerMotion:
    """Straight finger paths of one call and the tips that follow them.

    Attributes
    ----------
    names : tuple of str
        Finger names, in the state's order (a finger index is a position here).
    start : (f, 2) ndarray
        Tip reference points (a circle's centre) at s = 0, / L.
    translation : (f, 2) ndarray
        Translation of each finger over the call, / L.
    radius : (f,) ndarray
        Tip radii (a pad's edge radius) / L.
    rate : float
        Length of the stacked translation (depth per unit s, / L).
    depth0 : float
        Depth at s = 0, m.
    length : float
        The object size L, m.
    flat : (f,) ndarray or None
        Half widths of the tips' flat faces / L (None: circles).
    facing : (f,) ndarray or None
        Angles of the tips' facing directions, rad (None: 0).
    """

    names: tuple[str, ...]
    start: np.ndarray
    translation: np.ndarray
    radius: np.ndarray
    rate: float
    depth0: float
    length: float
    flat: np.ndarray | None = None
    facing: np.ndarray | None = None

    @cached_property
    def tip(self) -> TipGeometry:
        """The tips (f), lengths / L."""
        zeros = np.zeros(len(self.radius))
        return TipGeometry(self.radius, zeros if self.flat is None else self.flat,
                           zeros if self.facing is None else self.facing)

    @kept_property
    def _contact_tips(self) -> dict[bytes, ContactTips]:
        return {}

    def contact_tips(self, finger: np.ndarray) -> ContactTips:
        """The :class:`ContactTips` of the contacts on fingers ``finger`` (a contact set's
        finger indices, int), kept by their values for the call (the sets of the call with
        as many contacts on each finger share them): the fixed-set solves, the reads of the
        event functions, the work and the samples read them at every point.
        """
        tag = finger.tobytes()
        made = self._contact_tips.get(tag)
        if made is None:
            if len(self._contact_tips) >= CONTACT_TIPS_KEPT:
                self._contact_tips.clear()
            made = self._contact_tips[tag] = self._tips_of(finger)
        return made

    def _tips_of(self, finger: np.ndarray) -> ContactTips:
        masks = tuple(finger == f for f in range(len(self.names)))
        return ContactTips(self.tip.take(finger), self.start[finger], self.translation[finger],
                           masks, tuple(bool(mine.any()) for mine in masks))

    @classmethod
    def of(cls, state: ContactState, translations: Mapping[str, tuple[float, float]],
           length: float) -> FingerMotion:
        """The motion of ``state``'s fingers by ``translations`` (name -> (dx, dy), m; fingers
        not named stay still).
        """
        names = tuple(f.name for f in state.fingers)
        unknown = sorted(set(translations) - set(names))
        if unknown:
            raise InvalidInputError(
                f"translation given for unknown finger {unknown[0]!r} (state has {list(names)})"
            )
        D = np.array([translations.get(n, (0.0, 0.0)) for n in names], float) / length
        require_finite("finger translations", D)
        tip = tip_geometry(state.fingers).scaled(length)
        return cls(names, np.array([f.center for f in state.fingers], float) / length, D,
                   tip.radius, float(np.linalg.norm(D)), state.depth, length, tip.flat,
                   tip.facing)

    def centers(self, s: float) -> np.ndarray:
        """Tip centres (f, 2) at s."""
        return self.start + s * self.translation

    def depth_at(self, s: float) -> float:
        """Depth (m) at s."""
        return self.depth0 + s * self.rate * self.length

    def gaps(self, points: np.ndarray, s: float) -> np.ndarray:
        """Gaps (k, f) of ``points`` (k, 2) to every tip at s (negative: penetration)."""
        return self.tip.gaps(points, self.centers(s))

    def gap_slopes(self, points: np.ndarray, velocities: np.ndarray, s: float) -> np.ndarray:
        """d/ds (k, f) of the gaps of ``points`` (k, 2) that move with ``velocities`` (d/ds)."""
        return self.tip.gap_slopes(points, velocities, self.centers(s), self.translation)

    def touch_angle(self, point: np.ndarray, finger: int, s: float, near: float | None) -> float:
        """Contact coordinate (rad; a circle's polar angle) of ``point`` on tip ``finger`` at
        s, its normal within pi of ``near``'s (the mean coordinate of the finger's other
        contacts, so a segment stays unwrapped; default the tip's facing direction).
        """
        rel = point - (self.start[finger] + s * self.translation[finger])
        return self.tip.coordinate(rel, finger, near)
