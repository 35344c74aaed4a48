# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Crafted recordings: a recording is data from elsewhere, and ``replay`` treats it so.

Issue 34: a crafted recording made ``replay`` import any installed module; a 0.8 MB one made it
use 3.2 GB (a decompression bomb); one corrupt sensor message, or a ``metadata.yaml`` listing
``X`` and ``./X``, stalled it until its 300 s timeout. Each case is crafted here from a real
recording and must end at once with one clear line (exit 2), or replay correctly.
"""
from __future__ import annotations

import json
import os
import shutil
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
import zstandard
from mcap.data_stream import RecordBuilder
from mcap.records import Chunk, DataEnd, Footer, Header
from mcap.writer import CompressionType, Writer
from test_recording_readers import record

from squeeze_grasp_ros.ros.recording.bag import MAX_CHUNK_BYTES, BagError, read_bag

MAGIC = b"\x89MCAP0\r\n"


@pytest.fixture(scope="module")
def bag(tmp_path_factory) -> Path:
    """A real recording (the small square through every node): its ``.mcap`` file."""
    return record(tmp_path_factory.mktemp("crafted"), hidden=False)


def rewrite(source: Path, target: Path, *, types: dict | None = None,
            data: dict | None = None) -> Path:
    """``source``'s messages as a bare ``.mcap`` with some topics' type names (``types``:
    topic -> name) or some messages' bytes (``data``: index -> bytes) replaced.
    """
    types, data = types or {}, data or {}
    with open(target, "wb") as f:
        writer = Writer(f, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="crafted")
        schemas: dict[str, int] = {}
        channels: dict[str, int] = {}
        for k, m in enumerate(read_bag(source).messages):
            type_name = types.get(m.topic, m.type)
            if type_name not in schemas:
                schemas[type_name] = writer.register_schema(type_name, "ros2msg", b"")
            if m.topic not in channels:
                channels[m.topic] = writer.register_channel(m.topic, "cdr", schemas[type_name])
            writer.add_message(channels[m.topic], m.log_time_ns, data.get(k, m.data),
                               m.log_time_ns)
        writer.finish()
    return target


def bomb(target: Path, chunks: int, size: int) -> Path:
    """An MCAP file of ``chunks`` zstd chunks, each ``size`` zero bytes uncompressed (a few
    kilobytes compressed; with ``size`` a multiple of 9 they parse as empty records of an
    unknown kind, which readers skip).
    """
    zeros = b"\0" * (1 << 20)
    builder = RecordBuilder()
    builder.write(MAGIC)
    Header(profile="ros2", library="bomb").write(builder)
    for _ in range(chunks):
        packer = zstandard.ZstdCompressor().compressobj()
        packed = b"".join(packer.compress(zeros) for _ in range(size >> 20))
        packed += packer.compress(zeros[:size % len(zeros)]) + packer.flush()
        Chunk(compression="zstd", data=packed, message_end_time=0, message_start_time=0,
              uncompressed_crc=0, uncompressed_size=size).write(builder)
    DataEnd(0).write(builder)
    Footer(0, 0, 0).write(builder)
    builder.write(MAGIC)
    target.write_bytes(builder.end())
    return target


def replay(target: Path, **env: str) -> tuple[subprocess.CompletedProcess, float, int]:
    """``squeeze-grasp replay --json TARGET`` as a process: (result, seconds, its peak RSS in
    bytes).
    """
    started = time.monotonic()
    # VmHWM: this process's own peak (ru_maxrss would include the forking test process's)
    command = [sys.executable, "-c",
               "import sys\n"
               "from squeeze_grasp_ros.entry import cli\n"
               "sys.argv = ['squeeze-grasp', 'replay', '--json', sys.argv[1]]\n"
               "try:\n    code = cli()\nfinally:\n"
               "    peak = [l for l in open('/proc/self/status') if l.startswith('VmHWM')]\n"
               "    print('peak', peak[0].split()[1], file=sys.stderr)\n"
               "sys.exit(code)\n", str(target)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=240,
                          env={**os.environ, **env})
    rss = int(done.stderr.rsplit("peak", 1)[1].split()[0]) * 1024
    return done, time.monotonic() - started, rss


def test_a_recording_cannot_make_replay_import_a_module(bag, tmp_path):
    """A reading whose type names an installed package with import-time code: replay refuses
    the recording and that code never runs.
    """
    package = tmp_path / "site" / "evil_pkg"
    package.mkdir(parents=True)
    marker = tmp_path / "imported"
    (package / "__init__.py").write_text(f"open({str(marker)!r}, 'w').close()\n")
    (package / "msg.py").write_text("PoseStamped = None\n")
    crafted = rewrite(bag, tmp_path / "evil.mcap",
                      types={"/devices/barrett_f1/pose": "evil_pkg/msg/PoseStamped"})
    done, _, _ = replay(crafted, PYTHONPATH=str(tmp_path / "site"))
    assert done.returncode == 2, done.stderr[-2000:]
    assert json.loads(done.stdout)["error"] == (
        "/devices/barrett_f1/pose has type 'evil_pkg/msg/PoseStamped' in the recording; "
        "replay publishes it as geometry_msgs/msg/PoseStamped")
    assert not marker.exists()


def test_a_corrupt_sensor_message_is_refused_at_once(bag, tmp_path):
    """Before: the monitor could not decode it, never answered its tick, and replay waited
    for its 300 s timeout.
    """
    messages = read_bag(bag).messages
    k = next(i for i, m in enumerate(messages) if m.topic == "/devices/barrett_f3/wrench")
    crafted = rewrite(bag, tmp_path / "corrupt.mcap", data={k: messages[k].data[:12]})
    done, seconds, _ = replay(crafted)
    assert done.returncode == 2, done.stderr[-2000:]
    error = json.loads(done.stdout)["error"]
    assert error.startswith("the message on /devices/barrett_f3/wrench logged at ")
    assert "does not decode as geometry_msgs/msg/WrenchStamped" in error
    assert seconds < 60  # before: the replay timeout, 300 s


def test_metadata_listing_a_file_twice_by_two_names_replays_once(bag, tmp_path):
    folder = tmp_path / "twice"
    shutil.copytree(bag.parent, folder)
    meta = folder / "metadata.yaml"
    name = bag.name
    text = meta.read_text()
    meta.write_text(text.replace(f"- {name}", f"- {name}\n  - ./{name}", 1))
    assert f"./{name}" in meta.read_text()
    assert len(read_bag(folder).messages) == len(read_bag(bag).messages)
    done, _, _ = replay(folder)
    assert done.returncode == 0, done.stderr[-2000:]
    assert json.loads(done.stdout)["reproduced"] is True


def test_a_decompression_bomb_is_refused_before_decompressing(tmp_path):
    """One chunk declaring 256 MiB of zeros (a 8 kB file): refused from its declared size;
    the process stays small.
    """
    crafted = bomb(tmp_path / "bomb.mcap", 1, 256 << 20)
    assert crafted.stat().st_size < 100_000
    with pytest.raises(BagError, match="refused before decompressing"):
        read_bag(crafted)
    done, _, rss = replay(crafted)
    assert done.returncode == 2, done.stderr[-2000:]
    assert "declares 268,435,456 bytes uncompressed" in json.loads(done.stdout)["error"]
    assert rss < 300 << 20, rss  # a normal replay peaks at about 130 MB


def test_many_small_bombs_are_refused_by_the_files_expansion_bound(tmp_path):
    """Chunks each under the per-chunk bound, together far more than the file could hold:
    refused once they exceed 64 times the file's size plus one chunk bound.
    """
    size = 9 * (MAX_CHUNK_BYTES // 18)  # valid (empty) records: only the bound stops them
    crafted = bomb(tmp_path / "bombs.mcap", 8, size)
    with pytest.raises(BagError, match="64 times the file's size"):
        read_bag(crafted)


ROSBAG2_TABLES = (
    "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
    "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)",
    "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, "
    "data BLOB)",
)
"""rosbag2's SQLite3 tables (its columns are NOT NULL; left open here to craft NULLs)."""


def sqlite_bag(target: Path, rows: list[tuple]) -> Path:
    """A rosbag2 SQLite3 file at ``target``: one topic, ``rows`` of (timestamp, data)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    db = sqlite3.connect(target)
    try:
        for statement in ROSBAG2_TABLES:
            db.execute(statement)
        db.execute("INSERT INTO topics VALUES (1, '/clock', 'rosgraph_msgs/msg/Clock', 'cdr', "
                   "'')")
        db.executemany("INSERT INTO messages(topic_id, timestamp, data) VALUES (1, ?, ?)", rows)
        db.commit()
    finally:
        db.close()
    return target


def not_a_database(target: Path) -> Path:
    target.write_bytes(b"SQLite format 3\n" + bytes(range(256)) * 8)
    return target


def empty_file(target: Path) -> Path:
    target.write_bytes(b"")
    return target


def other_tables(target: Path) -> Path:
    db = sqlite3.connect(target)
    db.execute("CREATE TABLE notes(text TEXT)")
    db.commit()
    db.close()
    return target


@pytest.mark.parametrize("craft, reason", [
    (not_a_database, "file is not a database"),
    (empty_file, "no such table: messages"),
    (other_tables, "no such table: messages"),
    (lambda target: sqlite_bag(target, [(1, None)]), "a message without data"),
    (lambda target: sqlite_bag(target, [("soon", b"\x00\x01")]), "a message timestamp"),
])
def test_a_db3_that_is_not_a_rosbag2_bag_is_refused_in_one_line(tmp_path, craft, reason):
    """Before: sqlite3.DatabaseError / OperationalError / TypeError tracebacks, exit 1."""
    crafted = craft(tmp_path / "bag.db3")
    with pytest.raises(BagError) as raised:
        read_bag(crafted)
    message = str(raised.value)
    assert message.startswith(f"{crafted} is not a readable rosbag2 SQLite3 file (")
    assert reason in message and "\n" not in message


def test_replay_of_a_db3_that_is_not_a_database_exits_2_with_one_line(tmp_path):
    crafted = not_a_database(tmp_path / "bag.db3")
    done, _, _ = replay(crafted)
    assert done.returncode == 2, done.stderr[-2000:]
    assert "Traceback" not in done.stderr
    assert json.loads(done.stdout)["error"] == (
        f"{crafted} is not a readable rosbag2 SQLite3 file (DatabaseError: file is not a "
        "database)")


@pytest.mark.parametrize("folder", ["run#1", "run?mode=rwc", "run%41"])
def test_a_db3_in_a_folder_named_with_uri_characters_is_read_from_its_own_file(tmp_path,
                                                                                folder):
    """The file is opened by its URI: before, '#' and '?' cut the path short ('run#1/bag.db3'
    opened, and created, the database 'run') and '%41' read as 'A'.
    """
    crafted = sqlite_bag(tmp_path / folder / "bag.db3", [(5, b"\x00\x01"), (3, b"\x02")])
    assert [(m.log_time_ns, m.data) for m in read_bag(crafted).messages] == [
        (3, b"\x02"), (5, b"\x00\x01")]
    assert sorted(p.name for p in tmp_path.iterdir()) == [folder]


@pytest.mark.parametrize("param, error", [
    ("mu=[1", "--param mu: invalid YAML at line 1, column 3: expected ',' or ']', but got "
              "'<stream end>'"),
    ("mu=*x", "--param mu: YAML aliases (*name) are not accepted (line 1, column 1)"),
    ("Mu=0.4", "--param Mu: the monitor has no such parameter (its parameters: "
               "config/monitor.yaml)"),
    ("finger_devices=F1", "parameter 'finger_devices' must be a list of strings, got 'F1'"),
    ("finger_devices=[]", "parameter 'finger_devices' must be a list of strings, got '[]'"),
    ("qos_depth=1.5", "parameter 'qos_depth' must be an integer, got '1.5'"),
    ("qos_depth=null", "parameter 'qos_depth' must be an integer, got 'None'"),
    ("mu={a: 1}", "parameter 'mu' must be true or false, an integer, a number, a string or a "
                  "list of one of them, got \"{'a': 1}\""),
    ("streams=[1, a]", "parameter 'streams' must be true or false, an integer, a number, a "
                       "string or a list of one of them, got \"[1, 'a']\""),
])
def test_a_bad_replay_param_is_one_line_naming_it(bag, capfd, param, error):
    """Before: a YAML, TypeError or rclpy traceback with exit 1, and an unknown name (a typo)
    was ignored without a word.
    """
    from squeeze_grasp_ros.cli import main

    assert main(["replay", str(bag), "--param", param]) == 2
    out, err = capfd.readouterr()
    assert (out, err) == ("", f"squeeze-grasp replay: error: {error}\n")


@pytest.mark.parametrize("topic, type_name", [
    ("/sim/tick", "squeeze_grasp_interfaces/msg/Tick"),
    ("/monitor/events", "squeeze_grasp_interfaces/msg/ContactEventArray"),
    ("/planner/predicted_events", "squeeze_grasp_interfaces/msg/ContactEventArray"),
])
def test_a_corrupt_tick_or_event_message_is_refused_in_one_line(bag, tmp_path, topic,
                                                               type_name):
    """Replay reads these too (the ticks, the recorded events it compares with, the prediction
    it hands the monitor). Before: an RMWError traceback, exit 1.
    """
    messages = read_bag(bag).messages
    k = next(i for i, m in enumerate(messages) if m.topic == topic)
    crafted = rewrite(bag, tmp_path / "corrupt.mcap", data={k: messages[k].data[:6]})
    done, _, _ = replay(crafted)
    assert done.returncode == 2, done.stderr[-2000:]
    assert json.loads(done.stdout)["error"] == (
        f"the message on {topic} logged at {messages[k].log_time_ns * 1e-9:.6f} s does not "
        f"decode as {type_name} (RMWError); the recording is corrupt")


def test_ticks_of_another_type_are_refused_not_misread(bag, tmp_path):
    """Before: read as Tick whatever their declared type, and the replay said the events
    differed (exit 1).
    """
    crafted = rewrite(bag, tmp_path / "ticks.mcap", types={"/sim/tick": "std_msgs/msg/String"})
    done, _, _ = replay(crafted)
    assert done.returncode == 2, done.stderr[-2000:]
    assert json.loads(done.stdout)["error"] == (
        "/sim/tick has type 'std_msgs/msg/String' in the recording; replay reads it as "
        "squeeze_grasp_interfaces/msg/Tick")


def test_a_re_sent_tick_recorded_twice_replays_once(bag, tmp_path):
    """A lost tick is re-sent with its stamp, its readings too; a recorder outside the lockstep
    (``ros2 bag record``) keeps both copies, where ours drops the second. Before: the monitor's
    answer to the copy carried a stamp already answered, replay waited for it and ended after
    10 s with "the monitor did not answer tick 101 of 702", exit 4.
    """
    messages = list(read_bag(bag).messages)
    tick = [i for i, m in enumerate(messages) if m.topic == "/sim/tick"][100]
    stamp = messages[tick].log_time_ns
    copies = [m for m in messages if m.log_time_ns == stamp and (
        m.topic == "/sim/tick" or m.topic.endswith(("/pose", "/wrench", "/tactile")))]
    assert len(copies) > 1
    folder = tmp_path / "twice"  # the bag's metadata.yaml: the run's monitor parameters
    shutil.copytree(bag.parent, folder)
    crafted = folder / bag.name
    with open(crafted, "wb") as f:
        writer = Writer(f, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="crafted")
        schemas: dict[str, int] = {}
        channels: dict[str, int] = {}
        for k, m in enumerate(messages + copies):
            if m.type not in schemas:
                schemas[m.type] = writer.register_schema(m.type, "ros2msg", b"")
            if m.topic not in channels:
                channels[m.topic] = writer.register_channel(m.topic, "cdr", schemas[m.type])
            writer.add_message(channels[m.topic], m.log_time_ns, m.data, m.log_time_ns,
                               sequence=k)
        writer.finish()
    done, _, _ = replay(folder)
    assert done.returncode == 0, done.stderr[-2000:]
    result = json.loads(done.stdout)
    assert result["reproduced"] is True
    assert result["ticks"] == sum(m.topic == "/sim/tick" for m in messages)
