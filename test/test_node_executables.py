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
    documented = re.findall(r"recorder ready: (recording \d+ topics)", shown)
    assert documented and set(documented) == {topics}


def test_the_hardware_mode_commands_of_grippers_md_print_its_ready_lines(tmp_path):
    """docs/grippers.md's hardware-mode ``ros2 run`` commands of the monitor and the executor
    (run from a folder holding the repository's config/) log the ready lines the page shows,
    their stamps shown as ``[...]``.
    """
    from doc_transcripts import blocks

    page = REPO / "docs" / "grippers.md"
    found = [b.lines for b in blocks(page) if b.language == "" and b.lines
             and b.lines[0].startswith(("ros2 run squeeze_grasp_ros monitor ",
                                        "[INFO] [...] [monitor]: monitor ready: "))]
    assert len(found) == 2, found
    commands, shown = " ".join(found[0]).replace("\\ ", "").split("ros2 run ")[1:], found[1]
    (tmp_path / "config").symlink_to(REPO / "config")
    processes = {}
    for command in commands:
        words = shlex.split(command)
        assert words[0] == "squeeze_grasp_ros", words
        processes[words[1]] = subprocess.Popen(
            [script(words[1]), *words[2:]], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
            text=True, cwd=tmp_path, stdin=subprocess.DEVNULL)
    logged = []
    try:
        for name, process in processes.items():
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline:
                line = process.stdout.readline()
                if f"[{name}]: {name} ready: " in line or not line:
                    logged.append(re.sub(r"^(\[\w+\]) \[[\d.]+\]", r"\1 [...]", line.rstrip()))
                    break
    finally:
        for process in processes.values():
            process.send_signal(signal.SIGINT)
        codes = {name: p.wait(timeout=60) for name, p in processes.items()}
    assert list(processes) == ["monitor", "executor"] and logged == list(shown), logged
    assert codes == dict.fromkeys(processes, 0)
