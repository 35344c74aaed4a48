# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Several clients of one planner on real rclpy: bursts of requests and goals, shared object
ids, bounded identifiers and abandoned work (issue 34, items 2, 9, 10, 11, 15).
"""
from __future__ import annotations

import re
import time
from collections import Counter
from pathlib import Path

import yaml
from action_msgs.msg import GoalStatus
from geometry_msgs.msg import Point32
from planner_support import BLOB, Harness
from rclpy.action import ActionClient
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from test_planner_node import RESIST_FIG10

from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.msg import Material, ObjectDescription
from squeeze_grasp_interfaces.srv import EventSqueeze, LoadObject, PlanSqueeze
from squeeze_grasp_ros.planning import ErrorCode
from squeeze_grasp_ros.ros.refusals import REFUSAL_LOG_INTERVAL_S

BURST = 200
"""Requests or goals sent at once (the issue's burst)."""
KEEP_ALL = QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=1,
                      reliability=ReliabilityPolicy.RELIABLE)
"""A burst client's own queue: a client with rclpy's default (keep-last 10) drops responses."""


def spin_until_done(harness: Harness, futures: list, timeout: float = 120.0) -> None:
    """Spin the harness until every future is done; fail naming how many were not."""
    deadline = time.monotonic() + timeout
    while not all(f.done() for f in futures):
        assert time.monotonic() < deadline, \
            f"{sum(not f.done() for f in futures)} of {len(futures)} never answered"
        harness.executor.spin_once(0.05)


def burst(harness: Harness, srv_type: type, name: str, requests: list) -> list:
    """Send every request at once from one keep-all client; the responses, in order."""
    client = harness.node.create_client(srv_type, f"{harness.planner_name}/{name}",
                                        qos_profile=KEEP_ALL)
    assert client.wait_for_service(timeout_sec=30.0)
    futures = [client.call_async(r) for r in requests]
    spin_until_done(harness, futures)
    return [f.result() for f in futures]


# --------------------------------------------------------------------------- bursts


def test_a_burst_of_200_plan_squeeze_requests_is_answered_in_full(planner):
    """Before: 105 of 200 answered (a request queue of 100 inside DDS dropped the rest)."""
    planner.load(BLOB, "blob")
    responses = burst(planner, PlanSqueeze, "plan_squeeze", [
        PlanSqueeze.Request(object_id="blob", squeeze_type="stable", depth=1e-3 * (1 + k % 3))
        for k in range(BURST)])
    assert all(r.success for r in responses)
    stiffness = {round(r.stiffness, 9) for r in responses}
    assert len(stiffness) == 1  # one object, one stiffness whatever the depth


def test_a_burst_of_200_refused_requests_is_200_reasons_and_a_few_log_lines(planner, capfd):
    """Every refused request gets its reason; the planner's log gets the first refusal of each
    kind per second and then the count it left out (before: 200 identical lines).
    """
    capfd.readouterr()
    start = time.monotonic()
    responses = burst(planner, PlanSqueeze, "plan_squeeze", [
        PlanSqueeze.Request(object_id=f"ghost{k}", squeeze_type="stable", depth=1e-3)
        for k in range(BURST)])
    seconds = time.monotonic() - start
    assert all(ErrorCode(r.error_code) == ErrorCode.UNKNOWN_OBJECT for r in responses)
    assert {r.message for r in responses} == {
        f"unknown object_id 'ghost{k}': load it first with load_object (objects are evicted "
        "when the cache is full)" for k in range(BURST)}
    time.sleep(1.1)  # past the refusal log's interval
    last = burst(planner, PlanSqueeze, "plan_squeeze", [
        PlanSqueeze.Request(object_id="late", squeeze_type="stable", depth=1e-3)])
    assert ErrorCode(last[0].error_code) == ErrorCode.UNKNOWN_OBJECT
    lines = [line for line in capfd.readouterr().err.splitlines()
             if "refused (UNKNOWN_OBJECT)" in line]
    assert 2 <= len(lines) <= 2 + seconds / REFUSAL_LOG_INTERVAL_S, (seconds, lines)
    skipped = [int(line.split("(and ")[1].split()[0]) for line in lines if "(and " in line]
    assert re.search(r"refused \(UNKNOWN_OBJECT\): unknown object_id 'late': .*\(and \d+ more "
                     r"UNKNOWN_OBJECT refusals in the \d+\.\d s before, not logged\)$",
                     lines[-1]), lines[-1]  # the format docs/ros.md quotes
    assert len(lines) + sum(skipped) == BURST + 1, lines


def test_a_burst_of_200_loads_gets_200_answers_ok_or_busy(planner):
    """Before: 16 OK, 94 BUSY and 90 never answered. Now every load beyond max_pending (16)
    is answered BUSY at once with the reason, and the others load.
    """
    responses = burst(planner, LoadObject, "load_object", [
        LoadObject.Request(scene_yaml=BLOB, object_id=f"o{k}") for k in range(BURST)])
    codes = Counter(ErrorCode(r.error_code) for r in responses)
    assert set(codes) <= {ErrorCode.OK, ErrorCode.BUSY}, codes
    assert codes[ErrorCode.OK] >= 16 and codes[ErrorCode.BUSY] > 0, codes
    busy = [r.message for r in responses if r.error_code == ErrorCode.BUSY]
    assert all("max_pending" in m and "retry" in m for m in busy)


def test_a_burst_of_200_grasp_map_goals_gets_200_responses_and_results(planner):
    """Before: 20 goal responses and 12 results of 200 (the action server's goal and result
    services kept rclpy's default queue of 10). Every goal is now accepted and ends: SUCCEEDED
    with the map, or ABORTED with error code BUSY and the reason.
    """
    planner.load(BLOB, "blob")
    action = ActionClient(planner.node, GraspMapAction, f"{planner.planner_name}/grasp_map",
                          goal_service_qos_profile=KEEP_ALL,
                          result_service_qos_profile=KEEP_ALL)
    try:
        assert action.wait_for_server(timeout_sec=30.0)
        sent = [action.send_goal_async(GraspMapAction.Goal(object_id="blob", mu=0.4))
                for _ in range(BURST)]
        spin_until_done(planner, sent)
        assert all(f.result().accepted for f in sent)
        results = [f.result().get_result_async() for f in sent]
        spin_until_done(planner, results)
    finally:
        action.destroy()
    outcomes = Counter((r.result().status, ErrorCode(r.result().result.error_code))
                       for r in results)
    assert set(outcomes) <= {(GoalStatus.STATUS_SUCCEEDED, ErrorCode.OK),
                             (GoalStatus.STATUS_ABORTED, ErrorCode.BUSY)}, outcomes
    assert outcomes[(GoalStatus.STATUS_SUCCEEDED, ErrorCode.OK)] >= 16
    maps = {r.result().result.map.pairs for r in results
            if r.result().status == GoalStatus.STATUS_SUCCEEDED}
    assert len(maps) == 1 and maps.pop() > 0


def test_mixed_requests_from_several_clients_at_once_are_all_answered(planner):
    """Five clients at once, each with its own keep-all queue: YAML and typed loads, squeezes of
    an object still loading, and requests with one garbage field (empty or broken YAML, a NaN
    modulus, a 1,000-character id, two sources, NaN, negative and infinite depths, an unknown
    squeeze type, an unknown id). Every request is answered; loads are OK or BUSY; squeezes of
    the loading object OK or UNKNOWN_OBJECT; every bad field INVALID_ARGUMENT or
    UNKNOWN_OBJECT with the field named (a bad load beyond ``max_pending`` may be answered BUSY
    first: sent again, it is refused naming the field); no INTERNAL_ERROR; afterwards the
    planner serves on.
    """
    import math

    import numpy as np

    from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
    from squeeze_grasp_ros.ros.messages.objects import object_description

    def typed(modulus: float = 5.0e4):
        return object_description(
            Outline(np.array([[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, 0.05]])),
            "object", youngs_modulus=modulus, poisson_ratio=0.3, thickness=0.0254,
            placements=((-0.05, 0.0), (0.05, 0.0)), tip_radius=0.02, mu=0.4, mesh_nodes=300)

    def squeeze(**fields) -> PlanSqueeze.Request:
        return PlanSqueeze.Request(**{"object_id": "y0", "squeeze_type": "stable",
                                      "depth": 1e-3, **fields})

    loads = ([LoadObject.Request(scene_yaml=BLOB, object_id=f"y{k}") for k in range(8)]
             + [LoadObject.Request(object=typed(), object_id=f"t{k}") for k in range(8)])
    bad_loads = {
        "scene_yaml": LoadObject.Request(scene_yaml="{"),
        "exactly one": LoadObject.Request(),
        "youngs_modulus": LoadObject.Request(object=typed(math.nan)),
        "object_id": LoadObject.Request(scene_yaml=BLOB, object_id="x" * 1000),
        "exactly one of": LoadObject.Request(scene_yaml=BLOB, object=typed()),
    }
    bad_squeezes = {
        "depth": squeeze(depth=math.nan),
        "depth ": squeeze(depth=-1e-3),
        "depth  ": squeeze(depth=math.inf),
        "squeeze_type": squeeze(squeeze_type="bogus"),
        "unknown object_id": squeeze(object_id="nobody"),
    }
    clients = {name: planner.node.create_client(srv, f"{planner.planner_name}/{name}",
                                                qos_profile=KEEP_ALL)
               for name, srv in (("load_object", LoadObject), ("plan_squeeze", PlanSqueeze))}
    yaml_loads = planner.node.create_client(LoadObject, f"{planner.planner_name}/load_object",
                                            qos_profile=KEEP_ALL)
    bad_client = planner.node.create_client(LoadObject, f"{planner.planner_name}/load_object",
                                            qos_profile=KEEP_ALL)
    squeezes = planner.node.create_client(PlanSqueeze, f"{planner.planner_name}/plan_squeeze",
                                          qos_profile=KEEP_ALL)
    every = [*clients.values(), yaml_loads, bad_client, squeezes]
    try:
        for client in every:
            assert client.wait_for_service(timeout_sec=30.0)
        sent = {
            "loads": [(yaml_loads if k < 8 else clients["load_object"]).call_async(r)
                      for k, r in enumerate(loads)],
            "squeezes": [squeezes.call_async(squeeze()) for _ in range(20)],
            "bad_loads": [bad_client.call_async(r) for r in bad_loads.values()],
            "bad_squeezes": [clients["plan_squeeze"].call_async(r)
                             for r in bad_squeezes.values()],
        }
        spin_until_done(planner, [f for futures in sent.values() for f in futures])
    finally:
        for client in every:
            planner.node.destroy_client(client)
    got = {kind: [f.result() for f in futures] for kind, futures in sent.items()}
    codes = {kind: Counter(ErrorCode(r.error_code) for r in responses)
             for kind, responses in got.items()}
    assert set(codes["loads"]) <= {ErrorCode.OK, ErrorCode.BUSY}, codes
    assert codes["loads"][ErrorCode.OK] >= 1, codes
    assert set(codes["squeezes"]) <= {ErrorCode.OK, ErrorCode.UNKNOWN_OBJECT}, codes
    busy = [r for r in got["bad_loads"] if r.error_code == ErrorCode.BUSY]
    assert all("max_pending" in r.message for r in busy)
    for field, response in [*((f, r) for f, r in zip(bad_loads, got["bad_loads"])
                              if r.error_code != ErrorCode.BUSY),
                            *zip(bad_squeezes, got["bad_squeezes"])]:
        assert response.error_code in (ErrorCode.INVALID_ARGUMENT, ErrorCode.UNKNOWN_OBJECT), \
            (field, response.message)
        assert field.strip().split()[-1] in response.message, (field, response.message)
        assert len(response.message) < 400, field
    assert not any(r.error_code == ErrorCode.INTERNAL_ERROR
                   for responses in got.values() for r in responses)
    planner.load(BLOB, "after")
    for field, request in bad_loads.items():  # what was BUSY (loads beyond max_pending)
        response = planner.call(LoadObject, "load_object", request)
        assert response.error_code == ErrorCode.INVALID_ARGUMENT, (field, response.message)
        assert field.split()[-1] in response.message, (field, response.message)
    assert stiffness(planner, "after").success


# --------------------------------------------------------------------------- object ids

DISK = """
name: stiff_disk
object:
  shape: {type: disk, radius: 0.05}
  material: {E: 5.0e6, nu: 0.3, thickness: 0.0254}
  mesh: {nodes: 300}
fingers:
  F1: {placement: {angle_deg: 180}}
  F2: {placement: {angle_deg: 0}}
"""
"""Another client's object: a disk 100 times stiffer than BLOB."""


def stiffness(harness: Harness, object_id: str, digest: str = "") -> PlanSqueeze.Response:
    """A stable squeeze of ``object_id`` at the scene's placements (quoting ``digest``)."""
    return harness.call(PlanSqueeze, "plan_squeeze", PlanSqueeze.Request(
        object_id=object_id, object_digest=digest, squeeze_type="stable", depth=1e-3))


def test_a_load_under_another_clients_id_is_refused_and_the_owner_keeps_its_object(planner):
    """Before: client B's disk replaced client A's object and A's next plan_squeeze answered
    with the disk's stiffness (44,801.8 N/m instead of 469.61).
    """
    a = planner.load(BLOB, "obj")
    own = stiffness(planner, "obj", a.object_digest)
    disk = stiffness(planner, planner.load(DISK, "disk").object_id)
    assert disk.stiffness > 10 * own.stiffness  # the two objects are told apart by stiffness
    b = planner.call(LoadObject, "load_object", LoadObject.Request(scene_yaml=DISK,
                                                                   object_id="obj"))
    assert b.error_code == ErrorCode.INVALID_ARGUMENT
    assert "'obj' is already loaded from another scene" in b.message and "replace" in b.message
    after = stiffness(planner, "obj", a.object_digest)
    assert after.success and after.stiffness == own.stiffness
    again = planner.load(BLOB, "obj")  # the same scene again: the cached object
    assert again.object_digest == a.object_digest and again.precompute_time == 0.0


def test_a_replaced_object_is_refused_to_clients_quoting_the_old_digest(planner):
    a = planner.load(BLOB, "obj")
    b = planner.load(DISK, "obj", replace=True)
    assert b.object_digest != a.object_digest and len(b.object_digest) == 64
    stale = stiffness(planner, "obj", a.object_digest)
    assert stale.error_code == ErrorCode.UNKNOWN_OBJECT
    assert "holds another object now" in stale.message and a.object_digest[:12] in stale.message
    current = stiffness(planner, "obj", b.object_digest)
    assert current.success and current.stiffness == stiffness(planner, "obj").stiffness
    event = planner.call(EventSqueeze, "event_squeeze", EventSqueeze.Request(
        object_id="obj", object_digest=a.object_digest))
    assert event.error_code == ErrorCode.UNKNOWN_OBJECT


def test_an_id_evicted_and_loaded_again_from_another_scene_is_detected(ros_context):
    """With a cache of one object, A's object is evicted and B loads its own under the freed
    id: A's request quoting its digest is refused instead of computing on B's disk.
    """
    from rclpy.parameter import Parameter

    harness = Harness(ros_context, parameter_overrides=[Parameter("cache_size", value=1)])
    try:
        a = harness.load(BLOB, "obj")
        harness.load(BLOB, "other")  # evicts obj
        harness.load(DISK, "obj")  # a free id: allowed
        stale = stiffness(harness, "obj", a.object_digest)
        assert stale.error_code == ErrorCode.UNKNOWN_OBJECT, stale.message
        bad = stiffness(harness, "obj", "not-a-digest")
        assert bad.error_code == ErrorCode.INVALID_ARGUMENT and "64 hex digits" in bad.message
    finally:
        harness.close()


def test_two_clients_loading_one_id_at_once_get_one_object(planner):
    """Concurrent loads of two scenes under one id: one wins, the other is refused (the check
    is repeated when the object is stored), and the id holds the winner's object.
    """
    responses = burst(planner, LoadObject, "load_object", [
        LoadObject.Request(scene_yaml=text, object_id="shared") for text in (BLOB, DISK)])
    winners = [r for r in responses if r.success]
    losers = [r for r in responses if not r.success]
    assert len(winners) == 1 and len(losers) == 1, [r.message for r in responses]
    assert losers[0].error_code == ErrorCode.INVALID_ARGUMENT
    assert stiffness(planner, "shared", winners[0].object_digest).success


# --------------------------------------------------------------------------- echoes


def test_no_response_or_log_line_echoes_a_huge_field(planner, capfd):
    """Before: a 1 MB object_id came back whole in the response (1,000,097 characters) and in
    the log line.
    """
    huge = "x" * 1_000_000
    planner.load(BLOB, "blob")
    unknown = stiffness(planner, huge)
    assert unknown.error_code == ErrorCode.UNKNOWN_OBJECT and "(1000000 characters)" in \
        unknown.message and len(unknown.message) < 300
    load = planner.call(LoadObject, "load_object", LoadObject.Request(scene_yaml=BLOB,
                                                                      object_id=huge))
    assert load.error_code == ErrorCode.INVALID_ARGUMENT and load.object_id == ""
    assert load.message == "object_id has 1000000 characters, more than 256"
    kind = planner.call(PlanSqueeze, "plan_squeeze", PlanSqueeze.Request(
        object_id="blob", squeeze_type=huge))
    assert kind.error_code == ErrorCode.INVALID_ARGUMENT and len(kind.message) < 300
    path = planner.call(LoadObject, "load_object", LoadObject.Request(scene_path=huge))
    assert path.error_code == ErrorCode.INVALID_ARGUMENT and len(path.message) < 300
    missing = "/nonexistent/" + "d" * 200 + "/scene.yaml"  # quoted whole: its end names the file
    path = planner.call(LoadObject, "load_object", LoadObject.Request(scene_path=missing))
    assert not path.success and missing in path.message, path.message
    name = planner.call(LoadObject, "load_object", LoadObject.Request(
        scene_yaml=BLOB.replace("name: blob", f"name: {'n' * 300}")))
    assert name.error_code == ErrorCode.INVALID_ARGUMENT
    assert name.message.startswith("the scene's name (the default object_id) has 300 characters")
    control = planner.call(LoadObject, "load_object", LoadObject.Request(
        scene_yaml=BLOB, object_id="a\nb"))
    assert control.error_code == ErrorCode.INVALID_ARGUMENT and "control character" in \
        control.message
    logged = capfd.readouterr()
    longest = max(len(line) for line in (logged.out + logged.err).splitlines())
    assert longest < 1000, longest


def test_an_absurd_mesh_size_is_refused_in_one_short_line(planner):
    """``mesh: {max_area: 1e-308}`` on the foam square asks for about 8e305 nodes: before, the
    refusal quoted that count as an integer of 306 digits (a message of 425 characters).
    """
    foam = (Path(__file__).resolve().parents[1] / "config" / "scenes" / "foam_square.yaml")
    text = foam.read_text().replace("nodes: 2000", "max_area: 1.0e-308")
    tiny = planner.call(LoadObject, "load_object", LoadObject.Request(scene_yaml=text))
    assert tiny.error_code == ErrorCode.INVALID_ARGUMENT
    assert tiny.message.startswith("oversized factorized mesh: 8e+305 nodes, more than the "
                                   "planner's limit of 60000"), tiny.message
    assert len(tiny.message) < 200, len(tiny.message)


def test_a_fingertip_beyond_the_float_range_is_refused_naming_the_field(planner):
    """``tip_radius: 1.0e308``: before, the load succeeded and the event squeeze failed with
    NUMERICAL_FAILURE ("no contact mode of nodes [49, 114] can be solved"), numpy overflow
    warnings in the planner's log; now the load is refused with the field and its range.
    """
    foam = (Path(__file__).resolve().parents[1] / "config" / "scenes" / "foam_square.yaml")
    text = foam.read_text().replace("tip_radius: 0.02", "tip_radius: 1.0e308")
    huge = planner.call(LoadObject, "load_object", LoadObject.Request(scene_yaml=text))
    assert huge.error_code == ErrorCode.INVALID_ARGUMENT, huge.message
    assert huge.message == "fingers.F1.tip_radius must be in [0.0, 1000.0] m, got 1e+308"


def test_an_outline_placed_beyond_the_scenes_range_names_the_frame_pose(planner):
    """A typed square in frame ``camera`` whose ``frame_pose`` sits at x = 1e300 m: before, the
    refusal named ``object.shape_parameters points``, a field the request did not give.
    """
    desc = ObjectDescription(material=Material(youngs_modulus=5e4, poisson_ratio=0.3,
                                               thickness=0.0254), mesh_nodes=500)
    desc.outline.header.frame_id = "camera"
    desc.outline.polygon.points = [Point32(x=x, y=y) for x, y in (
        (-0.05, -0.05), (0.05, -0.05), (0.05, 0.05), (-0.05, 0.05))]
    desc.frame_pose.position.x, desc.frame_pose.orientation.w = 1e300, 1.0
    far = planner.call(LoadObject, "load_object", LoadObject.Request(object=desc))
    assert far.error_code == ErrorCode.INVALID_ARGUMENT
    assert far.message.startswith("object.outline.polygon.points[0] lies at [1e+300, "), \
        far.message
    assert "object.frame_pose" in far.message and len(far.message) < 200


# --------------------------------------------------------------------------- abandoned work


def test_a_frictional_resistance_whose_client_leaves_stops_inside_its_squeeze(planner):
    """Before: plan_resistance with frictional contacts ran to its end (18 s in the issue)
    after its client had gone. The planner now asks the graph before stepper substeps (at most
    every 0.1 s), so the request stops inside the squeeze that precedes Algorithm 2, before
    any progress report, and the planner serves the next request.
    """
    from geometry_msgs.msg import Vector3

    from squeeze_grasp_interfaces.srv import PlanResistance
    from squeeze_grasp_ros.scene import placement_node

    data = yaml.safe_load(RESIST_FIG10)
    data["object"]["mesh"]["nodes"] = 3000
    data["squeeze"]["step"] = 2e-5  # about 1,500 substeps, seconds of work
    loaded = planner.load(yaml.safe_dump(data), "fig10")
    obj = planner.planner.cache.get("fig10")
    adversary = placement_node(obj.solid().mesh, obj.scene.adversary.placement, "adversary")
    slow = planner.node.create_client(PlanResistance,
                                      f"{planner.planner_name}/plan_resistance")
    assert slow.wait_for_service(timeout_sec=30.0)
    slow.call_async(PlanResistance.Request(
        object_id="fig10", object_digest=loaded.object_digest,
        contacts=[*loaded.finger_nodes, adversary], a=Vector3(x=0.0024, y=0.0044),
        mode="stable", contact_model="friction"))
    deadline = time.monotonic() + 60
    while planner.planner._pending == 0:
        assert time.monotonic() < deadline
        planner.executor.spin_once(0.01)
    planner.node.destroy_client(slow)
    while planner.planner._pending:
        assert time.monotonic() < deadline
        planner.executor.spin_once(0.05)
    assert planner.planner.abandoned == [()]  # stopped before its first progress report
    assert stiffness(planner, "fig10").success


def test_a_client_the_graph_does_not_know_yet_is_not_taken_for_gone(planner, monkeypatch):
    """Before: a `--processes` run's first load_object was refused "abandoned: no client ...
    is left" because the planner's graph had not yet learnt of the client whose request it was
    serving. A client unknown to the graph now counts as gone only after the discovery grace;
    with the grace at zero the same request is refused (the check still works).
    """
    from squeeze_grasp_ros.ros.nodes import planner as planner_module

    monkeypatch.setattr(planner.planner, "count_clients", lambda name: 0)
    assert planner.load(BLOB, "unseen").success
    monkeypatch.setattr(planner_module, "DISCOVERY_GRACE", -1.0)
    refused = planner.call(LoadObject, "load_object",
                           LoadObject.Request(scene_yaml=BLOB, object_id="unseen_late"))
    assert not refused.success and refused.error_code == ErrorCode.CANCELLED
    assert "abandoned" in refused.message


def test_a_load_whose_dense_blocks_exceed_the_memory_bound_is_refused_before_factoring(
        ros_context):
    """Before: a thin rectangle (height 1e-5 m, every node on the boundary) grew the planner
    by gigabytes inside SuperLU for minutes and could not be stopped. The mesher now refuses
    that one before meshing; what it allows is sized right after meshing against the planner's
    memory bound, before the factorisation: here a 1 mm strip of 2,000 nodes (664 on the
    boundary; measured: its load peaks at 173 MB and the object holds 86 MB) against a bound
    of 64 MiB. The refusal is the budget's, not the cache's after the work.
    """
    from rclpy.parameter import Parameter

    data = yaml.safe_load(BLOB)
    data["object"]["shape"] = {"type": "rectangle", "width": 0.1, "height": 1e-3}
    data["object"]["mesh"] = {"nodes": 2000}
    harness = Harness(ros_context,
                      parameter_overrides=[Parameter("cache_max_megabytes", value=64)])
    try:
        response = harness.call(LoadObject, "load_object", LoadObject.Request(
            scene_yaml=yaml.safe_dump(data), object_id="strip"))
        assert response.error_code == ErrorCode.INVALID_ARGUMENT, response.message
        assert "MiB for its dense" in response.message and "2 rows per boundary node" in \
            response.message and "cache_max_megabytes" in response.message
        assert harness.planner.cache.ids() == []
        data["object"]["mesh"] = {"nodes": 300}  # 64 MiB is plenty for a coarser strip
        assert harness.load(yaml.safe_dump(data), "strip").success
    finally:
        harness.close()
