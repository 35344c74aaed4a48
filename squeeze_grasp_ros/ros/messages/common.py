# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Building blocks: arrays, vectors, responses, stamps and headers."""
from __future__ import annotations

import array
from collections.abc import Sequence
from typing import Any, TypeVar

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Vector3
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Header

from squeeze_grasp_ros.planning import (
    ErrorCode,
)

Response = TypeVar("Response")




# --------------------------------------------------------------------------- building blocks


def float64_array(values: Any) -> array.array:
    """``values`` flattened (row-major) into an ``array('d')`` for a float64[] field."""
    out = array.array("d")
    out.frombytes(np.ascontiguousarray(values, dtype=np.float64).tobytes())
    return out


def int32_array(values: Any) -> array.array:
    """``values`` flattened (row-major) into an ``array('i')`` for an int32[] field."""
    out = array.array("i")
    out.frombytes(np.ascontiguousarray(values, dtype=np.int32).tobytes())
    return out


def bool_list(values: Any) -> list[bool]:
    """``values`` flattened (row-major) into the list of bools a bool[] field takes."""
    return np.asarray(values, dtype=bool).reshape(-1).tolist()


def vector3(xy: Sequence[float] | np.ndarray) -> Vector3:
    """A planar vector (x, y) as a ``Vector3`` with z = 0 (same unit)."""
    return Vector3(x=float(xy[0]), y=float(xy[1]), z=0.0)


def success(response_type: type[Response], **fields: Any) -> Response:
    """A response (or action result) with success, error_code OK and ``fields``."""
    return response_type(success=True, error_code=ErrorCode.OK, message="", **fields)


def failure(response_type: type[Response], code: ErrorCode, message: str) -> Response:
    """A response (or action result) with success false, ``code`` and the reason."""
    return response_type(success=False, error_code=int(code), message=message)


# --------------------------------------------------------------------------- pipeline: time


def stamp(ns: int) -> Time:
    """A ``builtin_interfaces/Time`` of ``ns`` nanoseconds (sim or wall time)."""
    return Time(sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))


def stamp_ns(time: Time) -> int:
    """Nanoseconds of a ``builtin_interfaces/Time`` (inverse of :func:`stamp`)."""
    return int(time.sec) * 1_000_000_000 + int(time.nanosec)


def header(ns: int, frame_id: str = "") -> Header:
    """A ``Header`` stamped ``ns`` nanoseconds in ``frame_id``."""
    return Header(stamp=stamp(ns), frame_id=frame_id)


def clock_msg(ns: int) -> Clock:
    """The ``/clock`` message of sim time ``ns``."""
    return Clock(clock=stamp(ns))


def set_stamp(time: Time, ns: int) -> None:
    """Set a ``builtin_interfaces/Time`` to ``ns`` nanoseconds in place."""
    time.sec, time.nanosec = divmod(int(ns), 1_000_000_000)
