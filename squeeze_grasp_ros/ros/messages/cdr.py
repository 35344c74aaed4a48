# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The lockstep loop's messages read from, and written to, their serialised CDR bytes.

A lockstep tick delivers six readings to the monitor, its status to the executor and two
setpoints to the simulated hardware. rclpy turns each into Python message objects (a
``PoseStamped`` is six of them, about 40 us), of which a node needs a stamp and a few numbers.
These functions read those numbers from the bytes of a raw subscription instead, in a few
microseconds: the stamp, a pose's position, a wrench's force, a tactile array's taxels and a
status's per-finger vectors and depth (a status with events or alarms is left to rclpy). The
values are the same float64 numbers bit for bit (``test/test_cdr_readings.py`` and
``test/test_cdr_writers.py`` check them against rclpy's own deserialisation, for every
alignment a frame id or finger name can cause).

The other way, the loop's publishers hand rclpy the serialised bytes (``Publisher.publish``
takes ``bytes``): :class:`CdrWriter` and the ``*_cdr`` writers below put a tick's readings, its
ground truth, the monitor's status and contact state and the executor's setpoints straight
from numpy into CDR, where rclpy would first fill a Python message and then convert it field by
field (``test/test_cdr_writers.py`` checks every writer against rclpy's deserialisation; the
alignment padding is written as zeros, where rclpy leaves whatever its buffer held).

The layout is classic CDR (XCDR1, ``CDR_LE`` or ``CDR_BE``), what rmw implementations of ROS 2
Jazzy send: a 4-byte encapsulation header, then the fields in order, each aligned to its own
size counted from the end of that header; a string is a uint32 length (its terminating NUL
included) and its bytes, a sequence a uint32 count and its elements.
"""
from __future__ import annotations

import functools
import math
import struct
import threading
from typing import NamedTuple

import numpy as np

from squeeze_grasp_ros.ros.messages.contacts import TactileReadings, check_taxels

__all__ = ["CdrTemplate", "CdrWriter", "cdr_stamp_ns", "clock_cdr", "monitor_status_cdr_reading",
           "PLANAR_ORIGIN", "planar", "pose_position_cdr", "pose_stamped_cdr", "refilled",
           "tactile_array_cdr", "tactile_readings_cdr", "tick_cdr", "tick_readings_cdr",
           "wrench_force_cdr", "wrench_stamped_cdr", "write_contact_arrays",
           "write_finger_vectors"]

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

    def uint64(self) -> int:
        self._align(8)
        (value,) = struct.unpack_from(self.order + "Q", self.data, self.offset)
        self.offset += 8
        return value

    def float64(self) -> float:
        self._align(8)
        (value,) = struct.unpack_from(self.order + "d", self.data, self.offset)
        self.offset += 8
        return value

    def skip_string(self) -> None:
        size = self.uint32()
        self.offset += size

    def string(self) -> str:
        size = self.uint32()
        self.offset += size
        return bytes(self.data[self.offset - size:self.offset - 1]).decode()

    def strings(self) -> list[str]:
        """A ``string[]`` sequence."""
        return [self.string() for _ in range(self.uint32())]

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
    return _after_header(data, 2)


def wrench_force_cdr(data: bytes) -> tuple[int, np.ndarray]:
    """(stamp ns, force (3,) in N) of a serialised ``geometry_msgs/WrenchStamped``."""
    return _after_header(data, 3)


def _after_header(data: bytes, count: int) -> tuple[int, np.ndarray]:
    """(stamp ns, the first ``count`` float64 after the header) of a message that starts with a
    ``std_msgs/Header``: a little-endian one read at the offset its frame id's length gives, any
    other walked by :class:`_Reader` (which also refuses what is not classic CDR).
    """
    if data[:2] == _CDR_LE and len(data) >= _BODY + 12:
        at = _BODY + 12 + _U32_LE(data, _BODY + 8)[0]
        at += -(at - _BODY) % 8
        if at + 8 * count <= len(data):
            sec, nanosec = _STAMP_LE(data, _BODY)
            return (sec * 1_000_000_000 + nanosec,
                    np.frombuffer(data, "<f8", count, at).astype(np.float64))
    reader = _Reader(data)
    stamp = reader.header()
    reader.skip_string()
    return stamp, reader.float64s(count)


_CDR_LE = b"\x00\x01"
"""The encapsulation of little-endian classic CDR."""
_U32_LE, _STAMP_LE = struct.Struct("<I").unpack_from, struct.Struct("<iI").unpack_from


def tactile_readings_cdr(data: bytes) -> tuple[int, TactileReadings]:
    """(stamp ns, taxel angles in rad and forces in N) of a serialised
    ``squeeze_grasp_interfaces/TactileArray``.

    An array of the layout of one read before (the same length, frame, finger and taxel count)
    is read at that one's offsets.
    """
    layout = _known_layout(data)
    if layout is not None:
        if layout.stride:  # the three arrays evenly spaced: one strided copy
            taxels = np.ndarray((3, layout.size), "<f8", data, layout.runs[0],
                                (layout.stride, 8)).astype(np.float64)
            return cdr_stamp_ns(data), TactileReadings(layout.finger, *taxels)
        return cdr_stamp_ns(data), TactileReadings(
            layout.finger, *(np.frombuffer(data, "<f8", layout.size, at).copy()
                             for at in layout.runs))
    reader = _Reader(data)
    stamp = reader.header()
    reader.skip_string()
    finger = reader.string()
    counts, runs, arrays = [], [], []
    for _ in range(3):
        counts.append(reader.offset + -(reader.offset - _BODY) % 4)
        arrays.append(reader.sequence())
        runs.append(reader.offset - 8 * len(arrays[-1]))
    count = len(arrays[0])
    if reader.order == "<" and reader.offset == len(data) and count and \
            all(len(a) == count for a in arrays) and \
            sum(map(len, _TACTILE_LAYOUTS.values())) < 64:
        stride = runs[1] - runs[0] if runs[2] - runs[1] == runs[1] - runs[0] else 0
        _TACTILE_LAYOUTS.setdefault(len(data), []).append(_Layout(
            counts[0] + 4, bytes(data[_BODY + 8:counts[0] + 4]), tuple(counts[1:]),
            bytes(data[counts[0]:counts[0] + 4]), finger, count, tuple(runs), stride))
    return stamp, TactileReadings(finger, *arrays)


def _known_layout(data: bytes) -> _Layout | None:
    """The layout read before that a little-endian tactile array ``data`` has, if any."""
    if data[1] != 1:
        return None
    for layout in _TACTILE_LAYOUTS.get(len(data), ()):
        if data[_BODY + 8:layout.start] == layout.prefix \
                and all(data[at:at + 4] == layout.count for at in layout.counts):
            return layout
    return None


def tick_readings_cdr(data: bytes) -> tuple[int, list[str]]:
    """(stamp ns, readings "<device>/<stream>") of a serialised
    ``squeeze_grasp_interfaces/Tick``.

    The readings of a tick with an empty frame id (as the simulated hardware writes it) are
    looked up by their bytes when the same list was read before.
    """
    tail = data[_BODY + 24:] if data[1] == 1 and data[_BODY + 8:_BODY + 16] == _NO_FRAME \
        else None
    readings = _TICK_READINGS.get(tail)
    if readings is not None:
        return cdr_stamp_ns(data), list(readings)
    reader = _Reader(data)
    stamp = reader.header()
    reader.skip_string()
    reader.uint64()  # the tick's index
    readings = reader.strings()
    if tail is not None and len(_TICK_READINGS) < 64:
        _TICK_READINGS[bytes(tail)] = tuple(readings)
    return stamp, readings


class _Layout(NamedTuple):
    """Where a message read before keeps its arrays (byte offsets): a tactile array."""

    start: int
    """End of the frame id and the finger name (from the end of the stamp: ``prefix``)."""
    prefix: bytes
    """The bytes from the end of the stamp to ``start``, the first count included."""
    counts: tuple[int, ...]
    """Offsets of the other arrays' counts."""
    count: bytes
    """Each count's bytes."""
    finger: str
    size: int
    """Numbers per array."""
    runs: tuple[int, ...]
    """Offsets of the arrays."""
    stride: int = 0
    """Bytes from one array to the next when they are evenly spaced (else 0)."""


_TACTILE_LAYOUTS: dict[int, list[_Layout]] = {}
"""Tactile array layouts read before, by message length (little-endian, at most 64 in all).
Each finger has its own (its name is in the message): the two fingers of a gripper, whose
arrays have the same length, keep one each."""
_TICK_READINGS: dict[bytes, tuple[str, ...]] = {}
"""A tick's readings by the bytes of its ``string[]`` (at most 64 lists)."""
_NO_FRAME = b"\x01\x00\x00\x00\x00\x00\x00\x00"
"""An empty frame id (its length 1, the NUL) and the zero padding before the tick's index."""


def monitor_status_cdr_reading(data: bytes) -> tuple | None:
    """(stamp ns, fingers, positions (k, 3) m, forces (k, 3) N, normals (k, 3), depth m) of a
    serialised ``squeeze_grasp_interfaces/MonitorStatus`` that carries no event and no alarm
    (most ticks); None when it carries any, or when its positions, forces or normals are not
    one per finger (deserialise it whole then; before, the vectors were read from the bytes
    after a short array).

    The arrays are read-only views of ``data``. A status of the layout of one read before (the
    same length, frame, fingers and counts, no event and no alarm) is read at that one's offsets
    (:class:`_StatusLayout`), without walking its fields again.
    """
    layout = _STATUS_LAYOUTS.get(len(data))
    if layout is not None and data[1] == 1 and data[-8:] == _NO_EVENTS \
            and data[_BODY + 8:layout.start] == layout.prefix \
            and all(data[at:at + 4] == layout.count for at in layout.counts):
        runs = [np.frombuffer(data, "<f8", layout.size, at).reshape(-1, 3)
                for at in layout.runs]
        (depth,) = _F64_FROM(data, layout.depth)
        return (cdr_stamp_ns(data), layout.fingers, *runs, depth)
    reader = _Reader(data)
    stamp = reader.header()
    reader.skip_string()
    fingers = reader.strings()
    start, counts, runs = reader.offset, [], []
    for _ in range(3):
        counts.append(reader.offset + -(reader.offset - _BODY) % 4)
        count = reader.uint32()
        if count != len(fingers):  # not one vector per finger: deserialise it whole
            return None
        if count:
            reader._align(8)
        runs.append(reader.offset)
        reader.offset += 24 * count
    reader.sequence()  # sensor ages
    depth_at = reader.offset + -(reader.offset - _BODY) % 8
    depth = reader.float64()
    reader.float64()  # relative depth
    if reader.uint32() or reader.uint32():  # events, then alarms
        return None
    vectors = [np.frombuffer(data, reader.order + "f8", 3 * len(fingers), at).reshape(-1, 3)
               .astype(np.float64) for at in runs]
    if reader.order == "<" and reader.offset == len(data) and len(set(map(
            bytes, (data[at:at + 4] for at in counts)))) == 1 and len(_STATUS_LAYOUTS) < 64:
        _STATUS_LAYOUTS[len(data)] = _StatusLayout(start, bytes(data[_BODY + 8:start]),
                                                   tuple(counts),
                                                   bytes(data[counts[0]:counts[0] + 4]),
                                                   tuple(fingers), 3 * len(fingers),
                                                   tuple(runs), depth_at)
    return (stamp, fingers, *vectors, depth)


class _StatusLayout(NamedTuple):
    """Where a ``MonitorStatus`` without events and alarms keeps its numbers (byte offsets)."""

    start: int
    """End of the frame id and the finger names (from the end of the stamp: ``prefix``)."""
    prefix: bytes
    counts: tuple[int, ...]
    """Offsets of the positions', forces' and normals' counts."""
    count: bytes
    """Each count's bytes (the number of fingers)."""
    fingers: tuple[str, ...]
    size: int
    """float64 numbers per vector run (3 per finger)."""
    runs: tuple[int, ...]
    """Offsets of the positions, forces and normals."""
    depth: int


_STATUS_LAYOUTS: dict[int, _StatusLayout] = {}
"""Status layouts read before, by message length (little-endian, at most 64)."""
_NO_EVENTS = bytes(8)
"""A status's last 8 bytes without events and alarms: their two zero counts."""
_F64_FROM = struct.Struct("<d").unpack_from


_ZEROS = tuple(bytes(n) for n in range(8))
"""Padding of 0-7 bytes."""
_U32, _I32, _U64, _F64, _TIME = (struct.Struct(f).pack for f in ("<I", "<i", "<Q", "<d", "<iI"))


@functools.lru_cache(maxsize=256)
def _string(text: str) -> bytes:
    """A string's CDR: its uint32 length (the NUL included), its UTF-8 bytes and a NUL (after
    4-byte alignment). Cached: a tick writes the same finger names and frames again and again.
    """
    data = text.encode()
    return _U32(len(data) + 1) + data + b"\x00"


class CdrWriter:
    """One classic little-endian CDR message (``CDR_LE``), written field by field.

    The mirror of the readers above: every field aligned to its own size counted from the end
    of the encapsulation header, the padding zeros; a string is its uint32 length (the NUL
    included), its UTF-8 bytes and a NUL; a sequence its uint32 count and its elements (an empty
    one is not aligned, as Fast CDR writes it).
    """

    __slots__ = ("buffer",)

    def __init__(self) -> None:
        self.buffer = bytearray(b"\x00\x01\x00\x00")

    def uint32(self, value: int) -> None:
        buffer = self.buffer
        buffer += _ZEROS[-len(buffer) % 4]
        buffer += _U32(value)

    def int32(self, value: int) -> None:
        buffer = self.buffer
        buffer += _ZEROS[-len(buffer) % 4]
        buffer += _I32(value)

    def uint64(self, value: int) -> int:
        """Write a ``uint64``; return its offset."""
        buffer = self.buffer
        buffer += _ZEROS[-(len(buffer) - _BODY) % 8]
        offset = len(buffer)
        buffer += _U64(value)
        return offset

    def float64(self, value: float) -> int:
        """Write a ``float64``; return its offset."""
        buffer = self.buffer
        buffer += _ZEROS[-(len(buffer) - _BODY) % 8]
        offset = len(buffer)
        buffer += _F64(value)
        return offset

    def string(self, text: str) -> None:
        buffer = self.buffer
        buffer += _ZEROS[-len(buffer) % 4]
        buffer += _string(text)

    def strings(self, texts) -> None:
        """A ``string[]`` sequence."""
        buffer = self.buffer
        buffer += _ZEROS[-len(buffer) % 4]
        buffer += _U32(len(texts))
        for text in texts:
            buffer += _ZEROS[-len(buffer) % 4]
            buffer += _string(text)

    def header(self, ns: int, frame_id: str = "") -> int:
        """A ``std_msgs/Header`` stamped ``ns`` nanoseconds (its stamp first, as the readers
        read it); return the stamp's offset.
        """
        buffer = self.buffer
        buffer += _ZEROS[-len(buffer) % 4]
        offset = len(buffer)
        buffer += _TIME(*divmod(int(ns), 1_000_000_000))
        buffer += _string(frame_id)
        return offset

    def float64s(self, values) -> int:
        """A fixed-size run of float64 fields (``Point``, ``Vector3``, ...), or the elements of
        a sequence of such messages; nothing, not even alignment, for none. Return the offset
        of the first value (the end of the buffer for none).
        """
        data = np.asarray(values, dtype="<f8")
        buffer = self.buffer
        if data.size:
            buffer += _ZEROS[-(len(buffer) - _BODY) % 8]
            offset = len(buffer)
            buffer += data.tobytes()
            return offset
        return len(buffer)

    def sequence(self, values, dtype: str = "<f8") -> int:
        """A sequence of numbers (``float64[]`` by default; ``"<i4"`` int32, ``"u1"`` uint8):
        its count, then its elements aligned to their size (nothing for none, as Fast CDR
        writes it). Return the offset of the first element (the end of the buffer for none).
        """
        data = np.asarray(values, dtype=dtype)
        size, buffer = data.size, self.buffer
        buffer += _ZEROS[-len(buffer) % 4]
        buffer += _U32(size)
        if size:
            buffer += _ZEROS[-(len(buffer) - _BODY) % data.itemsize]
            offset = len(buffer)
            buffer += data.tobytes()
            return offset
        return len(buffer)

    def data(self) -> bytes:
        """The serialised message, ready for ``Publisher.publish``."""
        return bytes(self.buffer)


class CdrTemplate:
    """A serialised message to refill in place: the next message of the same layout (the same
    strings and sequence lengths) differs only in its stamps, ``uint64`` counters and float64
    runs, which :meth:`refill` writes over the first message's bytes.

    Parameters
    ----------
    writer : CdrWriter
        The first message, written in full; its buffer is kept (and no longer grows).
    stamps : sequence of int
        Offsets of the message's stamps (``builtin_interfaces/Time``).
    runs : sequence of (int, int or tuple of int) or (int, tuple of int, int)
        (offset, shape) of each float64 run refilled, in :meth:`refill`'s order (a shape
        (k, 3): k vectors); with a third entry, only that many leading columns are refilled
        (``(offset, (k, 3), 2)``: k planar vectors whose z keeps the first message's value).
    counters : sequence of int
        Offsets of the ``uint64`` fields refilled.
    """

    __slots__ = ("buffer", "counters", "runs", "stamps")

    def __init__(self, writer: CdrWriter, stamps=(), runs=(), counters=()) -> None:
        self.buffer = writer.buffer
        self.stamps = tuple(stamps)
        views = (_run_view(self.buffer, *run) for run in runs)
        self.runs = tuple((index, view) for index, view in enumerate(views) if view.size)
        """(index in refill's values, writable view) of each run that has numbers."""
        self.counters = tuple(counters)

    def refill(self, ns: int, values=(), counts=()) -> bytes:
        """The message stamped ``ns`` with float64 runs ``values`` (each as many numbers as its
        run) and counters ``counts``, serialised; the same bytes a writer would write.
        """
        buffer = self.buffer
        sec, nanosec = divmod(int(ns), 1_000_000_000)
        for offset in self.stamps:
            _TIME_INTO(buffer, offset, sec, nanosec)
        for offset, count in zip(self.counters, counts):
            _U64_INTO(buffer, offset, count)
        for index, run in self.runs:
            run[:] = values[index]
        return bytes(buffer)


def _run_view(buffer: bytearray, offset: int, shape, columns: int | None = None) -> np.ndarray:
    """A writable view of the float64 run of ``shape`` at ``offset`` (its first ``columns``
    columns only, if given).
    """
    view = np.frombuffer(buffer, "<f8", math.prod(np.atleast_1d(shape)), offset).reshape(shape)
    return view if columns is None else view[..., :columns]


_TIME_INTO, _U64_INTO = (struct.Struct(f).pack_into for f in ("<iI", "<Q"))
KEPT_LAYOUTS = 256
"""Templates each thread keeps (all are dropped when it has more, e.g. after many scenes)."""
_LAYOUTS = threading.local()


def refilled(key: tuple, write, ns: int, values=(), counts=()) -> bytes:
    """A message of layout ``key``: :meth:`CdrTemplate.refill` of the template kept for it (per
    thread: a refill is not atomic), or, the first time, the bytes of ``write()``, a function
    that writes the message in full and returns its :class:`CdrTemplate`.
    """
    kept = _LAYOUTS.__dict__
    template = kept.get(key)
    if template is not None:
        return template.refill(ns, values, counts)
    template = write()
    if len(kept) >= KEPT_LAYOUTS:
        kept.clear()
    kept[key] = template
    return bytes(template.buffer)


def pose_stamped_cdr(position, ns: int, frame_id: str) -> bytes:
    """A ``geometry_msgs/PoseStamped`` of a fingertip centre (x, y), m, at z = 0 with the
    identity orientation (:func:`..devices.pose_msg`'s message), serialised.
    """
    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp = writer.header(ns, frame_id)
        at = writer.float64s((position[0], position[1], 0.0, 0.0, 0.0, 0.0, 1.0))
        return CdrTemplate(writer, (stamp,), ((at, 2),))
    return refilled(("pose", frame_id), write, ns, (position[:2],))


def wrench_stamped_cdr(force, torque, ns: int, frame_id: str) -> bytes:
    """A ``geometry_msgs/WrenchStamped`` of a force (3,), N, and torque (3,), N m, serialised."""
    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp = writer.header(ns, frame_id)
        forces = writer.float64s(np.concatenate((force, torque)))
        return CdrTemplate(writer, (stamp,), ((forces, 3), (forces + 24, 3)))
    return refilled(("wrench", frame_id), write, ns, (force, torque))


def tactile_array_cdr(readings: TactileReadings, ns: int, frame_id: str) -> bytes:
    """A ``squeeze_grasp_interfaces/TactileArray`` (angles rad, forces N), serialised.

    Raises
    ------
    ValueError
        If the arrays differ in length.
    """
    check_taxels(readings.finger, readings.angles, readings.normal, readings.tangential)
    arrays = (readings.angles, readings.normal, readings.tangential)
    count = len(readings.angles)

    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp = writer.header(ns, frame_id)
        writer.string(readings.finger)
        return CdrTemplate(writer, (stamp,),
                           tuple((writer.sequence(values), count) for values in arrays))
    return refilled(("tactile", frame_id, readings.finger, count), write, ns, arrays)


def clock_cdr(ns: int) -> bytes:
    """The ``rosgraph_msgs/Clock`` of sim time ``ns``, serialised."""
    return b"\x00\x01\x00\x00" + _TIME(*divmod(int(ns), 1_000_000_000))


def tick_cdr(index: int, ns: int, readings) -> bytes:
    """The ``squeeze_grasp_interfaces/Tick`` of lockstep tick ``index`` at sim time ``ns``
    (readings as "<device>/<stream>"), serialised.
    """
    def write() -> CdrTemplate:
        writer = CdrWriter()
        stamp = writer.header(ns)
        at = writer.uint64(index)
        writer.strings(readings)
        return CdrTemplate(writer, (stamp,), (), (at,))
    return refilled(("tick", *readings), write, ns, (), (index,))


def write_contact_arrays(writer: CdrWriter, ns: int, frame_id: str, fingers, nodes, angles,
                         modes, forces_x, forces_y, depth: float, relative_depth: float
                         ) -> tuple[int, list[tuple[int, int]]]:
    """A ``squeeze_grasp_interfaces/ContactState`` (parallel per-contact arrays: angles rad,
    forces N; depth m) into ``writer``. Return its stamp's offset and (offset, count) of its
    float64 runs: angles, forces x and y, depth, relative depth (:class:`CdrTemplate`).
    """
    stamp = writer.header(ns, frame_id)
    writer.strings(fingers)
    writer.sequence(nodes, "<i4")
    count = len(nodes)
    runs = [(writer.sequence(angles), count)]
    writer.sequence(modes, "u1")
    runs += [(writer.sequence(forces_x), count), (writer.sequence(forces_y), count),
             (writer.float64(depth), 1), (writer.float64(relative_depth), 1)]
    return stamp, runs


PLANAR_ORIGIN = np.zeros(2)
PLANAR_ORIGIN.flags.writeable = False
"""(0, 0): the planar vector a message reports for a finger without one (a position, a total
force); read-only, shared."""


def planar(vectors) -> np.ndarray:
    """The (k, 2) float64 array of ``vectors``, each (x, y): the values of a planar run of
    :func:`write_finger_vectors` (a vector of another length is refused by the refill).
    """
    return np.array(vectors, dtype=np.float64)


def write_finger_vectors(writer: CdrWriter, ns: int, frame_id: str, fingers, vectors,
                         per_finger) -> tuple[int, list[tuple]]:
    """The per-finger head of ``MonitorStatus`` and ``SimState`` into ``writer``: a header, the
    ``string[]`` of ``fingers``, a ``Point[]`` / ``Vector3[]`` of each of ``vectors`` (each a
    (k, 2) array, one planar (x, y) per finger, written with z = 0) and the ``float64[]``
    ``per_finger``. Return the stamp's offset and each run's (offset, shape), the vectors'
    as planar runs (offset, (k, 3), 2) (:class:`CdrTemplate`: a refill writes their x and y
    from (k, 2) arrays and leaves z zero).
    """
    stamp = writer.header(ns, frame_id)
    writer.strings(fingers)
    runs: list = []
    count = len(fingers)
    for values in vectors:
        writer.uint32(count)
        spatial = np.zeros((count, 3))
        spatial[:, :2] = np.reshape(values, (-1, 2))
        runs.append((writer.float64s(spatial), (count, 3), 2))
    runs.append((writer.sequence(per_finger), count))
    return stamp, runs
