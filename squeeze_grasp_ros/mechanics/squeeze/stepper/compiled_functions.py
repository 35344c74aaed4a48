# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The event functions at a point by the compiled kernel (the numba route of the linear model).

:class:`CompiledFunctions` computes what :class:`~.functions.EventFunctions` reads at a solution
(the watched values: per-contact functions, the free rows' gaps, the area bound and the pickup
margin; their slopes d/ds) by one call of :func:`..substeps_numba.watched_values` or
:func:`..substeps_numba.slope_values`, instead of some fifty numpy calls. They are the numpy
code's floats, a zero's sign aside: the products are the BLAS calls numpy makes, with the
arrays in the layouts numpy has them (the set's E as it holds it), the sums in numpy's order.
The kernel computes an element near inversion's exact det F too, in the model's order, once
the set's load gradients are kept (:meth:`~..contact_model.ContactModel.area_tables`: by the
object, so from a set's second squeeze on); before that, and for a strain limit, the model
computes. With ``SQUEEZE_GRASP_KERNEL=numpy``, for the reference model and for
models with their own boundary displacement or area check (the nonlinear ones), none of this
runs: :class:`~.functions.EventFunctions` computes in numpy, the reference path.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    GRADIENT_BOUND_EXACT,
    ContactModel,
    SetData,
    Solution,
)
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import (
    Kernel,
    compiled_substeps,
    selected,
)
from squeeze_grasp_ros.mechanics.squeeze.kept import kept_for
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.vocabulary import Termination

if TYPE_CHECKING:
    from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions

__all__ = ["CompiledFunctions"]

_NO_BOUNDS = np.zeros((0, 0))
_NO_KAPPA = np.zeros(0)
_NO_VALUES = np.zeros(0)
_NO_PICK = np.zeros(0, np.int64)
ROW_TABLES_KEPT = 64
"""Tables of (contact set, boundary rows) the compiled reads of an object's calls keep
(:meth:`CompiledFunctions._rows_of`)."""


AREA_DEFERRED_FROM = 100_000
"""Elements times contacts from which a read for the pending events alone leaves the area check
out (:meth:`CompiledFunctions._read`). The check's O(t m) bound costs about 7 us of a kernel
call at 4,800 (a 400-node foam square, 6 contacts), 40 us at 55,000 (2,000 nodes, 14 contacts)
and 160 us at 410,000 (8,000 nodes, 26 contacts); computing it in a second call when the
terminations read it adds a call, about 20 us with its arguments."""


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two index arrays are equal (the same kept table, most often)."""
    return a is b or np.array_equal(a, b)


class CompiledFunctions:
    """The compiled reads of one call's :class:`~.functions.EventFunctions` (see the module).

    Use :meth:`of`, which returns None when the call's functions are computed in numpy, and
    :meth:`takes` for each contact set (the fast model's boundary compliance).
    """

    def __init__(self, functions: EventFunctions) -> None:
        self.functions = functions
        self.kernel = compiled_substeps()
        model, lim = functions.model, functions.model.limits
        # the object's weight in force units when the pickup is checked, else NaN
        self.weight = (lim.weight / model.force_unit if lim.weight is not None
                       and Termination.PICKED_UP in functions.terminate_on else np.nan)
        self._last: tuple | None = None
        self._last_slopes: tuple | None = None
        self._last_rows: tuple | None = None
        self._rows: dict[tuple, tuple] = functions.model.obj._shared.setdefault(
            "compiled_rows", {})

    @classmethod
    def of(cls, functions: EventFunctions) -> CompiledFunctions | None:
        """The compiled reads of ``functions``, or None on the numpy route and for models
        whose boundary displacement or area check is their own.
        """
        model = functions.model
        if (selected() != Kernel.NUMBA or model.reference
                or type(model).boundary_displacement is not ContactModel.boundary_displacement
                or type(model).area_ratio is not ContactModel.area_ratio):
            return None
        return cls(functions)

    @staticmethod
    def takes(contacts: ContactSet) -> bool:
        """Whether the contact set has the fast model's boundary compliance."""
        return contacts.data.A_bc is not None

    def values(self, contacts: ContactSet, sol: Solution, s: float, rows: np.ndarray,
               pick: np.ndarray, terminations: bool, *, strain: bool = True) -> tuple:
        """(the per-contact values ``pick`` and the gaps of ``rows``, det F, its element or
        -1, eps* - max strain, pickup margin) at ``sol``: the terminations inf unless asked
        (the area also while the fingers do not move, the strain unless ``strain``), the
        model's det F once an element nears inversion.
        """
        values, det, element, pickup = self._read(contacts, sol, s, rows, pick,
                                                  terminations or self._area_kept(contacts))
        if not terminations:
            return values, np.inf, -1, np.inf, np.inf
        functions = self.functions
        if np.isnan(det):  # the set's load gradients are not kept yet: the model keeps them
            det, element = functions.model.area_ratio(contacts.data, sol.delta, sol.F)
        margin = functions.strain_margin(contacts, sol) if strain else np.inf
        return values, det, element, margin, pickup

    def _read(self, contacts: ContactSet, sol: Solution, s: float, rows: np.ndarray,
              pick: np.ndarray, area: bool) -> tuple[np.ndarray, float, int, float]:
        """The kernel's (values, area ratio, its element, pickup margin) at ``sol``; the area
        ratio inf unless ``area`` (its O(t m) bound over every element is most of a read's
        time on a large mesh, and a read for the pending events alone does not use it:
        :meth:`_area_kept`).

        The last read is kept: at an event point the pending events, the terminations and the
        next substep's start read the same solution (the area and the pickup margin of any
        rows, the values of the same rows, contacts and point), one kernel call for all, and
        one more for the area when the pending events' read left it out.
        """
        last = self._last
        if last is not None and last[0] is contacts and last[1] is sol:
            same = last[2] == s and _same(last[3], rows) and _same(last[4], pick)
            if same or not len(rows) and not len(pick):
                if area and not last[7]:
                    args, ends = self._arguments(contacts, sol, s, _NO_PICK, _NO_PICK, True)
                    last = self._last = (*last[:6], self.kernel.watched_values(*args, *ends)[1:],
                                         True)
                return (last[5] if same else _NO_VALUES, *last[6])
        args, ends = self._arguments(contacts, sol, s, rows, pick, area)
        values, *ends = self.kernel.watched_values(*args, *ends)
        self._last = (contacts, sol, s, rows, pick, values, ends, area)
        return (values, *ends)

    def _arguments(self, contacts: ContactSet, sol: Solution, s: float, rows: np.ndarray,
                   pick: np.ndarray, area: bool) -> tuple[tuple, tuple]:
        """:func:`..substeps_numba.watched_values`'s arguments: those of the values
        (:func:`..substeps_numba._watched`'s), those of the terminations (no area bounds,
        so no area check, unless ``area``).
        """
        functions = self.functions
        model, motion = functions.model, functions.motion
        rate = motion.rate
        A, R, points, bounds = self._rows_of(contacts, rows)
        tip = motion.tip
        if not area:
            bounds = _NO_BOUNDS
        loads = model.area_tables(contacts.data)[1] if len(bounds) else None
        return ((sol.delta, sol.F, sol.dtheta, sol.normal_angle, pick, float(model.mu),
                 contacts.slip, motion.contact_tips(contacts.finger).tip.radius,
                 rate if rate > 0 else 1.0, A, R, contacts.data.E, points, motion.centers(s),
                 tip.radius, tip.flat, tip._facing_tangent),
                (contacts.stick, contacts.finger, self.weight, model.obj.rigid_gradients, bounds,
                 self.kernel.NO_LOADS if loads is None else loads, GRADIENT_BOUND_EXACT))

    def point(self, contacts: ContactSet, sol: Solution, s: float, rows: np.ndarray,
              pick: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(the values :meth:`values` reads, the gap slopes of ``rows`` to every finger, each
        contact's normal-force and cone-margin slopes) at ``sol`` by one kernel call
        (:func:`..substeps_numba.point_values`; the area check left out on a large mesh, see
        :meth:`_read`), kept as the last read and the last slopes: the pending events at a
        point read both, the terminations and the next substep's start read them again.
        """
        area = self._area_kept(contacts)
        args, ends = self._arguments(contacts, sol, s, rows, pick, area)
        values, det, element, pickup, gaps, rates = self.kernel.point_values(
            *args, *ends, sol.ddelta, sol.dF, self._kappa(sol), self.functions.motion.translation)
        self._last = (contacts, sol, s, rows, pick, values, (det, element, pickup), area)
        self._last_slopes = (contacts, sol, s, rows, gaps, rates)
        return values, gaps, rates

    def slopes(self, contacts: ContactSet, sol: Solution, s: float,
               rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(the gap slopes of ``rows`` to every finger, each contact's normal-force and
        cone-margin slopes), raveled, at ``sol`` (those :meth:`point` read last if it read
        them).
        """
        last = self._last_slopes
        if (last is not None and last[0] is contacts and last[1] is sol and last[2] == s
                and _same(last[3], rows)):
            return last[4], last[5]
        motion = self.functions.motion
        A, R, points, _ = self._rows_of(contacts, rows)
        tip = motion.tip
        return self.kernel.slope_values(
            sol.delta, sol.F, sol.ddelta, sol.dF, sol.dtheta, sol.normal_angle,
            self._kappa(sol), float(self.functions.model.mu), A, R, contacts.data.E, points,
            motion.centers(s), motion.translation, tip.flat, tip._facing_tangent)

    def _area_kept(self, contacts: ContactSet) -> bool:
        """Whether a read that does not need the area check computes it all the same: on a
        mesh whose elements times contacts are under :data:`AREA_DEFERRED_FROM`, where the
        check costs less than a second call for it when the terminations read it.
        """
        return len(self.functions.model.obj.mesh.triangles) * len(contacts) < AREA_DEFERRED_FROM

    @staticmethod
    def _kappa(sol: Solution) -> np.ndarray:
        """The contacts' d nu / d theta, or none for circular tips."""
        return _NO_KAPPA if sol.kappa is None else sol.kappa

    def _rows_of(self, contacts: ContactSet, rows: np.ndarray) -> tuple:
        """(the rows of the set's boundary compliance and rigid modes, the rows' undeformed
        positions, the area bounds or none while the fingers stay) of ``contacts`` and boundary
        ``rows``: kept for the call's last few sets (a point's reads and the substeps of a set
        ask for the same ones), by the object for its models' calls (what they depend on is
        the object's: a sweep's evaluations of an object ask for the same ones too); the last
        ones by identity (the free rows are a kept read-only array per set and holds).
        """
        sd, last = contacts.data, self._last_rows
        if last is not None and last[0] is sd and last[1] is rows:
            return last[2]
        moving = self.functions.motion.rate > 0
        made = kept_for(self._rows, sd, (moving, rows.dtype.str, rows.tobytes()),
                        lambda: self._tables(sd, rows, moving), ROW_TABLES_KEPT)
        self._last_rows = (sd, rows, made)
        return made

    def _tables(self, sd: SetData, rows: np.ndarray, moving: bool) -> tuple:
        functions = self.functions
        model = functions.model
        return (*model._boundary_rows(sd, rows), functions._boundary[rows],
                model.area_tables(sd)[0] if moving else _NO_BOUNDS)
