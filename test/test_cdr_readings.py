# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The device readings read from raw CDR bytes (ros/messages/cdr.py) against rclpy's own
serialisation and deserialisation: every alignment a frame id or finger name can cause, empty
and odd-length taxel arrays, big-endian data, and what is refused.
"""
from __future__ import annotations

import dataclasses
import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rclpy.serialization import serialize_message

from squeeze_grasp_ros.control.tracker import TrackedEvent, TrackerOutput
from squeeze_grasp_ros.mechanics.vocabulary import EventType
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages import cdr

FINITE = st.floats(allow_nan=False, allow_infinity=False, width=64)
NAMES = st.text(alphabet="abcdefghijklmnopqrstuvwxyz_/0123456789", max_size=17)
STAMPS = st.integers(min_value=0, max_value=2**31 * 1_000_000_000 - 1)


def _bits(values) -> bytes:
    return np.asarray(values, dtype=np.float64).tobytes()


@settings(max_examples=60, deadline=None)
@given(STAMPS, NAMES, st.tuples(FINITE, FINITE))
def test_pose_position_equals_rclpys(ns, frame, xy):
    msg = messages.pose_msg(xy, ns, frame)
    stamp, position = messages.pose_position_cdr(serialize_message(msg))
    assert stamp == ns == messages.stamp_ns(msg.header.stamp)
    assert position.tobytes() == _bits(messages.pose_position(msg))


@settings(max_examples=60, deadline=None)
@given(STAMPS, NAMES, st.tuples(FINITE, FINITE, FINITE), st.tuples(FINITE, FINITE, FINITE))
def test_wrench_force_equals_rclpys(ns, frame, force, torque):
    msg = messages.wrench_msg(np.array(force), np.array(torque), ns, frame)
    stamp, read = messages.wrench_force_cdr(serialize_message(msg))
    assert stamp == ns
    assert read.tobytes() == _bits(messages.wrench_force(msg))


@settings(max_examples=60, deadline=None)
@given(STAMPS, NAMES, NAMES, st.lists(st.tuples(FINITE, FINITE, FINITE), max_size=9))
def test_tactile_readings_equal_rclpys(ns, frame, finger, taxels):
    angles, normal, tangential = (np.array(column, dtype=float).reshape(-1)
                                  for column in zip(*taxels)) if taxels else (np.zeros(0),) * 3
    msg = messages.tactile_array_msg(messages.TactileReadings(finger, angles, normal, tangential),
                                     messages.header(ns, frame))
    stamp, read = messages.tactile_readings_cdr(serialize_message(msg))
    reference = messages.tactile_readings(msg)
    assert stamp == ns and read.finger == finger == reference.finger
    for ours, theirs in zip((read.angles, read.normal, read.tangential),
                            (reference.angles, reference.normal, reference.tangential)):
        assert ours.dtype == np.float64 and ours.flags.writeable
        assert ours.tobytes() == theirs.tobytes()


def test_big_endian_pose_is_read():
    """CDR_BE (encapsulation 00 00): a PoseStamped with a 3-byte frame id ("ab" + NUL) ends
    its header at byte 15 of the body, so the pose starts after 1 byte of padding.
    """
    body = struct.pack(">iI", 12, 345) + struct.pack(">I", 3) + b"ab\0" + b"\0"
    body += struct.pack(">7d", 0.25, -1.5, 0.0, 0.0, 0.0, 0.0, 1.0)
    stamp, position = messages.pose_position_cdr(b"\x00\x00\x00\x00" + body)
    assert stamp == 12_000_000_345
    assert position.tolist() == [0.25, -1.5] and position.dtype.isnative


@pytest.mark.parametrize("data", [b"\x00\x07\x00\x00" + bytes(80), b"\x01\x01\x00\x00" + bytes(80),
                                  b"\x00\x01\x00\x00\x00"])
def test_what_is_not_classic_cdr_is_refused(data):
    with pytest.raises(ValueError, match="classic CDR"):
        messages.pose_position_cdr(data)


def _forgetting(read, data):
    """``read(data)`` with no layout kept from earlier reads (the full walk over the fields)."""
    cdr._TACTILE_LAYOUTS.clear()
    cdr._STATUS_LAYOUTS.clear()
    cdr._TICK_READINGS.clear()
    return read(data)


def _same_reading(ours, theirs) -> None:
    if dataclasses.is_dataclass(ours):
        assert type(ours) is type(theirs)
        ours, theirs = ([getattr(r, f.name) for f in dataclasses.fields(r)]
                        for r in (ours, theirs))
    if isinstance(ours, np.ndarray):
        assert ours.dtype == theirs.dtype and ours.tobytes() == theirs.tobytes()
    elif isinstance(ours, (tuple, list)):
        assert len(ours) == len(theirs)
        for a, b in zip(ours, theirs):
            _same_reading(a, b)
    else:
        assert ours == theirs


@settings(max_examples=60, deadline=None)
@given(STAMPS, STAMPS, st.sampled_from(["F1", "F2", "ab"]), st.integers(1, 9),
       st.lists(st.sampled_from(["F1", "F2", "ab", "c"]), min_size=1, max_size=3, unique=True),
       st.lists(NAMES, max_size=6), st.floats(-1e6, 1e6))
def test_a_layout_read_before_reads_as_the_full_walk(ns, later, finger, taxels, fingers,
                                                     readings, value):
    """The second message of a layout (tactile array, status, tick) is read at the first's
    offsets: the same stamp, names and numbers as walking its fields; a message of the same
    length but another layout (other finger names, counts, an event) is not misread.
    """
    first = messages.tactile_array_cdr(messages.TactileReadings(
        finger, np.zeros(taxels), np.ones(taxels), np.zeros(taxels)), ns, "F1_tip")
    second = messages.tactile_array_cdr(messages.TactileReadings(
        finger, np.full(taxels, value), np.arange(taxels) * value, -np.ones(taxels)), later,
        "F1_tip")
    other = messages.tactile_array_cdr(messages.TactileReadings(
        {"F1": "F2", "F2": "ab", "ab": "F1"}[finger], np.ones(taxels), np.ones(taxels),
        np.ones(taxels)), later, "F1_tip")
    vectors = {f: np.array([value, -value]) for f in fingers}
    outs = [TrackerOutput(stamp, tuple(names), vectors, vectors, vectors,
                          {f: 0.0 for f in fingers}, (), events, (), value, 0.5)
            for stamp, names, events in (
                (ns, fingers, ()), (later, fingers, ()), (later, fingers[::-1], ()),
                (later, fingers, (TrackedEvent(EventType.A, fingers[0], 0.0, 0.0, 0.0),)))]
    statuses = [messages.monitor_status_cdr(out, "object") for out in outs]
    ticks = [messages.tick_cdr(k, stamp, readings) for k, stamp in ((0, ns), (7, later))]
    for read, kept, data in ((messages.tactile_readings_cdr, first, [second, other]),
                             (cdr.monitor_status_cdr_reading, statuses[0], statuses[1:]),
                             (messages.tick_readings_cdr, ticks[0], ticks[1:])):
        for message in data:
            want = _forgetting(read, message)
            read(kept)
            _same_reading(read(message), want)


def test_two_fingers_arrays_of_one_length_keep_a_layout_each(monkeypatch):
    """The two fingers of a gripper send tactile arrays of the same length, alternately: once
    each was read, both are read at their kept offsets (the walk over the fields, which each
    finger's array replaced the other's layout with on every tick before, is not needed), and
    read the same as by rclpy.
    """
    cdr._TACTILE_LAYOUTS.clear()
    arrays = {finger: messages.TactileReadings(finger, np.linspace(0.0, 1.0, 24),
                                               np.arange(24.0), -np.arange(24.0))
              for finger in ("F1", "F2")}
    data = {finger: messages.tactile_array_cdr(r, 5, f"{finger}_tip")
            for finger, r in arrays.items()}
    for message in data.values():
        messages.tactile_readings_cdr(message)
    monkeypatch.setattr(cdr, "_Reader", None)  # a walk over the fields now fails
    for finger, message in data.items():
        stamp, read = messages.tactile_readings_cdr(message)
        assert stamp == 5 and read.finger == finger
        _same_reading(read, arrays[finger])
