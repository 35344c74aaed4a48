# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The pipeline on real rclpy nodes in one process: ground truth against the mechanics API,
monitor events against the ground truth, the recording read back by independent readers,
replay, dropout holds, slip alarms, the reactive redirection and cancel.
"""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import yaml
from pipeline_support import (
    EVENT_TOLERANCE_TICKS,
    SLIPPING_SQUARE,
    SMALL_SQUARE,
    contact_modes,
    match_within,
    net_events,
    scene_data,
    write_scene,
)
from rclpy.serialization import deserialize_message

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.recording.bag import read_bag
from squeeze_grasp_ros.ros.recording.replay import replay
from squeeze_grasp_ros.ros.recording.schema import own_text
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import WAKE_PERIOD, PipelineRunner
from squeeze_grasp_ros.scene import (
    build_mesh,
    event_squeeze_scene,
    finger_nodes,
    load_scene,
    scene_material,
)

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"


def mechanics(scene_path: str):
    """(event tolerance in m, the mechanics API's event-driven squeeze) of a scene."""
    scene = load_scene(scene_path)
    obj = ElasticObject(build_mesh(scene), scene_material(scene))
    return (
        scene.squeeze.event_tol * obj.scale,
        event_squeeze_scene(scene, obj, finger_nodes(scene, obj.mesh)),
    )


def messages_of(bag, topic: str) -> list:
    """Deserialized messages of one topic of a :func:`read_bag` result."""
    cls = pipeline.message_type(bag.types[topic])
    return [deserialize_message(m.data, cls) for m in bag.messages if m.topic == topic]


@pytest.fixture(scope="module")
def foam(tmp_path_factory):
    """The shipped foam-square scene, recorded, through every node in one process."""
    record = tmp_path_factory.mktemp("foam") / "bag"
    path = str(SCENES / "foam_square.yaml")
    return {
        "path": path,
        "bag": record,
        "run": PipelineRunner(RunOptions(path, record=str(record))).run(),
    }


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """The small mu = 0.05 square (A, C, D events), recorded, no slip alarm."""
    directory = tmp_path_factory.mktemp("small")
    path = write_scene(directory, SMALL_SQUARE)
    options = RunOptions(
        path, record=str(directory / "bag"), overrides={"monitor": {"alarm_ratio": 2.0}}
    )
    return {"path": path, "bag": directory / "bag", "run": PipelineRunner(options).run()}


def assert_ground_truth_is_the_mechanics(run: dict, path: str) -> None:
    event_tol, api = mechanics(path)
    tol = 2 * event_tol + 1e-12
    print(
        f"ground truth vs mechanics: events (type, node, finger) equal, depths within {tol:.2g} m"
    )
    truth = run["events"]
    assert [(e["type"], e["node"], e["finger"]) for e in truth] == [
        (e.type.value, e.node, e.finger) for e in api.events
    ]
    assert all(abs(e["depth"] - a.depth) <= tol for e, a in zip(truth, api.events))
    expected = api.termination
    world = run["world_termination"]
    assert (world if world != "none" else "depth_reached") == expected
    assert run["depth"] == pytest.approx(api.depth, rel=1e-9, abs=tol)
    for finger in ("F1", "F2"):
        assert np.allclose(
            run["forces"][finger], api.state.finger_force(finger), rtol=1e-7, atol=1e-9
        )
        assert run["work"][finger] == pytest.approx(api.work[finger], rel=1e-6)
    assert sorted((c["node"], c["mode"]) for c in run["contacts"]) == sorted(
        (c.node, c.mode) for c in api.state.contacts
    )


def test_foam_square_ground_truth_equals_the_mechanics(foam):
    run = foam["run"]
    assert run["termination"] == "depth_reached" and run["success"]
    assert run["plan_source"] == "planner"
    assert_ground_truth_is_the_mechanics(run, foam["path"])
    assert run["measured_depth"] == pytest.approx(run["target_depth"], rel=1e-9)


def test_small_square_ground_truth_equals_the_mechanics(small):
    assert_ground_truth_is_the_mechanics(small["run"], small["path"])
    assert {"C", "D"} <= {e["type"] for e in small["run"]["events"]}


@pytest.mark.parametrize("case", ["foam", "small"])
def test_monitor_events_match_the_ground_truth(case, foam, small):
    fixture = {"foam": foam, "small": small}[case]
    bag = read_bag(fixture["bag"])
    states = [contact_modes(s) for s in messages_of(bag, "/sim/state")]
    dt_ns = load_scene(fixture["path"]).sim.dt * 1e9
    truth = net_events(states)
    seen = [
        (round(pipeline_stamp(e) / dt_ns), e.type, e.finger)
        for msg in messages_of(bag, "/monitor/events")
        for e in msg.events
    ]
    print(
        f"{case}: tolerance: type and finger exact, tick within {EVENT_TOLERANCE_TICKS} ticks "
        f"({EVENT_TOLERANCE_TICKS * dt_ns * 1e-6:.0f} ms of sim time); {len(truth)} ground-truth "
        f"net events, {len(seen)} monitor events"
    )
    assert truth and match_within(truth, seen, EVENT_TOLERANCE_TICKS) == []


def pipeline_stamp(msg) -> int:
    """Stamp of a message with a header, ns."""
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def test_recording_reads_back_with_rosbags(foam):
    from rosbags.highlevel import AnyReader

    run = foam["run"]
    ticks = run["ticks"] + 1
    expected = pipeline.pipeline_topics(["barrett_f1", "barrett_f3"])
    with AnyReader([foam["bag"]]) as reader:
        connections = {c.topic: c for c in reader.connections}
        assert set(connections) <= set(expected)
        for topic in (
            "/clock",
            "/sim/tick",
            "/sim/state",
            "/monitor/status",
            "/devices/barrett_f1/tactile",
            "/devices/barrett_f3/wrench",
        ):
            assert connections[topic].msgtype == expected[topic]
            assert connections[topic].msgcount == ticks
        assert connections["/devices/barrett_f1/setpoint"].msgcount == ticks - 1
        assert connections["/sim/events"].msgtype == expected["/sim/events"]
        last: dict[str, int] = {}
        decoded = set()
        for connection, timestamp, raw in reader.messages():
            assert timestamp >= last.get(connection.topic, 0)
            last[connection.topic] = timestamp
            if connection.topic not in decoded:
                msg = reader.deserialize(raw, connection.msgtype)
                decoded.add(connection.topic)
                if connection.topic == "/sim/markers":
                    namespaces = {m.ns for m in msg.markers}
        assert decoded == set(connections)
        assert namespaces >= {"outline", "fingertips", "contacts", "forces"}
        assert 0 < connections["/sim/markers"].msgcount < ticks / 10
    qos = connections["/sim/tick"].ext.offered_qos_profiles[0]
    assert qos.reliability.name == "RELIABLE"
    assert (foam["bag"] / "metadata.yaml").is_file()


def test_recording_reads_back_with_the_mcap_library(foam):
    from mcap.reader import make_reader

    files = list(Path(foam["bag"]).glob("*.mcap"))
    with open(files[0], "rb") as f:
        reader = make_reader(f)
        header = reader.get_header()
        summary = reader.get_summary()
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    assert header.profile == "ros2"
    assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
    assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
    assert all("offered_qos_profiles" in c.metadata for c in summary.channels.values())
    assert summary.statistics.message_count == sum(read_bag(foam["bag"]).counts().values())
    assert "serialized_metadata" in metadata["rosbag2"]


def test_replay_reproduces_the_recorded_events(foam):
    first = replay(str(foam["bag"]))
    assert first["reproduced"] is True and first["events"]
    second = replay(str(foam["bag"]))
    assert second["events"] == first["events"]


def test_recording_of_another_tool_replays(small, tmp_path):
    """A bag rewritten by rosbags (SQLite3, no ticks, no custom data) replays the same."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    bag = read_bag(small["bag"])
    store = get_typestore(Stores.ROS2_JAZZY)
    for name in ("ContactNode", "ContactEvent", "ContactEventArray", "TactileArray"):
        type_name = f"squeeze_grasp_interfaces/msg/{name}"
        store.register(get_types_from_msg(own_text(type_name), type_name))
    keep = [t for t in bag.types if replay_topic(t)]
    out = tmp_path / "other"
    with Writer(out, version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        connections = {t: writer.add_connection(t, bag.types[t], typestore=store) for t in keep}
        for m in bag.messages:
            if m.topic in connections:
                writer.write(connections[m.topic], m.log_time_ns, m.data)
    params = {
        "mu": 0.05,
        "alarm_ratio": 2.0,
        "relative_per_depth": load_relative_per_depth(small["bag"]),
    }
    result = replay(str(out), params)
    assert result["reproduced"] is True


def replay_topic(topic: str) -> bool:
    """Readings and the monitor's events: what another recorder would have."""
    return topic.endswith(("/pose", "/wrench", "/tactile")) or topic == "/monitor/events"


def load_relative_per_depth(bag_path) -> float:
    """The relative depth per unit depth the run's monitor used (from its custom data)."""
    return yaml.safe_load(read_bag(bag_path).custom_data["monitor_parameters"])[
        "relative_per_depth"
    ]


def test_sensor_dropout_makes_the_executor_hold(tmp_path):
    data = scene_data(
        SMALL_SQUARE,
        name="dropout_square",
        squeeze={"type": "stable", "relative_depth": 0.03},
        sensors={"dropout": 0.3, "seed": 4},
        effects=["friction", "force_sensing", "tactile_sensing", "sensor_dropout"],
    )
    runner = PipelineRunner(
        RunOptions(write_scene(tmp_path, data), overrides={"monitor": {"alarm_ratio": 2.0}})
    )
    run = runner.run()
    assert run["termination"] == "depth_reached"
    # one alarm message per stale episode; the executor holds on every stale tick
    assert run["hold_ticks"] > 0 and 1 <= run["alarms"]["stale_sensor"] <= run["hold_ticks"]
    positions = [np.array([[p.x, p.y] for p in s.positions]) for s in runner.observer.sim_states]
    moves = [np.abs(b - a).max() for a, b in zip(positions, positions[1:])]
    assert sum(1 for m in moves if m == 0.0) >= run["hold_ticks"]


def test_slip_alarm_comes_before_the_finger_slips(tmp_path):
    path = write_scene(tmp_path, SLIPPING_SQUARE)
    _, api = mechanics(path)
    assert api.termination == "finger_slip"
    run = PipelineRunner(RunOptions(path)).run()
    assert run["termination"] == "slip_alarm"
    alarm_depth = run["measured_depth"]
    print(
        f"slip alarm at depth {alarm_depth * 1e3:.4f} mm; the finger slips at "
        f"{api.depth * 1e3:.4f} mm"
    )
    assert alarm_depth < api.depth
    assert run["world_termination"] == "none"


def test_reactive_redirection_instead_of_stopping(tmp_path):
    path = write_scene(tmp_path, SLIPPING_SQUARE)
    held = PipelineRunner(RunOptions(path)).run()
    redirected = PipelineRunner(RunOptions(path, on_slip_alarm="normals")).run()
    assert redirected["redirected"]
    assert redirected["measured_depth"] > held["measured_depth"]


def test_cancel_holds_position(tmp_path):
    path = write_scene(tmp_path, SMALL_SQUARE)
    runner = PipelineRunner(RunOptions(path, overrides={"monitor": {"alarm_ratio": 2.0}}))
    try:
        runner.start()
        runner.send_goal()
        runner.spin_until(
            lambda: runner.observer.feedback and runner.observer.feedback[-1].depth > 1e-3, 120,
            "1 mm of depth"
        )
        runner.cancel()
        result = runner.wait_result()
    finally:
        runner.shutdown()
    assert result.termination == "canceled" and not result.success
    assert 1e-3 < result.depth < runner.plan.goal.depth
    last, before = runner.observer.sim_states[-1], runner.observer.sim_states[-2]
    assert [(p.x, p.y) for p in last.positions] == [(p.x, p.y) for p in before.positions]


def test_quiet_world_ticks_give_the_same_recording_byte_for_byte(foam, tmp_path, monkeypatch):
    """The foam-square run with every world tick through the stepper's advance() (no quiet
    ticks, as before issue 33) records the same messages, byte for byte, at the same times as
    the fixture's run (quiet ticks on).
    """
    import functools

    import squeeze_grasp_ros.sim.world as world_module

    monkeypatch.setattr(world_module, "SimWorld",
                        functools.partial(world_module.SimWorld, quiet=False))
    run = PipelineRunner(RunOptions(foam["path"], record=str(tmp_path / "bag"))).run()
    for key in ("events", "monitor_events", "forces", "work", "ticks"):
        assert run[key] == foam["run"][key], key
    ours, reference = read_bag(tmp_path / "bag"), read_bag(foam["bag"])
    assert ours.counts() == reference.counts()
    assert sorted((m.topic, m.log_time_ns, bytes(m.data)) for m in ours.messages) == sorted(
        (m.topic, m.log_time_ns, bytes(m.data)) for m in reference.messages)


def test_single_threaded_executor_gives_the_same_run_and_recording(small, tmp_path):
    """Also covers the recorder's drain at shutdown on this executor (its progress timer and
    the re-sent last tick once kept it from ever seeing the executor idle).
    """
    path = write_scene(tmp_path, SMALL_SQUARE)
    run = PipelineRunner(
        RunOptions(
            path,
            executor="single",
            record=str(tmp_path / "bag"),
            overrides={"monitor": {"alarm_ratio": 2.0}},
            timeout=120.0,
        )
    ).run()
    assert run["mode"].endswith("SingleThreadedExecutor")
    for key in ("events", "monitor_events", "forces", "work", "ticks"):
        assert run[key] == small["run"][key], key
    ours, reference = read_bag(tmp_path / "bag"), read_bag(small["bag"])
    for topic in ("/sim/tick", "/sim/state", "/monitor/status", "/devices/barrett_f1/tactile"):
        assert [m.log_time_ns for m in ours.messages if m.topic == topic] == [
            m.log_time_ns for m in reference.messages if m.topic == topic
        ], topic


def test_resistance_ground_truth_equals_algorithm_2():
    """Sec. 6.4 set-up (F1 on a Barrett finger, F2 on the Cobra arm, A on the pusher): the
    squeeze, then the executor streams Algorithm 2's waypoints; the simulated world's events,
    termination and work are those of the mechanics API.
    """
    from squeeze_grasp_ros.mechanics.resistance.frictional import (
        add_adversary,
        frictional_resistance,
    )
    from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
    from squeeze_grasp_ros.scene import placement_node

    path = str(SCENES / "resist_fig10.yaml")
    scene = load_scene(path)
    obj = ElasticObject(build_mesh(scene), scene_material(scene))
    squeeze = event_squeeze_scene(scene, obj, finger_nodes(scene, obj.mesh))
    model = ContactModel(obj, scene.mu, max_events_per_depth=scene.squeeze.max_events_per_depth)
    adv = scene.adversary
    start = add_adversary(
        squeeze.state,
        model,
        squeeze.displacement,
        placement_node(obj.mesh, adv.placement, "adversary"),
        adv.tip_radius,
    )
    plan = frictional_resistance(
        model, start, adv.a, mode=adv.mode, step=squeeze.step, event_tol=squeeze.event_tol
    )
    run = PipelineRunner(RunOptions(path, planner=False)).run()
    assert run["termination"] == "resisted"
    assert [(e["type"], e["node"], e["finger"]) for e in run["events"]] == [
        (e.type.value, e.node, e.finger) for e in squeeze.events + plan.events
    ]
    assert (run["world_termination"], plan.reason) == ("finger_slip", "F2 slips")
    for finger in ("F1", "F2", "A"):
        total = squeeze.work.get(finger, 0.0) + plan.work[finger]
        assert run["work"][finger] == pytest.approx(total, rel=1e-5)


def test_a_neo_hookean_world_is_the_neo_hookean_mechanics(tmp_path):
    """With ``object.material.model: neo_hookean`` the simulated world runs the
    finite-deformation squeeze: its events, forces and work are those of the mechanics API under
    the same model, and its forces differ from the linear world's.
    """
    data = scene_data(SMALL_SQUARE, name="neo_hookean_square",
                      object={**SMALL_SQUARE["object"], "mesh": {"nodes": 300, "min_angle": 30},
                              "material": {**SMALL_SQUARE["object"]["material"],
                                           "model": "neo_hookean"}},
                      squeeze={"type": "stable", "relative_depth": 0.06})
    path = write_scene(tmp_path, data)
    run = PipelineRunner(RunOptions(path, planner=False)).run()
    assert run["success"] and run["world_termination"] == "none"
    assert_ground_truth_is_the_mechanics(run, path)
    linear = scene_data(data, name="linear_square", object={
        **data["object"], "material": {**data["object"]["material"], "model": "linear"}})
    _, api = mechanics(write_scene(tmp_path, linear))
    assert run["forces"]["F1"][0] / api.state.finger_force("F1")[0] - 1 > 1e-3


def _count_calls(monkeypatch, module, name: str) -> list:
    """Replace function ``module.name`` by a counting wrapper in every loaded module that holds
    it (modules imported later take it from ``module``); returns the list of calls.
    """
    import sys

    original, calls = getattr(module, name), []

    def counted(*args, **kwargs):
        calls.append(args)
        return original(*args, **kwargs)

    for mod in list(sys.modules.values()):
        if getattr(mod, name, None) is original:
            monkeypatch.setattr(mod, name, counted)
    return calls


def test_a_run_parses_its_scene_once_and_meshes_it_once(tmp_path, monkeypatch):
    """Before: one process parsed the scene file 3 times and meshed the object twice (runner,
    planner, simulated world). Now the run reads the scene once and builds its object once for
    the planner and the world; the recorder, monitor and executor in the same process build
    nothing. Calls are counted in every thread (the run's planner spins in a thread).
    """
    import triangle

    import squeeze_grasp_ros.scene as scene_module

    path = write_scene(tmp_path, scene_data(SMALL_SQUARE, name="once", squeeze={
        "type": "stable", "relative_depth": 0.02}))
    parses = _count_calls(monkeypatch, scene_module, "parse_scene")
    meshes = _count_calls(monkeypatch, triangle, "triangulate")
    run = PipelineRunner(RunOptions(path, record=str(tmp_path / "bag"))).run()
    assert run["success"] and run["plan_source"] == "planner"
    assert len(parses) == 1 and len(meshes) == 1, (len(parses), len(meshes))


def test_unrecorded_monitor_outputs_are_written_only_while_subscribed(tmp_path, monkeypatch):
    """Without recording the monitor writes ``monitor/contact_state`` and
    ``monitor/force_residual`` only while a subscription has matched them (its matched events):
    none in a run nobody listens to, every tick's to a subscriber that came before the goal,
    and the same ticks and events either way.
    """
    from squeeze_grasp_interfaces.msg import ContactState, ForceResidual
    from squeeze_grasp_ros.ros import messages

    written = {"state": 0, "residual": 0}

    def counted(name, write):
        def count(*args, **kwargs):
            written[name] += 1
            return write(*args, **kwargs)
        return count
    monkeypatch.setattr(messages, "patches_state_cdr",
                        counted("state", messages.patches_state_cdr))
    monkeypatch.setattr(messages, "force_residual_cdr",
                        counted("residual", messages.force_residual_cdr))
    path = write_scene(tmp_path, scene_data(SMALL_SQUARE, name="unheard", squeeze={
        "type": "stable", "relative_depth": 0.03}))
    unheard = PipelineRunner(RunOptions(path)).run()
    assert unheard["success"] and written == {"state": 0, "residual": 0}

    runner = PipelineRunner(RunOptions(path))
    received: dict[str, list] = {"state": [], "residual": []}
    try:
        runner.start()
        qos = pipeline.loop_qos(100, kept=True)
        for name, kind, topic in (("state", ContactState, pipeline.CONTACT_STATE),
                                  ("residual", ForceResidual, pipeline.FORCE_RESIDUAL)):
            runner.client.create_subscription(kind, topic, received[name].append, qos,
                                              raw=True)
        monitor = runner.nodes["monitor"]
        runner.wait(lambda: monitor.state_heard.matched and monitor.forces.heard.matched, 10.0)
        runner.send_goal()
        heard = runner.summary(runner.wait_result())
        runner.wait(lambda: len(received["state"]) >= written["state"]
                    and len(received["residual"]) >= written["residual"], 10.0)
    finally:
        runner.shutdown()
    assert heard["ticks"] == unheard["ticks"] and heard["events"] == unheard["events"]
    assert written["state"] >= heard["ticks"] and written["residual"] > 0
    assert len(received["state"]) == written["state"]
    assert len(received["residual"]) == written["residual"]


def test_the_loop_spins_once_a_tick_not_once_an_event(tmp_path):
    """On ``EventsExecutor`` the wait for the goal's result spins the executor until the tick's
    ground truth arrives (one ``spin_until_future_complete`` a tick, plus the wall-clock
    wakes), not one ``spin_once`` per event (about 14 a tick before): the run is the same.
    A spin also ends when the 50 ms wake timer fires or when its own 50 ms timeout passes:
    each at most once per 50 ms of wall time (a clean-clone CI counted 277 spins for 251 ticks
    in 1.19 s, one more than ticks + one wake per period + 2).
    """
    path = write_scene(tmp_path, scene_data(SMALL_SQUARE, name="spins", squeeze={
        "type": "stable", "relative_depth": 0.03}))
    runner = PipelineRunner(RunOptions(path))
    executor, spins = runner.executor, Counter()

    class Counted:
        def __getattr__(self, name):
            attr = getattr(executor, name)
            if not name.startswith("spin"):
                return attr

            def counted(*args, **kwargs):
                spins[name] += 1
                return attr(*args, **kwargs)
            return counted
    try:
        runner.start()
        runner.send_goal()
        started = time.monotonic()
        runner.executor = runner.spinner.executor = Counted()
        run = runner.summary(runner.wait_result())
        wakes = 2 * (time.monotonic() - started) / WAKE_PERIOD + 2
    finally:
        runner.executor = runner.spinner.executor = executor
        runner.shutdown()
    assert run["success"] and run["ticks"] > 50
    assert set(spins) == {"spin_until_future_complete"}
    assert spins["spin_until_future_complete"] <= run["ticks"] + wakes
