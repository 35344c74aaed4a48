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
