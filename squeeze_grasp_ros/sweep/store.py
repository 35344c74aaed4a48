# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Sweep output directory: one Parquet part per finished task plus a manifest.

Layout::

    DIR/manifest.json           spec, spec hash, package version, per-task status
    DIR/parts/<task id>.parquet one file per finished task (rows sorted by eval_id)
    DIR/outlines/<object id>.json  the object's meshed outer boundary, m (for pictures)
    DIR/damaged/                parts a resume found bad, moved aside (never deleted)
    DIR/parts/.sweep.lock       locked by the sweep writing the folder (its process id inside)

Parts are written to a temporary file in ``parts/``, flushed to disk and renamed into place,
so a part either exists complete or not at all, whatever kills the process; a write that fails
(a full disk) removes its temporary file and ends the sweep with one line. A part vouches for
itself (task id, spec hash, row checksum: :mod:`.parts`), and what marks its task done is a part
that passes :func:`~.parts.read_part`: a resume moves every other one to ``damaged/`` and
redoes its task, and the report leaves it out with a line saying why. The manifest (also
replaced atomically) repeats the status for people and tools and records failed tasks with their
error; it is read only as a regular file of at most :data:`MAX_MANIFEST_BYTES` and must have the
manifest's structure. Re-running the same spec into the same directory therefore skips exactly
the finished, intact tasks. One sweep at a time writes a folder: the store holds a lock on
``parts/.sweep.lock`` from its opening until :meth:`Store.close` (or its process ends, however),
and a second sweep into the same folder is refused with the holder's process id, before it
touches anything (two writers would remove each other's temporary parts and interleave the
manifest). The lock is a POSIX record lock: it holds between processes of one machine, and
across machines only on a file system whose locks do (NFS with its lock service, not every
network file system).
"""

from __future__ import annotations

import fcntl
import json
import os
import time
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import pyarrow as pa

from squeeze_grasp_ros.inputs import InputError, read_bytes
from squeeze_grasp_ros.mechanics.errors import SqueezeGraspError
from squeeze_grasp_ros.outputs import output_error, write_atomically
from squeeze_grasp_ros.sweep.parts import SCHEMA, BadPart, part_table, read_part, write_part
from squeeze_grasp_ros.sweep.plan import Task
from squeeze_grasp_ros.sweep.spec import LoadedSpec, SweepError

MANIFEST_FORMAT = 1
MAX_MANIFEST_BYTES = 64 * 1024 * 1024
"""Largest manifest read (20,000 tasks and an 8 MiB spec take about 11 MB)."""
MAX_OUTLINE_BYTES = 16 * 1024 * 1024
"""Largest outline file read for pictures."""
STATUSES = ("done", "failed", "pending")
LOCK_NAME = ".sweep.lock"
"""The file in ``parts/`` a sweep writing the folder holds locked (its process id inside)."""


def package_version() -> str:
    """Installed version of squeeze_grasp_ros."""
    try:
        return metadata.version("squeeze_grasp_ros")
    except metadata.PackageNotFoundError:
        from squeeze_grasp_ros import __version__

        return __version__


def read_manifest(out: str | Path) -> dict:
    """The manifest of a sweep directory, checked: a regular file of at most
    :data:`MAX_MANIFEST_BYTES` holding a JSON object with a spec hash and a status per task.

    Raises
    ------
    SweepError
        One line: missing, not a regular file, too large, not JSON, or not a manifest.
    """
    path = Path(out) / "manifest.json"
    if not os.path.lexists(path):
        raise SweepError(f"{out} is not a sweep directory (no manifest.json)")
    try:
        text = read_bytes(path, what="manifest", max_bytes=MAX_MANIFEST_BYTES).decode("utf-8")
        doc = json.loads(text)
    except InputError as exc:
        raise SweepError(str(exc)) from None
    except UnicodeDecodeError as exc:
        raise SweepError(f"{path}: not a sweep manifest (not UTF-8 text at byte "
                         f"{exc.start})") from None
    except json.JSONDecodeError as exc:
        raise SweepError(f"{path}: not a sweep manifest (invalid JSON at line {exc.lineno}, "
                         f"column {exc.colno})") from None
    except RecursionError:
        raise SweepError(f"{path}: not a sweep manifest (nested too deeply)") from None
    problem = _manifest_problem(doc)
    if problem:
        raise SweepError(f"{path}: not a sweep manifest ({problem})")
    return doc


def _manifest_problem(doc) -> str | None:
    """What makes ``doc`` not a manifest, or None."""
    if not isinstance(doc, dict):
        return f"a JSON {type(doc).__name__}, not an object"
    for key, kind in (("spec_hash", str), ("tasks", dict), ("counts", dict),
                      ("package_version", str)):
        if not isinstance(doc.get(key), kind):
            return f"'{key}' is missing or not a {kind.__name__}"
    for tid, entry in doc["tasks"].items():
        if not (isinstance(entry, dict) and entry.get("status") in STATUSES):
            return f"task {tid[:80]!r} has no status among {list(STATUSES)}"
    return None


def _part_entries(parts: Path) -> dict[str, os.DirEntry]:
    """Task id -> directory entry of every ``*.parquet`` name in ``parts/`` (files, folders,
    FIFOs alike: :func:`~.parts.read_part` judges them).
    """
    if not parts.is_dir():
        return {}
    with os.scandir(parts) as it:
        return {e.name[:-len(".parquet")]: e for e in it
                if e.name.endswith(".parquet") and not e.name.startswith(".")}


@dataclass(frozen=True)
class Dataset:
    """The trustworthy rows of a sweep directory and what was left out.

    Attributes
    ----------
    table : pyarrow.Table
        Rows of every part that passed :func:`~.parts.read_part`, sorted by ``eval_id``.
    manifest : dict
        The checked manifest.
    counts : dict
        Tasks "done" (an intact part), "failed" (recorded failure, no part) and "pending".
    excluded : tuple of str
        One line per part left out and per task marked done without a part.
    """

    table: pa.Table
    manifest: dict
    counts: dict
    excluded: tuple[str, ...]


def load_dataset(out: str | Path) -> Dataset:
    """Every verified row of a sweep directory; bad, foreign or missing parts are listed, not
    read.
    """
    manifest = read_manifest(out)
    tasks, spec_hash = manifest["tasks"], manifest["spec_hash"]
    entries = _part_entries(Path(out) / "parts")
    tables, excluded, done = [], [], set()
    for tid, entry in sorted(entries.items()):
        if tid not in tasks:
            excluded.append(f"parts/{entry.name}: left out: belongs to no task of this sweep")
            continue
        try:
            tables.append(read_part(entry.path, tid, spec_hash))
            done.add(tid)
        except BadPart as exc:
            excluded.append(f"parts/{entry.name}: left out: {exc}")
    for tid, entry in sorted(tasks.items()):
        if entry["status"] == "done" and tid not in entries:
            excluded.append(f"task {tid}: marked done but its part is missing (re-run the "
                            "sweep to redo it)")
    failed = {t for t, e in tasks.items() if e["status"] == "failed"} - done
    counts = {"done": len(done), "failed": len(failed),
              "pending": len(tasks) - len(done) - len(failed)}
    table = pa.concat_tables(tables).sort_by("eval_id") if tables else SCHEMA.empty_table()
    return Dataset(table, manifest, counts, tuple(excluded))


def read_dataset(out: str | Path) -> pa.Table:
    """Every verified row of a sweep directory, sorted by ``eval_id`` (:func:`load_dataset`)."""
    return load_dataset(out).table


def read_outlines(out: str | Path) -> dict[str, list]:
    """Object id -> outer boundary loop [[x, y], ...], m, of the objects written so far
    (outline files that are not regular, too large or not an outline are skipped).
    """
    outlines = {}
    folder = Path(out) / "outlines"
    for p in sorted(folder.glob("*.json")) if folder.is_dir() else ():
        try:
            loop = json.loads(read_bytes(p, what="outline", max_bytes=MAX_OUTLINE_BYTES))
            loop = loop["outline"] if isinstance(loop, dict) else None
        except (InputError, ValueError, RecursionError):
            continue
        if isinstance(loop, list):
            outlines[p.stem] = loop
    return outlines


def _hold_lock(path: Path, out: Path) -> int:
    """Open ``path`` and lock it for this process (its id written in it); the descriptor.

    Raises
    ------
    SweepError
        If another process holds the lock (a sweep writing ``out`` now), naming its id.
    """
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as exc:
        raise output_error(exc, path, "the sweep's lock file") from None
    try:
        fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
        os.close(fd)
        raise SweepError(f"another sweep is writing {out} (process {holder or 'unknown'} holds "
                         f"{path.name}): wait for it to end or give another --out") from None
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
    return fd


class Store:
    """The output directory of one sweep spec.

    Attributes
    ----------
    repaired : list of str
        One line per part the opening found bad and moved to ``damaged/`` (its task is redone).
    """

    def __init__(self, out: str | Path, loaded: LoadedSpec, tasks: list[Task]) -> None:
        self.out = Path(out)
        self.parts = self.out / "parts"
        self.loaded = loaded
        self.tasks = {t.id: t for t in tasks}
        self.errors: dict[str, str] = {}
        self.repaired: list[str] = []
        self.created = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
        if os.path.lexists(self.out / "manifest.json"):
            old = read_manifest(self.out)
            if old["spec_hash"] != loaded.hash:
                raise SweepError(
                    f"{self.out} holds a sweep of another spec (hash "
                    f"{old['spec_hash'][:12]}, this spec {loaded.hash[:12]}; "
                    "a referenced file may have changed): give another --out or "
                    "delete it"
                )
            if isinstance(old.get("created"), str):
                self.created = old["created"][:40]  # the first run's, kept by every resume
        elif self.out.is_dir() and any(self.out.iterdir()):
            raise SweepError(
                f"--out {self.out} exists, is not empty and has no manifest.json: "
                "give a new or empty directory"
            )
        elif self.out.exists() and not self.out.is_dir():
            raise SweepError(f"--out {self.out} is a file; give a new or empty directory")
        try:
            self.parts.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise output_error(exc, self.parts, "the sweep's parts folder") from None
        self._lock = _hold_lock(self.parts / LOCK_NAME, self.out)
        try:
            self._open(loaded)
        except BaseException:
            self.close()
            raise

    def _open(self, loaded: LoadedSpec) -> None:
        """Remove stale temporary parts, check the parts on disk (moving bad ones aside) and
        write the manifest (under the folder's lock).
        """
        try:
            for stale in self.parts.glob(".*.tmp"):
                stale.unlink()
        except OSError as exc:
            raise output_error(exc, self.parts, "the sweep's parts folder") from None
        entries = _part_entries(self.parts)
        unknown = sorted(tid for tid in entries if tid not in self.tasks)
        if unknown:
            raise SweepError(f"{self.parts} has parts of no task of this spec ({unknown[0]}...)")
        self.finished: set[str] = set()
        for tid, entry in sorted(entries.items()):
            try:
                read_part(entry.path, tid, loaded.hash)
                self.finished.add(tid)
            except BadPart as exc:
                self.repaired.append(f"parts/{entry.name}: {exc}; moved to "
                                     f"{self._set_aside(entry)} and redone")
        self.write_manifest()

    def close(self) -> None:
        """Release the folder's lock (another sweep may then write it); idempotent."""
        if self._lock is not None:
            os.close(self._lock)  # closing the descriptor releases the record lock
            self._lock = None

    def __enter__(self) -> "Store":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _set_aside(self, entry: os.DirEntry) -> Path:
        """Move a bad part into ``damaged/`` under a name not taken yet; its new path."""
        folder = self.out / "damaged"
        try:
            folder.mkdir(exist_ok=True)
            k = 0
            while os.path.lexists(folder / f"{entry.name}.{k}"):
                k += 1
            os.replace(entry.path, folder / f"{entry.name}.{k}")
        except OSError as exc:
            raise output_error(exc, folder, "a damaged part into") from None
        return folder / f"{entry.name}.{k}"

    def part(self, task_id: str) -> Path:
        """Parquet file of a task."""
        return self.parts / f"{task_id}.parquet"

    def done(self, task_id: str) -> bool:
        """The task has an intact part (checked when the store was opened, or written since)."""
        return task_id in self.finished

    def write(self, task: Task, rows: list[dict], outline: list | None = None) -> int:
        """Write a task's rows (and its object's outline, once) atomically and update the
        manifest; returns the row count.

        Raises
        ------
        InvalidInputError, InternalError
            One line when the folder refuses the write (exit 2) or the disk is full (exit 4);
            the parts written before stay, and re-running resumes.
        """
        try:
            if outline is not None:
                path = self.out / "outlines" / f"{task.obj.id}.json"
                if not path.exists():
                    try:
                        path.parent.mkdir(exist_ok=True)
                    except OSError as exc:
                        raise output_error(exc, path.parent, "the outlines folder") from None
                    text = json.dumps({"object_id": task.obj.id, "outline": outline})
                    write_atomically(path, lambda p: p.write_text(text), "an outline")
            table = part_table(rows, task.id, self.loaded.hash)
            write_atomically(self.part(task.id), lambda p: write_part(p, table), "a part")
            self.finished.add(task.id)
            self.errors.pop(task.id, None)
            self.write_manifest()
        except SqueezeGraspError as exc:
            raise type(exc)(f"{exc}; the {len(self.finished)} part(s) written are kept: "
                            "re-run the same command to resume") from None
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
            "counts": {k: sum(1 for v in status.values() if v == k) for k in STATUSES},
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
        write_atomically(self.out / "manifest.json", lambda p: p.write_text(text), "the manifest")
