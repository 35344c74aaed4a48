# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The chattering bound: at most ``max_events_per_depth`` events of a node within one depth step.

A node over the bound is frozen in its state for one depth step: its event functions are not
watched (:meth:`ChatterBound.held`) and its gaps are not checked for Event A; each freeze is
reported as a :class:`~..contact_state.Chatter`. Depths in m.
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_state import Chatter, ContactState

__all__ = ["ChatterBound"]


class ChatterBound:
    """Recent events per node, the nodes frozen and until which depth (mutable, one call).

    Parameters
    ----------
    state : ContactState
        Its ``history`` and ``holds`` carry over from the previous call.
    window : float
        The depth step, m.
    max_events : int
        Events of one node allowed within the window.
    """

    def __init__(self, state: ContactState, window: float, max_events: int) -> None:
        self.window, self.max_events = window, max_events
        self.history = list(state.history)
        self.holds = dict(state.holds)
        self.chatter: list[Chatter] = []

    def admit(self, node: int, finger: str, depth: float) -> bool:
        """Count an event of ``node`` at ``depth``; False if the bound froze the node instead."""
        self.history = [(n, d) for n, d in self.history if d > depth - self.window]
        if sum(1 for n, _ in self.history if n == node) < self.max_events:
            self.history.append((node, depth))
            return True
        self.hold(node, finger, depth)
        return False

    def hold(self, node: int, finger: str, depth: float) -> None:
        """Freeze the state of ``node`` (touching ``finger``) from ``depth`` for one window."""
        until = depth + self.window
        self.holds[node] = until
        self.chatter.append(Chatter(node, finger, depth, until))

    def held(self, nodes: np.ndarray, depth: float) -> np.ndarray:
        """Boolean mask over ``nodes`` of those frozen at ``depth``."""
        if not self.holds:
            return np.zeros(len(nodes), bool)
        return np.array([self.holds.get(int(k), -np.inf) > depth for k in nodes], bool)

    def held_nodes(self, depth: float) -> list[int]:
        """Nodes frozen at ``depth``."""
        return [node for node, until in self.holds.items() if until > depth]

    def expiry(self, depth: float) -> float:
        """The depth (m) at which the first hold active at ``depth`` expires (inf: none)."""
        return min((until for until in self.holds.values() if until > depth), default=np.inf)

    def state_holds(self, depth: float) -> tuple[tuple[int, float], ...]:
        """(node, until) of the holds still active at ``depth``, for the next call's state."""
        return tuple(sorted((n, u) for n, u in self.holds.items() if u > depth))
