# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Whether a linear contact set's smallest element area ratio stays above a level, call after
call, without bounding every element each time (:class:`AreaWatch`).

:meth:`~..contact_model.ContactModel.area_ratio` bounds every element's displacement gradient,
||H_e|| <= B_e = sum_k b_ek ||F_k|| + ||R_e g|| (b_ek: the element's gradient per unit load at
contact k, R_e g: the gradient of the set's rigid part, g = E^T delta), and computes det F
exactly where B_e >= GRADIENT_BOUND_EXACT. Between two configurations of one set the bounds move
by at most

    |B_e - B_e,ref| <= sum_k max_e(b_ek) | ||F_k|| - ||F_k,ref|| | + max_e ||R_e||_F ||g - g_ref||,

so :class:`AreaWatch` bounds every element once at a reference configuration, keeps the
:data:`AREA_CANDIDATES` elements with the largest bounds (and their load gradients, stacked),
and, while that drift stays below the gap between the kept bounds and the rest, answers from the
kept elements alone: an element outside them has B_e < 1 - sqrt(level), so det F > level.
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    GRADIENT_BOUND_EXACT,
    ContactModel,
    SetData,
)

__all__ = ["AREA_CANDIDATES", "AreaWatch"]

AREA_CANDIDATES = 64
"""Elements kept (those with the largest bounds at the reference configuration)."""
_SLACK = 1e-12
"""Relative slack on the drift bound, for its own round-off."""


class AreaWatch:
    """The area check of one contact model's linear sets (see the module).

    Parameters
    ----------
    model : ContactModel
        A linear-material model (its :meth:`~..contact_model.ContactModel.area_ratio` is the
        check answered here).
    """

    def __init__(self, model: ContactModel) -> None:
        self.model = model
        self.renewals = 0
        self._ref: dict | None = None
        R = model.obj.rigid_gradients.reshape(-1, 4, 3)
        self._rigid = R
        self._rigid_norm = float(np.sqrt((R * R).sum(axis=(1, 2))).max())

    def above(self, sd: SetData, delta: np.ndarray, F: np.ndarray, level: float) -> bool:
        """Whether ``model.area_ratio(sd, delta, F)[0] > level`` (level just above
        INVERSION_AREA_RATIO), to the round-off of a bound or det F within 1e-12 of its
        threshold.
        """
        g = sd.E.T @ delta.reshape(-1)
        norms = np.sqrt((F * F).sum(axis=1))
        reach = 1.0 - level ** 0.5
        ref = self._ref
        if ref is None or ref["set"] is not sd or ref["reach"] != reach or self._drift(
                ref, g, norms) > ref["budget"]:
            ref = self._renew(sd, g, norms, reach)
        rigid = ref["rigid_rows"] @ g
        bound = ref["bounds"] @ norms + np.sqrt((rigid * rigid).sum(axis=1))
        exact = bound >= GRADIENT_BOUND_EXACT
        if np.any(bound[~exact] >= reach):
            return False  # a bound of the rest is at or past the level
        if not exact.any():
            return True
        H = rigid[exact] + ref["loads"][exact] @ F.reshape(-1)
        det = (1.0 + H[:, 0]) * (1.0 + H[:, 3]) - H[:, 1] * H[:, 2]
        return bool(det.min() > level)

    def _drift(self, ref: dict, g: np.ndarray, norms: np.ndarray) -> float:
        """The bound on how far any element's bound moved from the reference (with slack)."""
        return float(ref["column_max"] @ np.abs(norms - ref["norms"])
                     + self._rigid_norm * np.linalg.norm(g - ref["g"])) * (1.0 + _SLACK)

    def _renew(self, sd: SetData, g: np.ndarray, norms: np.ndarray, reach: float) -> dict:
        """Bound every element at this configuration and keep the largest bounds' elements."""
        self.renewals += 1
        obj = self.model.obj
        bounds = obj.gradient_bounds(tuple(sd.nodes.tolist()))
        rigid = self._rigid @ g
        B = bounds @ norms + np.sqrt((rigid * rigid).sum(axis=1))
        if len(B) > AREA_CANDIDATES:
            kept = np.argpartition(-B, AREA_CANDIDATES)[:AREA_CANDIDATES]
            budget = reach - np.delete(B, kept).max()
        else:
            kept, budget = np.arange(len(B)), np.inf
        kept = np.sort(kept)
        loads = obj.load_gradients(sd.nodes)
        self._ref = {
            "set": sd, "reach": reach, "norms": norms, "g": g, "budget": budget,
            "column_max": bounds.max(axis=0), "bounds": bounds[kept],
            "rigid_rows": self._rigid[kept],
            "loads": np.concatenate([G[kept] for G in loads], axis=2),
        }
        return self._ref
