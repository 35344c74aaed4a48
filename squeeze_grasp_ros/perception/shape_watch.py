# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Watching the squeeze (paper App. C, live): each camera frame's outline against the predicted
deformed boundary at the same squeeze depth, and at the depth the model predicts for the
measured force.

The prediction is sampled once, before the squeeze (:func:`predict_shapes`: the event-driven
squeeze of the planner's model to evenly spaced depths), and interpolated linearly between the
samples (:meth:`PredictedShapes.at`). A frame is matched with a **rigid** fit (rotation and
translation; :func:`~.shape_match.shape_residual`): the camera is calibrated, so a seen object
larger than the model is an error to report, and App. C's similarity fit would absorb it into
its scale (which is reported beside the residual). The residual is the RMS distance of the
predicted boundary nodes (outer curve and holes) from the seen curves; above the threshold the
model is wrong about the object (:func:`check_frame`). So is a frame that shows another number
of holes than the prediction: a hole that closed or vanished in the image, or one the model
lacks (holes the camera cannot resolve, under ``min_hole_area``, are not expected).

Under displacement control (both fingers driven to a depth) the deformed shape of a linear
elastic object does not depend on E (the displacement field is E-invariant, only the forces
scale with E), so the equal-depth match cannot see a wrong E. The model also predicts the force
at each depth: the shape it predicts *for the force the sensors measure* does depend on E (an
object 30 % softer than the model is squeezed deeper at that force than the model says). The
second match (:func:`depth_at_force`, then :func:`check_frame` at that depth) inverts the
prediction's force curve for the finger pair (the mean of the two fingers' forces along their
motion: in a two-finger squeeze they push equally, and the mean halves the sensors' noise). It
is skipped, with the reason (:class:`AtForce`), below a minimum force (noise over nothing), past
the prediction's largest force, and where the predicted force is not increasing in depth at the
measured force (an event or a slip makes the depth ambiguous).
"""
from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.control.force_watch import PredictedForces
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline, signed_area
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import AlarmType, ShapeFit
from squeeze_grasp_ros.perception.shape_match import ShapeMatch, deformed_outline, shape_residual
from squeeze_grasp_ros.scene import GraspSetup

__all__ = ["DEFAULT_SAMPLES", "SHAPE_MISMATCH", "AtForce", "DepthAtForce", "FrameCheck",
           "PredictedShapes", "check_frame", "depth_at_force", "pair_force", "predict_shapes"]

SHAPE_MISMATCH = AlarmType.SHAPE_MISMATCH
"""The alarm type (``Alarm.SHAPE_MISMATCH`` over ROS), like the tracker's alarm names."""

DEFAULT_SAMPLES = 6
"""Depth samples of a prediction, 0 and the target depth included."""

ROUND_OFF = 1e-9
"""Relative slack of :func:`depth_at_force` at the force curve's points: a force that equals
the curve's end up to round-off is on the curve."""


@dataclass(frozen=True)
class PredictedShapes:
    """The predicted deformed boundary at increasing depths (object frame, m).

    Attributes
    ----------
    depths : (k,) ndarray
        m, increasing, the first 0.
    outlines : tuple of (b, 2) ndarray
        The outer boundary nodes at each depth (the same nodes in the same order).
    holes : tuple of tuple of (c, 2) ndarray
        Each depth's hole loops (the same holes and nodes at every depth); empty for a solid
        object.
    """

    depths: np.ndarray
    outlines: tuple[np.ndarray, ...]
    holes: tuple[tuple[np.ndarray, ...], ...] = ()

    def __post_init__(self) -> None:
        depths = np.asarray(self.depths, float)
        if len(depths) < 1 or len(depths) != len(self.outlines) or np.any(np.diff(depths) <= 0):
            raise InvalidInputError("predicted shapes: one outline per depth, depths increasing")
        if len({np.shape(o) for o in self.outlines}) != 1:
            raise InvalidInputError("predicted shapes: every outline must have the same nodes")
        if self.holes and (len(self.holes) != len(depths) or len(
                {tuple(np.shape(h) for h in loops) for loops in self.holes}) != 1):
            raise InvalidInputError("predicted shapes: the same holes, with the same nodes, at "
                                    "every depth")

    @property
    def hole_count(self) -> int:
        """Holes of the predicted object."""
        return len(self.holes[0]) if self.holes else 0

    def at(self, depth: float) -> Outline:
        """The boundary at ``depth`` (m), linear between samples, held beyond the last."""
        depths = np.asarray(self.depths, float)
        d = float(np.clip(depth, depths[0], depths[-1]))
        k = int(np.clip(np.searchsorted(depths, d, side="right") - 1, 0, len(depths) - 1))
        loops = [(self.outlines[i],) + (self.holes[i] if self.holes else ())
                 for i in range(len(depths))]
        if k == len(depths) - 1:
            mixed = [np.asarray(loop, float) for loop in loops[k]]
        else:
            w = (d - depths[k]) / (depths[k + 1] - depths[k])
            mixed = [(1.0 - w) * np.asarray(a, float) + w * np.asarray(b, float)
                     for a, b in zip(loops[k], loops[k + 1])]
        return Outline(mixed[0], tuple(mixed[1:]))


@dataclass(frozen=True)
class FrameCheck:
    """One camera frame against the prediction (:func:`check_frame`).

    Attributes
    ----------
    match : ShapeMatch
        The rigid match; its ``rms_m`` is the residual (outer and hole nodes).
    scale : float
        App. C's similarity scale (1 = the size predicted).
    holes_predicted : int
        Predicted holes large enough to be seen (area at least ``min_hole_area``).
    holes_seen : int
        Holes in the frame's outline.
    mismatch : bool
        The residual exceeds the threshold, or the hole counts differ.
    """

    match: ShapeMatch
    scale: float
    holes_predicted: int
    holes_seen: int
    mismatch: bool

    @property
    def reason(self) -> str:
        """Why the frame mismatches ("" when it does not)."""
        if self.holes_seen < self.holes_predicted:
            return (f"{self.holes_predicted - self.holes_seen} of {self.holes_predicted} "
                    "predicted holes not seen (closed or vanished in the image)")
        if self.holes_seen > self.holes_predicted:
            return (f"{self.holes_seen} holes seen, {self.holes_predicted} predicted (the "
                    "model lacks a hole)")
        return "residual above the threshold" if self.mismatch else ""


def predict_shapes(setup: GraspSetup, depth: float, *,
                   samples: int = DEFAULT_SAMPLES) -> PredictedShapes:
    """Sample the deformed boundary of ``setup``'s squeeze at ``samples`` depths in [0, depth].

    Each sample is the event-driven squeeze of the setup (its contacts, kind and material
    model) to that depth; the outer boundary and the holes' loops.
    """
    if samples < 2 or not depth > 0:
        raise InvalidInputError(f"predict_shapes needs samples >= 2 and depth > 0 m, got "
                                f"{samples} and {depth!r}")
    mesh = setup.solid.mesh
    depths = np.linspace(0.0, depth, samples)
    shapes = [deformed_outline(mesh, np.zeros_like(mesh.nodes))] + [
        deformed_outline(mesh, setup.event_squeeze(depth=float(d)).displacement)
        for d in depths[1:]]
    return PredictedShapes(depths, tuple(s.points for s in shapes),
                           tuple(s.holes for s in shapes) if mesh.inner_boundaries else ())


def check_frame(seen: Outline, predicted: PredictedShapes, depth: float, threshold: float, *,
                min_hole_area: float = 0.0) -> FrameCheck:
    """Match a frame's outline against the prediction at ``depth`` (m).

    Parameters
    ----------
    seen : Outline
        The frame's outline (and holes), object frame, m.
    predicted : PredictedShapes
    depth : float
        The squeeze depth at the frame, m.
    threshold : float
        Largest RMS residual of a right model, m.
    min_hole_area : float
        m^2: predicted holes smaller than this are not expected in the frame (the extraction's
        smallest hole, e.g. ``min_area_px`` pixel footprints), nor matched.
    """
    model = predicted.at(depth)
    visible = tuple(h for h in model.holes if abs(signed_area(h)) >= min_hole_area)
    model = Outline(model.points, visible)
    rigid = shape_residual(seen, model, fit=ShapeFit.RIGID)
    scale = shape_residual(seen, model, fit=ShapeFit.SIMILARITY).scale
    return FrameCheck(rigid, scale, len(visible), len(seen.holes),
                      rigid.rms_m > threshold or len(visible) != len(seen.holes))


class AtForce(enum.Enum):
    """How the depth for a measured force was found (:func:`depth_at_force`)."""

    MATCHED = "matched"
    """One depth of the prediction has the measured force, on a rising stretch."""
    BELOW_MIN_FORCE = "below_min_force"
    """The measured force is below the minimum (sensor noise over nothing)."""
    OUTSIDE_PREDICTION = "outside_prediction"
    """The measured force exceeds the largest predicted force (the curve ends at the planned
    depth), or is below the smallest."""
    NOT_MONOTONIC = "not_monotonic"
    """The predicted force is flat or falling at the measured force (an event, a slip): more
    than one depth, or a range of them, has that force."""
    NO_FORCE_CURVE = "no_force_curve"
    """The prediction carries no force curve."""
    NO_FORCE = "no_force"
    """No finger with a force sensor (wrench, taxels or joint effort) was measured."""


@dataclass(frozen=True)
class DepthAtForce:
    """The depth at which the prediction's pair force equals a measured one.

    Attributes
    ----------
    status : AtForce
    force : float
        The measured pair force, N.
    depth : float
        m, the predicted depth at ``force`` (``status`` MATCHED), else 0.
    """

    status: AtForce
    force: float
    depth: float = 0.0

    @property
    def matched(self) -> bool:
        """A depth was found."""
        return self.status is AtForce.MATCHED

    def reason(self, min_force: float) -> str:
        """Why no depth was found, for a log line ("" when one was)."""
        return {
            AtForce.MATCHED: "",
            AtForce.BELOW_MIN_FORCE: f"the force {self.force:.4g} N is below the minimum "
                                     f"{min_force:.4g} N (shape_min_force)",
            AtForce.OUTSIDE_PREDICTION: f"the force {self.force:.4g} N is outside the "
                                        "predicted forces (the curve ends at the planned "
                                        "depth)",
            AtForce.NOT_MONOTONIC: f"the predicted force is not rising with depth at "
                                   f"{self.force:.4g} N (an event or a slip)",
            AtForce.NO_FORCE_CURVE: "the prediction has no force curve",
            AtForce.NO_FORCE: "no finger force was measured",
        }[self.status]


def pair_force(forces: Mapping[str, float]) -> float | None:
    """The finger pair's squeeze force: the mean of the fingers' forces on the object along
    their motion (N); None without any.
    """
    return float(np.mean(list(forces.values()))) if forces else None


def depth_at_force(prediction: PredictedForces, force: float, *,
                   min_force: float) -> DepthAtForce:
    """Invert the prediction's pair force curve (the mean over its fingers) at ``force`` (N).

    The curve is piecewise linear in depth (an event may add a jump at one depth). The depth is
    found when ``force`` is at least ``min_force`` (N) and within the curve's forces (up to
    :data:`ROUND_OFF` of the largest), and every
    stretch of the curve that reaches ``force`` rises there and they meet at one
    depth; otherwise the status says why not (never NaN).
    """
    if not force >= min_force:
        return DepthAtForce(AtForce.BELOW_MIN_FORCE, float(force))
    depths = np.asarray(prediction.depths, float)
    curve = np.mean([np.asarray(f, float) for f in prediction.forces.values()], axis=0)
    low, high = curve[:-1], curve[1:]
    slack = ROUND_OFF * float(np.abs(curve).max())
    spans = np.flatnonzero((np.minimum(low, high) - slack <= force)
                           & (force <= np.maximum(low, high) + slack))
    if not spans.size:
        return DepthAtForce(AtForce.OUTSIDE_PREDICTION, float(force))
    rising = high[spans] > low[spans]
    if not rising.all():
        return DepthAtForce(AtForce.NOT_MONOTONIC, float(force))
    w = np.clip((force - low[spans]) / (high[spans] - low[spans]), 0.0, 1.0)
    found = depths[spans] + w * (depths[spans + 1] - depths[spans])
    if np.ptp(found) > 1e-9 * max(depths[-1], 1e-12):
        return DepthAtForce(AtForce.NOT_MONOTONIC, float(force))
    return DepthAtForce(AtForce.MATCHED, float(force), float(found.mean()))
