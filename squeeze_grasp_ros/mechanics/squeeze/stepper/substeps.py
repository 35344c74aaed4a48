# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Substep control: how far each substep of a stepper call goes.

The interval s in [0, 1] is cut into substeps of ``step`` (depth, relative to the object size
L), the grid. A model whose evaluations are dear (``ContactModel.adaptive_steps``: the
large-deformation models, unless their ``SolveOptions`` switch it off) adapts them between
events instead (:meth:`SubstepControl.accept`): up to ADAPTIVE_MAX_STEPS grid steps while the
force slope changes little, the grid while a contact slides; a substep on whose cubic Hermite
interpolants a gap, force or cone function dips to zero inside is rejected and halved
(:func:`~.location.dips_inside`), so a double root the end values would miss is caught. All in
s (per unit of the call's motion).
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import Solution
from squeeze_grasp_ros.mechanics.squeeze.event_key import EventFunction, EventKey
from squeeze_grasp_ros.mechanics.squeeze.stepper.location import Values

__all__ = ["ADAPTIVE_GROWTH", "ADAPTIVE_MAX_STEPS", "ADAPTIVE_SLOPE_CHANGE", "SubstepControl"]

ADAPTIVE_GROWTH = 2.0
ADAPTIVE_SLOPE_CHANGE = 0.1
ADAPTIVE_MAX_STEPS = 4
"""Adaptive substeps: growth per substep, the relative change of the force slope over one
substep they aim at, and their largest length in grid steps."""
_SLOPELESS_TERMINATIONS = tuple(EventKey(f) for f in (EventFunction.AREA, EventFunction.STRAIN,
                                                      EventFunction.PICKUP))


class SubstepControl:
    """The next substep of a call (mutable: it remembers the last one planned).

    Parameters
    ----------
    grid : float
        The ``step`` grid in s.
    adaptive : bool
        Whether substeps adapt (else they stay on the grid).
    planned : float
        The substep planned so far, in s (a previous call's ``next_substep`` / rate).
    """

    def __init__(self, grid: float, adaptive: bool, planned: float) -> None:
        self.grid, self.adaptive = grid, adaptive
        self.h = grid
        if adaptive:
            self.h = min(ADAPTIVE_MAX_STEPS * grid, max(grid, planned))

    def end(self, a: float) -> float:
        """End of the substep that starts at a."""
        return min(a + self.h, 1.0)

    def reject(self, a: float, b: float) -> None:
        """[a, b] had an event function dip to zero inside: halve it (not below the grid)."""
        self.h = max(self.grid, 0.5 * (b - a))

    def may_reject(self, a: float, b: float) -> bool:
        """Whether [a, b] is an adaptive substep longer than the grid (one that can be halved)."""
        return self.adaptive and b - a > self.grid

    def accept(self, sol_a: Solution, sol_b: Solution, a: float, b: float, start: Values,
               end: Values, all_stick: bool) -> None:
        """Plan the next substep of an adaptive run after the accepted [a, b].

        It grows by up to ADAPTIVE_GROWTH while the slope of the contact forces changes by less
        than ADAPTIVE_SLOPE_CHANGE of their change over a substep (so the cubic interpolants
        of the event functions and of the work stay accurate), shrinks when it changes more,
        and stays within [grid, ADAPTIVE_MAX_STEPS grid]. It stays on the grid while a contact
        slides (``all_stick`` False: the slip rates have no slopes; the dissipation is
        integrated by the trapezoid rule), and within half the distance at which a
        termination function without slope (strain, inversion, pickup) would reach zero at
        its last rate of change.
        """
        if not self.adaptive:
            return
        hs = self.grid
        if not all_stick:
            self.h = hs
            return
        change = np.linalg.norm(sol_b.F - sol_a.F)
        slope_change = (b - a) * np.linalg.norm(sol_b.dF - sol_a.dF)
        if slope_change <= ADAPTIVE_SLOPE_CHANGE * change / ADAPTIVE_GROWTH:
            grow = ADAPTIVE_GROWTH
        else:
            grow = max(0.5, ADAPTIVE_SLOPE_CHANGE * change / slope_change)
        h = min(ADAPTIVE_MAX_STEPS * hs, max(hs, self.h * grow))
        for key in _SLOPELESS_TERMINATIONS:
            if key in start and key in end and end[key] < start[key]:
                h = min(h, max(hs, 0.5 * end[key] * (b - a) / (start[key] - end[key])))
        self.h = h
