# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Sweep output directory: one Parquet part per finished task plus a manifest.

Layout::

    DIR/manifest.json           spec, spec hash, package version, per-task status
    DIR/parts/<task id>.parquet one file per finished task (rows sorted by eval_id)
    DIR/outlines/<object id>.json  the object's meshed outer boundary, m (for pictures)

Parts are written to a temporary file in ``parts/``, flushed to disk and renamed into place,
so a part either exists complete or not at all, whatever kills the process. A part's existence
is what marks its task done; the manifest (also replaced atomically) repeats the status for
people and tools, and records failed tasks with their error. Re-running the same spec into the
same directory therefore skips exactly the finished tasks.
"""

from __future__ import annotations

import json
import os
import time
from importlib import metadata
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from squeeze_grasp_ros.sweep.evaluate import COLUMNS
from squeeze_grasp_ros.sweep.plan import Task
from squeeze_grasp_ros.sweep.spec import LoadedSpec, SweepError

ARROW_TYPES = {
    "string": pa.string(),
    "int32": pa.int32(),
    "float64": pa.float64(),
    "bool": pa.bool_(),
}
SCHEMA = pa.schema([(name, ARROW_TYPES[kind]) for name, kind in COLUMNS.items()])
"""Arrow schema of every part."""
MANIFEST_FORMAT = 1


def package_version() -> str:
    """Installed version of squeeze_grasp_ros."""
    try:
        return metadata.version("squeeze_grasp_ros")
    except metadata.PackageNotFoundError:
        from squeeze_grasp_ros import __version__

        return __version__


def _atomic_write(path: Path, write) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    write(tmp)
    with open(tmp, "rb") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, path)


class Store:
    """The output directory of one sweep spec."""

    def __init__(self, out: str | Path, loaded: LoadedSpec, tasks: list[Task]) -> None:
        self.out = Path(out)
        self.parts = self.out / "parts"
        self.loaded = loaded
        self.tasks = {t.id: t for t in tasks}
        manifest = self.out / "manifest.json"
        self.errors: dict[str, str] = {}
        if manifest.exists():
            try:
                old = json.loads(manifest.read_text())
            except ValueError as exc:
                raise SweepError(
                    f"{manifest}: unreadable manifest ({exc}); use another --out"
                ) from None
            if old.get("spec_hash") != loaded.hash:
                raise SweepError(
                    f"{self.out} holds a sweep of another spec (hash "
                    f"{str(old.get('spec_hash'))[:12]}, this spec {loaded.hash[:12]}; "
                    "a referenced file may have changed): give another --out or "
                    "delete it"
                )
        elif self.out.exists() and any(self.out.iterdir()):
            raise SweepError(
                f"--out {self.out} exists, is not empty and has no manifest.json: "
                "give a new or empty directory"
            )
        self.parts.mkdir(parents=True, exist_ok=True)
        for stale in self.parts.glob(".*.tmp"):
            stale.unlink()
        unknown = sorted(p.stem for p in self.parts.glob("*.parquet") if p.stem not in self.tasks)
        if unknown:
            raise SweepError(f"{self.parts} has parts of no task of this spec ({unknown[0]}...)")
        self.created = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
        self.write_manifest()

    def part(self, task_id: str) -> Path:
        """Parquet file of a task."""
        return self.parts / f"{task_id}.parquet"

    def done(self, task_id: str) -> bool:
        """The task's part exists (it is complete: parts appear by rename)."""
        return self.part(task_id).exists()

    def write(self, task: Task, rows: list[dict], outline: list | None = None) -> int:
        """Write a task's rows (and its object's outline, once) atomically and update the
        manifest; returns the row count.
        """
        if outline is not None:
            path = self.out / "outlines" / f"{task.obj.id}.json"
            if not path.exists():
                path.parent.mkdir(exist_ok=True)
                text = json.dumps({"object_id": task.obj.id, "outline": outline})
                _atomic_write(path, lambda p: p.write_text(text))
        table = pa.Table.from_pylist(rows, schema=SCHEMA)
        _atomic_write(self.part(task.id), lambda p: pq.write_table(table, p))
        self.errors.pop(task.id, None)
        self.write_manifest()
        return len(rows)

    def fail(self, task: Task, error: str) -> None:
        """Record a task that raised as a whole (it is redone by the next run)."""
        self.errors[task.id] = error
        self.write_manifest()

    def status(self) -> dict[str, str]:
        """Task id -> "done", "failed" or "pending"."""
        return {
            tid: "done" if self.done(tid) else "failed" if tid in self.errors else "pending"
            for tid in sorted(self.tasks)
        }

    def write_manifest(self) -> None:
        """Replace manifest.json atomically."""
        status = self.status()
        doc = {
            "format": MANIFEST_FORMAT,
            "name": self.loaded.spec.name,
            "spec": self.loaded.raw,
            "spec_hash": self.loaded.hash,
            "package_version": package_version(),
            "created": self.created,
            "updated": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            "counts": {
                k: sum(1 for v in status.values() if v == k) for k in ("done", "failed", "pending")
            },
            "tasks": {
                tid: (
                    {"status": s, "error": self.errors[tid]}
                    if s == "failed"
                    else {"status": s, "evaluations": self.tasks[tid].evaluations}
                )
                for tid, s in status.items()
            },
        }
        text = json.dumps(doc, indent=1, sort_keys=True, default=str)
        _atomic_write(self.out / "manifest.json", lambda p: p.write_text(text))


def read_dataset(out: str | Path) -> pa.Table:
    """Every finished row of a sweep directory, sorted by ``eval_id``."""
    parts = Path(out) / "parts"
    if not (Path(out) / "manifest.json").is_file():
        raise SweepError(f"{out} is not a sweep directory (no manifest.json)")
    files = sorted(parts.glob("*.parquet"))
    if not files:
        return SCHEMA.empty_table()
    table = pa.concat_tables([pq.read_table(f, schema=SCHEMA) for f in files])
    return table.sort_by("eval_id")


def read_outlines(out: str | Path) -> dict[str, list]:
    """Object id -> outer boundary loop [[x, y], ...], m, of the objects written so far."""
    return {
        p.stem: json.loads(p.read_text())["outline"]
        for p in sorted((Path(out) / "outlines").glob("*.json"))
    }


def read_manifest(out: str | Path) -> dict:
    """The manifest of a sweep directory."""
    path = Path(out) / "manifest.json"
    if not path.is_file():
        raise SweepError(f"{out} is not a sweep directory (no manifest.json)")
    return json.loads(path.read_text())
