# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""rosbag2 bags with MCAP storage: written from raw CDR with the ``mcap`` library, and read back.

A bag is a folder with ``metadata.yaml`` (rosbag2 metadata version 9, Jazzy) and one
``<folder name>_0.mcap``. Inside the MCAP (profile ``ros2``): one schema per type (encoding
``ros2msg``, the complete message definition of :mod:`.schema`), one channel per topic
(message encoding ``cdr``; metadata ``offered_qos_profiles`` as YAML and ``topic_type_hash``),
messages with log and publish times in ns, chunks (compressed with zstd, lz4 or not at all)
written to the file as soon as they fill, a ``rosbag2`` metadata record whose
``serialized_metadata`` is the YAML of ``metadata.yaml``, and the summary with statistics.
:meth:`BagWriter.close` writes the summary and ``metadata.yaml``; call it from a ``finally`` (or
a SIGINT handler) and an interrupted run leaves a complete recording.

A full disk (or a file-size or quota limit) does not cost the recording: the write that failed
is cut off at the last complete record, the bag stops taking messages (:attr:`BagWriter.failure`
says why, :attr:`BagWriter.dropped` counts what was refused), and :meth:`BagWriter.close` ends
the file after its last complete chunk as a finished writer would (a metadata record,
DataEnd, a summary rebuilt from the file's own records, the footer:
:mod:`.mcap_end`), using the room of a reserve file the writer holds from the start.
``metadata.yaml`` then counts the messages kept and says in ``custom_data.recording_stopped``
why the recording ended early.

:func:`read_bag` reads our bags and those of other tools with the same layout: a folder with
``metadata.yaml`` and MCAP or SQLite3 (``.db3``) storage, or a bare ``.mcap`` file.
"""

from __future__ import annotations

import errno
import io
import os
import sqlite3
from collections import Counter
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import lz4.frame
import yaml
import zstandard
from mcap.records import Channel, Chunk, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import CompressionType, Writer

from squeeze_grasp_ros.inputs import InputError, load_yaml, read_text
from squeeze_grasp_ros.ros.recording.mcap_end import DataSection, file_end, read_data_section
from squeeze_grasp_ros.ros.recording.schema import message_definition, type_hash

METADATA_VERSION = 9
COMPRESSION = {
    "zstd": CompressionType.ZSTD,
    "lz4": CompressionType.LZ4,
    "none": CompressionType.NONE,
}
INFINITE = {"sec": 9223372036, "nsec": 854775807}
"""rosbag2's rendering of an unset (infinite) QoS duration."""
SPACE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})
"""Write errors that mean 'no more room' (disk full, quota, file-size limit)."""
RESERVE_BYTES = 256 * 1024
"""Room a bag holds from its start for the end of its file and metadata.yaml after a full disk
(both hold the bag information, about 15 kB for a run's 40 topics)."""
RESERVE_NAME = ".space_reserve"
STOPPED_KEY = "recording_stopped"
"""``custom_data`` key of ``metadata.yaml`` saying why a recording ended early."""
LOST_KEY = "messages_lost"
"""``custom_data`` key of ``metadata.yaml`` listing, as a YAML mapping of topic to count, the
messages its recorder never received that the middleware reported lost (absent: none)."""
INCOMPATIBLE_KEY = "incompatible_publishers"
"""``custom_data`` key of ``metadata.yaml`` listing, as a YAML mapping of topic to QoS policy,
the topics that had a publisher whose QoS the recorder's reader could not take (the middleware
never matches them: nothing of that publisher was recorded; absent: none)."""
MAX_CHUNK_BYTES = 64 * 2**20
"""Largest chunk a reader decompresses (ours are 256 KiB, rosbag2's 768 KiB); checked on the
chunk's declared size before decompressing, and on what decompression yields."""
MAX_EXPANSION = 64
"""A file's chunks may decompress to at most this many times its size, plus one
:data:`MAX_CHUNK_BYTES` (a run's bag: 6.5 times)."""


class _PlainDumper(yaml.SafeDumper):
    """YAML without anchors and aliases (rosbag2's parser expects plain mappings)."""

    def ignore_aliases(self, data) -> bool:
        return True


def plain_yaml(data) -> str:
    """YAML text of ``data`` without anchors and aliases (rcl and rosbag2 refuse them)."""
    return yaml.dump(data, Dumper=_PlainDumper, sort_keys=False)


class BagError(ValueError):
    """A path is not a readable bag."""


def qos_dict(history: str, depth: int, reliability: str, durability: str) -> dict:
    """One offered QoS profile as rosbag2 v9 writes it (names lower case, durations infinite)."""
    return {
        "history": history,
        "depth": int(depth),
        "reliability": reliability,
        "durability": durability,
        "deadline": dict(INFINITE),
        "lifespan": dict(INFINITE),
        "liveliness": "automatic",
        "liveliness_lease_duration": dict(INFINITE),
        "avoid_ros_namespace_conventions": False,
    }


class _Direct(io.IOBase):
    """A write-through file for the MCAP writer: every record goes to the OS at once.

    ``boundaries`` holds the file offsets at which complete writes ended; a write that fails is
    cut back to the last of them, so the file always ends on a record boundary.
    """

    def __init__(self, path: Path) -> None:
        self._file = open(path, "wb", buffering=0)  # noqa: SIM115 - closed by close()
        self.boundaries = [0]

    def write(self, data: bytes) -> int:
        view = memoryview(data)
        try:
            while view:
                view = view[self._file.write(view) :]
        except OSError:
            self.cut(self.boundaries[-1])
            raise
        self.boundaries.append(self._file.tell())
        return len(data)

    def cut(self, offset: int) -> None:
        """Truncate the file to ``offset`` and continue writing there."""
        self._file.truncate(offset)
        self._file.seek(offset)
        while self.boundaries[-1] > offset:
            self.boundaries.pop()

    def tell(self) -> int:
        return self._file.tell()

    def close(self) -> None:
        self._file.close()
        super().close()


@dataclass
class _Topic:
    name: str
    type: str
    channel: int
    qos: list
    count: int = 0


class BagWriter:
    """Write a rosbag2 bag (MCAP storage) from serialized messages.

    Parameters
    ----------
    path : path-like
        Bag folder to create (must not exist or be empty).
    compression : {"zstd", "lz4", "none"}
        Chunk compression.
    chunk_size : int
        Uncompressed chunk size, bytes, at which a chunk is written out.
    custom_data : mapping of str to str
        Stored in ``metadata.yaml`` ``custom_data`` (e.g. the scene and node parameters).
    """

    def __init__(
        self,
        path: str | Path,
        compression: str = "zstd",
        chunk_size: int = 256 * 1024,
        custom_data: Mapping[str, str] | None = None,
    ) -> None:
        self.path = Path(path)
        if self.path.exists() and any(self.path.iterdir()):
            raise BagError(f"{self.path} exists and is not empty")
        if compression not in COMPRESSION:
            raise BagError(
                f"compression must be one of {sorted(COMPRESSION)}, got {compression!r}"
            )
        created = not self.path.exists()
        self.file_name = f"{self.path.name}_0.mcap"
        try:
            self.path.mkdir(parents=True, exist_ok=True)
            fd = os.open(self.path / RESERVE_NAME, os.O_WRONLY | os.O_CREAT, 0o644)
            try:
                os.posix_fallocate(fd, 0, RESERVE_BYTES)
            finally:
                os.close(fd)
            self._stream = _Direct(self.path / self.file_name)
            self._writer = Writer(
                self._stream,
                chunk_size=chunk_size,
                compression=COMPRESSION[compression],
                enable_data_crcs=True,
            )
            self._writer.start(profile="ros2", library="squeeze_grasp_ros")
        except OSError as exc:
            for leftover in (self.path / RESERVE_NAME, self.path / self.file_name):
                leftover.unlink(missing_ok=True)  # not even a 0-byte reserve stays behind
            if created and self.path.is_dir():
                self.path.rmdir()
            raise BagError(f"cannot start a recording in {self.path}: {exc.strerror}") from None
        self._schemas: dict[str, int] = {}
        self.topics: dict[str, _Topic] = {}
        self.custom_data = dict(custom_data or {})
        self.start_ns: int | None = None
        self.end_ns: int | None = None
        self.closed = False
        self.failure: str | None = None
        """Why the bag stopped taking messages (a write failed for lack of room), or None."""
        self.dropped = 0
        """Messages given to :meth:`write` that are not in the file (after a failure)."""
        self.stopped: str | None = None
        """After :meth:`close`: why the recording stopped early and how many messages it lost
        (what ``metadata.yaml`` says under ``custom_data.recording_stopped``), or None."""

    def add_topic(self, name: str, type_name: str, offered_qos: Sequence[dict] = ()) -> None:
        """Declare topic ``name`` of type ``type_name`` ('pkg/msg/Type') with its offered QoS."""
        if name in self.topics:
            return
        qos = list(offered_qos)
        try:
            if type_name not in self._schemas:
                self._schemas[type_name] = self._writer.register_schema(
                    type_name, "ros2msg", message_definition(type_name).encode()
                )
            channel = self._writer.register_channel(
                name,
                "cdr",
                self._schemas[type_name],
                {
                    "offered_qos_profiles": plain_yaml(qos) if qos else "",
                    "topic_type_hash": type_hash(type_name),
                },
            )
        except OSError as exc:
            self._fail(exc)
            channel = -1
        self.topics[name] = _Topic(name, type_name, channel, qos)

    def write(
        self, topic: str, data: bytes, log_time_ns: int, publish_time_ns: int | None = None
    ) -> None:
        """Append one serialized (CDR) message of a declared topic (dropped, and counted in
        :attr:`dropped`, once a write has failed for lack of room).
        """
        t = self.topics[topic]
        if self.failure is not None:
            self.dropped += 1
            return
        try:
            self._writer.add_message(
                t.channel,
                log_time_ns,
                bytes(data),
                log_time_ns if publish_time_ns is None else publish_time_ns,
                sequence=t.count,
            )
        except OSError as exc:
            self._fail(exc)
            self.dropped += 1
            return
        t.count += 1
        self.start_ns = log_time_ns if self.start_ns is None else min(self.start_ns, log_time_ns)
        self.end_ns = log_time_ns if self.end_ns is None else max(self.end_ns, log_time_ns)

    def metadata(self) -> dict:
        """The ``rosbag2_bagfile_information`` mapping of the bag so far."""
        start = self.start_ns or 0
        duration = (self.end_ns or 0) - start
        count = sum(t.count for t in self.topics.values())
        return {
            "version": METADATA_VERSION,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": count,
            "topics_with_message_count": [
                {
                    "topic_metadata": {
                        "name": t.name,
                        "type": t.type,
                        "serialization_format": "cdr",
                        "offered_qos_profiles": t.qos,
                        "type_description_hash": type_hash(t.type),
                    },
                    "message_count": t.count,
                }
                for t in self.topics.values()
            ],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [self.file_name],
            "files": [
                {
                    "path": self.file_name,
                    "starting_time": {"nanoseconds_since_epoch": start},
                    "duration": {"nanoseconds": duration},
                    "message_count": count,
                }
            ],
            "custom_data": dict(self.custom_data),
            "ros_distro": "jazzy",
        }

    def _fail(self, exc: OSError) -> None:
        """Stop taking messages after a write failed (for lack of room: anything else raises)."""
        if exc.errno not in SPACE_ERRORS:
            raise exc
        self.failure = f"{exc.strerror} (errno {errno.errorcode.get(exc.errno, exc.errno)})"

    def close(self) -> None:
        """Write the rosbag2 metadata record, the MCAP summary and ``metadata.yaml``
        (idempotent); after a failed write, end the file after its last complete record.
        """
        if self.closed:
            return
        self.closed = True
        (self.path / RESERVE_NAME).unlink(missing_ok=True)
        if self.failure is None:
            info = self.metadata()
            try:
                self._writer.add_metadata("rosbag2", {"serialized_metadata": plain_yaml(info)})
                self._writer.finish()
            except OSError as exc:
                self._fail(exc)
        if self.failure is not None:
            info = self._end_after_failure()
        self._stream.close()
        text = plain_yaml({"rosbag2_bagfile_information": info})
        tmp = self.path / "metadata.yaml.tmp"
        tmp.write_text(text)
        tmp.replace(self.path / "metadata.yaml")

    def _end_after_failure(self) -> dict:
        """End the file after the last complete record that leaves room for its end (DataEnd,
        a rebuilt summary, the footer): the kept messages are counted from the file itself;
        returns the bag information of what is kept.
        """
        written = sum(t.count for t in self.topics.values())
        while len(self._stream.boundaries) > 1:
            section = self._count_kept(self._stream.boundaries[-1])
            lost = written + self.dropped - sum(t.count for t in self.topics.values())
            self.stopped = f"{self.failure}; the last {lost} messages were not recorded"
            self.custom_data[STOPPED_KEY] = self.stopped
            info = self.metadata()
            tail = b""
            for record in (Metadata("rosbag2", {"serialized_metadata": plain_yaml(info)}), None):
                tail = file_end(section, record)
                try:
                    self._stream.write(tail)
                    return info
                except OSError:
                    continue
            # no room for the end: give up at least as many bytes of data as it needs
            earlier = [b for b in self._stream.boundaries if b <= section.end - len(tail)]
            self._stream.cut(earlier[-1] if len(earlier) > 1 else 0)
        raise BagError(f"{self.path / self.file_name}: no room even for the end of the file")

    def _count_kept(self, end: int) -> DataSection:
        """Index the first ``end`` bytes of the file and cut it where the indexed data ends;
        set every topic's count, and the time range, to the messages kept.
        """
        with open(self.path / self.file_name, "rb") as f:
            section = read_data_section(f, end)
        self._stream.cut(section.end)
        for t in self.topics.values():
            t.count = section.counts.get(t.channel, 0)
        self.start_ns, self.end_ns = section.start_time, section.end_time
        return section


@dataclass(frozen=True)
class BagMessage:
    """One recorded message.

    Attributes
    ----------
    topic : str
    type : str
        'pkg/msg/Type'.
    log_time_ns : int
    data : bytes
        Serialized (CDR) message.
    """

    topic: str
    type: str
    log_time_ns: int
    data: bytes


@dataclass(frozen=True)
class BagContents:
    """Everything :func:`read_bag` found.

    Attributes
    ----------
    messages : tuple of BagMessage
        In log-time order (ties in storage order).
    types : dict of str to str
        Topic -> type.
    custom_data : dict of str to str
    """

    messages: tuple[BagMessage, ...]
    types: dict[str, str]
    custom_data: dict[str, str]

    def counts(self) -> Counter:
        """Messages per topic."""
        return Counter(m.topic for m in self.messages)


def bag_info(path: str | Path) -> dict:
    """The ``rosbag2_bagfile_information`` of a bag folder or bare MCAP file ({} if it has none).

    Raises
    ------
    BagError
        If the path is no bag or its metadata is not rosbag2 metadata.
    """
    return _storage_files(Path(path))[1]


def _storage_files(path: Path) -> tuple[list[Path], dict]:
    """(storage files, metadata mapping or {}) of a bag folder or a bare storage file.

    Without ``metadata.yaml`` the metadata comes from the ``rosbag2`` record inside the MCAP
    file, which holds the same YAML.
    """
    if path.is_file():
        return [path], _embedded_info(path)
    meta_path = path / "metadata.yaml"
    if not meta_path.is_file():
        files = sorted(path.glob("*.mcap")) + sorted(path.glob("*.db3"))
        if not files:
            raise BagError(f"{path} has no metadata.yaml and no .mcap/.db3 file")
        return files, _embedded_info(files[0])
    try:
        data = load_yaml(read_text(meta_path, what="metadata.yaml"), what=str(meta_path))
        info = data["rosbag2_bagfile_information"]
        names = list(dict.fromkeys(info.get("relative_file_paths") or []))
    except (InputError, KeyError, TypeError, AttributeError) as exc:
        raise BagError(f"{meta_path} is not rosbag2 metadata: {exc}") from None
    files = []
    for name in names:
        file = (path / str(name)).resolve()
        if file.parent != path.resolve() or not file.is_file():
            raise BagError(f"{meta_path} lists {str(name)[:80]!r}, which is not a file of this "
                           "bag")
        files.append(file)
    return list(dict.fromkeys(files)), info  # 'X' and './X' are one file, read once


def _embedded_info(path: Path) -> dict:
    """The bag information of the ``rosbag2`` metadata record of an MCAP file ({} if none)."""
    if path.suffix != ".mcap":
        return {}
    try:
        with open(path, "rb") as f:  # top-level records only: no chunk is decompressed
            for record in StreamReader(f, emit_chunks=True,
                                       record_size_limit=MAX_CHUNK_BYTES).records:
                if isinstance(record, Metadata) and record.name == "rosbag2":
                    data = load_yaml(
                        record.metadata.get("serialized_metadata", ""),
                        what=f"{path} rosbag2 metadata",
                    )
                    return dict((data or {}).get("rosbag2_bagfile_information", data or {}))
    except Exception:  # noqa: BLE001 (unreadable: the messages' reader says why)
        return {}
    return {}


def _read_mcap(path: Path) -> Iterator[BagMessage]:
    """Every message of an MCAP file, with its chunk and data-section CRCs checked.

    Raises
    ------
    BagError
        A CRC does not match or a record cannot be parsed: the file is corrupt.
    """
    schemas: dict[int, str] = {}
    topics: dict[int, tuple[str, str]] = {}
    out: list[BagMessage] = []
    budget = [MAX_EXPANSION * path.stat().st_size + MAX_CHUNK_BYTES]
    try:
        with open(path, "rb") as f:
            reader = StreamReader(f, validate_crcs=True, emit_chunks=True,
                                  record_size_limit=MAX_CHUNK_BYTES)
            for outer in reader.records:
                inner = _chunk_records(outer, budget) if isinstance(outer, Chunk) else [outer]
                for record in inner:
                    if isinstance(record, Schema):
                        schemas[record.id] = record.name
                    elif isinstance(record, Channel):
                        topics[record.id] = (record.topic, schemas.get(record.schema_id, ""))
                    elif isinstance(record, Message):
                        topic, type_name = topics[record.channel_id]
                        out.append(BagMessage(topic, type_name, record.log_time,
                                              bytes(record.data)))
    except BagError:
        raise
    except Exception as exc:  # noqa: BLE001 (any failure to parse these bytes means corruption)
        raise BagError(f"{path} is corrupt ({_damage(exc, path.stat().st_size)}); it cannot be "
                       "trusted, not even in part") from None
    out.sort(key=lambda m: m.log_time_ns)
    yield from out


def _damage(exc: Exception, size: int) -> str:
    """What the MCAP reader's ``exc`` says of a file of ``size`` bytes; the reader's EndOfFile
    says nothing, so the file's end is named (a recorder killed before it closed the file, or a
    copy cut short).

    >>> _damage(EOFError(), 0)
    'EOFError: the file is empty'
    >>> _damage(EOFError(), 1234)
    'EOFError: the file ends inside a record, at byte 1234'
    >>> _damage(ValueError("bad opcode"), 10)
    'ValueError: bad opcode'
    """
    detail = str(exc) or ("the file is empty" if size == 0 else
                          f"the file ends inside a record, at byte {size}")
    return f"{type(exc).__name__}: {detail}"


def _chunk_records(chunk: Chunk, budget: list[int]) -> list:
    """The records of ``chunk``, decompressed only if its declared size fits the limits
    (:data:`MAX_CHUNK_BYTES`, and what is left of ``budget[0]``, which it uses up), and never to
    more than that size (a decompression bomb is refused, not expanded).

    Raises
    ------
    BagError
        The chunk is, or decompresses to, more than it may.
    """
    size = chunk.uncompressed_size
    if size > MAX_CHUNK_BYTES or size > budget[0]:
        raise BagError(
            f"a chunk declares {size:,} bytes uncompressed, more than a reader takes "
            f"({min(MAX_CHUNK_BYTES, budget[0]):,} bytes: at most {MAX_CHUNK_BYTES // 2**20} MiB "
            f"a chunk and {MAX_EXPANSION} times the file's size in all); refused before "
            "decompressing")
    budget[0] -= size
    if chunk.compression == "zstd":
        data = zstandard.ZstdDecompressor().decompress(chunk.data, max_output_size=size)
    elif chunk.compression == "lz4":
        data = lz4.frame.LZ4FrameDecompressor().decompress(chunk.data, max_length=size + 1)
    else:
        data = chunk.data
    if len(data) != size:
        raise BagError(f"a chunk decompresses to {'more' if len(data) > size else 'fewer'} "
                       f"bytes than the {size:,} it declares")
    return breakup_chunk(Chunk(compression="", data=data,
                               message_end_time=chunk.message_end_time,
                               message_start_time=chunk.message_start_time,
                               uncompressed_crc=chunk.uncompressed_crc, uncompressed_size=size),
                         validate_crc=True)


def _read_sqlite(path: Path) -> Iterator[BagMessage]:
    """Every message of a rosbag2 SQLite3 file, in time order. The file is opened read-only
    by its own URI (percent-encoded, so '#', '?' and '%' in its path are its characters).

    Raises
    ------
    BagError
        Not an SQLite3 database, or without rosbag2's tables, or a message row without data
        or an integer timestamp.
    """
    out: list[BagMessage] = []
    try:
        db = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
        try:
            rows = db.execute(
                "SELECT topics.name, topics.type, messages.timestamp, messages.data "
                "FROM messages JOIN topics ON messages.topic_id = topics.id "
                "ORDER BY messages.timestamp, messages.id"
            )
            for name, type_name, timestamp, data in rows:
                if not isinstance(data, bytes):
                    raise TypeError("a message without data")
                if not isinstance(timestamp, int):
                    raise TypeError(f"a message timestamp {str(timestamp)[:40]!r} is not an "
                                    "integer")
                out.append(BagMessage(str(name), str(type_name), timestamp, data))
        finally:
            db.close()
    except (sqlite3.Error, TypeError) as exc:
        raise BagError(f"{path} is not a readable rosbag2 SQLite3 file "
                       f"({type(exc).__name__}: {exc})") from None
    yield from out


def read_bag(path: str | Path, topics: Sequence[str] | None = None) -> BagContents:
    """Read a rosbag2 bag (MCAP or SQLite3 storage) or a bare ``.mcap`` file.

    Parameters
    ----------
    path : path-like
    topics : sequence of str, optional
        Only these topics.

    Raises
    ------
    BagError
        If ``path`` is not a bag.
    """
    path = Path(path)
    if not path.exists():
        raise BagError(f"no bag at {path}")
    files, info = _storage_files(path)
    wanted = set(topics) if topics is not None else None
    messages: list[BagMessage] = []
    for file in files:
        reader = _read_sqlite if file.suffix == ".db3" else _read_mcap
        messages += [m for m in reader(file) if wanted is None or m.topic in wanted]
    messages.sort(key=lambda m: m.log_time_ns)
    types = {m.topic: m.type for m in messages}
    for entry in info.get("topics_with_message_count", []):
        meta = entry["topic_metadata"]
        types.setdefault(meta["name"], meta["type"])
    return BagContents(tuple(messages), types, dict(info.get("custom_data") or {}))
