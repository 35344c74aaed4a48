# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A property-based stream of requests against one planner node on real rclpy.

Each request is either good or has exactly one bad field (NaN, infinity, a negative depth or
mu, unknown object ids, contacts off the boundary or repeated, bad YAML or scenes, unknown
choices). Good requests must succeed (or be reported NOT_FEASIBLE where the mechanics may say
so); bad ones must fail with the expected code and a message naming the field. No request may
produce INTERNAL_ERROR, and afterwards the node still answers with the mechanics' numbers.
"""
from __future__ import annotations

import functools
import math
import re
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
import yaml
from geometry_msgs.msg import Vector3
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from planner_support import BLOB, RING, Harness, flat, planner_threads, scene_of, solid_of
from rclpy.context import Context

from squeeze_grasp_interfaces.srv import (
    EventSqueeze,
    GraspMap,
    LoadObject,
    PlanResistance,
    PlanSqueeze,
    RingGraspTest,
)
from squeeze_grasp_ros.mechanics.squeeze.graspmap import grasp_map
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze
from squeeze_grasp_ros.planning import ErrorCode
from squeeze_grasp_ros.scene import finger_nodes

SOLID = solid_of(BLOB)
BOUNDARY = SOLID.mesh.boundary.tolist()
INTERIOR = np.setdiff1d(np.arange(SOLID.mesh.n), SOLID.mesh.boundary).tolist()
RING_NODES = 80


@dataclass(frozen=True)
class Case:
    """One fuzzed request and what must come back.

    Attributes
    ----------
    service : str
    srv_type : type
    request : Any
    bad : str
        A regular expression the message must match (naming the corrupted field); "" for a
        good request.
    code : ErrorCode
        Expected error code of a bad request.
    may_fail : tuple of ErrorCode
        Codes a good request may also get (e.g. NOT_FEASIBLE from the mechanics).
    """

    service: str
    srv_type: Any
    request: Any
    bad: str = ""
    code: ErrorCode = ErrorCode.INVALID_ARGUMENT
    may_fail: tuple[ErrorCode, ...] = ()


def floats(low: float, high: float) -> st.SearchStrategy[float]:
    """Finite floats in [low, high]."""
    return st.floats(low, high, allow_nan=False, allow_infinity=False)


NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])
NEGATIVE = st.one_of(floats(-1e6, -1e-12), st.just(-math.inf))


def pair(nodes: list[int]) -> st.SearchStrategy[list[int]]:
    """Two distinct nodes of ``nodes``."""
    return st.lists(st.sampled_from(nodes), min_size=2, max_size=2, unique=True)


BAD_CONTACTS = st.one_of(
    st.tuples(st.sampled_from(BOUNDARY), st.sampled_from(INTERIOR)).map(list),
    st.sampled_from(BOUNDARY).map(lambda n: [n, n]),
    st.sampled_from(BOUNDARY).map(lambda n: [n]),
    st.tuples(st.integers(-10**6, -1), st.sampled_from(BOUNDARY)).map(list),
    st.tuples(st.sampled_from(BOUNDARY), st.integers(SOLID.mesh.n, 2**31 - 1)).map(list),
)
"""Contacts that are surely bad: off the boundary, repeated, single, negative, too large."""


def corrupt(draw: st.DrawFn, fields: dict[str, Any],
            bad: dict[str, tuple[st.SearchStrategy, ErrorCode, str]]) -> tuple[str, ErrorCode]:
    """Maybe replace one field of ``fields`` by a bad value; return (reason, code) or ("", OK)."""
    field = draw(st.sampled_from(["", *bad]))
    if not field:
        return "", ErrorCode.OK
    strategy, code, reason = bad[field]
    fields[field] = draw(strategy)
    return reason, code


@st.composite
def plan_squeeze_cases(draw: st.DrawFn) -> Case:
    fields = {"object_id": "blob", "contacts": draw(st.one_of(st.just([]), pair(BOUNDARY))),
              "squeeze_type": draw(st.sampled_from(["stable", "pure"])),
              "depth": draw(st.one_of(st.just(0.0), floats(0.0, 0.05)))}
    reason, code = corrupt(draw, fields, {
        "object_id": (st.text(max_size=8).filter(lambda s: s not in ("blob", "ring")),
                      ErrorCode.UNKNOWN_OBJECT, "unknown object_id"),
        "contacts": (BAD_CONTACTS, ErrorCode.INVALID_ARGUMENT, "contact"),
        "squeeze_type": (st.text(max_size=6).filter(lambda s: s not in ("stable", "pure")),
                         ErrorCode.INVALID_ARGUMENT, "squeeze_type"),
        "depth": (st.one_of(NON_FINITE, NEGATIVE), ErrorCode.INVALID_ARGUMENT, "depth"),
    })
    if not reason and fields["depth"] > 0 and relative_depth(
            tuple(fields["contacts"]), fields["squeeze_type"], fields["depth"]) >= 1:
        reason, code = "fingers would meet", ErrorCode.INVALID_ARGUMENT
    return Case("plan_squeeze", PlanSqueeze, PlanSqueeze.Request(**fields), reason, code)


@functools.lru_cache(maxsize=None)
def relative_depth(contacts: tuple[int, ...], kind: str, depth: float) -> float:
    """The finger approach over the contacts' distance at ``depth`` (the planner's check)."""
    nodes = list(contacts) or list(finger_nodes(scene_of(BLOB), SOLID.mesh))
    return plan_squeeze(SOLID, nodes, kind=kind).relative_depth(depth)


def scene_text(data: dict) -> str:
    return yaml.safe_dump(data)


BAD_SCENE_FIELDS = {
    ("object", "material", "nu"): (st.one_of(floats(0.500001, 10), floats(-10, -1)),
                                   "object\\.material\\.nu"),
    ("object", "material", "E"): (st.one_of(NON_FINITE, NEGATIVE, st.just(0.0)),
                                  "object.material.E"),
    ("object", "shape"): (st.sampled_from([{}, {"type": "blob"}, {"type": "polygon", "points": []},
                                           {"type": "polygon", "points": [[0, 0], [0.1, 0.08],
                                                                          [0.1, 0], [0, 0.1]]}]),
                          "shape"),
    ("object", "mesh"): (st.one_of(st.integers(70_000, 10**9).map(lambda n: {"nodes": n}),
                                   floats(1e-15, 1e-9).map(lambda a: {"max_area": a})),
                         "oversized|mesh.nodes must be in|at most 250000"),
    ("squeeze", "depth"): (NEGATIVE, "squeeze.depth"),
    ("friction", "mu"): (NEGATIVE, "friction.mu"),
}


@st.composite
def load_object_cases(draw: st.DrawFn) -> Case:
    kind = draw(st.sampled_from(["cached", "small", "bad scene", "bad yaml", "neither",
                                 "hostile"]))
    if kind == "cached":
        return Case("load_object", LoadObject,
                    LoadObject.Request(scene_yaml=BLOB, object_id="blob"))
    data = yaml.safe_load(BLOB)
    object_id = draw(st.sampled_from(["fuzz1", "fuzz2"]))
    if kind == "small":
        data["object"]["mesh"] = {"nodes": draw(st.integers(20, 120))}
        return Case("load_object", LoadObject,  # a client reloading its id with a new scene
                    LoadObject.Request(scene_yaml=scene_text(data), object_id=object_id,
                                       replace=True))
    if kind == "bad scene":
        path = draw(st.sampled_from(sorted(BAD_SCENE_FIELDS)))
        strategy, reason = BAD_SCENE_FIELDS[path]
        entry = data
        for key in path[:-1]:
            entry = entry[key]
        entry[path[-1]] = draw(strategy)
        return Case("load_object", LoadObject,
                    LoadObject.Request(scene_yaml=scene_text(data), object_id=object_id), reason)
    if kind == "bad yaml":
        text = draw(st.sampled_from(["object: [", "{", ":\n- - ]", "a: b: c"]))
        return Case("load_object", LoadObject, LoadObject.Request(scene_yaml=text), "invalid YAML")
    if kind == "hostile":
        return draw(st.sampled_from(HOSTILE_LOADS))
    return Case("load_object", LoadObject, LoadObject.Request(), "exactly one of")


HOSTILE_LOADS = [
    Case("load_object", LoadObject, LoadObject.Request(scene_path=path),
         "outside the allowed folders")
    for path in ("/etc/shadow", "/proc/self/environ", "../../../../etc/passwd", "/dev/zero")
] + [
    Case("load_object", LoadObject, LoadObject.Request(scene_yaml=text), reason)
    for text, reason in (
        ("a: &a [x, x, x]\nb: &b [*a, *a, *a]\nc: [*b, *b, *b]\n", "aliases"),
        (scene_text({**yaml.safe_load(BLOB), "object": {**yaml.safe_load(BLOB)["object"],
                     "shape": {"type": "polygon", "points": [[-0.05, -0.05], [0.05, -0.05],
                                                             [0.05, 0.05], [0, 0],
                                                             [-0.05, 0.05], [0, 0]]}}}),
         "self-intersecting"),
        ("# " + "x" * (2 * 1024 * 1024), "larger than"),
    )
]
"""Loads a careless or hostile client sends: paths outside the planner's folders, a YAML alias
bomb, a polygon that crashed the mesher, an oversized request."""


@st.composite
def grasp_map_cases(draw: st.DrawFn) -> Case:
    fields = {"object_id": "blob", "mu": draw(floats(0.0, 5.0)),
              "best_count": draw(st.integers(0, 50))}
    reason, code = corrupt(draw, fields, {
        "object_id": (st.sampled_from(["", "nope", "fuzz9"]), ErrorCode.UNKNOWN_OBJECT,
                      "unknown object_id"),
        "mu": (st.one_of(NON_FINITE, NEGATIVE), ErrorCode.INVALID_ARGUMENT, "mu"),
        "best_count": (st.integers(-2**31, -1), ErrorCode.INVALID_ARGUMENT, "best_count"),
    })
    return Case("grasp_map", GraspMap, GraspMap.Request(**fields), reason, code)


@st.composite
def resistance_cases(draw: st.DrawFn) -> Case:
    triple = draw(st.lists(st.sampled_from(BOUNDARY), min_size=3, max_size=3, unique=True))
    angle, length = draw(floats(0.0, 2 * math.pi)), draw(floats(1e-4, 0.01))
    fields = {"object_id": "blob", "contacts": triple,
              "a": Vector3(x=length * math.cos(angle), y=length * math.sin(angle)),
              "mode": draw(st.sampled_from(["stable", "pure"])), "contact_model": "point",
              "directions": draw(st.integers(0, 64))}
    reason, code = corrupt(draw, fields, {
        "contacts": (st.one_of(BAD_CONTACTS, pair(BOUNDARY)), ErrorCode.INVALID_ARGUMENT,
                     "contact"),
        "a": (st.one_of(NON_FINITE.map(lambda v: Vector3(x=v)), st.just(Vector3()),
                        floats(1e-3, 1.0).map(lambda z: Vector3(x=0.01, z=z))),
              ErrorCode.INVALID_ARGUMENT, r"\ba[. ]"),
        "mode": (st.sampled_from(["", "soft", "Stable"]), ErrorCode.INVALID_ARGUMENT, "mode"),
        "contact_model": (st.sampled_from(["", "friction ", "line"]), ErrorCode.INVALID_ARGUMENT,
                          "contact_model"),
        "directions": (st.integers(-2**31, -1), ErrorCode.INVALID_ARGUMENT, "directions"),
    })
    return Case("plan_resistance", PlanResistance, PlanResistance.Request(**fields), reason, code,
                may_fail=(ErrorCode.NOT_FEASIBLE,))


@st.composite
def ring_cases(draw: st.DrawFn) -> Case:
    fields = {"object_id": "ring",
              "contacts": draw(st.one_of(st.just([]), pair(list(range(RING_NODES))))),
              "squeeze_type": draw(st.sampled_from(["stable", "pure"])),
              "mu": draw(floats(0.0, 2.0)), "strain_limit": draw(st.sampled_from([0.0, 0.03])),
              "relative_depth": draw(floats(0.0, 1.0))}
    reason, code = corrupt(draw, fields, {
        "object_id": (st.just("blob"), ErrorCode.INVALID_ARGUMENT, "not a ring"),
        "mu": (st.one_of(NON_FINITE, NEGATIVE), ErrorCode.INVALID_ARGUMENT, "mu"),
        "strain_limit": (st.one_of(NON_FINITE, NEGATIVE), ErrorCode.INVALID_ARGUMENT,
                         "strain_limit"),
        "relative_depth": (st.one_of(NON_FINITE, NEGATIVE, floats(1.000001, 1e9)),
                           ErrorCode.INVALID_ARGUMENT, "relative_depth"),
        "contacts": (st.one_of(st.integers(RING_NODES, 10**6).map(lambda n: [0, n]),
                               st.just([3, 3]), st.just([1, 2, 3])),
                     ErrorCode.INVALID_ARGUMENT, "contact"),
    })
    return Case("ring_grasp_test", RingGraspTest, RingGraspTest.Request(**fields), reason, code)


@st.composite
def event_squeeze_cases(draw: st.DrawFn) -> Case:
    fields: dict[str, Any] = {"object_id": "blob"}
    reason, code = corrupt(draw, fields, {
        "object_id": (st.sampled_from(["nope", "ring"]), ErrorCode.INVALID_ARGUMENT, "object"),
        "depth": (st.one_of(NON_FINITE, NEGATIVE), ErrorCode.INVALID_ARGUMENT, "depth"),
        "relative_depth": (st.one_of(NON_FINITE, NEGATIVE, floats(1.5, 1e9)),
                           ErrorCode.INVALID_ARGUMENT, "relative_depth"),
        "step": (st.one_of(NON_FINITE, NEGATIVE, floats(1e-12, 1e-6)),
                 ErrorCode.INVALID_ARGUMENT, "step"),
        "contacts": (BAD_CONTACTS, ErrorCode.INVALID_ARGUMENT, "contact"),
        "squeeze_type": (st.sampled_from(["none", "Pure"]), ErrorCode.INVALID_ARGUMENT,
                         "squeeze_type"),
    })
    if fields["object_id"] == "nope":
        code = ErrorCode.UNKNOWN_OBJECT
    return Case("event_squeeze", EventSqueeze, EventSqueeze.Request(**fields), reason, code)


CASES = st.one_of(plan_squeeze_cases(), load_object_cases(), grasp_map_cases(),
                  resistance_cases(), ring_cases(), event_squeeze_cases())


@pytest.fixture
def planner(ros_context: Context) -> Iterator[Harness]:
    """A planner with the fuzz's objects loaded."""
    harness = Harness(ros_context)
    harness.load(BLOB)
    harness.load(RING)
    try:
        yield harness
    finally:
        harness.close()
    assert planner_threads() == []


def check(case: Case, response: Any) -> None:
    """The response is what ``case`` expects."""
    if not case.bad:
        assert response.success or response.error_code in case.may_fail, response.message
        assert (response.message == "") == response.success
        return
    assert not response.success, f"{case.service} accepted a bad {case.bad}: {case.request}"
    assert response.error_code == case.code, response.message
    assert re.search(case.bad, response.message), (case.bad, response.message)


def run_stream(planner: Harness, examples: int) -> Counter:
    """Send ``examples`` fuzzed requests; return counts of (service, good/bad)."""
    counts: Counter = Counter()

    @settings(max_examples=examples, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(case=CASES)
    def one(case: Case) -> None:
        response = planner.call(case.srv_type, case.service, case.request)
        assert response.error_code != ErrorCode.INTERNAL_ERROR, response.message
        check(case, response)
        counts[case.service, "bad" if case.bad else "good"] += 1

    one()
    return counts


def still_correct(planner: Harness) -> None:
    """After the stream, the planner answers with the mechanics' numbers."""
    fingers = list(planner.load(BLOB).finger_nodes)
    response = planner.call(PlanSqueeze, "plan_squeeze", PlanSqueeze.Request(
        object_id="blob", squeeze_type="pure", depth=0.002))
    assert np.array_equal(flat(response.forces),
                          0.002 * plan_squeeze(SOLID, fingers, kind="pure").forces)
    gmap = planner.call(GraspMap, "grasp_map", GraspMap.Request(
        object_id="blob", mu=0.4, full_matrices=True))
    assert np.array_equal(flat(gmap.map.stiffness), grasp_map(SOLID, 0.4).stiffness.reshape(-1))


def test_a_fuzzed_stream_of_1000_requests(planner: Harness) -> None:
    counts = run_stream(planner, 1000)
    assert sum(counts.values()) >= 1000
    assert all(counts[service, kind] > 0 for service, _ in counts for kind in ("good", "bad"))
    still_correct(planner)


@pytest.mark.slow
def test_a_fuzzed_stream_of_10000_requests(planner: Harness) -> None:
    counts = run_stream(planner, 10_000)
    assert sum(counts.values()) >= 10_000
    still_correct(planner)
