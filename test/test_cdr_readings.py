# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The device readings read from raw CDR bytes (ros/messages/cdr.py) against rclpy's own
serialisation and deserialisation: every alignment a frame id or finger name can cause, empty
and odd-length taxel arrays, big-endian data, and what is refused.
"""
from __future__ import annotations

import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rclpy.serialization import serialize_message

from squeeze_grasp_ros.ros import messages

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
