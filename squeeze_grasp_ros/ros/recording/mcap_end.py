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

from mcap.data_stream import ReadDataStream, RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (Channel, Chunk, ChunkIndex, DataEnd, Footer, Message, MessageIndex,
                          Metadata, MetadataIndex, Schema, Statistics, SummaryOffset)
from mcap.stream_reader import breakup_chunk
from mcap.writer import MCAP0_MAGIC

__all__ = ["DataSection", "file_end", "read_data_section"]

_RECORD_HEAD = struct.Struct("<BQ")


@dataclass
class DataSection:
    """What the data section of a file holds, for its summary.

    Attributes
    ----------
    schemas, channels : dict
        Records by id, in the order first seen.
    chunk_indexes : list of ChunkIndex
    metadata_indexes : list of MetadataIndex
    counts : Counter
        Messages per channel id.
    start, end : int or None
        Smallest and largest message log time, ns.
    """

    schemas: dict = field(default_factory=dict)
    channels: dict = field(default_factory=dict)
    chunk_indexes: list = field(default_factory=list)
    metadata_indexes: list = field(default_factory=list)
    counts: Counter = field(default_factory=Counter)
    start: int | None = None
    end: int | None = None

    def _message(self, message: Message) -> None:
        self.counts[message.channel_id] += 1
        t = message.log_time
        self.start = t if self.start is None else min(self.start, t)
        self.end = t if self.end is None else max(self.end, t)


def read_data_section(data: bytes) -> DataSection:
    """Index the records of ``data``: an MCAP file's bytes from its magic up to a record
    boundary (no DataEnd, summary or footer).
    """
    section = DataSection()
    chunk_index: ChunkIndex | None = None
    pos = len(MCAP0_MAGIC)
    while pos + _RECORD_HEAD.size <= len(data):
        opcode, length = _RECORD_HEAD.unpack_from(data, pos)
        body = ReadDataStream(io.BytesIO(data[pos + _RECORD_HEAD.size:
                                              pos + _RECORD_HEAD.size + length]))
        size = _RECORD_HEAD.size + length
        if opcode != Opcode.MESSAGE_INDEX:
            chunk_index = None
        if opcode == Opcode.CHUNK:
            chunk = Chunk.read(body)
            chunk_index = ChunkIndex(chunk_length=size, chunk_start_offset=pos,
                                     compression=chunk.compression,
                                     compressed_size=len(chunk.data),
                                     message_end_time=chunk.message_end_time,
                                     message_index_length=0, message_index_offsets={},
                                     message_start_time=chunk.message_start_time,
                                     uncompressed_size=chunk.uncompressed_size)
            section.chunk_indexes.append(chunk_index)
            for record in breakup_chunk(chunk):
                _collect(section, record)
        elif opcode == Opcode.MESSAGE_INDEX and section.chunk_indexes:
            index = section.chunk_indexes[-1]
            index.message_index_offsets[MessageIndex.read(body).channel_id] = pos
            index.message_index_length += size
        elif opcode == Opcode.METADATA:
            section.metadata_indexes.append(MetadataIndex(offset=pos, length=size,
                                                          name=Metadata.read(body).name))
        elif opcode == Opcode.SCHEMA:
            _collect(section, Schema.read(body))
        elif opcode == Opcode.CHANNEL:
            _collect(section, Channel.read(body))
        elif opcode == Opcode.MESSAGE:
            section._message(Message.read(body, length))
        pos += size
    return section


def _collect(section: DataSection, record) -> None:
    if isinstance(record, Schema):
        section.schemas.setdefault(record.id, record)
    elif isinstance(record, Channel):
        section.channels.setdefault(record.id, record)
    elif isinstance(record, Message):
        section._message(record)


def file_end(section: DataSection, offset: int, metadata: Metadata | None = None) -> bytes:
    """The bytes that end a file whose data section (indexed in ``section``) ends at byte
    ``offset``: ``metadata`` (if given), DataEnd, the summary section, the footer and the magic.
    Data-section and summary CRCs are 0 (not computed), as the format allows.
    """
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
        message_count=sum(section.counts.values()), message_end_time=section.end or 0,
        message_start_time=section.start or 0, metadata_count=len(metadata_indexes),
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
