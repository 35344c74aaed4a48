# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner's conversions in ros/messages/ (pure functions) and the request layer's caches."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from planner_support import BLOB, RING, scene_of, solid_of

from squeeze_grasp_interfaces.action import EventSqueeze as EventSqueezeAction
from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.msg import ContactNode, TactileArray
from squeeze_grasp_interfaces.srv import (
    EventSqueeze,
    GraspMap,
    LoadObject,
    PlanResistance,
    PlanSqueeze,
    RingGraspTest,
)
from squeeze_grasp_ros import planning
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactNode as MechanicsContactNode
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, Event, FingerState
from squeeze_grasp_ros.mechanics.squeeze.graspmap import grasp_map
from squeeze_grasp_ros.planning import ErrorCode
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.scene import build_mesh

RESPONSES = [LoadObject.Response, PlanSqueeze.Response, GraspMap.Response,
             PlanResistance.Response, RingGraspTest.Response, EventSqueeze.Response,
             GraspMapAction.Result, EventSqueezeAction.Result]


@pytest.mark.parametrize("response_type", RESPONSES, ids=lambda t: t.__qualname__)
def test_error_codes_match_every_interface(response_type: type) -> None:
    for code in ErrorCode:
        assert getattr(response_type, code.name) == code.value
    failed = messages.failure(response_type, ErrorCode.UNKNOWN_OBJECT, "why")
    assert (failed.success, failed.error_code, failed.message) == (False, 2, "why")
    assert messages.success(response_type).success


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(allow_nan=False), max_size=40))
def test_arrays_round_trip_bit_for_bit(values: list[float]) -> None:
    data = np.array(values)
    assert np.array_equal(np.asarray(messages.float64_array(data.reshape(-1, 1))), data)
    ints = np.arange(len(values), dtype=np.int64) - 7
    assert np.asarray(messages.int32_array(ints)).tolist() == ints.tolist()


def test_tactile_readings_round_trip() -> None:
    readings = messages.TactileReadings("F2", np.linspace(-0.5, 0.5, 7), np.arange(7.0),
                                        -np.arange(7.0) / 3)
    message = messages.tactile_array_msg(readings)
    assert isinstance(message, TactileArray) and message.finger == "F2"
    back = messages.tactile_readings(message)
    for name in ("angles", "normal", "tangential"):
        assert np.array_equal(getattr(back, name), getattr(readings, name))
    with pytest.raises(ValueError, match="differ in length"):
        messages.tactile_array_msg(messages.TactileReadings("F1", np.zeros(3), np.zeros(2),
                                                            np.zeros(3)))


def test_contact_state_and_events_keep_units_and_modes() -> None:
    nodes = (MechanicsContactNode(4, "F1", "stick", 0, 0.25, np.zeros(2), np.array([1.5, -2.0])),
             MechanicsContactNode(9, "F2", "slip", -1, -3.0, np.ones(2), np.array([0.0, 0.5])))
    fingers = tuple(FingerState(f, np.zeros(2), 0.02, np.zeros(2)) for f in ("F1", "F2"))
    state = ContactState(fingers, nodes, depth=0.003, relative_per_depth=10.0)
    message = messages.contact_state_msg(state)
    assert (message.depth, message.relative_depth) == (0.003, 0.03)
    assert list(zip(message.nodes, message.fingers, message.modes, message.polar_angles,
                    message.forces_x, message.forces_y)) == [
        (4, "F1", ContactNode.STICK, 0.25, 1.5, -2.0), (9, "F2", ContactNode.SLIP, -3.0, 0.0, 0.5)]
    assert messages.contact_records(message)[1] == {
        "node": 9, "finger": "F2", "mode": "slip", "polar_angle": -3.0, "force": [0.0, 0.5]}
    event = messages.contact_event_msg(Event("C", 9, "F2", 0.002, 0.02, "slip", -1))
    assert (event.type, event.node, event.finger, event.depth, event.relative_depth) == (
        "C", 9, "F2", 0.002, 0.02)


def test_grasp_map_data_best_and_matrices() -> None:
    gmap = grasp_map(solid_of(BLOB), 0.5)
    data = messages.grasp_map_data(gmap, "blob", 3, full_matrices=False)
    assert [list(c.contacts) for c in data.best] == [[i, j] for i, j, _ in gmap.best(3)]
    assert len(data.stiffness) == len(data.inward) == len(data.force_closure) == 0
    full = messages.grasp_map_data(gmap, "blob", 3, full_matrices=True)
    b = len(gmap.boundary)
    assert len(full.stiffness) == len(full.inward) == len(full.force_closure) == b * b


def test_object_cache_evicts_the_least_recently_used() -> None:
    limits = planning.PlannerLimits()
    source = planning.read_scene(BLOB, "")
    cache = planning.ObjectCache(2)
    for object_id in ("a", "b"):
        cache.put(planning.load_object(source, planning.object_key(source, object_id, "", limits),
                                       limits))
    cache.get("a")
    loaded, cached = planning.load_cached(cache, source, "c", "", limits)
    assert not cached and cache.ids() == ["a", "c"]
    again, cached = planning.load_cached(cache, source, "c", "", limits)
    assert cached and again is loaded
    with pytest.raises(planning.PlannerError, match="unknown object_id 'b'"):
        cache.get("b")


def test_object_cache_is_bounded_by_memory() -> None:
    """The cache counts the arrays an object holds (its boundary compliance, stiffness and
    factorisation dominate) and evicts by bytes; one object larger than the bound is refused.
    """
    limits = planning.PlannerLimits()
    source = planning.read_scene(BLOB, "")
    loaded = planning.load_object(source, planning.object_key(source, "a", "", limits), limits)
    body = loaded.body
    size = planning.resident_bytes(loaded)
    known = body.boundary_compliance.nbytes + body.stiffness.data.nbytes + body.mesh.nodes.nbytes
    assert known <= size < 20 * known
    assert planning.resident_bytes({"x": body, "y": [body]}) == planning.resident_bytes(body)
    cache = planning.ObjectCache(8, max_bytes=int(1.5 * size))
    cache.put(loaded)
    other = planning.load_object(source, planning.object_key(source, "b", "", limits), limits)
    assert cache.put(other) == ["a"] and cache.ids() == ["b"]
    assert cache.bytes == planning.resident_bytes(other.body)
    tiny = planning.ObjectCache(8, max_bytes=size // 2)
    with pytest.raises(planning.PlannerError, match="cache_max_megabytes") as info:
        tiny.put(loaded)
    assert info.value.code == planning.ErrorCode.INVALID_ARGUMENT and tiny.ids() == []


MEMORY_PROBE = """
import ctypes, gc, json, os
from squeeze_grasp_ros import planning
from squeeze_grasp_ros.ros.service_latency import scene_text

def rss():
    gc.collect()
    ctypes.CDLL("libc.so.6").malloc_trim(0)  # give freed temporaries back to the system
    return int(open("/proc/self/statm").read().split()[1]) * os.sysconf("SC_PAGE_SIZE")

source = planning.read_scene(scene_text(10000), "")
limits = planning.PlannerLimits()
key = planning.object_key(source, "probe", "", limits)
before = rss()
loaded = planning.load_object(source, key, limits)
grown = rss() - before
counted = planning.resident_bytes(loaded.body)
del loaded
print(json.dumps({"grown": grown, "freed": before + grown - rss(), "counted": counted}))
"""


def test_the_object_cache_counts_what_an_object_really_holds() -> None:
    """An independent measure: the resident memory a fresh process gains by loading a
    10,000-node object and frees when it drops it (malloc_trim'd). Measured: 86 MB gained,
    78 MB freed, 82 MB counted; before, the count missed the sparse copies of L and U that
    scipy's SuperLU keeps once read (46 MB counted; the issue: 389 MiB counted, 669 MiB held).
    """
    import json
    import subprocess
    import sys

    probe = json.loads(subprocess.run([sys.executable, "-c", MEMORY_PROBE], check=True,
                                      capture_output=True, text=True).stdout)
    assert 0.8 * probe["freed"] < probe["counted"] < 1.2 * probe["grown"], probe


def test_requested_nodes_are_known_before_meshing() -> None:
    assert planning.requested_nodes(scene_of(BLOB)) == 300
    assert planning.requested_nodes(scene_of(RING)) == 80
    scene = scene_of(BLOB.replace("nodes: 300", "max_area: 1.0e-6"))
    estimate = planning.requested_nodes(scene)
    mesh_nodes = build_mesh(scene).n
    assert 0.7 * mesh_nodes < estimate < 1.3 * mesh_nodes


def test_progress_can_cancel_a_load() -> None:
    stages: list[str] = []

    def progress(stage: str, index: int, count: int, num_nodes: int) -> None:
        stages.append(stage)
        if stage == "factorisation":
            raise planning.Cancelled()

    source = planning.read_scene(BLOB, "")
    limits = planning.PlannerLimits()
    with pytest.raises(planning.Cancelled):
        planning.load_object(source, planning.object_key(source, "", "", limits), limits,
                             progress)
    assert stages == ["mesh", "stiffness", "factorisation"]
    assert planning.classify(planning.Cancelled())[0] == ErrorCode.CANCELLED
    assert planning.classify(RuntimeError("boom"))[0] == ErrorCode.INTERNAL_ERROR
