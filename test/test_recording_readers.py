# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Recordings decode completely in the standard readers users open them with.

Foxglove (its own TypeScript libraries, run under node), ``mcap_ros2`` (Foxglove's Python
decoder) and rosbags each decode every message of every channel of a fresh recording. The
schema text is checked against rosbag2's own writer, byte for byte.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from foxglove_support import first_messages, foxglove_decode, layout_paths, resolve
from mcap.reader import make_reader
from pipeline_support import SMALL_SQUARE, write_scene

from squeeze_grasp_ros.ros.recording.schema import SEPARATOR, message_definition, own_text
from squeeze_grasp_ros.ros.run.options import RunOptions
from squeeze_grasp_ros.ros.run.runner import PipelineRunner

ACTION_TOPICS = {"/executor/execute_grasp/_action/feedback",
                 "/executor/execute_grasp/_action/status"}


GRIPPER_TOPICS = ("/joint_states",)
"""Topics of the shipped Foxglove layout that only a gripper scene's recording holds."""
CAMERA_TOPICS = ("/monitor/shape_residual",)
"""Plotted topics of the shipped layout that only a camera scene's recording holds."""


def record(directory: Path, *, hidden: bool) -> Path:
    """The small square through every node in one process, recorded; the ``.mcap`` file."""
    path = write_scene(directory, SMALL_SQUARE)
    PipelineRunner(RunOptions(path, record=str(directory / "bag"),
                              include_hidden_topics=hidden)).run()
    return next((directory / "bag").glob("*.mcap"))


@pytest.fixture(scope="module")
def default_bag(tmp_path_factory) -> Path:
    return record(tmp_path_factory.mktemp("default"), hidden=False)


@pytest.fixture(scope="module")
def hidden_bag(tmp_path_factory) -> Path:
    return record(tmp_path_factory.mktemp("hidden"), hidden=True)


def channel_counts(mcap_file: Path) -> dict[str, int]:
    """Topic -> message count from the file's own statistics record."""
    with open(mcap_file, "rb") as f:
        summary = make_reader(f).get_summary()
    return {summary.channels[c].topic: n
            for c, n in summary.statistics.channel_message_counts.items()}


def mcap_ros2_counts(mcap_file: Path, topics=None) -> dict[str, int]:
    from mcap_ros2.decoder import DecoderFactory

    counts: dict[str, int] = {}
    with open(mcap_file, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, _, decoded in reader.iter_decoded_messages(topics=topics):
            assert decoded is not None
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    return counts


def rosbags_counts(bag: Path) -> dict[str, int]:
    from rosbags.highlevel import AnyReader

    counts: dict[str, int] = {}
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages():
            reader.deserialize(raw, connection.msgtype)
            counts[connection.topic] = counts.get(connection.topic, 0) + 1
    return counts


def test_hidden_action_topics_are_recorded_only_when_asked(default_bag, hidden_bag):
    assert not ACTION_TOPICS & set(channel_counts(default_bag))
    assert ACTION_TOPICS <= set(channel_counts(hidden_bag))


def test_foxglove_libraries_decode_every_message(default_bag, hidden_bag):
    for mcap_file in (default_bag, hidden_bag):
        expected = channel_counts(mcap_file)
        report = foxglove_decode(mcap_file)
        assert {t: r["decoded"] for t, r in report.items()} == expected
        assert all(r["error"] is None for r in report.values()), report
    report = foxglove_decode(default_bag)
    assert report["/sim/markers"]["frame_ids"] == ["object"]
    assert report["/sim/markers"]["schema"] == "visualization_msgs/msg/MarkerArray"


def test_mcap_ros2_decodes_every_message(default_bag):
    assert mcap_ros2_counts(default_bag) == channel_counts(default_bag)


def test_mcap_ros2_rejects_only_the_action_feedback(hidden_bag):
    """mcap_ros2 0.6 accepts message names matching [A-Z][A-Za-z0-9]* only, so it cannot parse
    rosidl's action messages (``ExecuteGrasp_FeedbackMessage``); every other channel decodes.
    The ``--include-hidden-topics`` help says so.
    """
    expected = channel_counts(hidden_bag)
    feedback = "/executor/execute_grasp/_action/feedback"
    others = [t for t in expected if t != feedback]
    assert mcap_ros2_counts(hidden_bag, topics=others) == {t: expected[t] for t in others}
    with pytest.raises(Exception, match="ExecuteGrasp_") as info:
        mcap_ros2_counts(hidden_bag, topics=[feedback])
    assert info.typename == "InvalidResourceName"


def test_rosbags_decodes_every_message(default_bag, hidden_bag):
    for mcap_file in (default_bag, hidden_bag):
        assert rosbags_counts(mcap_file.parent) == channel_counts(mcap_file)


def test_schema_text_is_rosbag2s_for_standard_types(default_bag):
    """rosbag2's layout: the root .msg verbatim, then depth first and in sorted order each used
    type once, after a blank line, 80 '=' and 'MSG: pkg/Type' (no '/msg/').
    """
    def msg(name: str) -> str:
        return own_text(name.replace("/", "/msg/"))

    def section(name: str) -> str:
        return f"\n{SEPARATOR}\nMSG: {name}\n{msg(name)}"

    expected = (msg("geometry_msgs/PoseStamped") + section("geometry_msgs/Pose")
                + section("geometry_msgs/Point") + section("geometry_msgs/Quaternion")
                + section("std_msgs/Header") + section("builtin_interfaces/Time"))
    with open(default_bag, "rb") as f:
        schemas = {s.name: s.data.decode() for s in make_reader(f).get_summary().schemas.values()}
    assert schemas["geometry_msgs/msg/PoseStamped"] == expected
    assert "MSG: std_msgs/Header\n" in schemas["visualization_msgs/msg/MarkerArray"]
    assert all("/msg/" not in line for text in schemas.values()
               for line in text.splitlines() if line.startswith("MSG: "))


def test_schema_text_matches_rosbag2s_own_unit_test(tmp_path, monkeypatch):
    """rosbag2_cpp's test_local_message_definition_source (can_find_msg_deps), ported."""
    share = tmp_path / "share" / "rosbag2_test_msgdefs" / "msg"
    share.mkdir(parents=True)
    (share / "ComplexMsg.msg").write_text("rosbag2_test_msgdefs/BasicMsg b\n")
    (share / "BasicMsg.msg").write_text("float32 c\n")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    own_text.cache_clear()
    try:
        text = message_definition("rosbag2_test_msgdefs/ComplexMsg")
    finally:
        own_text.cache_clear()
    assert text == ("rosbag2_test_msgdefs/BasicMsg b\n"
                    "\n"
                    f"{'=' * 80}\n"
                    "MSG: rosbag2_test_msgdefs/BasicMsg\n"
                    "float32 c\n")


def test_shipped_viewers_show_what_a_recording_holds(default_bag):
    """Every topic and message path of the Foxglove layout, and the RViz2 display topic and fixed
    frame, exist in a fresh recording; the force-vs-depth plot reads numbers.
    """
    import json

    import yaml

    from squeeze_grasp_ros.resources import viewer_file

    messages = first_messages(default_bag.parent)
    layout = json.loads(viewer_file("foxglove_layout.json").read_text())
    panels = layout["configById"]
    # the gripper's joint_states panel: test_joint_feedback checks it on a gripper recording;
    # the shape residual panel: test_camera_loop on a camera recording
    paths = [v for v in layout_paths(panels)
             if not v.startswith(GRIPPER_TOPICS + CAMERA_TOPICS)]
    assert paths
    for value in paths:
        topic, _, field = value.partition(".")
        assert isinstance(resolve(messages[topic], field), float), value
    # every plotted topic is a curve: it has a message per tick (executor/status, with one
    # message per state change, drew the "commanded depth" as a straight line)
    counts = channel_counts(default_bag)
    plotted = {value.partition(".")[0] for value in paths}
    assert min(counts[topic] for topic in plotted) >= 500, counts
    topics = [t for c in panels.values() for t in c.get("topics", {})]
    topics += [c["topicPath"] for c in panels.values() if "topicPath" in c]
    assert set(topics) <= set(messages)
    frame = panels["3D!squeeze"]["followTf"]
    assert {m.header.frame_id for m in messages["/sim/markers"].markers} == {frame}

    rviz = yaml.safe_load(viewer_file("squeeze_grasp.rviz").read_text())["Visualization Manager"]
    markers = next(d for d in rviz["Displays"] if d["Class"].endswith("/MarkerArray"))
    assert markers["Topic"]["Value"] in messages
    assert rviz["Global Options"]["Fixed Frame"] == frame
    assert set(markers["Namespaces"]) == {m.ns for m in messages["/sim/markers"].markers if m.ns}


def test_corrupt_recordings_are_refused_never_misread(default_bag, tmp_path):
    """Single-bit flips anywhere in the file (60 seeded positions plus one in every chunk's
    data): read_bag either refuses the file or returns exactly the original messages.
    """
    import numpy as np
    from mcap.reader import make_reader as reader_of

    from squeeze_grasp_ros.ros.recording.bag import BagError, read_bag

    original = read_bag(default_bag).messages
    data = default_bag.read_bytes()
    with open(default_bag, "rb") as f:
        chunks = reader_of(f).get_summary().chunk_indexes
    positions = [c.chunk_start_offset + c.chunk_length - 1 - c.compressed_size // 2
                 for c in chunks]
    positions += np.random.default_rng(7).integers(8, len(data) - 8, 60).tolist()
    refused = 0
    for k, position in enumerate(positions):
        flipped = bytearray(data)
        flipped[position] ^= 1 << (k % 8)
        path = tmp_path / f"flip_{k}.mcap"
        path.write_bytes(bytes(flipped))
        try:
            assert read_bag(path).messages == original, position
        except BagError as exc:
            assert "corrupt" in str(exc)
            refused += 1
    assert refused >= len(chunks)


def test_replay_of_a_bare_mcap_and_odd_metadata_reproduces(default_bag, tmp_path):
    import shutil

    from squeeze_grasp_ros.cli import main

    folder = default_bag.parent
    bare_folder = tmp_path / "no_metadata"
    bare_folder.mkdir()
    shutil.copy(default_bag, bare_folder)
    twice = tmp_path / "twice"
    shutil.copytree(folder, twice)
    meta = (twice / "metadata.yaml").read_text()
    name = default_bag.name
    (twice / "metadata.yaml").write_text(meta.replace(f"- {name}", f"- {name}\n  - {name}", 1))
    assert meta != (twice / "metadata.yaml").read_text()
    for target in (default_bag, bare_folder, twice):
        assert main(["replay", str(target)]) == 0, target
    corrupt = tmp_path / "corrupt.mcap"
    data = bytearray(default_bag.read_bytes())
    data[len(data) // 3] ^= 0x10
    corrupt.write_bytes(bytes(data))
    assert main(["replay", str(corrupt)]) == 2


def test_an_empty_or_cut_short_mcap_is_refused_naming_its_end(default_bag, tmp_path, capsys):
    """A recorder killed before it wrote, or a copy cut short: before, "is corrupt (EndOfFile:
    )" with nothing after the colon.
    """
    from squeeze_grasp_ros.cli import main

    data = default_bag.read_bytes()
    for name, size in (("empty", 0), ("cut", len(data) // 2)):
        path = tmp_path / f"{name}.mcap"
        path.write_bytes(data[:size])
        assert main(["replay", str(path)]) == 2
        err = capsys.readouterr().err
        end = ("the file is empty" if size == 0 else
               f"the file ends inside a record, at byte {size}")
        assert f"{path} is corrupt (EndOfFile: {end}); it cannot be trusted" in err, err

