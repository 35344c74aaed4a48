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
predicted boundary nodes from the seen curve; above the threshold the model is wrong about
the object (:func:`check_frame`).

Under displacement control (both fingers driven to a depth) the deformed shape of a linear
elastic object does not depend on E (the displacement field is E-invariant, only the forces
scale with E): an error in E shows in the forces (the monitor's prediction check), not in
the shape.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ShapeFit
from squeeze_grasp_ros.perception.shape_match import ShapeMatch, shape_residual
from squeeze_grasp_ros.scene import GraspSetup

__all__ = ["DEFAULT_SAMPLES", "PredictedShapes", "check_frame", "predict_shapes"]

DEFAULT_SAMPLES = 6
"""Depth samples of a prediction, 0 and the target depth included."""


@dataclass(frozen=True)
class PredictedShapes:
    """The predicted deformed outer boundary at increasing depths (object frame, m).

    Attributes
    ----------
    depths : (k,) ndarray
        m, increasing, the first 0.
    outlines : tuple of (b, 2) ndarray
        The boundary nodes at each depth (the same nodes in the same order).
    """

    depths: np.ndarray
    outlines: tuple[np.ndarray, ...]

    def __post_init__(self) -> None:
        depths = np.asarray(self.depths, float)
        if len(depths) < 1 or len(depths) != len(self.outlines) or np.any(np.diff(depths) <= 0):
            raise InvalidInputError("predicted shapes: one outline per depth, depths increasing")
        if len({np.shape(o) for o in self.outlines}) != 1:
            raise InvalidInputError("predicted shapes: every outline must have the same nodes")

    def at(self, depth: float) -> Outline:
        """The boundary at ``depth`` (m), linear between samples, held beyond the last."""
        depths = np.asarray(self.depths, float)
        d = float(np.clip(depth, depths[0], depths[-1]))
        k = int(np.clip(np.searchsorted(depths, d, side="right") - 1, 0, len(depths) - 1))
        if k == len(depths) - 1:
            return Outline(np.asarray(self.outlines[k], float))
        w = (d - depths[k]) / (depths[k + 1] - depths[k])
        a, b = np.asarray(self.outlines[k], float), np.asarray(self.outlines[k + 1], float)
        return Outline((1.0 - w) * a + w * b)


def predict_shapes(setup: GraspSetup, depth: float, *,
                   samples: int = DEFAULT_SAMPLES) -> PredictedShapes:
    """Sample the deformed boundary of ``setup``'s squeeze at ``samples`` depths in [0, depth].

    Each sample is the event-driven squeeze of the setup (its contacts, kind and material
    model) to that depth.
    """
    if samples < 2 or not depth > 0:
        raise InvalidInputError(f"predict_shapes needs samples >= 2 and depth > 0 m, got "
                                f"{samples} and {depth!r}")
    mesh = setup.solid.mesh
    rest = mesh.nodes[mesh.boundary]
    depths = np.linspace(0.0, depth, samples)
    outlines = [rest] + [rest + setup.event_squeeze(depth=float(d)).displacement[mesh.boundary]
                         for d in depths[1:]]
    return PredictedShapes(depths, tuple(outlines))


def check_frame(seen: Outline, predicted: PredictedShapes, depth: float,
                threshold: float) -> tuple[ShapeMatch, float, bool]:
    """Match a frame's outline against the prediction at ``depth``.

    Returns
    -------
    (ShapeMatch, float, bool)
        The rigid match (its ``rms_m`` is the residual), App. C's similarity scale, and whether
        the residual exceeds ``threshold`` (m): shape_mismatch.
    """
    model = predicted.at(depth)
    rigid = shape_residual(seen, model, fit=ShapeFit.RIGID)
    scale = shape_residual(seen, model, fit=ShapeFit.SIMILARITY).scale
    return rigid, scale, rigid.rms_m > threshold
