# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The lockstep loop's messages written straight to CDR (ros/messages/cdr.py and the ``*_cdr``
writers) against rclpy: every writer's bytes, deserialised by rclpy, equal the message the
Python builders make of the same values, and have the length of rclpy's own serialisation, for
every alignment that frame ids, finger names, taxel counts, contacts, events and alarms can
cause; the readers read the writers' bytes back bit for bit; a simulated world's ground truth
along the foam square's squeeze serialises alike tick by tick.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rclpy.serialization import deserialize_message, serialize_message
from rosgraph_msgs.msg import Clock

from squeeze_grasp_interfaces.msg import ContactState, ForceResidual, MonitorStatus, SimState, Tick
from squeeze_grasp_ros.control.tracker import Patch, TrackedAlarm, TrackedEvent, TrackerOutput
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, EventType
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages import cdr
from squeeze_grasp_ros.ros.messages.cdr import CdrWriter, write_contact_arrays

FINITE = st.floats(allow_nan=False, allow_infinity=False, width=64)
NAMES = st.text(alphabet="abcdefghijklmnopqrstuvwxyz_/0123456789", max_size=17)
STAMPS = st.integers(min_value=0, max_value=2**31 * 1_000_000_000 - 1)
XY = st.tuples(FINITE, FINITE)


def _same(data: bytes, msg) -> None:
    """``data`` is ``msg``: rclpy reads it back equal, and its bytes are rclpy's serialisation
    of ``msg`` but for the padding, which the writer zeros: rclpy's alignment padding keeps what
    its buffer held, and its buffer ends in up to 7 more bytes after each empty float64[]
    (sized as if the empty array were aligned; Fast CDR writes it without aligning).
    """
    assert isinstance(data, bytes) and data[:4] == b"\x00\x01\x00\x00"
    assert deserialize_message(data, type(msg)) == msg
    theirs = serialize_message(msg)
    assert len(data) <= len(theirs) <= len(data) + 7 * str(msg).count("[]")
    assert all(ours == their or ours == 0 for ours, their in zip(data, theirs))


@settings(max_examples=60, deadline=None)
@given(STAMPS, NAMES, XY)
def test_pose_is_rclpys_and_reads_back(ns, frame, xy):
    data = messages.pose_stamped_cdr(np.array(xy), ns, frame)
    _same(data, messages.pose_msg(xy, ns, frame))
    stamp, position = messages.pose_position_cdr(data)
    assert stamp == ns and position.tobytes() == np.array(xy).tobytes()


@settings(max_examples=60, deadline=None)
@given(STAMPS, NAMES, st.tuples(FINITE, FINITE, FINITE), st.tuples(FINITE, FINITE, FINITE))
def test_wrench_is_rclpys(ns, frame, force, torque):
    data = messages.wrench_stamped_cdr(np.array(force), np.array(torque), ns, frame)
    _same(data, messages.wrench_msg(np.array(force), np.array(torque), ns, frame))
    assert messages.wrench_force_cdr(data)[1].tobytes() == np.array(force).tobytes()


@settings(max_examples=60, deadline=None)
@given(STAMPS, NAMES, NAMES, st.lists(st.tuples(FINITE, FINITE, FINITE), max_size=9))
def test_tactile_array_is_rclpys(ns, frame, finger, taxels):
    angles, normal, tangential = (np.array(column, dtype=float).reshape(-1)
                                  for column in zip(*taxels)) if taxels else (np.zeros(0),) * 3
    readings = messages.TactileReadings(finger, angles, normal, tangential)
    data = messages.tactile_array_cdr(readings, ns, frame)
    _same(data, messages.tactile_array_msg(readings, messages.header(ns, frame)))
    read = messages.tactile_readings_cdr(data)[1]
    assert read.finger == finger and read.normal.tobytes() == normal.tobytes()


def test_tactile_arrays_of_different_lengths_are_refused():
    with pytest.raises(ValueError, match="tactile arrays of F1 differ in length"):
        messages.tactile_array_cdr(messages.TactileReadings(
            "F1", np.zeros(3), np.zeros(3), np.zeros(2)), 0, "F1_tip")


@settings(max_examples=40, deadline=None)
@given(STAMPS, st.integers(min_value=0, max_value=2**64 - 1), st.lists(NAMES, max_size=7))
def test_clock_and_tick_are_rclpys_and_read_back(ns, index, readings):
    """The tick's readings are read back from rclpy's serialisation and from the writer's."""
    _same(messages.clock_cdr(ns), Clock(clock=messages.stamp(ns)))
    tick = Tick(header=messages.header(ns), index=index, readings=readings)
    data = messages.tick_cdr(index, ns, readings)
    _same(data, tick)
    for serialised in (data, serialize_message(tick)):
        assert messages.tick_readings_cdr(serialised) == (ns, readings)


CONTACTS = st.lists(st.tuples(st.sampled_from(["F1", "F2", "A"]),
                              st.integers(min_value=-1, max_value=2**31 - 1), FINITE,
                              st.sampled_from([ContactState.STICK, ContactState.SLIP]),
                              FINITE, FINITE), max_size=8)


@settings(max_examples=60, deadline=None)
@given(STAMPS, NAMES, CONTACTS, FINITE, FINITE)
def test_contact_state_is_rclpys(ns, frame, contacts, depth, relative):
    columns = [list(c) for c in zip(*contacts)] if contacts else [[] for _ in range(6)]
    msg = messages.fill_contact_arrays(ContactState(header=messages.header(ns, frame)),
                                       *columns, depth, relative)
    writer = CdrWriter()
    write_contact_arrays(writer, ns, frame, *columns, depth, relative)
    _same(writer.data(), msg)


FINGER_NAMES = st.lists(st.sampled_from(["F1", "F2", "A"]), unique=True, max_size=3)


@st.composite
def tracker_outputs(draw) -> TrackerOutput:
    """A tracker output: some fingers without a position, patches, events and alarms."""
    fingers = tuple(draw(FINGER_NAMES))
    vectors = {name: {f: np.array(draw(XY)) for f in fingers} for name in ("p", "f", "n")}
    positions = {f: xy for f, xy in vectors["p"].items() if draw(st.booleans())}
    patches = tuple(Patch(draw(st.sampled_from(["F1", "F2"])), draw(FINITE), draw(FINITE),
                          draw(FINITE), draw(st.sampled_from(list(ContactMode))), 0)
                    for _ in range(draw(st.integers(0, 4))))
    events = tuple(TrackedEvent(draw(st.sampled_from(list(EventType))), draw(NAMES),
                                draw(FINITE), draw(FINITE), 0.0)
                   for _ in range(draw(st.integers(0, 3))))
    alarms = tuple(TrackedAlarm(draw(NAMES), draw(NAMES), draw(FINITE), draw(NAMES))
                   for _ in range(draw(st.integers(0, 3))))
    ages = {f: draw(st.one_of(st.floats(0.0, 10.0), st.just(float("inf")))) for f in fingers}
    return TrackerOutput(draw(STAMPS), fingers, positions, vectors["f"], vectors["n"], ages,
                         patches, events, alarms, draw(FINITE), draw(FINITE))


@settings(max_examples=80, deadline=None)
@given(tracker_outputs(), NAMES)
def test_monitor_status_and_patches_are_rclpys(out, frame):
    status = messages.monitor_status_cdr(out, frame)
    _same(status, messages.monitor_status_msg(out, frame))
    assert isinstance(deserialize_message(status, MonitorStatus), MonitorStatus)
    _same(messages.patches_state_cdr(out, frame), messages.patches_state_msg(out, frame))


@settings(max_examples=80, deadline=None)
@given(tracker_outputs(), NAMES)
def test_the_executors_observation_reads_the_status_bytes_as_rclpys_message(out, frame):
    """The executor reads a status without events and alarms from its bytes (ours and rclpy's,
    whose padding differs): the observation of rclpy's message, bit for bit; a status with an
    event or an alarm is left to rclpy (None).
    """
    msg = messages.monitor_status_msg(out, frame)
    want = messages.observation(msg)
    for data in (messages.monitor_status_cdr(out, frame), serialize_message(msg)):
        got = messages.observation_cdr(data)
        if out.events or out.alarms:
            assert got is None
            continue
        assert (got.stamp_ns, got.alarms, got.events) == (want.stamp_ns, (), ())
        assert np.float64(got.depth).tobytes() == np.float64(want.depth).tobytes()
        for ours, theirs in ((got.positions, want.positions), (got.forces, want.forces),
                             (got.normals, want.normals)):
            assert list(ours) == list(theirs) == list(out.fingers)
            assert all(ours[f].tobytes() == theirs[f].tobytes() for f in ours)


@settings(max_examples=40, deadline=None)
@given(STAMPS, NAMES, FINITE, st.lists(st.tuples(NAMES, FINITE, FINITE, FINITE), max_size=3),
       FINITE)
def test_force_residual_is_rclpys(ns, frame, depth, rows, tolerance):
    fingers, measured, predicted, relative = (list(c) for c in zip(*rows)) if rows \
        else ([], [], [], [])
    _same(messages.force_residual_cdr(ns, frame, depth, fingers, measured, predicted, relative,
                                      tolerance),
          ForceResidual(header=messages.header(ns, frame), depth=depth, fingers=fingers,
                        measured=measured, predicted=predicted, relative_error=relative,
                        tolerance=tolerance))


def test_the_worlds_ground_truth_is_rclpys_tick_by_tick():
    """Along the foam square's squeeze (contacts appear, grow, change mode) every tick's
    SimState, and the terminated one, serialises as the message builder's.
    """
    from squeeze_grasp_ros.bench.pipeline import squeeze_world
    from squeeze_grasp_ros.resources import scene_file
    from squeeze_grasp_ros.scene import GraspSetup, load_scene
    from squeeze_grasp_ros.sim.world import SimWorld

    world = SimWorld(GraspSetup.build(load_scene(scene_file("foam_square"))))
    outputs = squeeze_world(world, 120)
    assert max(len(out.state.contacts) for out in outputs) > 0
    for out in outputs[::7] + outputs[-1:]:
        for termination in (None, "finger_slip"):
            data = messages.sim_state_cdr(out.state, world.fingers, termination, out.stamp_ns,
                                          "object")
            _same(data, messages.sim_state_msg(out.state, world.fingers, termination,
                                               out.stamp_ns, "object"))
            assert isinstance(deserialize_message(data, SimState), SimState)


def _fresh(write, *args) -> bytes:
    """``write(*args)`` written in full: every kept template dropped first."""
    cdr._LAYOUTS.__dict__.clear()
    return write(*args)


@settings(max_examples=40, deadline=None)
@given(STAMPS, STAMPS, NAMES, NAMES, st.lists(st.tuples(FINITE, FINITE, FINITE), max_size=9),
       st.integers(min_value=0, max_value=2**64 - 1), st.lists(NAMES, max_size=7))
def test_a_refilled_message_is_the_bytes_a_fresh_writer_writes(ns, later, frame, finger, taxels,
                                                               index, readings):
    """The second message of a layout refills the first's bytes (cdr.CdrTemplate): the stamp,
    the counters and every number are the new message's, byte for byte what the writer writes
    from scratch; the first message's bytes are not touched.
    """
    array = np.array(taxels, dtype=float).reshape(-1, 3)
    first = messages.TactileReadings(finger, *array.T)
    second = messages.TactileReadings(finger, *(0.5 * array.T[::-1] - 1.0))
    calls = [(messages.pose_stamped_cdr, (array[:1, :2].sum(axis=0), ns, frame),
              (np.array([0.5, -3.0]), later, frame)),
             (messages.wrench_stamped_cdr, (np.ones(3), np.zeros(3), ns, frame),
              (array[:1].sum(axis=0), -array[-1:].sum(axis=0), later, frame)),
             (messages.tactile_array_cdr, (first, ns, frame), (second, later, frame)),
             (messages.tick_cdr, (0, ns, readings), (index, later, readings))]
    for write, before, after in calls:
        kept = _fresh(write, *before)
        refilled = write(*after)
        assert refilled == _fresh(write, *after)
        assert kept == _fresh(write, *before)


def test_the_worlds_ground_truth_refills_as_written():
    """Along the foam square's squeeze (contacts appear and change mode: new layouts; most
    ticks keep the layout: refills) every tick's SimState is the bytes written from scratch.
    """
    from squeeze_grasp_ros.bench.pipeline import squeeze_world
    from squeeze_grasp_ros.resources import scene_file
    from squeeze_grasp_ros.scene import GraspSetup, load_scene
    from squeeze_grasp_ros.sim.world import SimWorld

    world = SimWorld(GraspSetup.build(load_scene(scene_file("foam_square"))))
    outputs = squeeze_world(world, 200)
    cdr._LAYOUTS.__dict__.clear()
    kept = [messages.sim_state_cdr(out.state, world.fingers, None, out.stamp_ns, "object")
            for out in outputs]
    assert len(cdr._LAYOUTS.__dict__) < len(outputs) / 4  # most ticks refilled
    assert kept == [_fresh(messages.sim_state_cdr, out.state, world.fingers, None,
                           out.stamp_ns, "object") for out in outputs]


@settings(max_examples=60, deadline=None)
@given(tracker_outputs(), NAMES, STAMPS, st.floats(-1e6, 1e6))
def test_the_monitors_messages_refill_as_written(out, frame, later, scale):
    """The monitor's status, contact state and force residual of a second tick with the same
    fingers and patches (new stamp, positions, forces, ages, depths) are the bytes written from
    scratch; a status with events or alarms is always written in full.
    """
    def shifted(v):
        return v * 0.5 - scale

    nxt = out._replace(
        stamp_ns=later, positions={f: shifted(v) for f, v in out.positions.items()},
        forces={f: shifted(v) for f, v in out.forces.items()},
        normals={f: -v for f, v in out.normals.items()},
        ages={f: a / 2.0 for f, a in out.ages.items()},
        patches=tuple(p._replace(angle=shifted(p.angle), normal=p.tangential,
                                 tangential=shifted(p.normal)) for p in out.patches),
        depth=shifted(out.depth), relative_depth=-out.relative_depth)
    residual = (frame, out.depth, list(out.fingers))
    for write, args in ((messages.monitor_status_cdr, (frame,)),
                        (messages.patches_state_cdr, (frame,))):
        kept = _fresh(write, out, *args)
        assert write(nxt, *args) == _fresh(write, nxt, *args)
        assert kept == _fresh(write, out, *args)
    k = len(out.fingers)
    kept = _fresh(messages.force_residual_cdr, out.stamp_ns, *residual, [1.0] * k, [2.0] * k,
                  [0.5] * k, 0.1)
    again = messages.force_residual_cdr(later, frame, nxt.depth, list(out.fingers),
                                        [scale] * k, [-scale] * k, [0.25] * k, 0.2)
    assert again == _fresh(messages.force_residual_cdr, later, frame, nxt.depth,
                           list(out.fingers), [scale] * k, [-scale] * k, [0.25] * k, 0.2)
    assert kept == _fresh(messages.force_residual_cdr, out.stamp_ns, *residual, [1.0] * k,
                          [2.0] * k, [0.5] * k, 0.1)
