# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""How far the fingers may travel in one sticking mode before a watched function that is not
linear in the forces can reach the quiet margin (:class:`TravelRates`): what lets a quiet tick
skip the dear checks.

In a sticking mode of a linear contact set every quantity a quiet call watches is affine in the
fingers' stacked translation T (/ L) from a reference configuration: each contact node rides on
its finger (d delta_k = dT_f(k)), the forces change by dF = C d delta = K dT (K = C S, S the
node-to-finger selection), the rigid part by dg = E^T S dT, and a boundary point by
A_bc dF + R dg = M dT. The contacts' normal forces and cone margins are linear in the forces
(one small product per tick, :class:`~.quiet.QuietSteps` checks them at every tick); the others
change by at most a rate times ||dT||:

* the gap of a free boundary row i to tip f by ||M_i - I_f||, I_f the motion of tip f's centre
  (a signed distance to a convex tip is 1-Lipschitz in the point less the tip's centre);
* the area check's bound on every element's gradient change (AreaWatch's ``moved``) by
  sum_k max_e b_ek ||K_k|| + max_e ||R_e|| ||E^T S|| (:meth:`~.area_watch.AreaWatch.rate`).

Frobenius norms bound the 2-norms. Where every function clears the margin, the smallest
(value - margin) / rate is a travel within which none can reach it: a quiet call ending within
that distance of the configuration needs neither evaluated (:meth:`TravelRates.travel`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import node_dofs
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.stepper.area_watch import AreaWatch
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet

__all__ = ["TRAVEL_SLACK", "TravelRates"]

TRAVEL_SLACK = 1e-9
"""Relative amount a travel is shortened by, for the round-off of its rates and values."""


@dataclass(frozen=True)
class TravelRates:
    """The rates (per unit stacked finger translation, / L) of one sticking mode's watched
    functions that are not linear in the forces (see the module).

    Attributes
    ----------
    gaps : (r, f) ndarray
        Of each free boundary row's gap to each tip.
    area : float
        Of the area check's gradient bound (:meth:`~.area_watch.AreaWatch.rate`).
    """

    gaps: np.ndarray
    area: float

    @classmethod
    def of(cls, model: ContactModel, contacts: ContactSet, fingers: int, rows: np.ndarray,
           area: AreaWatch) -> TravelRates:
        """The rates of the set ``contacts`` (every node sticking) on ``fingers`` tips and its
        free boundary ``rows``.
        """
        sd, m = contacts.data, len(contacts)
        select = np.zeros((2 * m, 2 * fingers))
        for k, f in enumerate(contacts.finger.tolist()):
            select[2 * k:2 * k + 2, 2 * f:2 * f + 2] = np.eye(2)
        K = sd.C @ select                       # dF / dT, (2m, 2f)
        G = sd.E.T @ select                     # dg / dT, (3, 2f)
        blocks = K.reshape(m, 2, 2 * fingers)
        A = sd.A_bc[node_dofs(rows)]
        R = model.obj.rigid[node_dofs(model.boundary_nodes[rows])]
        M = (A @ K + R @ G).reshape(len(rows), 2, fingers, 2)
        gaps = np.empty((len(rows), fingers))
        for f in range(fingers):
            rel = M.copy()
            rel[:, :, f, :] -= np.eye(2)
            gaps[:, f] = np.sqrt((rel * rel).sum(axis=(1, 2, 3)))
        k_norms = np.sqrt((blocks * blocks).sum(axis=(1, 2)))
        return cls(gaps, area.rate(sd, k_norms, float(np.sqrt((G * G).sum()))))

    def travel(self, gaps: np.ndarray, area_reserve: float, margin: float) -> float:
        """The travel (stacked, / L) within which neither the rows' ``gaps`` nor the area check
        (its ``area_reserve``, :meth:`~.area_watch.AreaWatch.reserve`) can reach ``margin``
        from the configuration with these values; 0.0 when one is at or below it already.
        """
        room = (gaps - margin).ravel()
        if room.min(initial=np.inf) <= 0.0 or not area_reserve > 0.0:
            return 0.0
        with np.errstate(divide="ignore"):
            reach = min((room / self.gaps.ravel()).min(initial=np.inf),
                        area_reserve / self.area if self.area > 0.0 else np.inf)
        return float(reach) * (1.0 - TRAVEL_SLACK)
