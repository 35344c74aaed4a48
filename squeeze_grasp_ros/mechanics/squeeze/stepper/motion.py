# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The fingertips of one stepper call: where they are at s, and their shape.

Within a call finger f moves from c_f to c_f + s d_f, s in [0, 1]. The tips are rigid circles;
their shape enters the stepper only through :meth:`FingerMotion.gaps`,
:meth:`FingerMotion.gap_slopes` and :meth:`FingerMotion.touch_angle` (and the fixed-set solve's
:class:`~..contact_model.Configuration`), so another tip shape replaces those.
Dimensionless (lengths / L).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState
from squeeze_grasp_ros.mechanics.squeeze.fingertips import tip_gaps

__all__ = ["FingerMotion"]


@dataclass(frozen=True)
class FingerMotion:
    """Straight finger paths of one call and the round tips that follow them.

    Attributes
    ----------
    names : tuple of str
        Finger names, in the state's order (a finger index is a position here).
    start : (f, 2) ndarray
        Tip centres at s = 0, / L.
    translation : (f, 2) ndarray
        Translation of each finger over the call, / L.
    radius : (f,) ndarray
        Tip radii / L.
    rate : float
        Length of the stacked translation (depth per unit s, / L).
    depth0 : float
        Depth at s = 0, m.
    length : float
        The object size L, m.
    """

    names: tuple[str, ...]
    start: np.ndarray
    translation: np.ndarray
    radius: np.ndarray
    rate: float
    depth0: float
    length: float

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
        return cls(names, np.array([f.center for f in state.fingers], float) / length, D,
                   np.array([f.radius for f in state.fingers], float) / length,
                   float(np.linalg.norm(D)), state.depth, length)

    def centers(self, s: float) -> np.ndarray:
        """Tip centres (f, 2) at s."""
        return self.start + s * self.translation

    def depth_at(self, s: float) -> float:
        """Depth (m) at s."""
        return self.depth0 + s * self.rate * self.length

    def gaps(self, points: np.ndarray, s: float) -> np.ndarray:
        """Gaps (k, f) of ``points`` (k, 2) to every tip at s (negative: penetration)."""
        return tip_gaps(points, self.centers(s), self.radius)

    def gap_slopes(self, points: np.ndarray, velocities: np.ndarray, s: float) -> np.ndarray:
        """d/ds (k, f) of the gaps of ``points`` (k, 2) that move with ``velocities`` (d/ds)."""
        rel = points[:, None, :] - self.centers(s)[None]
        rel_rate = velocities[:, None, :] - self.translation[None]
        return np.einsum("rfi,rfi->rf", rel, rel_rate) / np.linalg.norm(rel, axis=2)

    def touch_angle(self, point: np.ndarray, finger: int, s: float, near: float | None) -> float:
        """Polar angle (rad) of ``point`` about tip ``finger`` at s, taken within pi of
        ``near`` (the mean angle of the finger's other contacts, so a segment stays unwrapped).
        """
        rel = point - (self.start[finger] + s * self.translation[finger])
        theta = float(np.arctan2(rel[1], rel[0]))
        if near is None:
            return theta
        return near + float(np.angle(np.exp(1j * (theta - near))))
