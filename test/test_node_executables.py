# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The node executables as ``ros2 run`` starts them: a ready line, and one clear line (exit 2)
when a required parameter is missing. Real processes on real rclpy.
"""
from __future__ import annotations

import re
import shlex
import signal
import subprocess
import time
from pathlib import Path

import pytest
import rclpy
from executables import script

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("node, parameter", [("sim_hardware", "scene"), ("recorder", "output")])
def test_a_missing_required_parameter_is_one_line_and_exit_2(node, parameter):
    done = subprocess.run([script(node)], capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{node}: error: parameter '{parameter}'")
    assert f"-p {parameter}:=" in lines[0]


@pytest.mark.parametrize("value, message", [
    ("-1.0", "parameter 'mu' must be a finite number >= 0 (0: no friction), got -1.0"),
    ("abc", "parameter 'mu' must be a number, got 'abc'"),
])
def test_a_bad_friction_coefficient_is_one_line_naming_it_and_exit_2(value, message):
    """``hardware.launch.py mu:=-1`` started a monitor with mu -1.0; ``mu:=abc`` ended it with
    "could not convert string to float: 'abc'", naming no parameter.
    """
    done = subprocess.run([script("monitor"), "--ros-args", "-p", f"mu:={value}"],
                          capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert lines == [f"monitor: error: {message}"], lines


def test_ros_args_rcl_cannot_parse_are_one_error_line_and_exit_2():
    # an unquoted YAML list whose items hold a colon, as a user types it after -p
    done = subprocess.run([script("monitor"), "--ros-args", "-p",
                           "finger_devices:=[F1:jaw_f1, F2:jaw_f2]"], capture_output=True,
                          text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    ours = [line for line in done.stderr.splitlines() if line.startswith("monitor: error:")]
    assert len(ours) == 1 and "finger_devices:=[F1:jaw_f1, F2:jaw_f2]" in ours[0]


def test_every_node_logs_when_it_is_ready(tmp_path):
    """Started alone (as ``ros2 run`` does), each node says it is ready and what it serves,
    and stops cleanly on SIGINT.
    """
    scene = REPO / "config" / "scenes" / "foam_square.yaml"
    commands = {
        "executor": [],
        "monitor": [],
        "sim_hardware": ["-p", f"scene:={scene}"],
        "recorder": ["-p", f"output:={tmp_path / 'bag'}"],
        "planner": [],
        "outline": [],
    }
    processes = {name: subprocess.Popen([script(name), "--ros-args", *extra],
                                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                        text=True, cwd=tmp_path, stdin=subprocess.DEVNULL)
                 for name, extra in commands.items()}
    outputs = {}
    try:
        for name, process in processes.items():
            deadline, lines = time.monotonic() + 120, []
            while time.monotonic() < deadline:
                line = process.stdout.readline()
                lines.append(line)
                if f"[{name}]: {name} ready: " in line or not line:
                    break
            outputs[name] = "".join(lines)
    finally:
        for process in processes.values():
            process.send_signal(signal.SIGINT)
        codes = {name: p.wait(timeout=60) for name, p in processes.items()}
    for name in commands:
        assert f"[{name}]: {name} ready: " in outputs[name], outputs[name]
    assert "scene foam_square" in outputs["sim_hardware"]
    assert f"into {tmp_path / 'bag'}" in outputs["recorder"]
    assert "action /executor/execute_grasp" in outputs["executor"]
    assert "camera/mask, camera/pose, frame object" in outputs["outline"]
    assert codes == dict.fromkeys(commands, 0)
    # the ready lines docs/ros.md shows (recorded with ros2 launch) say what these say
    shown = (REPO / "docs" / "ros.md").read_text(encoding="utf-8")
    limits = re.search(r"planner ready: (PlannerLimits\(.*?\));", outputs["planner"]).group(1)
    documented = re.findall(r"planner ready: (PlannerLimits\(.*?\));", shown)
    assert documented and set(documented) == {limits}
    topics = re.search(r"recorder ready: (recording \d+ topics)", outputs["recorder"]).group(1)
    documented = re.findall(r"recorder ready: (recording \d+ topics) into (\S+)", shown)
    # the hardware launch's recorder (hw_bag) records no simulation topics: test_ros_interfaces
    simulated = {shown_topics for shown_topics, bag in documented if "hw_bag" not in bag}
    assert simulated == {topics}


STAMP = re.compile(r"^(\[\w+\]) \[[\d.]+\]")
"""The wall-clock stamp of a log line, which the docs show as ``[...]``."""


def grippers_md_hardware_mode() -> tuple[list[list[str]], list[str]]:
    """docs/grippers.md's hardware-mode ``ros2 run`` commands (their words after ``ros2 run``)
    and the ready lines the page shows for them.
    """
    from doc_transcripts import blocks

    found = [b.lines for b in blocks(REPO / "docs" / "grippers.md") if b.language == ""
             and b.lines and b.lines[0].startswith(("ros2 run squeeze_grasp_ros monitor ",
                                                    "[INFO] [...] [monitor]: monitor ready: "))]
    assert len(found) == 2, found
    commands = " ".join(found[0]).replace("\\ ", "").split("ros2 run ")[1:]
    return [shlex.split(command) for command in commands], list(found[1])


def read_until(process: subprocess.Popen, text: str, timeout: float = 120.0) -> str:
    """The first line ``process`` logs that holds ``text`` (its stamp as ``[...]``), or the
    last line read when it ends or the time is up.
    """
    deadline, line = time.monotonic() + timeout, ""
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if text in line or not line:
            break
    return STAMP.sub(r"\1 [...]", line.rstrip())


def test_the_hardware_mode_commands_of_grippers_md_print_its_ready_lines(tmp_path):
    """docs/grippers.md's hardware-mode ``ros2 run`` commands of the monitor and the executor
    (run from a folder holding the repository's config/) log the ready lines the page shows.
    """
    commands, shown = grippers_md_hardware_mode()
    (tmp_path / "config").symlink_to(REPO / "config")
    processes = {}
    for words in commands:
        assert words[0] == "squeeze_grasp_ros", words
        processes[words[1]] = subprocess.Popen(
            [script(words[1]), *words[2:]], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
            text=True, cwd=tmp_path, stdin=subprocess.DEVNULL)
    try:
        logged = [read_until(process, f"[{name}]: {name} ready: ")
                  for name, process in processes.items()]
    finally:
        for process in processes.values():
            process.send_signal(signal.SIGINT)
        codes = {name: p.wait(timeout=60) for name, p in processes.items()}
    assert list(processes) == ["monitor", "executor"] and logged == shown, logged
    assert codes == dict.fromkeys(processes, 0)


def fill(message, fields: dict):
    """``message`` with ``fields`` (a ros2cli YAML message, nested dicts) set."""
    for key, value in fields.items():
        if isinstance(value, dict):
            fill(getattr(message, key), value)
        else:
            setattr(message, key, type(getattr(message, key))(value))
    return message


def test_the_gripper_pose_example_of_grippers_md_logs_its_lines(tmp_path):
    """docs/grippers.md's ``ros2 topic pub`` of a gripper pose to the hardware-mode monitor
    (started as the page's command, with ``-p mu:=0.6``): the monitor's ready line and the
    line it logs for the pose are the page's. The publisher is rclpy with the command's QoS.
    """
    import yaml
    from doc_transcripts import blocks
    from geometry_msgs.msg import PoseStamped
    from rclpy.context import Context
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    block = next(b.lines for b in blocks(REPO / "docs" / "grippers.md") if b.language == ""
                 and b.lines and b.lines[0].strip().startswith("ros2 topic pub --once"))
    text = " ".join(line.strip() for line in block[:2]).replace("\\ ", "")
    words = shlex.split(text)
    assert words[:9] == ["ros2", "topic", "pub", "--once", "--qos-durability",
                         "transient_local", "--qos-reliability", "reliable", "gripper_pose"]
    assert words[9] == "geometry_msgs/msg/PoseStamped", words
    shown = [line.strip() for line in block[2:]]
    monitor = next(w for w in grippers_md_hardware_mode()[0] if w[1] == "monitor")
    (tmp_path / "config").symlink_to(REPO / "config")
    process = subprocess.Popen([script("monitor"), *monitor[2:], "-p", "mu:=0.6"],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               cwd=tmp_path, stdin=subprocess.DEVNULL)
    context = Context()
    rclpy.init(context=context)
    try:
        logged = [read_until(process, "[monitor]: monitor ready: ")]
        node = rclpy.create_node("topic_pub", context=context)
        qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                         reliability=ReliabilityPolicy.RELIABLE)
        node.create_publisher(PoseStamped, words[8], qos).publish(
            fill(PoseStamped(), yaml.safe_load(words[10])))
        logged.append(read_until(process, "[monitor]: gripper_pose: ", timeout=60.0))
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
        process.send_signal(signal.SIGINT)
        code = process.wait(timeout=60)
    assert logged == shown and code == 0, logged
