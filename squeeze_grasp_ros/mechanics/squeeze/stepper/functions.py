# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The event functions: their values and slopes d/ds at a solution (paper Sec. 5.1-5.3).

:func:`event_values` and :func:`pickup_margin` are pure functions of one contact set's arrays;
:class:`EventFunctions` evaluates them for a call (its model, finger motion and terminations)
at a solution and names each by its :class:`~..event_key.EventKey`:

=============  ==========================================  =============  ========  ========
key function   value (positive = no event)                 nodes          slope     paper
=============  ==========================================  =============  ========  ========
GAP            gap |x_k - o_f| - r_f, per finger           free boundary  yes       eq. 48
NORMAL_FORCE   normal force f_n = f . e(theta)             contact        yes       eq. 49
CONE_PLUS/-    cone margins mu f_n +/- f_t                 sticking       yes       eq. 50
SLIP_RATE      slip . d theta / ds (slip rate)             sliding        no        eq. 51
AREA           min det F - INVERSION_AREA_RATIO            (object)       no
STRAIN         eps* - max strain (with a strain limit)     (object)       no        eq. 45
PICKUP         w / n_f - min_f sum_k c_k (with a weight)   (object)       no
=============  ==========================================  =============  ========  ========

A new kind of event is a new :class:`~..event_key.EventFunction`, its value in
:meth:`EventFunctions.entries` and :meth:`EventFunctions.value`, and, if it has one, its slope
in :meth:`EventFunctions.slopes` (then it is located on Hermite interpolants and checked for
double roots inside an adaptive substep).

>>> values = event_values(mu=0.5, fn=np.array([1.0]), ft=np.array([0.2]), slip=np.array([0]),
...                       dtheta=np.zeros(1), radius=np.ones(1), rate=1.0, gaps=np.zeros((0, 2)))
>>> float(values.c_plus[0]), float(values.c_minus[0])
(0.7, 0.3)
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    INVERSION_AREA_RATIO,
    ContactModel,
    Solution,
)
from squeeze_grasp_ros.mechanics.squeeze.event_key import (
    SHARED_KEYS,
    EventFunction,
    EventKey,
    KeyTable,
)
from squeeze_grasp_ros.mechanics.squeeze.kept import kept_property
from squeeze_grasp_ros.mechanics.squeeze.stepper.compiled_functions import CompiledFunctions
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.motion import FingerMotion
from squeeze_grasp_ros.mechanics.vocabulary import Termination

__all__ = ["EventFunctions", "EventValues", "KeyOrder", "WatchedValues", "event_values",
           "pending_values", "pickup_margin"]

_NO_ROWS = np.zeros(0, int)
_SLOPED_FUNCTIONS = (EventFunction.NORMAL_FORCE, EventFunction.CONE_PLUS,
                     EventFunction.CONE_MINUS)
"""The per-contact functions with a slope, in the order of a contact's slopes."""
ENTRY_TABLES_KEPT = 2048
"""Tables of keys and rows an object keeps for its calls' event functions
(:attr:`EventFunctions._entry_tables`; checked once per call)."""


def pickup_margin(
    mu: float,
    fn: np.ndarray,
    ft: np.ndarray,
    stick: np.ndarray,
    finger: np.ndarray,
    fingers: list[int],
    weight: float,
) -> float:
    """How far the grasp is from lifting the object, in force units (> 0: cannot lift yet).

    The object lies on a horizontal plane and is lifted out of it. A contact node with normal
    force f_n and in-plane tangential force f_t can supply at most
    c_k = sqrt(mu^2 f_n^2 - f_t^2) of vertical friction (Sec. 5.1); a sliding node (force on the
    cone edge) supplies none. The object is picked up when every finger with contacts can
    supply its share: min over those fingers of sum_k c_k >= w / (number of such fingers)
    (torque balance by friction assumed, as in the paper). Returns w / n_f - min_f sum_k c_k.
    """
    c = np.where(stick, np.sqrt(np.maximum(mu * mu * fn * fn - ft * ft, 0.0)), 0.0)
    totals = [c[finger == f].sum() for f in fingers]
    return float(weight / len(fingers) - min(totals))


@dataclass(frozen=True)
class EventValues:
    """Event-function values at one solution.

    Attributes
    ----------
    fn : (m,) ndarray
        Normal forces (Event B at 0).
    c_plus, c_minus : (m,) ndarray
        Cone margins mu f_n + f_t and mu f_n - f_t (Event C at 0).
    d : (m,) ndarray
        Slip rates of sliding nodes along their slip direction (Event D at 0).
    gaps : (k, f) ndarray
        Gaps of free boundary nodes to every fingertip (Event A at 0).
    strain, pickup : float
        Termination margins (inf when not checked).
    area : float
        Smallest element area ratio det F less the inversion threshold (termination at 0; inf
        when not checked).
    """

    fn: np.ndarray
    c_plus: np.ndarray
    c_minus: np.ndarray
    d: np.ndarray
    gaps: np.ndarray
    strain: float
    pickup: float
    area: float = np.inf

    def of_contact(self, function: EventFunction, k: int) -> float:
        """The value of a per-contact function (B, C+, C-, D) of contact k."""
        return float({EventFunction.NORMAL_FORCE: self.fn, EventFunction.CONE_PLUS: self.c_plus,
                      EventFunction.CONE_MINUS: self.c_minus,
                      EventFunction.SLIP_RATE: self.d}[function][k])


def event_values(*, mu: float, fn: np.ndarray, ft: np.ndarray, slip: np.ndarray,
                 dtheta: np.ndarray, radius: np.ndarray, rate: float, gaps: np.ndarray,
                 strain: float = np.inf, pickup: float = np.inf,
                 area: float = np.inf) -> EventValues:
    """The event functions of one contact set at one solution.

    ``slip`` is each node's slip direction (0 when sticking), ``dtheta`` d theta/ds, ``radius``
    the tip radius of its finger, ``rate`` the length of the fingers' motion per unit s.
    """
    d = slip * dtheta * radius / (rate if rate > 0 else 1.0)
    return EventValues(fn, mu * fn + ft, mu * fn - ft, d, gaps, strain, pickup, area)


@dataclass(frozen=True, eq=False)
class KeyOrder:
    """The keys of the watched functions held in one array, in its order."""

    keys: tuple[EventKey, ...]

    @kept_property
    def position(self) -> dict[EventKey, int]:
        """Each key's index in the array."""
        return {key: k for k, key in enumerate(self.keys)}


class WatchedValues(Mapping):
    """The watched functions' values at one point, by key (a read-only mapping): the
    per-contact functions and the gaps in one array ``values`` with its keys ``order``, the
    terminations checked in ``ends``. Two of them with the same ``order`` (a substep's ends)
    are compared elementwise (:func:`~.location.crossings`).
    """

    __slots__ = ("ends", "order", "values")

    def __init__(self, order: KeyOrder, values: np.ndarray, ends: dict[EventKey, float]) -> None:
        self.order, self.values, self.ends = order, values, ends

    def __getitem__(self, key: EventKey) -> float:
        k = self.order.position.get(key)
        return self.ends[key] if k is None else self.values[k]

    def __contains__(self, key: object) -> bool:
        return key in self.order.position or key in self.ends

    def __iter__(self) -> Iterator[EventKey]:
        yield from self.order.keys
        yield from self.ends

    def __len__(self) -> int:
        return len(self.order.keys) + len(self.ends)

    def items(self) -> list[tuple[EventKey, float]]:  # type: ignore[override]
        """(key, value) in order."""
        return [*zip(self.order.keys, self.values), *self.ends.items()]


@dataclass(frozen=True)
class EventFunctions:
    """The event functions of one call (dimensionless).

    Attributes
    ----------
    model : ContactModel
    motion : FingerMotion
    terminate_on : tuple of Termination
        Terminations the call checks (strain and pickup only if the model's limits declare
        them; element inversion always).
    """

    model: ContactModel
    motion: FingerMotion
    terminate_on: tuple[str, ...]

    @property
    def frictionless(self) -> bool:
        """Whether mu = 0: every contact slides and no cone margin is watched."""
        return self.model.mu == 0.0

    def free_rows(self, contacts: ContactSet, held: list[int]) -> np.ndarray:
        """Boundary loop positions watched for Event A: not in contact, not ``held`` (kept
        for the call's contact sets and holds; read-only).
        """
        tag = ("free", contacts.rows.tobytes(), *held)
        made = self._entry_tables.get(tag)
        if made is None:
            mask = np.ones(len(self.model.boundary_nodes), bool)
            mask[contacts.rows] = False
            for node in held:
                mask[self.model.obj.boundary_positions([node])[0]] = False
            made = self._entry_tables[tag] = np.flatnonzero(mask)
            made.flags.writeable = False
        return made

    def rows_of(self, nodes) -> np.ndarray:
        """Boundary loop positions of ``nodes``."""
        return self.model.obj.boundary_positions(nodes)

    @property
    def keys(self) -> KeyTable:
        """The event keys (one table for the process: keys are values)."""
        return SHARED_KEYS

    @kept_property
    def _gap_keys(self) -> list[tuple[EventKey, ...]]:
        """The gap keys of every boundary loop position, one per finger."""
        return self.keys.gaps(self.model.boundary_nodes.tolist(), len(self.motion.names))

    @kept_property
    def _boundary(self) -> np.ndarray:
        """Undeformed positions / L (b, 2) of the outer boundary loop."""
        return self.model.positions(self.model.boundary_nodes)

    def _boundary_points(self, contacts: ContactSet, sol: Solution,
                         rows: np.ndarray) -> np.ndarray:
        """Deformed positions / L of boundary loop positions ``rows`` at ``sol``."""
        u = self.model.boundary_displacement(contacts.data, sol.delta, sol.F, rows)
        return self._boundary[rows] + u

    def boundary_point(self, contacts: ContactSet, sol: Solution, node: int) -> np.ndarray:
        """Deformed position / L (2,) of boundary ``node`` at ``sol``."""
        return self._boundary_points(contacts, sol, self.rows_of([node]))[0]

    def gaps(self, contacts: ContactSet, sol: Solution, s: float,
             rows: np.ndarray) -> np.ndarray:
        """Gaps (k, f) of boundary positions ``rows`` to every fingertip."""
        return self.motion.gaps(self._boundary_points(contacts, sol, rows), s)

    def termination_values(self, contacts: ContactSet, sol: Solution) -> tuple[float, float]:
        """(eps* - max strain, pickup margin); inf for criteria not declared or not enabled."""
        model, lim = self.model, self.model.limits
        strain, pickup = self.strain_margin(contacts, sol), np.inf
        if lim.weight is not None and Termination.PICKED_UP in self.terminate_on:
            pickup = pickup_margin(model.mu, sol.normal, sol.tangential, contacts.stick,
                                   contacts.finger, sorted(set(contacts.finger.tolist())),
                                   lim.weight / model.force_unit)
        return strain, pickup

    def strain_margin(self, contacts: ContactSet, sol: Solution) -> float:
        """eps* - max strain (inf without a strain limit or when it is not enabled)."""
        lim = self.model.limits
        if lim.strain is None or Termination.STRAIN_LIMIT not in self.terminate_on:
            return np.inf
        return lim.strain - self.model.max_strain(contacts.data, sol.delta, sol.F)[0]

    def area_value(self, contacts: ContactSet, sol: Solution) -> float:
        """The smallest area ratio det F less INVERSION_AREA_RATIO (element_inverted at <= 0)."""
        return area_ratio_at(self.model, contacts, sol)[0] - INVERSION_AREA_RATIO

    def values(self, contacts: ContactSet, sol: Solution, s: float, rows: np.ndarray,
               terminations: bool = True) -> EventValues:
        """All event functions at ``sol`` (and the termination functions if asked)."""
        strain, pickup = (self.termination_values(contacts, sol) if terminations
                          else (np.inf, np.inf))
        area = (self.area_value(contacts, sol) if terminations and self.motion.rate > 0
                else np.inf)
        return event_values(mu=self.model.mu, fn=sol.normal, ft=sol.tangential,
                            slip=contacts.slip, dtheta=sol.dtheta,
                            radius=self.motion.radius[contacts.finger], rate=self.motion.rate,
                            gaps=self.gaps(contacts, sol, s, rows), strain=strain,
                            pickup=pickup, area=area)

    def entries(self, contacts: ContactSet, v: EventValues, rows: np.ndarray,
                held: np.ndarray) -> WatchedValues:
        """The watched functions by key, in a fixed order: per contact not ``held`` (mask) its
        normal force and its cone margins or slip rate, per held sticking contact its cone
        margins (a frozen node may still start to slide, never stick outside its cone), then
        every free boundary row's gaps (one array, its keys a table kept for the contact set,
        mask and rows), then the terminations that are checked.
        """
        keys, pick = self._contact_entries(contacts, held)
        table = np.concatenate((v.fn, v.c_plus, v.c_minus, v.d))
        values = np.concatenate((table[pick], v.gaps.ravel()))
        return WatchedValues(self._order(keys, rows), values,
                             self._ends(v.area, v.strain, v.pickup))

    def watched(self, contacts: ContactSet, sol: Solution, s: float, rows: np.ndarray,
                held: np.ndarray, *, terminations: bool = True) -> WatchedValues:
        """:meth:`entries` of :meth:`values` at ``sol`` (free boundary ``rows``, contacts
        ``held`` left out; the terminations if asked).

        On the numba route, for the fast model's boundary compliance, the per-contact values,
        the gaps, the area ratio while no element nears inversion and the pickup margin are one
        compiled call (:class:`~.compiled_functions.CompiledFunctions`, the numpy code's
        floats, a zero's sign aside); an element near inversion and a strain limit are
        computed by the model.
        """
        compiled = self._compiled
        if compiled is None or not compiled.takes(contacts):
            return self.entries(contacts, self.values(contacts, sol, s, rows, terminations),
                                rows, held)
        keys, pick = self._contact_entries(contacts, held)
        values, det, _, strain, pickup = compiled.values(contacts, sol, s, rows, pick,
                                                         terminations)
        return WatchedValues(self._order(keys, rows), values,
                             self._ends(det - INVERSION_AREA_RATIO, strain, pickup))

    def end_values(self, contacts: ContactSet, sol: Solution) -> tuple[float, int, float, float]:
        """(smallest area ratio det F, its element or -1 when none is near inversion,
        eps* - max strain, pickup margin) at ``sol``: what the terminations check, in their
        order (the margins inf for criteria not declared or not enabled, and not measured when
        the area already ends the motion). On the numba route as :meth:`watched` computes
        them.
        """
        compiled = self._compiled
        if compiled is None or not compiled.takes(contacts):
            det, element = area_ratio_at(self.model, contacts, sol)
            if det <= INVERSION_AREA_RATIO:
                return det, element, np.inf, np.inf
            return (det, element, *self.termination_values(contacts, sol))
        _, det, element, _, pickup = compiled.values(contacts, sol, 0.0, _NO_ROWS, _NO_ROWS,
                                                     True, strain=False)
        if det <= INVERSION_AREA_RATIO:
            return det, element, np.inf, np.inf
        return det, element, self.strain_margin(contacts, sol), pickup

    @kept_property
    def _compiled(self) -> CompiledFunctions | None:
        """The compiled reads of this call's functions (numba route), or None."""
        return CompiledFunctions.of(self)

    def _order(self, keys: list[EventKey], rows: np.ndarray) -> KeyOrder:
        """The :class:`KeyOrder` of per-contact ``keys`` and the gaps of ``rows`` (kept with
        ``keys``, by identity: a list the tables no longer hold may share a dead one's id).
        """
        tag = ("watched", id(keys), rows.dtype.str, rows.tobytes())
        made = self._entry_tables.get(tag)
        if made is None or made[0] is not keys:
            made = self._entry_tables[tag] = (
                keys, KeyOrder((*keys, *self._row_gap_keys(rows))))
        return made[1]

    def _ends(self, area: float, strain: float, pickup: float) -> dict[EventKey, float]:
        """The termination functions that are checked (finite), by key."""
        ends = {}
        for function, value in ((EventFunction.AREA, area), (EventFunction.STRAIN, strain),
                                (EventFunction.PICKUP, pickup)):
            if math.isfinite(value):
                ends[self.keys.get(function)] = value
        return ends

    @kept_property
    def _entry_tables(self) -> dict[tuple, object]:
        """Key lists and free rows made so far (:meth:`_contact_entries`, :meth:`_row_gap_keys`,
        :meth:`_sloped_keys`, :meth:`free_rows`, :meth:`_order`), by what they depend on: kept
        by the object for the calls of its models with friction or without and as many
        fingers (they depend on those and their tag only; a sweep's evaluations of an object
        ask for the same ones), emptied beyond :data:`ENTRY_TABLES_KEPT`.
        """
        tables = self.model.obj._shared.setdefault(
            ("event_tables", self.frictionless, len(self.motion.names)), {})
        if len(tables) >= ENTRY_TABLES_KEPT:
            tables.clear()
        return tables

    def _contact_entries(self, contacts: ContactSet,
                         held: np.ndarray) -> tuple[list[EventKey], np.ndarray]:
        """The keys of the per-contact functions :meth:`entries` watches, and where each one's
        value is in the table (fn, c_plus, c_minus, d) of the contacts' values laid end to end.
        """
        tag = ("contacts", contacts.nodes.tobytes(), contacts.stick.tobytes(),
               np.asarray(held, bool).tobytes())
        made = self._entry_tables.get(tag)
        if made is None:
            m, keys, pick, key = len(contacts), [], [], self.keys.get
            for k, node in enumerate(contacts.nodes.tolist()):
                if not held[k]:
                    keys.append(key(EventFunction.NORMAL_FORCE, node))
                    pick.append(k)
                if self.frictionless or (held[k] and not contacts.stick[k]):
                    continue
                if contacts.stick[k]:
                    keys += [key(EventFunction.CONE_PLUS, node),
                             key(EventFunction.CONE_MINUS, node)]
                    pick += [m + k, 2 * m + k]
                else:
                    keys.append(key(EventFunction.SLIP_RATE, node))
                    pick.append(3 * m + k)
            made = self._entry_tables[tag] = (keys, np.array(pick, int))
        return made

    def _row_gap_keys(self, rows: np.ndarray) -> list[EventKey]:
        """The gap keys of boundary positions ``rows``, row after row, finger after finger
        (the order of a (rows, fingers) array raveled).
        """
        tag = ("rows", rows.dtype.str, rows.tobytes())
        made = self._entry_tables.get(tag)
        if made is None:
            gap_keys = self._gap_keys
            made = self._entry_tables[tag] = [k for row in rows.tolist() for k in gap_keys[row]]
        return made

    def slopes(self, contacts: ContactSet, sol: Solution, s: float,
               rows: np.ndarray) -> dict[EventKey, float]:
        """Slopes d/ds at ``sol`` of the gaps of boundary positions ``rows`` and of every
        contact's normal force and cone margins (the functions with
        :attr:`~..event_key.EventFunction.has_slope`).
        """
        compiled = self._compiled
        if compiled is not None and compiled.takes(contacts):
            gaps, rates = compiled.slopes(contacts, sol, s, rows)
            out = dict(zip(self._row_gap_keys(rows), gaps.tolist())) if len(rows) else {}
            out.update(zip(self._sloped_keys(contacts), rates.tolist()))
            return out
        fn_r, ft_r = sol.normal_rate, sol.tangential_rate
        mu = self.model.mu
        out = {}
        if len(rows):
            points = self._boundary_points(contacts, sol, rows)
            velocities = self.model.boundary_rate(contacts.data, sol, rows)
            g_rate = self.motion.gap_slopes(points, velocities, s)
            out.update(zip(self._row_gap_keys(rows), g_rate.ravel().tolist()))
        rates = np.empty((len(contacts), 3))
        rates[:, 0] = fn_r
        rates[:, 1] = mu * fn_r + ft_r
        rates[:, 2] = mu * fn_r - ft_r
        out.update(zip(self._sloped_keys(contacts), rates.ravel().tolist()))
        return out

    def _sloped_keys(self, contacts: ContactSet) -> list[EventKey]:
        """Each contact's normal-force and cone-margin keys, contact after contact."""
        tag = ("sloped", contacts.nodes.tobytes())
        made = self._entry_tables.get(tag)
        if made is None:
            key = self.keys.get
            made = self._entry_tables[tag] = [
                key(function, node) for node in contacts.nodes.tolist()
                for function in _SLOPED_FUNCTIONS]
        return made

    def value(self, key: EventKey, contacts: ContactSet, sol: Solution, s: float) -> float:
        """The value of one function at ``sol`` (for root location)."""
        function = key.function
        if function == EventFunction.AREA:
            return self.area_value(contacts, sol)
        if function in (EventFunction.STRAIN, EventFunction.PICKUP):
            strain, pickup = self.termination_values(contacts, sol)
            return strain if function == EventFunction.STRAIN else pickup
        if function == EventFunction.GAP:
            return float(self.gaps(contacts, sol, s, self.rows_of([key.node]))[0, key.finger])
        v = self.values(contacts, sol, s, _NO_ROWS, terminations=False)
        return v.of_contact(function, contacts.index(key.node))

    def slope(self, key: EventKey, contacts: ContactSet, sol: Solution, s: float) -> float:
        """The slope d/ds of one function that has one."""
        rows = self.rows_of([key.node]) if key.function == EventFunction.GAP else _NO_ROWS
        return self.slopes(contacts, sol, s, rows)[key]


def area_ratio_at(model: ContactModel, contacts: ContactSet, sol: Solution) -> tuple[float, int]:
    """``model``'s :meth:`~..contact_model.ContactModel.area_ratio` (smallest det F, its
    element or -1) at ``sol`` of ``contacts``, kept in the solution: at an event point the
    terminations and the next substep's start read the same solution, and on a large mesh
    the check's O(t m) bound over every element is most of a read (the 20,091-node foam
    square's numpy route at mu = 0.05: 285 checks before, 231 with this).
    """
    kept = sol.__dict__.get("_area_ratio")
    if kept is None or kept[0] is not contacts.data:
        kept = sol.__dict__["_area_ratio"] = (
            contacts.data, model.area_ratio(contacts.data, sol.delta, sol.F))
    return kept[1]


def pending_values(
    functions: EventFunctions, contacts: ContactSet, sol: Solution, s: float, rows: np.ndarray,
    held: np.ndarray, sloped: Callable[[dict[EventKey, int]], dict[int, EventKey]],
    gap_nodes: list[int],
) -> tuple[KeyOrder, np.ndarray, dict[int, EventKey], list[float]]:
    """What the pending events at a point read: the watched per-contact values and gaps of
    :meth:`EventFunctions.watched` (no terminations), their keys, the watched keys whose
    slopes are needed (``sloped`` of the keys' positions: gaps of ``gap_nodes``, normal
    forces, cone margins) and those slopes.

    On the numba route one compiled call computes the values and the slopes of every watched
    function (:meth:`~.compiled_functions.CompiledFunctions.point`; a gap's slope is then the
    free rows' product, in numpy the rows of ``gap_nodes``': only its sign decides); in numpy,
    :meth:`EventFunctions.watched`, then :meth:`EventFunctions.slopes` of the rows of
    ``gap_nodes`` when slopes are needed.
    """
    compiled = functions._compiled
    if compiled is None or not compiled.takes(contacts):
        watched = functions.watched(contacts, sol, s, rows, held, terminations=False)
        order = watched.order
        by_slope = sloped(order.position)
        if not by_slope:
            return order, watched.values, by_slope, []
        slopes = functions.slopes(contacts, sol, s, functions.rows_of(gap_nodes))
        return order, watched.values, by_slope, [slopes[key] for key in by_slope.values()]
    keys, pick = functions._contact_entries(contacts, held)
    order = functions._order(keys, rows)
    by_slope = sloped(order.position)
    if not by_slope:
        values, *_ = compiled.values(contacts, sol, s, rows, pick, False)
        return order, values, by_slope, []
    values, gaps, rates = compiled.point(contacts, sol, s, rows, pick)
    first_gap, sloped_keys = len(pick), by_slope.values()
    at = np.searchsorted(contacts.nodes, [key.node for key in sloped_keys]).tolist()
    gaps, rates = gaps.tolist(), rates.tolist()
    return order, values, by_slope, [
        gaps[k - first_gap] if key.function == EventFunction.GAP
        else rates[3 * i + _SLOPED_FUNCTIONS.index(key.function)]
        for (k, key), i in zip(by_slope.items(), at)]
