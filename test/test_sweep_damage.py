# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A sweep's output folder damaged the ways disks and people damage folders: the report reads
only parts that vouch for themselves and says what it left out; a resume redoes what is bad;
unreadable manifests, FIFOs, sparse giants, full disks and read-only folders end in one line.

The sweep is small (one ellipse, 4 placements x 2 friction values, one task per placement) and
its parts are computed once per module without Dask; each test damages its own copy.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from output_support import CLI, private_mount

from squeeze_grasp_ros.cli import main

pa = pytest.importorskip("pyarrow", reason="pip install -e '.[sweep]'")
pytest.importorskip("distributed", reason="pip install -e '.[sweep]'")

from squeeze_grasp_ros.sweep.evaluate import run_task  # noqa: E402
from squeeze_grasp_ros.sweep.parts import part_table, write_part  # noqa: E402
from squeeze_grasp_ros.sweep.plan import plan_tasks  # noqa: E402
from squeeze_grasp_ros.sweep.spec import SweepError, parse_sweep_spec  # noqa: E402
from squeeze_grasp_ros.sweep.store import Store, load_dataset, read_dataset  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SPEC = {
    "name": "damage",
    "base": str(ROOT / "config" / "scenes" / "foam_square.yaml"),
    "seed": 3,
    "objects": [{"shape": {"type": "ellipse", "a": 0.05, "b": 0.035}}],
    "mesh": {"nodes": 150},
    "friction": [0.3, 0.8],
    "relative_depth": [0.03],
    "placements": {"mode": "sample", "count": 4},
    "chunk": 2,
}


@pytest.fixture(scope="module")
def pristine(tmp_path_factory) -> Path:
    """A finished sweep folder (4 tasks of 2 rows), written through the store."""
    base = tmp_path_factory.mktemp("pristine")
    (base / "spec.yaml").write_text(yaml.safe_dump(SPEC))
    loaded = parse_sweep_spec(SPEC, base)
    tasks = plan_tasks(loaded)
    store = Store(base / "out", loaded, tasks)
    for task in tasks:
        result = run_task(task)
        store.write(task, result["rows"], result["outline"])
    return base


@pytest.fixture()
def sweep(pristine, tmp_path) -> Path:
    """A copy of the finished sweep: ``tmp_path/spec.yaml`` and ``tmp_path/out``."""
    shutil.copytree(pristine, tmp_path, dirs_exist_ok=True)
    return tmp_path


def parts(sweep: Path) -> list[Path]:
    return sorted((sweep / "out" / "parts").glob("*.parquet"))


def report(sweep: Path, capsys) -> dict:
    assert main(["sweep-report", str(sweep / "out"), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def reopen(sweep: Path) -> Store:
    loaded = parse_sweep_spec(SPEC, sweep)
    return Store(sweep / "out", loaded, plan_tasks(loaded))


def test_the_pristine_sweep_reports_every_row(sweep, capsys):
    rep = report(sweep, capsys)
    assert rep["evaluations"] == 8 and rep["excluded"] == []
    assert rep["manifest"]["counts"] == {"done": 4, "failed": 0, "pending": 0}


@pytest.mark.parametrize("damage", ["empty", "truncated", "flipped byte", "edited rows"])
def test_a_damaged_part_is_left_out_of_the_report_and_redone_by_resume(sweep, damage, capsys):
    victim = parts(sweep)[1]
    data = victim.read_bytes()
    if damage == "empty":
        victim.write_bytes(b"")
    elif damage == "truncated":
        victim.write_bytes(data[: len(data) // 2])
    elif damage == "flipped byte":
        victim.write_bytes(data[:200] + bytes([data[200] ^ 0x10]) + data[201:])
    else:  # a row changed and the file rewritten whole, metadata and all
        import pyarrow.parquet as pq

        table = pq.read_table(victim)
        energy = table.column("energy").to_pylist()
        energy[0] = 2.0 * energy[0]
        pq.write_table(table.set_column(table.schema.get_field_index("energy"), "energy",
                                        pa.array(energy)), victim)
    rep = report(sweep, capsys)
    assert rep["evaluations"] == 6
    assert rep["manifest"]["counts"]["done"] == 3
    [line] = rep["excluded"]
    assert line.startswith(f"parts/{victim.name}: left out: ")
    store = reopen(sweep)
    [repaired] = store.repaired
    assert repaired.startswith(f"parts/{victim.name}: ") and "moved to" in repaired
    assert not store.done(victim.stem) and not victim.exists()
    assert len(list((sweep / "out" / "damaged").iterdir())) == 1  # kept, not deleted
    task = next(t for t in plan_tasks(store.loaded) if t.id == victim.stem)
    store.write(task, run_task(task)["rows"])
    assert report(sweep, capsys)["evaluations"] == 8


def test_a_part_copied_over_another_is_told_apart(sweep, capsys):
    first, second = parts(sweep)[:2]
    shutil.copy(first, second)
    rep = report(sweep, capsys)
    assert rep["evaluations"] == 6
    assert f"holds the rows of task '{first.stem}', not of '{second.stem}'" in rep["excluded"][0]
    assert reopen(sweep).repaired and not second.exists()


def test_a_part_of_another_sweep_is_left_out(sweep, capsys):
    other = parse_sweep_spec({**SPEC, "seed": 4}, sweep)
    task = plan_tasks(other)[0]
    victim = sweep / "out" / "parts" / f"{task.id}.parquet"
    assert victim.exists()  # the same task ids: only the spec hash tells the sweeps apart
    write_part(victim, part_table(run_task(task)["rows"], task.id, other.hash))
    rep = report(sweep, capsys)
    assert rep["evaluations"] == 6
    assert "belongs to another sweep" in rep["excluded"][0]


def test_unknown_parts_folders_and_deleted_parts(sweep, capsys):
    shutil.copy(parts(sweep)[0], sweep / "out" / "parts" / "zz-evil.parquet")
    folder = parts(sweep)[1]
    folder.unlink()
    folder.mkdir()
    deleted = parts(sweep)[2]
    deleted.unlink()
    rep = report(sweep, capsys)
    assert rep["evaluations"] == 4
    assert rep["manifest"]["counts"] == {"done": 2, "failed": 0, "pending": 2}
    lines = "\n".join(rep["excluded"])
    assert "zz-evil.parquet: left out: belongs to no task of this sweep" in lines
    assert f"{folder.name}: left out: part path is not a regular file" in lines
    assert f"task {deleted.stem}: marked done but its part is missing" in lines
    with pytest.raises(SweepError, match="has parts of no task of this spec"):
        reopen(sweep)
    (sweep / "out" / "parts" / "zz-evil.parquet").unlink()
    store = reopen(sweep)
    assert not store.done(folder.stem) and not store.done(deleted.stem)
    assert "not a regular file" in store.repaired[0]


def test_the_text_report_says_what_it_left_out(sweep, capsys):
    parts(sweep)[0].write_bytes(b"")
    assert main(["sweep-report", str(sweep / "out")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("1 part(s) left out of this report")
    assert "tasks done 3, failed 0, pending 1; 6 evaluations" in out


@pytest.mark.parametrize("text, problem", [
    ("{bad", "invalid JSON at line 1, column 2"),
    ("[1, 2]", "a JSON list, not an object"),
    ('{"spec_hash": "x", "tasks": [], "counts": {}, "package_version": "1"}',
     "'tasks' is missing or not a dict"),
    ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
])
def test_a_bad_manifest_is_one_line(sweep, text, problem, capfd):
    (sweep / "out" / "manifest.json").write_text(text)
    for argv in (["sweep-report", str(sweep / "out")],
                 ["sweep", str(sweep / "spec.yaml"), "--out", str(sweep / "out")]):
        assert main(argv) == 2
        err = capfd.readouterr().err
        assert f"not a sweep manifest ({problem})" in err, err
        assert len(err.strip().splitlines()) == 1


def _edit_rows(part: Path) -> None:
    """Double one row's energy and rewrite the part whole, metadata and all."""
    import pyarrow.parquet as pq

    table = pq.read_table(part)
    energy = table.column("energy").to_pylist()
    energy[0] = 2.0 * energy[0]
    pq.write_table(table.set_column(table.schema.get_field_index("energy"), "energy",
                                    pa.array(energy)), part)


def _other_sweeps_part(sweep: Path) -> None:
    other = parse_sweep_spec({**SPEC, "seed": 4}, sweep)
    task = plan_tasks(other)[0]
    write_part(sweep / "out" / "parts" / f"{task.id}.parquet",
               part_table(run_task(task)["rows"], task.id, other.hash))


def _folder_for_part(sweep: Path) -> None:
    victim = parts(sweep)[1]
    victim.unlink()
    victim.mkdir()


DOC_DAMAGES = {
    "empty or truncated part": lambda s: parts(s)[1].write_bytes(b""),
    "a part copied over another's name": lambda s: shutil.copy(parts(s)[0], parts(s)[1]),
    "a part of another sweep": _other_sweeps_part,
    "a part edited in place, a flipped byte": lambda s: _edit_rows(parts(s)[1]),
    "an unknown part (`zz-evil.parquet`)": lambda s: shutil.copy(
        parts(s)[0], s / "out" / "parts" / "zz-evil.parquet"),
    "a folder named like a part": _folder_for_part,
    "a deleted part": lambda s: parts(s)[1].unlink(),
    "`manifest.json` is `{bad`": lambda s: (s / "out" / "manifest.json").write_text("{bad"),
    "`manifest.json` is a FIFO": lambda s: ((s / "out" / "manifest.json").unlink(),
                                            os.mkfifo(s / "out" / "manifest.json")),
}
"""The damages of docs/reliability.md's table, by the start of their row."""


def test_the_damage_table_quotes_what_sweep_report_says(pristine, tmp_path):
    """Each message docs/reliability.md's table of damaged sweep folders quotes in its
    "``sweep-report`` now" column (``X``, ``A``, ``B`` standing for task ids and ``...`` for
    any text) is in what ``sweep-report`` prints for that damage, in a child process.
    """
    page = (ROOT / "docs" / "reliability.md").read_text(encoding="utf-8")
    rows = [line.split(" | ") for line in page.splitlines()
            if line.startswith("| ") and line.count(" | ") == 3]
    checked = 0
    for k, (start, damage) in enumerate(DOC_DAMAGES.items()):
        row = next(r for r in rows if r[0].removeprefix("| ").startswith(start))
        quoted = re.findall(r"`([^`]+)`", row[2])
        sweep = tmp_path / str(k)
        shutil.copytree(pristine, sweep)
        damage(sweep)
        done = run_cli(["sweep-report", str(sweep / "out")])
        said = done.stdout + done.stderr
        for quote in quoted:
            pattern = re.sub(r"\b[XAB]\b", r"[\\w~.-]+",
                             re.escape(quote).replace(r"\.\.\.", ".*"))
            assert re.search(pattern, said), (start, quote, said)
            checked += 1
    assert checked >= 8


def run_cli(args: list[str], timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "squeeze_grasp_ros.cli", *args],
                          capture_output=True, text=True, timeout=timeout)


def test_a_fifo_or_a_sparse_giant_manifest_is_refused_without_reading_it(sweep):
    """A FIFO used to hang the sweep in open() (deaf to SIGINT); a 3 GB sparse manifest was
    read whole (3.28 GB of memory). Both are refused at once, in a child that must not hang.
    """
    manifest = sweep / "out" / "manifest.json"
    manifest.unlink()
    os.mkfifo(manifest)
    for args in (["sweep-report", str(sweep / "out")],
                 ["sweep", str(sweep / "spec.yaml"), "--out", str(sweep / "out")]):
        done = run_cli(args)
        assert done.returncode == 2 and "manifest path is not a regular file" in done.stderr
    manifest.unlink()
    with open(manifest, "wb") as fh:
        fh.truncate(3 * 1024**3)
    done = run_cli(["sweep-report", str(sweep / "out")])
    assert done.returncode == 2
    assert "manifest file is larger than the 67108864-byte limit" in done.stderr


def test_the_report_of_a_folder_without_parts_and_plots_into_a_file(sweep, capfd):
    shutil.rmtree(sweep / "out" / "parts")
    assert main(["sweep-report", str(sweep / "out")]) == 0
    assert "0 evaluations" in capfd.readouterr().out
    with pytest.raises(SystemExit) as info:
        main(["sweep-report", str(sweep / "out"), "--plot", str(sweep / "spec.yaml")])
    assert info.value.code == 2
    assert "exists and is not a folder" in capfd.readouterr().err




def test_read_only_folders_are_refused_in_one_line_before_any_work(sweep):
    ro = sweep / "ro"
    scene = str(ROOT / "config" / "scenes" / "foam_square.yaml")
    for args, code, message in (
        (["sweep", str(sweep / "spec.yaml"), "--out", str(ro / "out")], 2,
         "Read-only file system (EROFS)"),
        (["squeeze", scene, "--save-boundary", str(ro / "b.csv")], 2,
         "cannot create files in"),
        (["plan", scene, "--plot", str(ro / "p.png")], 2, "cannot create files in"),
        (["bench", "--only", "solvers", "--quick", "--out", str(ro / "bench")], 2,
         "Read-only file system (EROFS)"),
    ):
        done = private_mount(ro, "ro,size=1m", [*CLI, *args])
        assert done.returncode == code, done.stderr
        assert message in done.stderr and "Traceback" not in done.stderr, done.stderr
        assert done.stderr.strip().splitlines()[-1].startswith("squeeze-grasp")


def test_a_full_disk_during_a_sweep_is_one_line_and_leaves_no_temporary_file(sweep):
    """The output folder is a 48 kB tmpfs: the first parts fit, then a write fails with
    ENOSPC. The sweep ends with one line and exit 4, the parts written are intact (the report
    reads them after the mount is gone, from the copy the child made), and no temporary file
    is left, neither a part nor a manifest.
    """
    full = sweep / "full"
    keep = sweep / "kept"
    shell = (f"{' '.join(CLI)} sweep '{sweep / 'spec.yaml'}' --out '{full / 'out'}' "
             f"--workers 1 --no-progress; echo EXIT=$?; cp -r '{full / 'out'}' '{keep}'")
    start = time.monotonic()
    done = private_mount(full, "size=48k", ["sh", "-c", shell])
    assert time.monotonic() - start < 300
    err = done.stderr.strip().splitlines()
    assert "EXIT=4" in done.stdout, (done.stdout, done.stderr)
    assert "No space left on device (ENOSPC)" in err[-1] and "re-run" in err[-1], err
    assert not any("Traceback" in line for line in err)
    leftovers = [p.name for p in keep.rglob(".*.tmp")]
    assert leftovers == []
    data = load_dataset(keep)
    assert data.excluded == () and data.counts["done"] >= 1
    assert len(read_dataset(keep)) == 2 * data.counts["done"]


def test_the_output_layout_sweep_md_draws_is_the_folder(pristine):
    """docs/sweep.md's block of a sweep's output folder (``DIR/...`` paths, ``<...>`` for a
    name) lists what a finished sweep's folder holds: every path drawn exists, and every file
    there is drawn.
    """
    import fnmatch

    page = (ROOT / "docs" / "sweep.md").read_text(encoding="utf-8")
    block = page[page.index("```\nDIR/manifest.json"):]
    block = block[4:block.index("```", 4)]
    drawn = [re.sub(r"<[^>]+>", "*", line).split()[0].removeprefix("DIR/")
             for line in block.splitlines() if line.strip()]
    out = pristine / "out"
    held = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    assert len(drawn) >= 4
    assert [d for d in drawn if not fnmatch.filter(held, d)] == [], (drawn, held)
    assert [h for h in held if not any(fnmatch.fnmatch(h, d) for d in drawn)] == [], held
