# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The pipeline across processes and under SIGINT: the same run as in one process, and an
interrupted run leaves a readable recording.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from pipeline_support import SMALL_SQUARE, scene_data, write_scene
from rclpy.serialization import deserialize_message

from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.recording.bag import read_bag
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner

QUICK = scene_data(SMALL_SQUARE, name="quick_square",
                   squeeze={"type": "stable", "relative_depth": 0.06})
"""The small square squeezed 6 %: a few hundred ticks with A, C and D events."""
DETERMINISTIC = ("/clock", "/sim/tick", "/sim/state", "/sim/events", "/monitor/status",
                 "/monitor/events", "/monitor/contact_state", "/devices/barrett_f1/setpoint",
                 "/devices/barrett_f3/setpoint", "/devices/barrett_f1/tactile",
                 "/devices/barrett_f3/wrench", "/executor/status")
"""Topics whose messages (content and log time) do not depend on how the nodes ran (the
action's goal ids are random; markers are logged at the recorder's clock)."""


def contents(bag_path) -> dict:
    """Topic -> [(log time, message)] of the deterministic topics of a bag."""
    bag = read_bag(bag_path)
    out = {}
    for topic in DETERMINISTIC:
        cls = pipeline.message_type(bag.types[topic])
        out[topic] = [(m.log_time_ns, deserialize_message(m.data, cls)) for m in bag.messages
                      if m.topic == topic]
    return out


def test_one_process_and_processes_give_the_same_run_and_recording(tmp_path):
    path = write_scene(tmp_path, QUICK)
    overrides = {"monitor": {"alarm_ratio": 2.0}}
    one = PipelineRunner(RunOptions(path, record=str(tmp_path / "one"),
                                    overrides=overrides)).run()
    many = PipelineRunner(RunOptions(path, record=str(tmp_path / "many"), processes=True,
                                     overrides=overrides)).run()
    assert many["mode"] == "processes" and one["mode"].startswith("one process")
    for key in ("events", "monitor_events", "termination", "ticks", "forces", "work",
                "measured_work", "alarms"):
        assert one[key] == many[key], key
    assert {e["type"] for e in one["events"]} >= {"A", "D"}
    a, b = contents(tmp_path / "one"), contents(tmp_path / "many")
    for topic in DETERMINISTIC:
        assert a[topic] == b[topic], topic
    assert [t for t, _ in b["/executor/status"]][0] == 0  # squeezing, from the goal's tick 0
    offered = offered_durability(tmp_path / "many")
    for topic in ("/sim/events", "/monitor/events", "/monitor/force_residual",
                  "/executor/status"):
        assert offered[topic] == {"transient_local"}, (topic, offered[topic])


def offered_durability(bag_path: Path) -> dict[str, set[str]]:
    """Topic -> the durabilities its publishers offered, as the recording says (rosbag2's
    ``offered_qos_profiles`` of each MCAP channel).
    """
    import yaml
    from mcap.reader import make_reader

    with open(next(bag_path.glob("*.mcap")), "rb") as stream:
        channels = make_reader(stream).get_summary().channels.values()
    return {c.topic: {q["durability"] for q in yaml.safe_load(
        c.metadata.get("offered_qos_profiles") or "[]")} for c in channels}


def run_command(*args: str) -> list[str]:
    """``squeeze-grasp`` as the user types it, in this interpreter."""
    return [sys.executable, "-m", "squeeze_grasp_ros.cli", *args]


@pytest.mark.parametrize("processes", [False, True], ids=["one_process", "processes"])
def test_sigint_leaves_a_readable_recording(tmp_path, processes):
    from rosbags.highlevel import AnyReader

    path = write_scene(tmp_path, scene_data(SMALL_SQUARE, name="long_square",
                                            squeeze={"type": "stable", "relative_depth": 0.2}))
    bag = tmp_path / "bag"
    extra = ["--processes"] if processes else []
    proc = subprocess.Popen(run_command("run", path, "--record", str(bag), "--quiet", *extra),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    data = bag / "bag_0.mcap"
    try:
        for _ in range(3000):
            if data.is_file() and data.stat().st_size > 64 * 1024:
                break
            try:
                proc.wait(0.05)
            except subprocess.TimeoutExpired:
                continue
            pytest.fail(f"the run ended before it was interrupted: {proc.stderr.read()[-2000:]}")
        else:
            pytest.fail("the recording did not grow within 150 s")
        proc.send_signal(signal.SIGINT)
        proc.wait(120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert (bag / "metadata.yaml").is_file()
    with AnyReader([bag]) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        stamps = [t for c, t, _ in reader.messages(
            connections=[c for c in reader.connections if c.topic == "/sim/tick"])]
    assert counts["/sim/tick"] > 10 and stamps == sorted(stamps)
    nodes = subprocess.run(["pgrep", "-f", f"squeeze_grasp_run_{proc.pid}_"],
                           capture_output=True, text=True)
    assert nodes.stdout.strip() == "", "node processes outlived the run"


BROKEN_PROFILE = """<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name="noisy" is_default_profile="true">
    <rtps><builtin><discovery_config><leaseDuration><sec>never</sec></leaseDuration>
    </discovery_config></builtin></rtps>
  </participant>
</profiles>
"""
"""A Fast DDS profile with a bad value: the middleware logs XMLPARSER errors through its
default log consumer, which writes to file descriptor 1 (as it does the shared-memory
transport's ``Failed init_port`` errors under load), and still starts."""


def test_run_verb_prints_json_whatever_the_middleware_logs(tmp_path):
    """``run --json`` prints one JSON object on stdout even when Fast DDS logs errors (to the
    process's descriptor 1): they reach stderr, so ``| jq`` always parses.
    """
    path = write_scene(tmp_path, QUICK)
    profile = tmp_path / "noisy_profile.xml"
    profile.write_text(BROKEN_PROFILE)
    env = {**os.environ, "FASTRTPS_DEFAULT_PROFILES_FILE": str(profile)}
    done = subprocess.run(run_command("run", path, "--json", "--no-planner"),
                          capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "XMLPARSER" in done.stderr and "XML_ERROR" in done.stderr  # the middleware logged
    assert len(done.stdout.splitlines()) == 1, done.stdout[:2000]
    result = json.loads(done.stdout)
    assert result["termination"] in ("depth_reached", "slip_alarm")
    assert result["plan_source"] == "mechanics" and result["events"]
    replayed = subprocess.run(run_command("replay", "--help"), capture_output=True, text=True)
    assert replayed.returncode == 0 and "--param" in replayed.stdout
    assert Path(path).is_file()


@pytest.mark.parametrize("kept", [True, False])
def test_a_recorder_that_matches_late_still_gets_the_first_lockstep_messages(ros_context, kept):
    """The lockstep topics' publishers keep their last messages for a late transient-local
    reader (the recorder across processes: it can see a publisher in the graph before that
    writer has matched its reader). The volatile case is the control: it gets nothing.
    """
    import time

    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from std_msgs.msg import Header

    writer = Node("monitor_like", context=ros_context)
    reader = Node("recorder_like", context=ros_context)
    publisher = writer.create_publisher(Header, pipeline.STATUS, pipeline.loop_qos(100, kept=True))
    for tick in range(3):
        publisher.publish(Header(frame_id=str(tick)))
    got: list[str] = []
    reader.create_subscription(Header, pipeline.STATUS, lambda m: got.append(m.frame_id),
                               pipeline.loop_qos(1000, kept=kept))
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(reader)
    deadline = time.monotonic() + 5.0
    while len(got) < 3 and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    if not kept:
        executor.spin_once(timeout_sec=0.5)
    assert got == (["0", "1", "2"] if kept else [])
    executor.shutdown()
    writer.destroy_node()
    reader.destroy_node()


@pytest.mark.parametrize("awaited", [True, False])
def test_a_monitor_awaiting_the_prediction_is_ready_only_once_it_arrived(ros_context, awaited):
    """Across processes the monitor could answer the lockstep hello before the run's latched
    prediction had reached it, and its first events were judged against none (3
    ``prediction_mismatch`` alarms, 1 run of 40). With ``await_prediction`` (``run`` sets it)
    it is ready only once the prediction is here; without, also while nobody publishes one
    (a launch without a planner), never while a publisher's prediction is on its way.
    """
    import time

    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    from squeeze_grasp_interfaces.msg import ContactEventArray, MonitorStatus, Tick
    from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode

    monitor = MonitorNode(context=ros_context, parameter_overrides=[
        Parameter("await_prediction", value=awaited), Parameter("force_watch", value=False)])
    peer = Node("driver_like", context=ros_context)
    kept = pipeline.loop_qos(100, kept=True)
    peer.create_publisher(Tick, pipeline.TICK, kept)
    peer.create_subscription(MonitorStatus, pipeline.STATUS, lambda _: None, kept)
    executor = SingleThreadedExecutor(context=ros_context)
    for node in (monitor, peer):
        executor.add_node(node)

    def spin_until(done) -> None:
        deadline = time.monotonic() + 10.0
        while not done():
            assert time.monotonic() < deadline
            executor.spin_once(timeout_sec=0.05)

    try:
        spin_until(lambda: monitor.count_publishers(pipeline.TICK) > 0
                   and monitor.status_pub.get_subscription_count() > 0)
        assert monitor.participant.ready() is not awaited
        prediction = peer.create_publisher(ContactEventArray, pipeline.PREDICTION,
                                           pipeline.LATCHED)
        spin_until(lambda: monitor.count_publishers(pipeline.PREDICTION) > 0)
        assert not monitor.participant.ready()
        prediction.publish(ContactEventArray())
        spin_until(monitor.participant.ready)
    finally:
        executor.shutdown()
        monitor.destroy_node()
        peer.destroy_node()
