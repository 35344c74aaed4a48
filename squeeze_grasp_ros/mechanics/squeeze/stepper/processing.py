# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event processing at one point of a stepper call (Algorithm 1 lines 10-14; deterministic).

Pending events are those whose function is <= 0, or, for functions that are zero by
construction at the point (a new contact's force and cone margins, a freed node's gap, a
just-stuck node's cone margin: the ``fresh`` keys), whose slope along the motion is negative.
They are processed one at a time in :data:`~..event_key.PROCESSING_ORDER` (B < D < C < A), then
by finger (F1, F2, A) and node index, re-solving after each:

* all new contacts pending at the point are added together and their modes decided jointly
  (:func:`~.modes.decide_modes`);
* a node whose C/D event would flip back at the same point has no consistent mode on its own:
  the nodes with C/D events at the point are then decided jointly, and their events at the
  point are replaced by the net mode change;
* finger slip is checked after every event and stops the processing; a break that would leave
  a finger without contact is not applied and ends the call as ``contact_lost``;
* a node that would exceed the chattering bound (:class:`~.chatter.ChatterBound`), flips again
  after a joint decision, or has a second A/B event at one point, is frozen instead; a frozen
  node that sticks still slides when its force reaches its friction cone (event C, not
  counted: it then stays sliding until the hold ends), so no node sticks outside its cone.

Then the terminations are checked in the order element_inverted < strain_limit <
contact_lost < finger_slip < picked_up.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial

import numpy as np

from squeeze_grasp_ros.mechanics.errors import NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import INVERSION_AREA_RATIO, Solution
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, Event
from squeeze_grasp_ros.mechanics.squeeze.event_key import WHOLE_OBJECT, EventFunction, EventKey
from squeeze_grasp_ros.mechanics.squeeze.stepper.chatter import ChatterBound
from squeeze_grasp_ros.mechanics.squeeze.stepper.contact_set import ContactSet
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import EventFunctions, pending_values
from squeeze_grasp_ros.mechanics.squeeze.stepper.modes import (
    RATE_NOISE,
    decide_modes,
    zero_functions,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper.solving import SetSolver
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, EventType, Termination

__all__ = ["EventProcessor"]

_CONES = (EventFunction.CONE_PLUS, EventFunction.CONE_MINUS)
_CONTACT_CHANGES = (EventFunction.GAP, EventFunction.NORMAL_FORCE)


@dataclass
class _Point:
    """What processing at one point has seen: the modes before it, where its events start,
    and the nodes with contact (A/B) or mode (C/D) events and those decided jointly.
    """

    before: dict[int, tuple[bool, int]]
    first_event: int
    contact_events: set[int] = field(default_factory=set)
    mode_events: set[int] = field(default_factory=set)
    settled: set[int] = field(default_factory=set)


class EventProcessor:
    """The contact set of a call at its current point s, and the processing of its events.

    Attributes
    ----------
    contacts : ContactSet
    fresh : set of EventKey
        Functions zero by construction at the current point.
    undetermined : set of int
        Contact nodes whose mode the next motion decides.
    lost : str or None
        A finger a contact break would have left without contact.
    events : list of Event
        Events processed during the call, in order.
    s : float
        The current point.
    tol : float
        Event tolerance, / L: a freed node's gap to another tip than the one that released it
        is not zero by construction.
    """

    def __init__(self, state: ContactState, contacts: ContactSet, functions: EventFunctions,
                 solver: SetSolver, chatter: ChatterBound, tol: float) -> None:
        self.functions, self.solver, self.chatter, self.tol = functions, solver, chatter, tol
        self.model, self.motion = functions.model, functions.motion
        self.relative_per_depth = state.relative_per_depth
        self.contacts = contacts
        self.fresh: set[EventKey] = set(state.fresh)
        self.undetermined = set(state.undetermined)
        self.lost: str | None = None
        self.events: list[Event] = []
        self.s = 0.0

    @property
    def depth(self) -> float:
        """Depth at the current point, m."""
        return self.motion.depth_at(self.s)

    def move_to(self, s: float, theta: np.ndarray) -> None:
        """Go on to point s, where the contacts are at polar angles ``theta`` and no function
        is zero by construction.
        """
        self.s = s
        self.fresh = set()
        self.contacts = self.contacts.with_theta(theta)

    # ------------------------------------------------------------------ recording
    def _log(self, kind: EventType, node: int, finger: int, mode: str, slip: int) -> None:
        depth = self.depth
        self.events.append(Event(kind, int(node), self.motion.names[finger], depth,
                                 depth * self.relative_per_depth, mode, int(slip)))

    def _log_contact(self, kind: EventType, k: int) -> None:
        """Append an event of contact k (its mode and slip after the event)."""
        c = self.contacts
        self._log(kind, c.nodes[k], c.finger[k],
                  ContactMode.STICK if c.stick[k] else ContactMode.SLIP, c.slip[k])

    def _admit(self, node: int, finger: int) -> bool:
        return self.chatter.admit(node, self.motion.names[finger], self.depth)

    # ------------------------------------------------------------------ modes
    @property
    def rate_floor(self) -> float:
        """The mode decision's noise floor on rates: :data:`~.modes.RATE_NOISE` x the motion
        per unit s (in units of E h and L a contact stiffness is of order 1, so this is the
        force rate of a stuck contact to within a factor of ten either way).
        """
        return RATE_NOISE * self.motion.rate

    def decide(self, nodes: list[int]) -> None:
        """Decide the modes of contact ``nodes`` jointly (:func:`~.modes.decide_modes`) and
        update the fresh keys: a sticking node keeps its zero cone margins, a sliding one not.
        """
        zero = zero_functions(self.contacts, self.fresh)
        choice = decide_modes(self.contacts, nodes, zero,
                              lambda contacts: self.solver.attempt(contacts, self.s),
                              mu=self.model.mu, rate_floor=self.rate_floor,
                              search=partial(self.solver.decide, s=self.s))
        if choice.violations > 0:
            self.solver.counters.ambiguous_modes += 1
        self.contacts = self.contacts.with_modes(choice.stick, choice.slip).with_theta(
            choice.theta)
        for node in nodes:
            cones = {EventKey(function, int(node)) for function in _CONES}
            if self.contacts.stick[self.contacts.index(node)]:
                self.fresh |= cones & zero
            else:
                self.fresh -= cones
        self.undetermined -= set(nodes)

    # ------------------------------------------------------------------ pending events
    def pending(self, sol: Solution) -> list[EventKey]:
        """Pending contact events at the current point, in processing order.

        A function is pending where its value is <= 0 (one array comparison), except the
        watched keys zero by construction (:meth:`_by_slope`), which are pending where their
        slope is negative (:func:`~.functions.pending_values` reads the values
        and those slopes together).
        """
        contacts, functions, depth = self.contacts, self.functions, self.depth
        rows = functions.free_rows(contacts, self.chatter.held_nodes(depth))
        gap_nodes = [key.node for key in self.fresh if key.function == EventFunction.GAP]
        order, values, by_slope, slopes = pending_values(
            functions, contacts, sol, self.s, rows, self.chatter.held(contacts.nodes, depth),
            self._by_slope, gap_nodes)
        hits = [k for k in np.flatnonzero(values <= 0).tolist() if k not in by_slope]
        for (k, key), slope in zip(by_slope.items(), slopes):
            if key.function == EventFunction.GAP and values[k] > self.tol:
                continue  # a freed node is at zero gap only to the finger that released it
            if slope < 0:
                hits.append(k)
        keys = order.keys
        return sorted([keys[k] for k in sorted(hits)], key=self.order)

    def _by_slope(self, position: dict[EventKey, int]) -> dict[int, EventKey]:
        """The watched keys (by their position) whose function is zero by construction and
        has a slope: a fresh node's gap to every tip, a fresh normal force or cone margin.
        """
        out = {}
        fingers = range(len(self.motion.names))
        for fresh in self.fresh:
            if fresh.function == EventFunction.GAP:
                candidates = [EventKey.gap(fresh.node, f) for f in fingers]
            elif fresh.function.has_slope:
                candidates = [fresh]
            else:
                continue
            for key in candidates:
                k = position.get(key)
                if k is not None:
                    out[k] = key
        return out

    def order(self, key: EventKey) -> tuple[int, int, int]:
        """Processing order of simultaneous events: event type, finger, node."""
        of_contact = key.function != EventFunction.GAP and key.node != WHOLE_OBJECT
        return key.rank, self.contacts.finger_of(key.node) if of_contact else key.finger, key.node

    # ------------------------------------------------------------------ one event
    def add_contacts(self, keys: list[EventKey], sol: Solution) -> None:
        """Event A for every key (one per node): put the nodes on their tips, decide jointly."""
        c = self.contacts
        nodes, fingers, theta = c.nodes, c.finger, sol.theta.copy()
        added = []
        for key in keys:
            node, f = key.node, key.finger
            if not self._admit(node, f):
                continue
            same = fingers == f
            near = float(np.mean(theta[same])) if same.any() else None
            point = self.functions.boundary_point(c, sol, node)
            nodes, fingers = np.append(nodes, node), np.append(fingers, f)
            theta = np.append(theta, self.motion.touch_angle(point, f, self.s, near))
            self.fresh = {k for k in self.fresh if k.node != node} | {
                EventKey(function, node) for function in (EventFunction.NORMAL_FORCE, *_CONES)}
            added.append(node)
        if not added:
            self.contacts = c.with_theta(theta)
            return
        n = len(added)
        self.contacts = ContactSet.of(self.model, nodes, fingers, np.append(c.stick, [True] * n),
                                      np.append(c.slip, [0] * n), theta)
        self.undetermined |= set(added)
        self.decide(added)
        for node in sorted(added):
            self._log_contact(EventType.A, self.contacts.index(node))

    def apply(self, key: EventKey, sol: Solution, *, admit: bool = True) -> None:
        """Process one B, C or D event (modes, the contact set and the fresh keys); ``admit``:
        count it against the chattering bound, which may freeze the node instead.
        """
        node, function = key.node, key.function
        k = self.contacts.index(node)
        f = int(self.contacts.finger[k])
        if admit and not self._admit(node, f):
            return
        self.contacts = self.contacts.with_theta(sol.theta.copy())
        if function == EventFunction.NORMAL_FORCE:
            if np.count_nonzero(self.contacts.finger == f) == 1:
                self.lost = self.motion.names[f]
                return
            self._log(EventType.B, node, f, "none", 0)
            self.contacts = self.contacts.without(self.model, k)
            self.fresh = {fk for fk in self.fresh if fk.node != node} | {
                EventKey(EventFunction.GAP, node)}
        elif function in _CONES:
            self.contacts = self.contacts.with_mode(k, False, function.slip)
            self.fresh -= {EventKey(cone, node) for cone in _CONES}
            self._log_contact(EventType.C, k)
        else:
            side = EventFunction.cone_edge(self.contacts.slip[k])
            self.contacts = self.contacts.with_mode(k, True, 0)
            self.fresh.add(EventKey(side, node))
            self._log_contact(EventType.D, k)

    def resettle(self, nodes: set[int], point: _Point) -> None:
        """Joint hypothesis-and-test for nodes whose C/D events at this point flip back.

        Their C/D events at this point are replaced by the net mode change from the start of
        the point (C for stick -> slip, D for slip -> stick, D then C for a slip reversal).
        """
        self.decide(sorted(nodes))
        first = point.first_event
        self.events[first:] = [e for e in self.events[first:]
                               if not (e.node in nodes and e.type in (EventType.C, EventType.D))]
        c = self.contacts
        for node in sorted(nodes):
            k = c.index(node)
            old = point.before.get(node, (True, 0))
            new = (bool(c.stick[k]), int(c.slip[k]))
            if new == old:
                continue
            if not old[0]:
                self._log(EventType.D, node, c.finger[k], ContactMode.STICK, 0)
            if not new[0]:
                self._log(EventType.C, node, c.finger[k], ContactMode.SLIP, new[1])
        for i, e in enumerate(self.events[first:], first):
            if e.type == EventType.A and e.node in nodes:
                k = c.index(e.node)
                self.events[i] = Event(e.type, e.node, e.finger, e.depth, e.relative_depth,
                                       ContactMode.STICK if c.stick[k] else ContactMode.SLIP,
                                       int(c.slip[k]))

    # ------------------------------------------------------------------ the point
    def resolve(self) -> Solution:
        """Process every pending event at the current point; returns the final solution."""
        if self.motion.rate == 0:
            return self.solver.solve(self.contacts, self.s)
        if self.undetermined:
            self.decide(sorted(self.undetermined))
        c = self.contacts
        before = {int(n): (bool(st), int(sl)) for n, st, sl in zip(c.nodes, c.stick, c.slip)}
        point = _Point(before, len(self.events))
        limit = 4 * (len(c) + 8) * self.model.max_events_per_depth
        for _ in range(limit):
            sol = self.solver.solve(self.contacts, self.s)
            if self.lost is not None or self.slipping_finger(sol) is not None:
                return sol
            todo = self.pending(sol)
            if not todo:
                return sol
            self._process(todo, sol, point)
        raise NumericalError("event processing at one point did not settle (chattering bound "
                             "exceeded); lower squeeze.max_events_per_depth")

    def _process(self, todo: list[EventKey], sol: Solution, point: _Point) -> None:
        """Process the first pending event ``todo[0]`` (with every pending A if it is one)."""
        key = todo[0]
        node, function = key.node, key.function
        if function in _CONES and node in self.chatter.held_nodes(self.depth):
            point.mode_events.discard(node)  # frozen and sticking: it slides, not counted
            self.apply(key, sol, admit=False)
        elif node in point.settled or (function in _CONTACT_CHANGES
                                     and node in point.contact_events):
            finger = key.finger if function == EventFunction.GAP else self.contacts.finger_of(node)
            self.chatter.hold(node, self.motion.names[finger], self.depth)
        elif function == EventFunction.GAP:
            batch: dict[int, EventKey] = {}
            for k in todo:
                if k.function == EventFunction.GAP and k.node not in point.contact_events:
                    batch.setdefault(k.node, k)
            self.add_contacts(sorted(batch.values(), key=lambda k: (k.finger, k.node)), sol)
            point.contact_events |= set(batch)
        elif function != EventFunction.NORMAL_FORCE and node in point.mode_events:
            group = point.mode_events | {node}
            self.resettle(group, point)
            point.settled |= group
        else:
            (point.contact_events if function == EventFunction.NORMAL_FORCE
             else point.mode_events).add(node)
            self.apply(key, sol)

    # ------------------------------------------------------------------ terminations
    def slipping_finger(self, sol: Solution) -> str | None:
        """A finger whose contact nodes all slide the same way (Sec. 5.1), or None."""
        if Termination.FINGER_SLIP not in self.functions.terminate_on:
            return None
        c, tips = self.contacts, self.motion.contact_tips(self.contacts.finger)
        f = c.sliding_finger(c.slip_signs(sol.dtheta, self.functions.frictionless), tips.masks)
        return None if f is None else self.motion.names[f]

    def termination(self, sol: Solution) -> Termination | None:
        """First termination that holds at the current point (order in the module docstring)."""
        if self.motion.rate == 0:
            return None
        det, element, strain, pickup = self.functions.end_values(self.contacts, sol)
        if det <= INVERSION_AREA_RATIO:
            counters = self.solver.counters
            counters.min_area_ratio, counters.inverted_element = det, element
            return Termination.ELEMENT_INVERTED
        if strain <= 0:
            return Termination.STRAIN_LIMIT
        if self.lost is not None:
            return Termination.CONTACT_LOST
        if self.slipping_finger(sol) is not None:
            return Termination.FINGER_SLIP
        if pickup <= 0:
            return Termination.PICKED_UP
        return None
