# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Runs that go wrong: the exit code and the summary say so, and every message printed is true.

Exit codes (``squeeze_grasp_ros.exit_codes``): 0 the grasp held, 1 the world says the grasp
failed (the executor is stopped), 2 user error, 4 internal error.
"""
from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from pipeline_support import SMALL_SQUARE
from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.ros.recording.bag import read_bag

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"


def test_a_failed_grasp_exits_1_and_stops_the_executor(capfd, tmp_path):
    code = main(["run", str(SCENES / "disk_finger_slip.yaml"), "--json", "--record",
                 str(tmp_path / "bag")])
    out = json.loads(capfd.readouterr().out)
    assert code == 1
    assert out["success"] is False and out["world_termination"] == "finger_slip"
    assert "grasp failed" in out["outcome"] and "finger_slip" in out["outcome"]
    assert out["termination"] == "canceled"
    slip_ns = out["world_end"]["stamp_ns"]
    dt_ns = 1_000_000
    assert out["ticks"] * dt_ns <= slip_ns + 50 * dt_ns  # stopped within 50 ticks of the slip
    assert out["measured_depth"] < 0.5 * out["target_depth"]
    assert (tmp_path / "bag" / "metadata.yaml").is_file()


def test_a_held_grasp_exits_0(capfd):
    assert main(["run", str(SCENES / "foam_square.yaml"), "--json", "--quiet"]) == 0
    out = json.loads(capfd.readouterr().out)
    assert out["success"] is True and out["outcome"] == "grasp held"


def long_scene(tmp_path: Path, **changes) -> str:
    """The foam square at a 0.1 ms tick: about 7,000 ticks, long enough to interrupt."""
    data = yaml.safe_load((SCENES / "foam_square.yaml").read_text())
    data["sim"] = {"dt": 1e-4}
    data.update(changes)
    path = tmp_path / "long_square.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)


def start_run(tmp_path: Path, *extra: str) -> tuple[subprocess.Popen, Path]:
    bag = tmp_path / "bag"
    proc = subprocess.Popen([sys.executable, "-m", "squeeze_grasp_ros.cli", "run",
                             long_scene(tmp_path), "--record", str(bag), "--quiet", *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not any(bag.glob("*.mcap")) or next(bag.glob("*.mcap")).stat().st_size < 300_000:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the run never started recording"
        time.sleep(0.2)
    return proc, bag


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_stops_a_one_process_run_at_once_with_a_readable_bag(tmp_path, signum):
    proc, bag = start_run(tmp_path)
    sent = time.monotonic()
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    stopped_after = time.monotonic() - sent
    assert proc.returncode == 128 + signum
    assert stopped_after < 10, stopped_after  # the whole squeeze takes several times longer
    messages = read_bag(bag).messages
    assert f"recording in {bag} is complete up to here ({len(messages)} messages)" in err
    ticks = [m for m in messages if m.topic == "/sim/tick"]
    assert 0 < len(ticks) < 7000


@pytest.mark.slow
def test_sigterm_to_the_processes_parent_takes_the_children_down(tmp_path):
    proc, bag = start_run(tmp_path, "--processes")
    children = subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True,
                              text=True).stdout.split()
    assert len(children) >= 4
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=90)
    assert proc.returncode == 143, err
    for pid in children:
        assert not Path(f"/proc/{pid}").exists() or \
            Path(f"/proc/{pid}/stat").read_text().split()[2] == "Z", pid
    assert read_bag(bag).messages


@pytest.mark.slow
def test_a_hung_node_ends_the_run_with_a_clear_error(tmp_path):
    proc, _ = start_run(tmp_path, "--processes", "--timeout", "20")
    monitor = subprocess.run(["pgrep", "-P", str(proc.pid), "-f", "nodes.monitor"],
                             capture_output=True, text=True).stdout.split()
    assert monitor
    os.kill(int(monitor[0]), signal.SIGSTOP)
    try:
        _, err = proc.communicate(timeout=120)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.kill(int(monitor[0]), signal.SIGCONT)
    assert proc.returncode == 4, err
    assert "timed out after 20 s" in err and "Traceback" not in err


def test_sensor_dropout_1_ends_the_goal_after_the_stale_budget(tmp_path, capfd):
    data = yaml.safe_load(yaml.safe_dump(SMALL_SQUARE))
    data["effects"] = data["effects"] + ["sensor_dropout"]
    data["sensors"] = {"dropout": 1.0, "seed": 3}
    path = tmp_path / "dropout.yaml"
    path.write_text(yaml.safe_dump(data))
    start = time.monotonic()
    code = main(["run", str(path), "--json"])
    out = json.loads(capfd.readouterr().out)
    assert time.monotonic() - start < 60
    assert code == 1 and out["termination"] == "stale_data"
    assert out["sim_time"] < 0.2 + 0.05
    assert sum(out["alarms"].values()) <= 4  # one per alarm episode and finger, not per tick


def test_a_second_run_on_the_same_domain_is_refused(tmp_path):
    first, first_bag = start_run(tmp_path)
    try:
        second = subprocess.run([sys.executable, "-m", "squeeze_grasp_ros.cli", "run",
                                 str(SCENES / "foam_square.yaml"), "--record",
                                 str(tmp_path / "second_bag"), "--quiet",
                                 "--discovery-wait", "3"],
                                capture_output=True, text=True, timeout=120)
    finally:
        first.send_signal(signal.SIGINT)
        first.communicate(timeout=60)
    assert second.returncode == 4
    assert "another simulated pipeline is running on ROS_DOMAIN_ID" in second.stderr
    assert not (tmp_path / "second_bag").exists()
    topics = {m.topic for m in read_bag(first_bag).messages}
    assert "/sim/tick" in topics
