# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor on a gripper's joint feedback (docs/grippers.md, "Watching the jaws on
joint_states"): the transmission's reading, the slip watch against the event squeeze's force
curves, and gripper scenes without fingertip sensors on real rclpy.
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import yaml
from foxglove_support import first_messages, layout_paths, resolve
from mcap.reader import make_reader
from pipeline_support import LogLines, write_scene
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState

from squeeze_grasp_interfaces.msg import MonitorStatus
from squeeze_grasp_ros.control.joint_feedback import JointSlipWatch
from squeeze_grasp_ros.resources import viewer_file
from squeeze_grasp_ros.ros.nodes.monitor import JointFeedback
from squeeze_grasp_ros.ros.recording.bag import read_bag
from squeeze_grasp_ros.ros.recording.replay import replay
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner
from squeeze_grasp_ros.scene import event_squeeze_scene, load_scene
from squeeze_grasp_ros.scene.controller import JointReadingError, scene_controller

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
SPONGE, SLIP = SCENES / "sponge_gripper.yaml", SCENES / "sponge_gripper_slip.yaml"
WINDOW, RATIO = 1e-4, 0.5
"""The monitor's defaults (config/monitor.yaml)."""


def squeeze_curve(path: Path):
    """(termination, jaw-force curve against closing of the aperture, m -> N) of the mechanics
    API's event squeeze of a scene: the independent reference of the slip watch.
    """
    result = event_squeeze_scene(load_scene(path))
    curve = np.asarray(result.force_curve["F1"], float).reshape(-1, 2)
    depth = curve[:, 0] * result.depth / result.relative_depth
    # both jaws close along the line by the same amount: aperture closing = sqrt(2) * depth
    return result.termination, np.sqrt(2.0) * depth, curve[:, 1]


def watch_along(closing: np.ndarray, force: np.ndarray, *, aperture0: float = 0.05,
                step: float = 2e-5) -> tuple[JointSlipWatch, list]:
    """Feed the watch the curve sampled every ``step`` m of closing (a control cycle's)."""
    watch = JointSlipWatch(("F1", "F2"), contact_force=0.002, window=WINDOW, ratio=RATIO)
    samples = np.arange(0.0, closing[-1], step)
    alarms = [(c, watch.update(aperture0 - c, float(np.interp(c, closing, force))))
              for c in samples]
    return watch, [(c, a) for c, a in alarms if a]


@pytest.fixture(scope="module")
def curves():
    return {"held": squeeze_curve(SPONGE), "slips": squeeze_curve(SLIP)}


def test_a_holding_squeeze_raises_no_slip_alarm(curves):
    for name, (termination, closing, force) in curves.items():
        watch, alarms = watch_along(closing, force)
        print(f"{name}: {termination} at {closing[-1] * 1e3:.4f} mm of closing, "
              f"{force[-1]:.4g} N; first touch {watch.first_touch}")
        assert alarms == [], name
        assert watch.first_touch == pytest.approx(0.05)
    assert curves["slips"][0] == "finger_slip" and curves["held"][0] == "depth_reached"


def test_closing_on_after_the_slip_raises_it_within_one_window(curves):
    termination, closing, force = curves["slips"]
    # after the finger slip the object no longer resists more closing: the force stays
    frozen_closing = np.append(closing, closing[-1] + 5 * WINDOW)
    frozen_force = np.append(force, force[-1])
    _, alarms = watch_along(frozen_closing, frozen_force)
    first, raised = alarms[0]
    assert closing[-1] < first <= closing[-1] + WINDOW + 2e-5
    assert {(a.type, a.finger) for a in raised} == {("slip_imminent", "F1"),
                                                    ("slip_imminent", "F2")}
    assert raised[0].value < RATIO
    # a force that drops while closing is a negative stiffness ratio
    dropped = np.append(force, 0.5 * force[-1])
    _, alarms = watch_along(frozen_closing, dropped)
    assert alarms and min(raised[0].value for _, raised in alarms) < 0


def test_losing_the_force_is_contact_lost():
    watch = JointSlipWatch(("F1", "F2"), contact_force=0.01, window=WINDOW, ratio=RATIO)
    assert watch.update(0.05, 0.5) == ()
    lost = watch.update(0.0499, 0.0)
    assert [(a.type, a.finger) for a in lost] == [("contact_lost", "F1"), ("contact_lost", "F2")]
    with pytest.raises(ValueError, match="ratio in"):
        JointSlipWatch(("F1",), contact_force=0.0, window=WINDOW, ratio=1.5)


def test_the_transmission_reads_a_joint_state_back():
    jaws = scene_controller(load_scene(SPONGE), SPONGE)
    positions, efforts = jaws.joint_positions(0.0321), jaws.joint_efforts(4.5)
    reading = jaws.reading(["other", "finger_joint"], [9.0, positions[0]], [9.0, efforts[0]])
    assert reading.aperture == pytest.approx(0.0321, abs=1e-15)
    assert reading.force == pytest.approx(4.5, abs=1e-15)
    for names, p, e, why in ((["wrong"], [0.1], [1.0], "are missing"),
                             (["finger_joint"], [float("nan")], [1.0], "not finite"),
                             (["finger_joint"], [0.1], [], "one of each")):
        with pytest.raises(JointReadingError, match=why):
            jaws.reading(names, p, e)


# --------------------------------------------------------------------------- on real rclpy
def sponge_without_sensors(tmp_path) -> str:
    data = yaml.safe_load(SPONGE.read_text())
    data.update(name="sponge_gripper_joints", effects=["friction"])
    return write_scene(tmp_path, data)


def test_the_monitor_measures_depth_and_force_from_joint_states(tmp_path):
    run = PipelineRunner(RunOptions(sponge_without_sensors(tmp_path), planner=False)).run()
    print(f"{run['outcome']}; measured depth {run['measured_depth'] * 1e3:.6f} mm, world "
          f"{run['depth'] * 1e3:.6f} mm; forces {run['measured_forces']} (truth {run['forces']})")
    assert run["termination"] == "depth_reached" and run["world_termination"] == "none"
    assert run["alarms"] == {} and run["monitor_events"] == []
    # the depth from the joint positions is the stepper's (both jaws close on the line)
    assert run["measured_depth"] == pytest.approx(run["depth"], rel=1e-9)
    # the jaw force from the joint effort is the truth's along the closing line (x = 0)
    for finger in ("F1", "F2"):
        measured, truth = run["measured_forces"][finger], run["forces"][finger]
        assert measured[1] == pytest.approx(truth[1], rel=1e-9)
        assert abs(measured[0]) < 1e-12 and abs(truth[0]) < 1e-3 * abs(truth[1])


@pytest.mark.parametrize("reaction", ["hold", "normals"])
def test_the_jaws_slip_the_joint_watch_stops_the_squeeze(reaction, tmp_path):
    termination, closing, _ = squeeze_curve(SLIP)
    assert termination == "finger_slip"
    bag = tmp_path / "bag"
    run = PipelineRunner(RunOptions(str(SLIP), planner=False, on_slip_alarm=reaction,
                                    record=str(bag))).run()
    slip_depth = run["world_end"]["depth"]
    print(f"{reaction}: {run['outcome']}; world slip at {slip_depth * 1e3:.4f} mm, alarm at "
          f"{run['measured_depth'] * 1e3:.4f} mm; first alarm {run['first_alarms']}")
    assert run["world_termination"] == "finger_slip"
    assert run["termination"] == "slip_alarm" and run["redirected"] == (reaction == "normals")
    assert "slip_imminent" in run["alarms"] and not run["monitor_events"]
    # detected, not forecast: after the slip, within the window (closing = sqrt(2) depth) plus
    # one control cycle, and for the re-squeeze its grace cycles
    first = run["first_alarms"]["slip_imminent"]
    assert first["finger"] in ("F1", "F2") and "while the jaw force went" in first["message"]
    ticks = first["stamp_ns"] / 1e6
    assert slip_depth < run["measured_depth"]
    if reaction == "hold":
        assert run["measured_depth"] - slip_depth <= (WINDOW + 3e-5) / np.sqrt(2.0)
    print(f"first alarm at tick {ticks:.0f}")
    # the shipped Foxglove layout's jaw panel plots numbers of this recording, one per tick
    panels = json.loads(viewer_file("foxglove_layout.json").read_text())["configById"]
    paths = [p["value"] for p in panels["Plot!jaws"]["paths"]]
    assert paths and all(v in layout_paths(panels) for v in paths)
    messages = first_messages(bag)
    with open(next(bag.glob("*.mcap")), "rb") as stream:
        counts = Counter(channel.topic for _, channel, _ in make_reader(stream).iter_messages())
    for value in paths:
        topic, _, path = value.partition(".")
        assert isinstance(resolve(messages[topic], path), float), value
        assert counts[topic] == run["ticks"] + 1, value
    # replayed into a fresh monitor, the recorded joint states raise the same alarms
    replayed = replay(str(bag))
    recorded = [a for m in read_bag(bag).messages if m.topic == "/monitor/status"
                for a in deserialize_message(m.data, MonitorStatus).alarms]
    assert replayed["ticks"] == run["ticks"] + 1
    assert replayed["alarms"] == len(recorded) >= 2


def test_a_hostile_joint_state_is_ignored_with_one_warning_line():
    params = {"controller_scene": str(SLIP), "load_threshold": 0.002,
              "joint_slip_window": WINDOW, "joint_slip_ratio": RATIO}
    jaws = JointFeedback.of(params, [])
    assert JointFeedback.of(params, ["wrench"]) is None  # sensors: their route
    poses = {"F1": np.array([0.012, -0.026]), "F2": np.array([0.012, 0.026])}
    log = LogLines()

    def sample(msg):
        fields = {f: {"position": p.copy()} for f, p in poses.items()}
        jaws.replace(fields, msg, log)
        return fields

    gripper = jaws.controller.gripper
    bad = [JointState(name=["wrong_joint"], position=[0.3], effort=[1.0]),
           JointState(name=["finger_joint"], position=[float("nan")], effort=[1.0]),
           JointState(name=["finger_joint"], position=[0.3], effort=[])]
    for k, msg in enumerate(bad):
        msg.header.stamp.nanosec = (k + 1) * 1_000_000
        assert all("force" not in f for f in sample(msg).values())
        sample(msg)  # the same stamp again (a re-sent tick): no second line
    assert len(log.lines) == 3
    for line, why in zip(log.lines, ("are missing", "not finite", "one of each")):
        assert line.startswith("ignored the joint state") and why in line
    # a good one: the jaws on the line at the joint's aperture, each pushing with the effort
    good = JointState(name=["finger_joint"], position=list(gripper.joint_positions(0.04)),
                      effort=list(gripper.joint_efforts(2.5)))
    good.header.stamp.nanosec = 9_000_000
    fields = sample(good)
    gap = fields["F2"]["position"] - fields["F1"]["position"]
    assert np.linalg.norm(gap) == pytest.approx(0.04 + 2 * gripper.pad.contact_radius)
    np.testing.assert_allclose(fields["F1"]["force"], [0.0, -2.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(fields["F2"]["force"], [0.0, 2.5, 0.0], atol=1e-12)
    assert fields["F1"]["force_stamp_ns"] == 9_000_000
