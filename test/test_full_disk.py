# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A disk that fills up during a recording: the bag stays readable up to its last complete
chunk, says why it stopped, and the run still prints its summary (exit 4, not a traceback).

The full disk is real: a 700 kB tmpfs mounted in a private mount namespace (``unshare -m``),
or, where this process may not create one, a file-size limit (RLIMIT_FSIZE, which makes writes
fail with EFBIG as a quota would).
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

from mcap.reader import make_reader
from rosbags.rosbag2 import Reader

from squeeze_grasp_ros.ros.recording.bag import STOPPED_KEY, bag_info, read_bag

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"

WRITE_UNTIL_FULL = textwrap.dedent("""
    import resource, sys
    resource.setrlimit(resource.RLIMIT_FSIZE, (2_500_000, 2_500_000))
    from rclpy.serialization import serialize_message
    from std_msgs.msg import Header
    from squeeze_grasp_ros.ros.recording.bag import BagWriter
    bag = BagWriter(sys.argv[1], "zstd", 64 * 1024)
    bag.add_topic("/tick", "std_msgs/msg/Header")
    for i in range(1_000_000):
        msg = Header(frame_id=f"{i:08d}" * 40)
        msg.stamp.sec, msg.stamp.nanosec = divmod(i * 1_000_000, 1_000_000_000)
        bag.write("/tick", serialize_message(msg), i * 1_000_000)
        if bag.dropped >= 50:
            break
    bag.close()
    print(bag.failure)
""")


def test_a_bag_that_runs_out_of_room_keeps_every_complete_chunk(tmp_path):
    """Messages are kept in order from the first, with nothing missing before the cut; the
    file ends with a rebuilt summary, so every reader (ours, the mcap library's indexed reader,
    rosbags, which reads MCAP only through its index) sees the count metadata.yaml states.
    """
    bag = tmp_path / "bag"
    out = subprocess.run([sys.executable, "-c", WRITE_UNTIL_FULL, str(bag)], check=True,
                         capture_output=True, text=True).stdout
    assert "EFBIG" in out
    assert sorted(p.name for p in bag.iterdir()) == ["bag_0.mcap", "metadata.yaml"]
    messages = read_bag(bag).messages
    assert len(messages) > 1000
    assert [m.log_time_ns for m in messages] == [i * 1_000_000 for i in range(len(messages))]
    with open(bag / "bag_0.mcap", "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        assert reader.get_summary().statistics.message_count == len(messages)
        assert sum(1 for _ in reader.iter_messages()) == len(messages)
    with Reader(bag) as indexed:  # rosbags reads MCAP through its index only
        assert sum(1 for _ in indexed.messages()) == len(messages)
    info = bag_info(bag)
    assert info["message_count"] == len(messages)
    assert "EFBIG" in info["custom_data"][STOPPED_KEY]


def full_disk_command(mount: Path, size: str, command: list[str]) -> tuple[list[str], object]:
    """``command`` with ``mount`` a tmpfs of ``size`` in a private mount namespace, or, where
    that is not allowed here, under a file-size limit; (argv, preexec_fn).
    """
    probe = subprocess.run(["unshare", "-m", "true"], capture_output=True)
    if shutil.which("unshare") and probe.returncode == 0:
        script = (f"mount -t tmpfs -o size={size} tmpfs {mount} && exec "
                  + " ".join(f"'{a}'" for a in command))
        return ["unshare", "-m", "sh", "-c", script], None

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (400_000, 400_000))
    return command, limit


def test_a_run_whose_disk_fills_up_prints_its_summary_and_leaves_a_readable_bag(tmp_path):
    """The 700-tick foam square (about 0.8 MB of recording) on a disk with room for about
    0.4 MB: the grasp is still run to its end and reported, the run exits 4 naming the reason,
    and the bag replays the events it holds.
    """
    scene = SCENES / "foam_square.yaml"
    mount = tmp_path / "small_disk"
    mount.mkdir()
    bag = mount / "bag"
    argv, preexec = full_disk_command(mount, "700k", [
        sys.executable, "-m", "squeeze_grasp_ros.cli", "run", str(scene), "--record", str(bag),
        "--json", "--quiet"])
    # the bag lives in the tmpfs only while the namespace exists: read it there
    check = (f"; {sys.executable} -m squeeze_grasp_ros.cli replay {bag} --json "
             f"> {tmp_path / 'replay.json'}; cp {bag}/* {tmp_path}/")
    if argv[0] == "unshare":
        argv[-1] = argv[-1].replace("&& exec ", "&& ") + "; code=$?" + check + "; exit $code"
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=300,
                          preexec_fn=preexec, env=os.environ)
    assert proc.returncode == 4, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr
    summary = json.loads(proc.stdout)
    assert summary["outcome"] == "grasp held"
    assert summary["world_termination"] == "none"
    stopped = summary["recording_stopped"]
    assert "ENOSPC" in stopped or "EFBIG" in stopped
    assert f"the recording in {bag} stopped early: {stopped}" in proc.stderr
    kept = tmp_path if argv[0] == "unshare" else bag
    info = bag_info(kept)
    assert info["custom_data"][STOPPED_KEY] == stopped
    messages = read_bag(kept).messages
    ticks = [m for m in messages if m.topic == "/sim/tick"]
    assert 0 < len(ticks) < 700
    assert len(messages) == info["message_count"]
    with Reader(kept) as indexed:
        assert sum(1 for _ in indexed.messages()) == len(messages)
    if argv[0] == "unshare":
        replay = json.loads((tmp_path / "replay.json").read_text())
        assert replay["reproduced"] is True
