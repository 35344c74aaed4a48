# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The incremental event stepper (paper Sec. 5.2-5.4, Algorithm 1 lines 4-15; docs/design.md).

:func:`advance` moves any number of fingertips by given translations from a frozen
:class:`~..contact_state.ContactState` and returns the new state with the events it located.
Squeezes, resistance and the simulated hardware are loops over it.

Within one call the motion is parametrised by s in [0, 1] (finger f at o_f + s d_f). One unit
per job, each usable and tested alone:

==========================  ===============================================================
module                      what it holds
==========================  ===============================================================
:mod:`.motion`              the finger paths and the tip shape (gaps, their slopes, angles)
:mod:`.contact_set`         the contact set: nodes, fingers, modes, polar angles (a value)
:mod:`.solving`             the fixed-set solve along the motion; the call's counters
:mod:`.functions`           event-function values and slopes, by :class:`~..event_key.EventKey`
:mod:`.modes`               the mode decision (hypothesis-and-test)
:mod:`.processing`          event processing at a point; terminations
:mod:`.chatter`             the chattering bound
:mod:`.location`            crossings and root location (Hermite, regula falsi)
:mod:`.substeps`            substep control (grid or adaptive)
:mod:`.run`                 :func:`advance`: the substep loop that joins them
:mod:`.compiled`            the substeps between events in one numba call (numba route)
:mod:`.compiled_functions`  the event functions at a point in one numba call (numba route)
:mod:`.quiet`               :class:`QuietSteps`: calls that cross no event, without the loop
==========================  ===============================================================

At each substep end the fixed-set problem is solved and the event functions are evaluated; a
function that changes sign is located to a bracket of depth width <= ``event_tol`` * L and the
events at the bracket end are processed in :data:`~..event_key.PROCESSING_ORDER`. Results
therefore depend on ``step`` only through missed double roots inside one substep, and on
``event_tol`` to within the tolerance. The reference model (``ContactModel.reference``) skips
the location: events are taken at the end of the fixed step, as in the paper. Every loop
advances s strictly or processes a bounded number of events, so a call always ends.

Between substeps the sliding angles are continued from the previous point (predictor
theta + dtheta/ds ds, Newton with line search); a substep whose Newton solve is slow or lands
off the predicted branch is halved.
"""

from squeeze_grasp_ros.mechanics.squeeze.stepper.quiet import QuietSteps
from squeeze_grasp_ros.mechanics.squeeze.stepper.run import (
                                                             MIN_EVENT_TOL,
                                                             MIN_STEP,
                                                             TERMINATION_ORDER,
                                                             advance,
)

__all__ = ["MIN_EVENT_TOL", "MIN_STEP", "TERMINATION_ORDER", "QuietSteps", "advance"]
