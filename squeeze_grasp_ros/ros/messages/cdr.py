# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The device readings read straight from their serialised CDR bytes.

A lockstep tick delivers six readings to the monitor and two setpoints to the simulated
hardware. rclpy turns each into Python message objects (a ``PoseStamped`` is six of them,
about 40 us), of which a node needs a stamp and a few numbers. These functions read those
numbers from the bytes of a raw subscription instead, in a few microseconds: the stamp, a
pose's position, a wrench's force and a tactile array's taxels. The values are the same float64
numbers bit for bit (``test/test_cdr_readings.py`` checks them against rclpy's own
deserialisation, for every alignment a frame id or finger name can cause).

The layout is classic CDR (XCDR1, ``CDR_LE`` or ``CDR_BE``), what rmw implementations of ROS 2
Jazzy send: a 4-byte encapsulation header, then the fields in order, each aligned to its own
size counted from the end of that header; a string is a uint32 length (its terminating NUL
included) and its bytes, a sequence a uint32 count and its elements.
"""
from __future__ import annotations

import struct

import numpy as np

from squeeze_grasp_ros.ros.messages.contacts import TactileReadings

__all__ = ["cdr_stamp_ns", "pose_position_cdr", "tactile_readings_cdr", "wrench_force_cdr"]

_BODY = 4
"""Bytes of the encapsulation header; alignment counts from its end."""


class _Reader:
    """A cursor over one CDR message (``data``, its encapsulation header first)."""

    def __init__(self, data: bytes) -> None:
        if len(data) < _BODY + 8 or data[0] != 0 or data[1] > 1:
            raise ValueError(f"not a classic CDR message (encapsulation {bytes(data[:2])!r}, "
                             f"{len(data)} bytes): only CDR_LE and CDR_BE are read")
        self.data = data
        self.order = "<" if data[1] & 1 else ">"
        self.offset = _BODY

    def _align(self, size: int) -> None:
        self.offset += -(self.offset - _BODY) % size

    def uint32(self) -> int:
        self._align(4)
        (value,) = struct.unpack_from(self.order + "I", self.data, self.offset)
        self.offset += 4
        return value

    def skip_string(self) -> None:
        size = self.uint32()
        self.offset += size

    def string(self) -> str:
        size = self.uint32()
        self.offset += size
        return bytes(self.data[self.offset - size:self.offset - 1]).decode()

    def float64s(self, count: int) -> np.ndarray:
        """``count`` float64 values (a fixed-size run of fields or a sequence's elements; an
        empty run is not aligned, as Fast CDR writes it).
        """
        if count == 0:
            return np.zeros(0)
        self._align(8)
        values = np.frombuffer(self.data, self.order + "f8", count, self.offset)
        self.offset += 8 * count
        return values.astype(np.float64)

    def sequence(self) -> np.ndarray:
        """A ``float64[]`` sequence."""
        return self.float64s(self.uint32())

    def header(self) -> int:
        """Read a ``std_msgs/Header`` (or a ``builtin_interfaces/Time``): its stamp, ns."""
        sec, nanosec = struct.unpack_from(self.order + "iI", self.data, self.offset)
        self.offset += 8
        return sec * 1_000_000_000 + nanosec


def cdr_stamp_ns(data: bytes) -> int:
    """Stamp (ns) at the start of a CDR message whose first field is a header or a time (any
    encapsulation: the stamp comes first in each).
    """
    sec, nanosec = struct.unpack_from("<iI" if data[1] & 1 else ">iI", data, _BODY)
    return sec * 1_000_000_000 + nanosec


def pose_position_cdr(data: bytes) -> tuple[int, np.ndarray]:
    """(stamp ns, planar position (x, y) in m) of a serialised ``geometry_msgs/PoseStamped``."""
    reader = _Reader(data)
    stamp = reader.header()
    reader.skip_string()
    return stamp, reader.float64s(2)


def wrench_force_cdr(data: bytes) -> tuple[int, np.ndarray]:
    """(stamp ns, force (3,) in N) of a serialised ``geometry_msgs/WrenchStamped``."""
    reader = _Reader(data)
    stamp = reader.header()
    reader.skip_string()
    return stamp, reader.float64s(3)


def tactile_readings_cdr(data: bytes) -> tuple[int, TactileReadings]:
    """(stamp ns, taxel angles in rad and forces in N) of a serialised
    ``squeeze_grasp_interfaces/TactileArray``.
    """
    reader = _Reader(data)
    stamp = reader.header()
    reader.skip_string()
    finger = reader.string()
    return stamp, TactileReadings(finger, reader.sequence(), reader.sequence(),
                                  reader.sequence())
