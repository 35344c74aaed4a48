# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Object ids and digests: the rule that keeps one client from silently using another's object.

The planner's object ids are a namespace shared by every client. The rule:

* an id holds one object at a time, named by its **digest** (SHA-256 of the solver route and
  the scene text); loading the same scene again under the same id is a cache hit;
* a load under an id that holds an object of **another digest** is refused (INVALID_ARGUMENT)
  unless the request sets ``replace``;
* every request that names an object may quote the digest its load returned
  (``object_digest``); if the id now holds another object (replaced, or evicted and loaded
  again from another scene) the request is refused with UNKNOWN_OBJECT instead of computing on
  the wrong object.

Ids are bounded (:data:`MAX_ID_CHARS` printable characters) and no message echoes more than
:data:`~squeeze_grasp_ros.inputs.SHOWN_CHARS` characters of any string a client sent
(:func:`~squeeze_grasp_ros.inputs.shown`).

>>> check_object_id("foam_square")
'foam_square'
>>> shown("x" * 1000)
"'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...' (1000 characters)"
"""

from __future__ import annotations

import re

from squeeze_grasp_ros.inputs import shown
from squeeze_grasp_ros.planning.errors import ErrorCode, PlannerError, invalid

MAX_ID_CHARS = 256
"""Longest object id (characters)."""
DIGEST = re.compile(r"[0-9a-f]{64}")
"""An object digest: SHA-256 in lower-case hex."""


def check_object_id(object_id: str, what: str = "object_id") -> str:
    """``object_id`` if it has 1 to :data:`MAX_ID_CHARS` printable characters.

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT naming ``what`` and the limit (quoting at most
        :data:`~squeeze_grasp_ros.inputs.SHOWN_CHARS` characters of the id).
    """
    if not object_id:
        raise invalid(f"{what} must not be empty")
    if len(object_id) > MAX_ID_CHARS:
        raise invalid(f"{what} has {len(object_id)} characters, more than {MAX_ID_CHARS}")
    if not object_id.isprintable():
        raise invalid(f"{what} {shown(object_id)} has a control character; use printable ones")
    return object_id


def check_digest(digest: str) -> str:
    """A quoted ``object_digest``: empty (not quoted) or 64 lower-case hex digits."""
    if digest and not DIGEST.fullmatch(digest):
        raise invalid(f"object_digest must be empty or the 64 hex digits load_object "
                      f"returned, got {shown(digest)}")
    return digest


def replaced(object_id: str, held: str, quoted: str) -> PlannerError:
    """UNKNOWN_OBJECT: ``object_id`` holds the object of digest ``held``, not ``quoted``."""
    return PlannerError(
        ErrorCode.UNKNOWN_OBJECT,
        f"object_id {shown(object_id)} holds another object now (object_digest {held[:12]}..., "
        f"yours {quoted[:12]}...): it was replaced, or evicted and loaded again from another "
        "scene; load yours again",
    )


def taken(object_id: str, held: str) -> PlannerError:
    """INVALID_ARGUMENT: a load under ``object_id``, which holds an object of digest ``held``
    built from another scene or solver route.
    """
    return invalid(
        f"object_id {shown(object_id)} is already loaded from another scene or solver route "
        f"(object_digest {held[:12]}...): load yours under another id, or set replace to "
        "replace it (requests quoting the old object_digest are then refused)"
    )
