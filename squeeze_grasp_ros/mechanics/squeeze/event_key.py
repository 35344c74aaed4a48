# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Names of the stepper's event functions, and the one processing order of simultaneous events.

The stepper (:mod:`.stepper`) watches one scalar function per possible event: a free boundary
node's gap to each fingertip (Event A), each contact's normal force (B), a sticking contact's
two cone margins (C) or a sliding contact's slip rate (D), and the termination margins. An
:class:`EventKey` names one of them; its :class:`EventFunction` says which kind it is and so
which :class:`~..vocabulary.EventType` (or :class:`~..vocabulary.Termination`) its sign change
is.

>>> key = EventKey.gap(node=17, finger=1)
>>> key.function.event_type, key.rank, key.at_node == EventKey(EventFunction.GAP, 17)
('A', 3, True)
>>> sorted(PROCESSING_ORDER, key=processing_rank) == list(PROCESSING_ORDER)
True
"""
from __future__ import annotations

from enum import Enum
from typing import NamedTuple

from squeeze_grasp_ros.mechanics.vocabulary import EventType, Termination

__all__ = ["ANY_FINGER", "EventFunction", "EventKey", "KeyTable", "PROCESSING_ORDER",
           "SHARED_KEYS", "WHOLE_OBJECT", "processing_rank"]

PROCESSING_ORDER: tuple[EventType, ...] = (EventType.B, EventType.D, EventType.C, EventType.A)
"""Processing order of simultaneous events: break < slip -> stick < stick -> slip < new
contact (the stepper's at one point, the monitor's within one tick and finger)."""
WHOLE_OBJECT = -1
"""The node of a function of the whole object (the terminations)."""
ANY_FINGER = -1
"""The finger of a key that is not about one fingertip."""


def processing_rank(event_type: EventType | str | None) -> int:
    """Position of ``event_type`` in :data:`PROCESSING_ORDER` (after all of them for None)."""
    if event_type is None:
        return len(PROCESSING_ORDER)
    return PROCESSING_ORDER.index(EventType(event_type))


class EventFunction(str, Enum):
    """Kinds of event function: positive while nothing happens, an event where it reaches 0."""

    GAP = "A"
    """Gap |x_k - o_f| - r_f of a free boundary node to a fingertip (eq. 48)."""
    NORMAL_FORCE = "B"
    """Normal force f_n of a contact node (eq. 49)."""
    CONE_PLUS = "C+"
    """Cone margin mu f_n + f_t of a sticking node (eq. 50): at 0 it slips with slip +1."""
    CONE_MINUS = "C-"
    """Cone margin mu f_n - f_t of a sticking node (eq. 50): at 0 it slips with slip -1."""
    SLIP_RATE = "D"
    """Slip rate of a sliding node along its slip direction (eq. 51)."""
    AREA = "inverted"
    """Smallest element area ratio det F less the inversion threshold."""
    STRAIN = "strain"
    """Strain limit less the largest strain (eq. 45)."""
    PICKUP = "pickup"
    """Pickup margin w / n_f - min_f sum_k c_k."""

    @property
    def event_type(self) -> EventType | None:
        """The contact event at this function's zero (None for a termination)."""
        return _EVENT_TYPES.get(self)

    @property
    def termination(self) -> Termination | None:
        """The termination at this function's zero (None for a contact event)."""
        return _TERMINATIONS.get(self)

    @property
    def has_slope(self) -> bool:
        """Whether the stepper knows d/ds of the function at every solution (gaps, normal
        forces and cone margins; slip rates and terminations need second derivatives).
        """
        return self in _SLOPED

    @property
    def slip(self) -> int:
        """Slip direction a sticking node takes when this cone margin reaches 0 (0 otherwise)."""
        return {EventFunction.CONE_PLUS: 1, EventFunction.CONE_MINUS: -1}.get(self, 0)

    @classmethod
    def cone_edge(cls, slip: int) -> EventFunction:
        """The cone margin that is zero while a node slides with direction ``slip`` (+1/-1)."""
        return cls.CONE_PLUS if slip > 0 else cls.CONE_MINUS


_EVENT_TYPES = {EventFunction.GAP: EventType.A, EventFunction.NORMAL_FORCE: EventType.B,
                EventFunction.CONE_PLUS: EventType.C, EventFunction.CONE_MINUS: EventType.C,
                EventFunction.SLIP_RATE: EventType.D}
_TERMINATIONS = {EventFunction.AREA: Termination.ELEMENT_INVERTED,
                 EventFunction.STRAIN: Termination.STRAIN_LIMIT,
                 EventFunction.PICKUP: Termination.PICKED_UP}
_SLOPED = frozenset({EventFunction.GAP, EventFunction.NORMAL_FORCE, EventFunction.CONE_PLUS,
                     EventFunction.CONE_MINUS})


class EventKey(NamedTuple):
    """One event function of a stepper call.

    A named tuple: the stepper's tables of function values are dicts keyed by it, hundreds of
    look-ups per substep, and a tuple of a str enum and two ints hashes and compares in C (a
    frozen dataclass calls a Python ``__hash__`` at every look-up). Keys order as their fields.

    Attributes
    ----------
    function : EventFunction
    node : int
        Mesh node (:data:`WHOLE_OBJECT` for a termination).
    finger : int
        Index of the fingertip in the state's fingers, for a gap (:data:`ANY_FINGER` else).
    """

    function: EventFunction
    node: int = WHOLE_OBJECT
    finger: int = ANY_FINGER

    @classmethod
    def gap(cls, node: int, finger: int) -> EventKey:
        """Event A's function: the gap of free boundary ``node`` to fingertip ``finger``."""
        return cls(EventFunction.GAP, node, finger)

    @property
    def at_node(self) -> EventKey:
        """The key without its finger: the form of :attr:`.ContactState.fresh`, where a freed
        node's gap is zero to whichever tip released it.
        """
        return self if self.finger == ANY_FINGER else EventKey(self.function, self.node)

    @property
    def rank(self) -> int:
        """Processing rank of its event type (:func:`processing_rank`)."""
        return processing_rank(self.function.event_type)


class KeyTable:
    """Each key made once: the stepper's tables of function values hold hundreds of keys per
    substep (a gap per free boundary node and finger), and making a key in Python costs
    several times a look-up here. Keys are values, the same for every object and model: the
    stepper uses one table for the process (:data:`SHARED_KEYS`), so a sweep that builds a
    model per evaluation makes an object's gap keys once, not once per evaluation. The table
    is bounded: past ``max_keys`` keys or ``max_loops`` boundary loops it starts again (a
    key made again equals the old one).

    >>> table = KeyTable()
    >>> table.get(EventFunction.NORMAL_FORCE, 4) is table.get(EventFunction.NORMAL_FORCE, 4)
    True
    >>> table.gaps([7, 9], fingers=2)[1] == (EventKey.gap(9, 0), EventKey.gap(9, 1))
    True
    >>> small = KeyTable(max_keys=2)  # full: starts again, with keys equal to the old ones
    >>> [small.get(f) for f in EventFunction][-1] == EventKey(list(EventFunction)[-1])
    True
    >>> len(EventFunction) > 2 and len(small._keys) <= 2
    True
    """

    def __init__(self, *, max_keys: int = 1_000_000, max_loops: int = 64) -> None:
        self._keys: dict[tuple, EventKey] = {}
        self._gaps: dict[tuple, list[tuple[EventKey, ...]]] = {}
        self._max_keys, self._max_loops = max_keys, max_loops

    def get(self, function: EventFunction, node: int = WHOLE_OBJECT,
            finger: int = ANY_FINGER) -> EventKey:
        """The key of (function, node, finger)."""
        made = self._keys.get((function, node, finger))
        if made is None:
            if len(self._keys) >= self._max_keys:
                self._keys.clear()
            made = self._keys[(function, node, finger)] = EventKey(function, node, finger)
        return made

    def gaps(self, nodes: list[int], fingers: int) -> list[tuple[EventKey, ...]]:
        """Per node of ``nodes`` (a boundary loop), its gap keys to fingers 0 .. fingers - 1."""
        made = self._gaps.get((tuple(nodes), fingers))
        if made is None:
            if len(self._gaps) >= self._max_loops:
                self._gaps.clear()
            made = [tuple(self.get(EventFunction.GAP, node, f) for f in range(fingers))
                    for node in nodes]
            self._gaps[(tuple(nodes), fingers)] = made
        return made


SHARED_KEYS = KeyTable()
"""The process's key table (the stepper's; threads may share it: a race makes a key twice,
and the two are equal)."""
