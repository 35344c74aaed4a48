# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The end of an MCAP file whose writer stopped after a complete record (a full disk): the
records the file holds are indexed again, so that the file ends as a finished writer would end
it — DataEnd, the summary section (schemas, channels, statistics, chunk and metadata indexes,
summary offsets) and the footer — and every reader, also those that need an index, reads it.

Only the ``mcap`` library's record classes are used; the file's data section is read, never
changed.
"""

from __future__ import annotations

import io
import struct
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, BinaryIO

from mcap.data_stream import ReadDataStream, RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Footer,
    Message,
    MessageIndex,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)
from mcap.stream_reader import breakup_chunk
from mcap.writer import MCAP0_MAGIC

__all__ = ["DataSection", "file_end", "read_data_section"]

_RECORD_HEAD = struct.Struct("<BQ")


@dataclass
class DataSection:
    """What the data section of a file holds, for its summary.

    Attributes
    ----------
    end : int
        Offset of the first byte not indexed: the data section ends here (a chunk whose message
        indexes are missing is left out, since readers that go by the index would skip it).
    schemas, channels : dict
        Records by id, in the order first seen.
    chunk_indexes : list of ChunkIndex
    metadata_indexes : list of MetadataIndex
    counts : Counter
        Messages per channel id.
    start_time, end_time : int or None
        Smallest and largest message log time, ns.
    """

    end: int = len(MCAP0_MAGIC)
    schemas: dict[int, Any] = field(default_factory=dict)
    channels: dict[int, Any] = field(default_factory=dict)
    chunk_indexes: list = field(default_factory=list)
    metadata_indexes: list = field(default_factory=list)
    counts: Counter = field(default_factory=Counter)
    start_time: int | None = None
    end_time: int | None = None

    def _add(self, record) -> None:
        if isinstance(record, Schema):
            self.schemas.setdefault(record.id, record)
        elif isinstance(record, Channel):
            self.channels.setdefault(record.id, record)
        elif isinstance(record, Message):
            self.counts[record.channel_id] += 1
            t = record.log_time
            self.start_time = t if self.start_time is None else min(self.start_time, t)
            self.end_time = t if self.end_time is None else max(self.end_time, t)


def read_data_section(stream: BinaryIO, size: int) -> DataSection:
    """Index the records of the first ``size`` bytes of an MCAP file open in ``stream``: its
    magic and whole records (no DataEnd, summary or footer), read one record at a time. A chunk
    counts once its message indexes follow it.
    """
    section = DataSection()
    chunk: tuple[ChunkIndex, Chunk] | None = None
    pos = len(MCAP0_MAGIC)
    stream.seek(pos)
    while pos + _RECORD_HEAD.size <= size:
        opcode, length = _RECORD_HEAD.unpack(stream.read(_RECORD_HEAD.size))
        record_size = _RECORD_HEAD.size + length
        if pos + record_size > size:
            break
        body = ReadDataStream(io.BytesIO(stream.read(length)))
        if opcode == Opcode.MESSAGE_INDEX and chunk is not None:
            index, records = chunk
            if not index.message_index_offsets:
                section.chunk_indexes.append(index)
                for record in breakup_chunk(records):
                    section._add(record)
            index.message_index_offsets[MessageIndex.read(body).channel_id] = pos
            index.message_index_length += record_size
        else:
            chunk = None
        if opcode == Opcode.CHUNK:
            records = Chunk.read(body)
            chunk = (ChunkIndex(chunk_length=record_size, chunk_start_offset=pos,
                                compression=records.compression,
                                compressed_size=len(records.data),
                                message_end_time=records.message_end_time,
                                message_index_length=0, message_index_offsets={},
                                message_start_time=records.message_start_time,
                                uncompressed_size=records.uncompressed_size), records)
        elif opcode == Opcode.METADATA:
            section.metadata_indexes.append(MetadataIndex(offset=pos, length=record_size,
                                                          name=Metadata.read(body).name))
        elif opcode == Opcode.SCHEMA:
            section._add(Schema.read(body))
        elif opcode == Opcode.CHANNEL:
            section._add(Channel.read(body))
        elif opcode == Opcode.MESSAGE:
            section._add(Message.read(body, length))
        pos += record_size
        if chunk is None or chunk[0].message_index_offsets:
            section.end = pos
    return section


def file_end(section: DataSection, metadata: Metadata | None = None) -> bytes:
    """The bytes that end a file at ``section.end``, after the data section it indexes:
    ``metadata`` (if given), DataEnd, the summary section, the footer and the magic.
    Data-section and summary CRCs are 0 (not computed), as the format allows.
    """
    offset = section.end
    data = RecordBuilder()
    metadata_indexes = list(section.metadata_indexes)
    if metadata is not None:
        metadata.write(data)
        metadata_indexes.append(MetadataIndex(offset=offset, length=data.count,
                                              name=metadata.name))
    DataEnd(0).write(data)
    summary_start = offset + data.count
    summary = RecordBuilder()
    offsets = []
    statistics = Statistics(
        attachment_count=0, channel_count=len(section.channels),
        channel_message_counts=dict(section.counts), chunk_count=len(section.chunk_indexes),
        message_count=sum(section.counts.values()), message_end_time=section.end_time or 0,
        message_start_time=section.start_time or 0, metadata_count=len(metadata_indexes),
        schema_count=len(section.schemas))
    for opcode, records in ((Opcode.SCHEMA, section.schemas.values()),
                            (Opcode.CHANNEL, section.channels.values()),
                            (Opcode.STATISTICS, [statistics]),
                            (Opcode.CHUNK_INDEX, section.chunk_indexes),
                            (Opcode.METADATA_INDEX, metadata_indexes)):
        start = summary.count
        for record in records:
            record.write(summary)
        offsets.append(SummaryOffset(group_opcode=opcode, group_start=summary_start + start,
                                     group_length=summary.count - start))
    summary_offset_start = summary_start + summary.count
    for record in offsets:
        record.write(summary)
    Footer(summary_start=summary_start, summary_offset_start=summary_offset_start,
           summary_crc=0).write(summary)
    return data.end() + summary.end() + MCAP0_MAGIC
