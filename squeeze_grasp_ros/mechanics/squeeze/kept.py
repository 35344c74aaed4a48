# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A property computed on first use and kept in the instance, without a lock.

:func:`functools.cached_property` of Python 3.11 takes a lock at every first use (removed in
3.12); the stepper's solutions and event functions are made thousands of times per
evaluation, each used from one thread, and the lock's calls were a sixth of an evaluation's
Python-visible calls at event points.
"""
from __future__ import annotations

from typing import Any, Callable

__all__ = ["kept_for", "kept_property"]


class kept_property:
    """Like :func:`functools.cached_property`, without its lock: the value is computed by the
    decorated function on first access and stored in the instance's ``__dict__`` (which then
    answers every later access; frozen dataclasses too, as with cached_property).

    >>> class Box:
    ...     @kept_property
    ...     def area(self):
    ...         print("computed")
    ...         return 6
    >>> box = Box()
    >>> box.area, box.area
    computed
    (6, 6)
    """

    def __init__(self, func: Callable[[Any], Any]) -> None:
        self.func, self.name, self.__doc__ = func, func.__name__, func.__doc__

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self
        value = instance.__dict__[self.name] = self.func(instance)
        return value


def kept_for(store: dict, owner: Any, tag: Any, make: Callable[[], Any], limit: int) -> Any:
    """What ``make()`` returns for ``owner`` (an object, by identity) and ``tag`` (hashable),
    kept in ``store``: computed once while ``owner`` lives; ``store`` is emptied when it holds
    ``limit`` entries.

    >>> store, key = {}, object()
    >>> kept_for(store, key, 1, lambda: print("made") or 2, 8), kept_for(store, key, 1, int, 8)
    made
    (2, 2)
    """
    made = store.get((id(owner), tag))
    if made is None or made[0] is not owner:  # a new object may reuse a dead one's id
        if len(store) >= limit:
            store.clear()
        made = store[id(owner), tag] = (owner, make())
    return made[1]
