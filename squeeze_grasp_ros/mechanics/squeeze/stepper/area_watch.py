# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""How far a linear contact set's elements are from inversion, call after call, without
bounding every element each time (:class:`AreaWatch`).

:meth:`~..contact_model.ContactModel.area_ratio` bounds every element's displacement gradient,
||H_e|| <= B_e = sum_k b_ek ||F_k|| + ||R_e g|| (b_ek: the element's gradient per unit load at
contact k, R_e g: the gradient of the set's rigid part, g = E^T delta), and computes det F
exactly where B_e >= GRADIENT_BOUND_EXACT. Between two configurations of one set the bounds and
the gradients move by at most

    moved = sum_k max_e(b_ek) ||F_k - F_k,ref|| + max_e ||R_e||_F ||g - g_ref||,

so :class:`AreaWatch` bounds every element once at a reference configuration, keeps the
:data:`AREA_CANDIDATES` elements with the largest bounds (and their load gradients, stacked),
and, while the drift of the bounds since the reference stays within the gap between the kept
bounds and the rest's reach 1 - sqrt(level) (where (1 - B_e)^2 = level), looks at the kept
elements alone: their det F exactly, the rest are above the level whatever they are.
:meth:`AreaWatch.reserve` turns that into how much ``moved`` may still grow from a
configuration with every element above the level, and :meth:`AreaWatch.rate` bounds how fast
``moved`` grows along a motion.
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
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
        check whose events are ruled out here).

    Attributes
    ----------
    renewals : int
        How many times every element was bounded (a new set, or the drift at half its budget).
    """

    def __init__(self, model: ContactModel) -> None:
        self.model = model
        self.renewals = 0
        self._ref: dict | None = None
        R = model.obj.rigid_gradients.reshape(-1, 4, 3)
        self._rigid, self._rigid_2d = R, model.obj.rigid_gradients
        self._of_set: tuple | None = None
        self._rigid_norm = float(np.sqrt((R * R).sum(axis=(1, 2))).max())

    def rate(self, sd: SetData, force_rates: np.ndarray, rigid_rate: float) -> float:
        """A bound on how fast ``moved`` (see the module) grows per unit of a motion that
        moves each contact force of ``sd`` by at most ``force_rates`` (m,) and the rigid part g
        by at most ``rigid_rate`` per unit (slack included).
        """
        return float(self._set(sd)[2] @ force_rates
                     + self._rigid_norm * rigid_rate) * (1.0 + _SLACK) ** 2

    def reserve(self, sd: SetData, delta: np.ndarray, F: np.ndarray, level: float) -> float:
        """How much ``moved`` (see the module) may grow from this configuration with every
        element's det F above ``level`` (just above INVERSION_AREA_RATIO); 0.0 when a kept
        element's is not above it here.

        A kept element's det F is computed here, and for a 2 x 2 gradient it moves by at most
        moved (sqrt 2 + ||H_e|| + moved) (|d det(I + H)| <= ||dH|| (sqrt 2 + ||H||) +
        ||dH||^2 / 2); the rest stay below the reach while the reference's drift stays within
        its budget (the reference is renewed when half the budget is used). With det F above
        ``level`` for every element, the area check of :func:`~.run.advance` finds no event: an
        element it bounds instead of solving has B_e < GRADIENT_BOUND_EXACT, and then a floor
        (1 - B_e)^2 > INVERSION_AREA_RATIO.
        """
        g = sd.E.T @ delta.reshape(-1)
        norms = np.sqrt((F * F).sum(axis=1))
        reach = 1.0 - level ** 0.5
        ref = self._ref
        stale = ref is None or ref["set"] is not sd or ref["reach"] != reach
        drift = 0.0 if stale else self._drift(ref, g, norms)
        if stale or drift > 0.5 * ref["budget"]:
            ref, drift = self._renew(sd, g, norms, reach), 0.0
        H = (ref["rigid_rows"] @ g).reshape(-1, 4) + ref["loads"] @ F.reshape(-1)
        det = (1.0 + H[:, 0]) * (1.0 + H[:, 3]) - H[:, 1] * H[:, 2]
        if not det.min(initial=np.inf) > level:
            return 0.0
        # per element the largest m with m (sqrt 2 + ||H_e|| + m) (1 + slack) < det - level
        b, c = 2.0 ** 0.5 + np.sqrt((H * H).sum(axis=1)), (det - level) / (1.0 + _SLACK)
        most = min((2.0 * c / (b + np.sqrt(b * b + 4.0 * c))).min(initial=np.inf),
                   ref["budget"] - drift)
        return max(0.0, float(most) * (1.0 - _SLACK))

    def _drift(self, ref: dict, g: np.ndarray, norms: np.ndarray) -> float:
        """The bound on how far any element's bound moved from the reference (with slack)."""
        return float(ref["column_max"] @ np.abs(norms - ref["norms"])
                     + self._rigid_norm * np.linalg.norm(g - ref["g"])) * (1.0 + _SLACK)

    def _set(self, sd: SetData) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
        """(b_ek (t, m), each node's load gradients (t, 4, 2), max_e b_ek (m,)) of the set
        ``sd``, kept for the last set (its renewals need them again).
        """
        kept = self._of_set
        if kept is None or kept[0] is not sd:
            obj = self.model.obj
            bounds = obj.gradient_bounds(tuple(sd.nodes.tolist()))
            kept = self._of_set = (sd, bounds, obj.load_gradients(sd.nodes), bounds.max(axis=0))
        return kept[1:]

    def _renew(self, sd: SetData, g: np.ndarray, norms: np.ndarray, reach: float) -> dict:
        """Bound every element at this configuration and keep the largest bounds' elements."""
        self.renewals += 1
        bounds, loads, column_max = self._set(sd)
        rigid = (self._rigid_2d @ g).reshape(-1, 4)
        B = bounds @ norms + np.sqrt((rigid * rigid).sum(axis=1))
        if len(B) > AREA_CANDIDATES:
            # the partition's next element is the largest bound of the rest
            order = np.argpartition(-B, AREA_CANDIDATES)
            kept, budget = order[:AREA_CANDIDATES], reach - B[order[AREA_CANDIDATES]]
        else:
            kept, budget = np.arange(len(B)), np.inf
        kept = np.sort(kept)
        self._ref = {
            "set": sd, "reach": reach, "norms": norms, "g": g, "budget": budget,
            "column_max": column_max, "rigid_rows": self._rigid[kept].reshape(-1, 3),
            "loads": np.concatenate([G[kept] for G in loads], axis=2),
        }
        return self._ref
