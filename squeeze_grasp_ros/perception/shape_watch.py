# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Watching the squeeze (paper App. C, live): each camera frame's outline against the predicted
deformed boundary at the same squeeze depth.

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
scale with E): an error in E shows in the forces (the monitor's prediction check), not in
the shape.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.shapes import Outline, signed_area
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ShapeFit
from squeeze_grasp_ros.perception.shape_match import ShapeMatch, deformed_outline, shape_residual
from squeeze_grasp_ros.scene import GraspSetup

__all__ = ["DEFAULT_SAMPLES", "FrameCheck", "PredictedShapes", "check_frame", "predict_shapes"]

DEFAULT_SAMPLES = 6
"""Depth samples of a prediction, 0 and the target depth included."""


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
