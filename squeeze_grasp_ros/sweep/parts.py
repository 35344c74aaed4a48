# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A sweep's Parquet parts and what vouches for them.

Every part carries, in its Parquet key-value metadata, the id of its task, the hash of its
sweep's spec and a SHA-256 checksum of its rows (their canonical JSON: every column, in order,
as Arrow decodes them). :func:`read_part` accepts a part only if it is a regular file of at most
:data:`MAX_PART_BYTES`, decodes as Parquet with the dataset's schema, names the task its file
name names and the sweep it lies in, and its rows match the checksum and that task. So an empty
or truncated part, a part copied over another's name, a part of another sweep, a folder named
like a part and a part edited in place are each told apart from a good one (:class:`BadPart`
says which) instead of being read as data.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from squeeze_grasp_ros.inputs import InputError, read_bytes
from squeeze_grasp_ros.sweep.evaluate import COLUMNS

ARROW_TYPES = {
    "string": pa.string(),
    "int32": pa.int32(),
    "float64": pa.float64(),
    "bool": pa.bool_(),
}
SCHEMA = pa.schema([(name, ARROW_TYPES[kind]) for name, kind in COLUMNS.items()])
"""Arrow schema of every part."""

MAX_PART_BYTES = 256 * 1024 * 1024
"""Largest part read (a task has at most 100,000 evaluations, about 60 MB of Parquet)."""

TASK_KEY, SPEC_KEY, CHECKSUM_KEY = (b"squeeze_grasp.task_id", b"squeeze_grasp.spec_hash",
                                    b"squeeze_grasp.rows_sha256")


class BadPart(Exception):
    """A part that cannot be trusted; the message says why (no file contents)."""


def rows_checksum(table: pa.Table) -> str:
    """SHA-256 of the rows of ``table`` as canonical JSON (floats exactly, by ``repr``)."""
    text = json.dumps(table.to_pylist(), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def part_table(rows: list[dict], task_id: str, spec_hash: str) -> pa.Table:
    """The Arrow table of a task's rows, with the metadata :func:`read_part` checks."""
    table = pa.Table.from_pylist(rows, schema=SCHEMA)
    meta = {TASK_KEY: task_id.encode(), SPEC_KEY: spec_hash.encode(),
            CHECKSUM_KEY: rows_checksum(table).encode()}
    return table.replace_schema_metadata(meta)


def write_part(path: Path, table: pa.Table) -> None:
    """Write a part made by :func:`part_table` (Parquet with page checksums)."""
    pq.write_table(table, path, write_page_checksum=True)


def read_part(path: str | Path, task_id: str, spec_hash: str) -> pa.Table:
    """The rows of task ``task_id``'s part of the sweep ``spec_hash``, verified.

    Raises
    ------
    BadPart
        The file is not a regular file, too large, not a part of this schema, carries another
        task's id or another sweep's hash, or its rows do not match its checksum or its task.
    """
    try:
        data = read_bytes(path, what="part", max_bytes=MAX_PART_BYTES)
    except InputError as exc:
        raise BadPart(str(exc).replace(f": {path}", "")) from None
    try:
        table = pq.read_table(pa.BufferReader(data), page_checksum_verification=True)
    except (pa.ArrowException, OSError, ValueError) as exc:
        raise BadPart(f"not a readable Parquet file ({type(exc).__name__})") from None
    meta = table.schema.metadata or {}
    if not all(key in meta for key in (TASK_KEY, SPEC_KEY, CHECKSUM_KEY)):
        raise BadPart("carries no task id, spec hash and checksum (not written by this sweep)")
    found = meta[TASK_KEY].decode(errors="replace")
    if found != task_id:
        raise BadPart(f"holds the rows of task {found[:80]!r}, not of {task_id!r}")
    other = meta[SPEC_KEY].decode(errors="replace")
    if other != spec_hash:
        raise BadPart(f"belongs to another sweep (spec hash {other[:12]}, this sweep "
                      f"{spec_hash[:12]})")
    table = table.replace_schema_metadata(None)
    if table.schema != SCHEMA:
        raise BadPart("has columns other than the dataset's")
    if rows_checksum(table) != meta[CHECKSUM_KEY].decode(errors="replace"):
        raise BadPart("rows do not match its checksum (changed or damaged)")
    if set(table.column("task_id").to_pylist()) - {task_id}:
        raise BadPart("has rows of another task")
    return table
