# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor's force watch: measured finger forces against the planner's force curve.

Under displacement control (the fingers are driven to a depth) the deformed shape of the
object does not depend on its Young's modulus E: the stiffness scales with E, the prescribed
displacements do not, so the displacement field is the same and only the forces scale with E
(linear and neo-Hookean; the friction ratios are unchanged). A wrong E is therefore invisible to
the camera's shape watch at equal depth (its equal-force residual sees it,
:func:`squeeze_grasp_ros.perception.shape_watch.depth_at_force`) and shows here: the measured
force of each finger along its motion direction against the planner's prediction at the
measured depth
(:meth:`PredictedForces.at`, linear between the planner's accepted points). Above
``tolerance`` in relative error the finger raises ``force_mismatch``
(:func:`check_forces`). The first ``min_fraction`` of the predicted depth is not judged: the
forces start at zero, so a relative error there is noise over nothing.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.control.tracker import TrackedAlarm
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.mechanics.vocabulary import AlarmType

__all__ = ["FORCE_MISMATCH", "ForceCheck", "PredictedForces", "check_forces",
           "force_along_motion", "squeeze_forces"]

FORCE_MISMATCH = AlarmType.FORCE_MISMATCH
"""The alarm type (``Alarm.FORCE_MISMATCH`` over ROS), like the tracker's alarm names."""


@dataclass(frozen=True)
class PredictedForces:
    """Each finger's predicted force along its motion direction against squeeze depth.

    Attributes
    ----------
    depths : (k,) ndarray
        m, non-decreasing (an event adds a point at the depth of the substep before it).
    forces : mapping of str to (k,) ndarray
        Finger -> force on the object along its motion direction at each depth, N.
    """

    depths: np.ndarray
    forces: Mapping[str, np.ndarray]

    def __post_init__(self) -> None:
        depths = np.asarray(self.depths, float)
        if len(depths) < 2 or np.any(np.diff(depths) < 0) or not depths[-1] > 0:
            raise InvalidInputError("predicted forces: at least two depths, non-decreasing, "
                                    f"the last > 0 m; got {len(depths)} depths")
        if any(np.shape(f) != depths.shape for f in self.forces.values()):
            raise InvalidInputError("predicted forces: one force per depth and finger")

    def at(self, finger: str, depth: float) -> float:
        """Finger's predicted force at ``depth`` (m), N: linear between samples, held beyond."""
        return float(np.interp(depth, self.depths, self.forces[finger]))

    @functools.cached_property
    def largest(self) -> dict[str, float]:
        """Finger -> its largest predicted |force|, N (computed once: the watch asks at every
        tick).
        """
        return {f: float(np.abs(c).max()) for f, c in self.forces.items()}


@dataclass(frozen=True)
class ForceCheck:
    """One tick's comparison.

    Attributes
    ----------
    depth : float
        Measured squeeze depth, m.
    measured, predicted, relative_error : mapping of str to float
        Per judged finger: the force along its motion (N), the prediction (N), and
        (measured - predicted) / |predicted|.
    alarms : tuple of TrackedAlarm
        ``force_mismatch`` for every finger whose |relative error| exceeds the tolerance.
    """

    depth: float
    measured: Mapping[str, float]
    predicted: Mapping[str, float]
    relative_error: Mapping[str, float]
    alarms: tuple[TrackedAlarm, ...]


def squeeze_forces(result: EventSqueeze) -> PredictedForces | None:
    """The force curve of an event-driven squeeze (its ``force_curve``, whose depths are
    relative) against depth in m; None for a squeeze that ended at depth 0 (e.g. a finger slipped
    at once: no depths to convert the relative ones with) or with fewer than two points.
    """
    if not result.relative_depth > 0:
        return None
    per_relative = result.depth / result.relative_depth
    curves = {f: np.asarray(c, float).reshape(-1, 2) for f, c in result.force_curve.items()}
    first = next(iter(curves.values()))
    if len(first) < 2 or not first[-1, 0] > 0:
        return None
    return PredictedForces(first[:, 0] * per_relative, {f: c[:, 1] for f, c in curves.items()})


def force_along_motion(force: np.ndarray, position: np.ndarray, start: np.ndarray) -> float:
    """Component of ``force`` (N) along the finger's measured motion ``position - start`` (m);
    0 before it has moved.
    """
    motion = np.asarray(position, float) - np.asarray(start, float)
    length = math.sqrt(motion.dot(motion))  # np.linalg.norm's own arithmetic, without its wrapper
    return float(np.asarray(force, float)[:2] @ motion) / length if length > 0 else 0.0


def check_forces(prediction: PredictedForces, depth: float, measured: Mapping[str, float], *,
                 tolerance: float, min_fraction: float) -> ForceCheck | None:
    """Compare the measured forces along the motion (N) with the prediction at ``depth`` (m).

    Judged: depths within ``min_fraction`` of the predicted depth range's ends (below it the
    forces are nothing yet; beyond the predicted depth, e.g. in a resistance phase, the squeeze
    prediction says nothing), and fingers whose predicted force there is at least
    ``min_fraction`` of their largest (a finger that does not push is not judged). Returns None
    when nothing is judged.
    """
    end = float(prediction.depths[-1])
    if not min_fraction * end <= depth <= (1.0 + min_fraction) * end:
        return None
    predicted = {f: prediction.at(f, depth) for f in measured if f in prediction.forces}
    fingers = [f for f, p in predicted.items()
               if abs(p) > 0 and abs(p) >= min_fraction * prediction.largest[f]]
    if not fingers:
        return None
    predicted = {f: predicted[f] for f in fingers}
    errors = {f: (measured[f] - predicted[f]) / abs(predicted[f]) for f in fingers}
    alarms = tuple(TrackedAlarm(FORCE_MISMATCH, f, errors[f],
                                f"{f} pushes {measured[f]:.4g} N at depth {depth * 1e3:.4g} mm, "
                                f"predicted {predicted[f]:.4g} N ({errors[f]:+.1%}, tolerance "
                                f"{tolerance:.0%})")
                   for f in fingers if abs(errors[f]) > tolerance)
    return ForceCheck(depth, {f: measured[f] for f in fingers}, predicted, errors, alarms)
