# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp sweep``: spec validation, seeds from ids, failures as rows, and real Dask runs
(a scheduler and two workers as separate processes on 127.0.0.1, a local cluster, SIGKILL of
the client and of a worker, resume) that must give the same table bit for bit.
"""

from __future__ import annotations

import dataclasses
import io
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.exit_codes import ExitCode
from squeeze_grasp_ros.sweep.evaluate import COLUMNS, run_task
from squeeze_grasp_ros.sweep.plan import objects, plan_tasks
from squeeze_grasp_ros.sweep.spec import SweepError, SweepSpec, parse_sweep_spec, sweep_help

SWEEP_EXTRA = "the sweep extra is not installed: pip install '.[sweep]' (Dask, pyarrow)"
pa = pytest.importorskip("pyarrow", reason=SWEEP_EXTRA)
pytest.importorskip("distributed", reason=SWEEP_EXTRA)

ROOT = Path(__file__).resolve().parents[1]
BASE = str(ROOT / "config" / "scenes" / "foam_square.yaml")
BIN = Path(sys.executable).parent

SMALL = {
    "name": "small",
    "base": BASE,
    "seed": 11,
    "objects": [
        {"shape": {"type": "ellipse", "a": 0.05, "b": 0.035}},
        {
            "family": {
                "type": "superellipse",
                "count": 2,
                "a": [0.04, 0.05],
                "b": [0.03, 0.04],
                "exponent": [2.5, 5.0],
            }
        },
        {"family": {"type": "fourier_blob", "count": 1, "radius": [0.04, 0.05]}},
    ],
    "mesh": {"nodes": 250},
    "friction": [0.3, 0.8],
    "tip_radius": [0.01],
    "relative_depth": [0.04],
    "placements": {"mode": "graspmap", "count": 4},
    "weight": 0.3,
    "adversary": {"directions": 24},
    "chunk": 4,
}


def write_spec(tmp_path: Path, data: dict, name: str = "spec.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def table_without_time(out: Path):
    from squeeze_grasp_ros.sweep.store import read_dataset

    return read_dataset(out).drop_columns(["time_s"])


def bare_rows(loaded) -> list[dict]:
    """The same evaluations in this process, no Dask, no Parquet."""
    rows = []
    for task in plan_tasks(loaded):
        rows += run_task(task)["rows"]
    for r in rows:
        del r["time_s"]
    return sorted(rows, key=lambda r: r["eval_id"])


def test_a_time_limit_cuts_only_the_squeezes_that_exceed_it(tmp_path):
    """``time_limit``: a limit no squeeze reaches leaves every row as without one, bit for bit;
    one every squeeze passes makes each row the squeeze's error, stopped at its first check
    (before its first solve, at depth 0). The limit is part of the spec's hash, so rows cut by
    one limit are not resumed under another.
    """
    data = {**SMALL, "objects": SMALL["objects"][:1], "friction": [0.3],
            "placements": {"mode": "graspmap", "count": 1}}
    loaded = {limit: parse_sweep_spec({**data, **({} if limit is None else
                                                  {"time_limit": limit})}, tmp_path)
              for limit in (None, 1000.0, 1e-9)}
    plain = bare_rows(loaded[None])
    assert plain and all(row["error"] is None for row in plain)
    assert bare_rows(loaded[1000.0]) == plain
    cut = bare_rows(loaded[1e-9])
    assert [row["eval_id"] for row in cut] == [row["eval_id"] for row in plain]
    assert all(row["error"] == "TimeLimitError: at depth 0 m (relative depth 0): the squeeze "
               "used more than 1e-09 s of CPU (the sweep's time_limit)" for row in cut)
    assert len({spec.hash for spec in loaded.values()}) == 3


# ----------------------------------------------------------------- spec


@pytest.mark.parametrize(
    "patch, message",
    [
        ({"frictoin": [0.2]}, "unknown key frictoin"),
        ({"friction": [-0.1]}, "friction[0] must be in [0.0, 1000.0]"),
        ({"friction": [0.2, 0.2]}, "friction lists a value twice"),
        ({"relative_depth": [1.5]},
         "relative_depth[0] must be in (0.0, 1.0) (at 1 the fingers would meet), got 1.5"),
        ({"depth": [0.01]}, "depth and relative_depth are exclusive"),
        ({"chunk": 0}, "chunk must be >= 1"),
        ({"time_limit": -1}, "time_limit must be > 0.0 s, got -1.0"),
        ({"placements": {"mode": "random"}}, "placements.mode must be one of"),
        ({"repeat": 2}, "only sampled placements are random"),
        (
            {
                "objects": [
                    {
                        "family": {
                            "type": "superellipse",
                            "count": 2,
                            "a": [0.05, 0.04],
                            "b": [0.03, 0.04],
                            "exponent": [3, 4],
                        }
                    }
                ]
            },
            "objects[0].family.a must be [low, high] with low <= high",
        ),
        (
            {
                "objects": [
                    {
                        "family": {
                            "type": "fourier_blob",
                            "count": 1,
                            "radius": [0.04, 0.05],
                            "exponent": [3, 4],
                        }
                    }
                ]
            },
            "objects[0].family.exponent does not apply to type fourier_blob",
        ),
        ({"objects": [{"shape": {"type": "ellipse", "a": 0.05}}]}, "missing required key shape.b"),
        ({"objects": [{"outline": "nowhere.csv"}]}, "objects[0].outline: file not found"),
        (
            {"objects": [{"shape": {"type": "disk", "radius": 0.05}, "outline": "x.csv"}]},
            "objects[0] needs exactly one of scene, outline, shape, family",
        ),
        (
            {"materials": {"foam": {"E": 5e4, "nu": 0.7, "thickness": 0.01}}},
            "materials.foam.nu must be in [-0.9, 0.5]",
        ),
        ({"adversary": {"position": 0.0}}, "adversary.position must be in (0.0, 1.0]"),
    ],
)
def test_spec_errors_name_the_key(tmp_path, patch, message):
    with pytest.raises(SweepError) as err:
        parse_sweep_spec({**SMALL, **patch}, tmp_path)
    assert message in str(err.value)


def test_cli_reports_spec_errors_without_traceback(tmp_path, capsys):
    spec = write_spec(tmp_path, {**SMALL, "tip_radius": [0.0]})
    assert main(["sweep", str(spec), "--out", str(tmp_path / "o")]) == 2
    assert "tip_radius[0] must be in (0.0, 1000.0] m, got 0.0" in capsys.readouterr().err


@pytest.mark.parametrize("workers", [0, 4 * (os.cpu_count() or 1) + 1, 100_000])
def test_a_local_cluster_size_out_of_range_is_refused_before_anything_starts(tmp_path, capsys,
                                                                           workers):
    """Before: --workers had no upper bound, and --workers 100000 began starting 100,000
    worker processes (over 90 MB each) on this 2-core machine.
    """
    spec = write_spec(tmp_path, SMALL)
    assert main(["sweep", str(spec), "--out", str(tmp_path / "o"), "--workers",
                 str(workers)]) == 2
    cores = os.cpu_count() or 1
    assert (f"--workers must be between 1 and {4 * cores} (4 per core of the {cores} here: "
            f"each worker is a process), got {workers}") in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("text, problem", [
    ("x,y\n0,0\n0.1,0\n", "bad.csv: line 1 is not 'x,y' (two numbers, metres)"),
    ("0,0\n0.1,0\n0.2,0\n", "bad.csv is degenerate (zero enclosed area)"),
])
def test_an_unusable_outline_file_is_named_by_its_objects_entry(tmp_path, capsys, text,
                                                                 problem):
    """Before: the scene's key, ``object.shape: outline file ...``, which a sweep spec does not
    have, for whichever entry it was.
    """
    (tmp_path / "bad.csv").write_text(text)
    spec = write_spec(tmp_path, {**SMALL, "objects": [SMALL["objects"][0],
                                                      {"outline": "bad.csv"}]})
    assert main(["sweep", str(spec), "--dry-run"]) == 2
    assert capsys.readouterr().err == (
        f"squeeze-grasp sweep: error: objects[1].outline: outline file {problem}\n")


LONG = "a" * 101


@pytest.mark.parametrize("patch, message", [
    ({"objects": [{"name": LONG, "shape": {"type": "disk", "radius": 0.05}}]},
     "objects[0].name is 101 bytes long; at most 100 (object and material names name the "
     "sweep's files)"),
    ({"materials": {LONG: {"E": 5e4, "nu": 0.3, "thickness": 0.01}}},
     f"materials: name '{LONG}' is 101 bytes long; at most 100 (object and material names "
     "name the sweep's files)"),
    ({"objects": [{"outline": f"{LONG}.csv"}]},
     f"objects[0].outline: the file's name {LONG!r} is 101 bytes long; at most 100 (object "
     "and material names name the sweep's files): give objects[0].name"),
])
def test_a_name_too_long_for_a_file_name_is_refused_before_the_run(tmp_path, capsys, patch,
                                                                   message):
    """Before: the sweep started its cluster, ran the task and then failed to write it (a file
    name is at most 255 bytes: ENAMETOOLONG), saying that a re-run would resume.
    """
    (tmp_path / f"{LONG}.csv").write_text("0,0\n0.1,0\n0.1,0.1\n0,0.1\n")
    spec = write_spec(tmp_path, {**SMALL, **patch})
    assert main(["sweep", str(spec), "--out", str(tmp_path / "o"), "--dry-run"]) == 2
    assert capsys.readouterr().err == f"squeeze-grasp sweep: error: {message}\n"


@pytest.mark.parametrize("name, problem", [
    ("../../evil", "has a '/' or a NUL, which no file name can hold"),
    (LONG, "is 101 bytes long; at most 100 (object and material names name the sweep's files)"),
])
def test_a_base_scene_whose_name_cannot_name_files_is_refused_before_the_run(tmp_path, capsys,
                                                                            name, problem):
    """Without ``objects`` the base scene's name names the object, its part and its outline
    file (any name a file can have is taken, spaces included). Before: a name with '/' or
    over 100 bytes ran the cluster and the task and then failed the write (ENOENT,
    ENAMETOOLONG), saying a re-run would resume.
    """
    scene = yaml.safe_load(Path(BASE).read_text())
    scene["name"] = name
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(scene))
    spec = {k: v for k, v in SMALL.items() if k != "objects"}
    spec = write_spec(tmp_path, {**spec, "base": str(tmp_path / "base.yaml")})
    assert main(["sweep", str(spec), "--out", str(tmp_path / "o"), "--dry-run"]) == 2
    assert capsys.readouterr().err == (
        f"squeeze-grasp sweep: error: base: the scene's name {name!r} {problem}: it names the "
        "sweep's object; give objects with a name\n")


def test_sweep_help_lists_every_key():
    text = sweep_help()
    for f in dataclasses.fields(SweepSpec):
        assert any(
            line.split()[0] in (f.name, f.name + "[]")
            for line in text.splitlines()
            if line.strip()
        ), f.name
    for key in (
        "objects[].family.exponent",
        "placements.require",
        "adversary.directions",
        "materials.<name>.E",
        "mesh.nodes",
    ):
        assert key in text
    lines = {line.split()[0]: line for line in text.splitlines() if line.strip()}
    assert lines["base"].endswith("[required]") and lines["name"].endswith("sweep name")
    assert lines["friction"].endswith("[in [0.0, 1000.0]]")


def test_seeds_come_from_ids_not_from_order(tmp_path):
    """Reordering the parameter axes or adding an object leaves each drawn shape and each
    sampled placement set unchanged; another seed changes them.
    """
    data = {**SMALL, "placements": {"mode": "sample", "count": 3}, "repeat": 2}
    one = parse_sweep_spec(data, tmp_path)
    more = parse_sweep_spec(
        {
            **data,
            "objects": SMALL["objects"] + [{"shape": {"type": "disk", "radius": 0.04}}],
            "friction": [0.8, 0.3],
        },
        tmp_path,
    )
    other = parse_sweep_spec({**data, "seed": 12}, tmp_path)
    shapes = {o.id: o.shape for o in objects(one)}
    assert all(shapes[o.id] == o.shape for o in objects(more) if o.id in shapes)
    assert [o.shape for o in objects(other)] != list(shapes.values())

    def placements(loaded):
        task = next(t for t in plan_tasks(loaded) if t.group.startswith("01-"))
        from squeeze_grasp_ros.sweep.evaluate import prepare

        return prepare(task).placements

    first = placements(one)
    assert first == placements(more)
    assert len(first) == 6 and {r for r, _, _ in first} == {0, 1}
    assert first != placements(other)


def test_failing_evaluation_is_a_row_not_a_crash(tmp_path):
    """An adversary on F1's own node raises inside the evaluation: the row carries the error,
    the other rows of the task are complete.
    """
    loaded = parse_sweep_spec(
        {
            **SMALL,
            "objects": SMALL["objects"][:1],
            "adversary": {"position": 1e-6},
            "friction": [0.3],
        },
        tmp_path,
    )
    rows = run_task(plan_tasks(loaded)[0])["rows"]
    assert rows and all(r["error"].startswith("SceneError: adversary.position 1e-06 is on the "
                                              "same boundary node as F1 or F2") for r in rows)
    assert all(r["termination"] is None and r["stiffness"] > 0 for r in rows)
    loaded = parse_sweep_spec(
        {**SMALL, "objects": SMALL["objects"][:1], "friction": [0.3]}, tmp_path
    )
    rows = run_task(plan_tasks(loaded)[0])["rows"]
    assert all(r.get("error") is None and r["termination"] for r in rows)
    assert set(rows[0]) == set(COLUMNS)


def test_rows_match_the_event_squeeze_and_grasp_map(tmp_path):
    """A row is the event engine's own result for that placement (cross-check in one process)."""
    from squeeze_grasp_ros.mechanics.squeeze.contact_model import TerminationLimits
    from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
    from squeeze_grasp_ros.sweep.evaluate import prepare

    loaded = parse_sweep_spec({**SMALL, "objects": SMALL["objects"][:1]}, tmp_path)
    task = plan_tasks(loaded)[0]
    row = run_task(task)["rows"][-1]
    group = prepare(task)
    res = event_squeeze(
        group.setup.solid,
        (row["node_F1"], row["node_F2"]),
        0.01,
        row["mu"],
        relative_depth=0.04,
        limits=TerminationLimits(weight=0.3),
    )
    assert row["termination"] == res.termination and row["depth"] == res.depth
    assert row["energy"] == res.energy and row["work_F1"] == res.work["F1"]
    assert row["events_A"] == res.event_counts["A"]
    assert row["picked_up"] == (res.termination == "picked_up")
    b = list(group.setup.solid.mesh.boundary)
    assert (
        row["stiffness"] == group.gmap.stiffness[b.index(row["node_F1"]), b.index(row["node_F2"])]
    )
    assert row["resist_min"] <= row["resist_max"]


def test_a_sweep_over_material_models_runs_each_and_names_its_measures(tmp_path):
    """A neo-Hookean material of a sweep is squeezed neo-Hookean (not linear): its row is the
    event engine's neo-Hookean result, with its log strain and Cauchy stress named, and the
    report keeps the strains of different measures apart.
    """
    from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
    from squeeze_grasp_ros.sweep.evaluate import prepare
    from squeeze_grasp_ros.sweep.report import summarise

    foam = {"E": 5e4, "nu": 0.3, "thickness": 0.0254}
    spec = {**SMALL, "objects": SMALL["objects"][:1], "friction": [0.8], "weight": None,
            "adversary": None, "placements": {"mode": "graspmap", "count": 2},
            "materials": {"lin": foam, "nh": {**foam, "model": "neo_hookean"}}}
    spec = {k: v for k, v in spec.items() if v is not None}
    rows = bare_rows(parse_sweep_spec(spec, tmp_path))
    measures = {(r["material_id"], r["material_model"], r["strain_measure"],
                 r["stress_measure"]) for r in rows}
    assert measures == {("lin", "linear", "small", "small_strain"),
                        ("nh", "neo_hookean", "log", "cauchy")}
    task = next(t for t in plan_tasks(parse_sweep_spec(spec, tmp_path)) if "~nh~" in t.id)
    row = next(r for r in rows if r["task_id"] == task.id)
    res = event_squeeze(prepare(task).setup.solid, (row["node_F1"], row["node_F2"]), 0.01, 0.8,
                        relative_depth=0.04, material_model="neo_hookean")
    h = res.health
    assert (row["max_strain"], row["max_von_mises"], row["energy"]) == (
        h.max_strain, h.max_von_mises, res.energy)
    assert row["max_strain_biot"] == h.max_principal_strain["biot"]
    dist = summarise(rows)["distributions"]
    assert {"max_strain [small]", "max_strain [log]", "max_von_mises [small_strain]",
            "max_von_mises [cauchy]", "max_strain_biot"} <= set(dist)
    assert "max_strain" not in dist and dist["max_strain [log]"]["count"] == len(rows) // 2


# ----------------------------------------------------------------- real Dask


def start_cluster(tmp_path: Path, workers: int = 2, *worker_options: str):
    """A `dask scheduler` and `dask worker` processes on 127.0.0.1 (own session each), the
    workers started with ``worker_options`` besides.
    """
    env = {
        **os.environ,
        "OMP_NUM_THREADS": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
    }
    file = tmp_path / "scheduler.json"
    procs = [
        subprocess.Popen(
            [
                str(BIN / "dask"),
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(file),
            ],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
    ]
    deadline = time.monotonic() + 60
    while True:  # Dask creates the file before it writes it
        try:
            address = json.loads(file.read_text())["address"]
            break
        except (OSError, ValueError, KeyError):
            assert time.monotonic() < deadline, "scheduler did not start"
            time.sleep(0.1)
    for _ in range(workers):
        procs.append(
            subprocess.Popen(
                [
                    str(BIN / "dask"),
                    "worker",
                    address,
                    "--nthreads",
                    "1",
                    "--no-nanny",
                    "--host",
                    "127.0.0.1",
                    "--no-dashboard",
                    *worker_options,
                ],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,
            )
        )
    from distributed import Client

    with Client(address, timeout="30s") as client:
        client.wait_for_workers(workers, timeout=60)
    return address, procs


def stop(procs) -> None:
    for p in procs:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
        p.wait()


def test_remote_cluster_local_cluster_and_bare_loop_agree_bit_for_bit(tmp_path):
    """Two `dask worker` processes (one SIGKILLed after the first part is written), a local
    cluster of one worker and the in-process loop give the same table, row for row.
    """
    from squeeze_grasp_ros.sweep.engine import run_sweep

    loaded = parse_sweep_spec(SMALL, tmp_path)
    address, procs = start_cluster(tmp_path)
    killed = []

    def kill_worker(task):
        if not killed:
            os.killpg(procs[1].pid, signal.SIGKILL)
            killed.append(task.id)

    try:
        remote = run_sweep(
            loaded, tmp_path / "remote", scheduler=address, progress=False, on_task=kill_worker
        )
    finally:
        stop(procs)
    assert killed and remote.done == remote.tasks == len(plan_tasks(loaded))
    assert remote.failed == 0 and remote.workers == 2
    local = run_sweep(loaded, tmp_path / "local", workers=1, progress=False)
    assert local.done == local.tasks
    a, b = table_without_time(tmp_path / "remote"), table_without_time(tmp_path / "local")
    assert a.num_rows == remote.evaluations > 20
    assert a.equals(b)
    assert a.to_pylist() == bare_rows(loaded)
    ok = [r for r in a.to_pylist() if r["error"] is None]
    assert len(ok) == a.num_rows and len({r["termination"] for r in ok}) >= 2
    manifest = json.loads((tmp_path / "remote" / "manifest.json").read_text())
    assert manifest["spec_hash"] == loaded.hash and manifest["counts"]["done"] == remote.tasks
    assert set(manifest["tasks"]) == {t.id for t in plan_tasks(loaded)}


def test_the_local_workers_route_is_chosen_by_the_sweeps_size(tmp_path, capsys, monkeypatch):
    """A sweep too small to repay numba's compilation (about 85 s of CPU per worker after an
    install) runs its local workers by numpy; one of at least COMPILED_FROM_EVALUATIONS by
    numba, when it is installed; the rows are the same bit for bit (linear objects).
    """
    from squeeze_grasp_ros.mechanics.squeeze import fixed_set_kernel
    from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE

    monkeypatch.delenv(KERNEL_VARIABLE, raising=False)
    spec = write_spec(tmp_path, SMALL)
    loaded = parse_sweep_spec(SMALL, tmp_path)
    total = sum(t.evaluations for t in plan_tasks(loaded))
    assert total < fixed_set_kernel.COMPILED_FROM_EVALUATIONS
    options = ["--json", "--no-progress", "--workers", "1"]
    assert main(["sweep", str(spec), "--out", str(tmp_path / "small"), *options]) == 0
    assert json.loads(capsys.readouterr().out)["kernel"] == "numpy"
    assert KERNEL_VARIABLE not in os.environ
    pytest.importorskip("numba", reason="the fast extra is not installed: pip install '.[fast]'")
    monkeypatch.setattr(fixed_set_kernel, "COMPILED_FROM_EVALUATIONS", total)
    assert main(["sweep", str(spec), "--out", str(tmp_path / "large"), *options]) == 0
    assert json.loads(capsys.readouterr().out)["kernel"] == "numba"
    assert table_without_time(tmp_path / "large").equals(table_without_time(tmp_path / "small"))


def test_a_dry_run_says_when_the_workers_take_another_route_than_its_sample(
        tmp_path, capsys, monkeypatch):
    pytest.importorskip("numba", reason="the fast extra is not installed: pip install '.[fast]'")
    from squeeze_grasp_ros.mechanics.squeeze import fixed_set_kernel

    monkeypatch.delenv(fixed_set_kernel.KERNEL_VARIABLE, raising=False)
    monkeypatch.setattr(fixed_set_kernel, "COMPILED_FROM_EVALUATIONS", 1)
    spec = write_spec(tmp_path, SMALL)
    assert main(["sweep", str(spec), "--dry-run"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        "the sample ran by numpy; the local workers will run by numba (the first run after an "
        "install compiles for about 85 s of CPU per worker, then each evaluation is faster)")
    assert fixed_set_kernel.KERNEL_VARIABLE not in os.environ  # a dry run starts no worker


def test_sigkill_of_the_client_loses_nothing_finished_and_resume_completes(tmp_path):
    """A real `squeeze-grasp sweep` process is SIGKILLed once parts exist; the parts it wrote
    stay byte-identical, the re-run writes only the rest, and the table equals a clean run's
    (the in-process loop).
    """
    data = {**SMALL, "chunk": 2}
    spec = write_spec(tmp_path, data)
    loaded = parse_sweep_spec(data, tmp_path)
    out = tmp_path / "out"
    cmd = [
        str(BIN / "squeeze-grasp"),
        "sweep",
        str(spec),
        "--out",
        str(out),
        "--workers",
        "1",
        "--no-progress",
    ]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    parts = out / "parts"
    deadline = time.monotonic() + 120
    try:
        while len(list(parts.glob("*.parquet"))) < 2:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline
            time.sleep(0.05)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    finally:
        stop([proc])
    before = {p.name: p.read_bytes() for p in parts.glob("*.parquet")}
    total = len(plan_tasks(loaded))
    assert 2 <= len(before) < total
    done = subprocess.run(cmd + ["--json"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["skipped"] == len(before) and result["done"] == total - len(before)
    assert not list(parts.glob(".*.tmp"))
    assert all((parts / name).read_bytes() == data_ for name, data_ in before.items())
    assert table_without_time(out).to_pylist() == bare_rows(loaded)
    again = subprocess.run(cmd + ["--json"], capture_output=True, text=True, timeout=120)
    assert json.loads(again.stdout)["skipped"] == total


@pytest.mark.parametrize(
    "signum, code",
    [(signal.SIGINT, 130), pytest.param(signal.SIGTERM, 143, marks=pytest.mark.slow)],
)
def test_ctrl_c_stops_cleanly_and_resumes(tmp_path, signum, code):
    """SIGINT (or SIGTERM) to the whole process group, as Ctrl-C in a terminal: exit 130 (143),
    one message and no traceback, the manifest agrees with the parts, and the re-run completes
    the table.
    """
    data = {**SMALL, "chunk": 2, "mesh": {"nodes": 600}, "relative_depth": [0.04, 0.08]}
    spec = write_spec(tmp_path, data)
    out = tmp_path / "out"
    cmd = [str(BIN / "squeeze-grasp"), "sweep", str(spec), "--out", str(out), "--workers", "1"]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    try:
        while len(list((out / "parts").glob("*.parquet"))) < 1:
            assert proc.poll() is None
            time.sleep(0.05)
        os.killpg(proc.pid, signum)
        assert proc.wait(timeout=60) == code
        err = proc.stderr.read().decode()
        assert "Re-run the same command to resume" in err and "Traceback" not in err
    finally:
        stop([proc])
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["counts"]["done"] == len(list((out / "parts").glob("*.parquet"))) >= 1
    assert subprocess.run(cmd + ["--no-progress"], capture_output=True).returncode == 0
    loaded = parse_sweep_spec(data, tmp_path)
    assert table_without_time(out).to_pylist() == bare_rows(loaded)


def sweep_command(spec: Path, out: Path, *options: str) -> list[str]:
    """The `squeeze-grasp sweep` console script of this environment."""
    return [str(BIN / "squeeze-grasp"), "sweep", str(spec), "--out", str(out), *options]


NO_PACKAGE = """
import sys


class NoPackage:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "squeeze_grasp_ros":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, NoPackage())
"""
"""A `dask worker --preload` that makes the worker a machine without this package."""
OTHER_VERSION = """
from squeeze_grasp_ros.sweep import store

store.package_version = lambda: "0.0.1"
"""
"""A `dask worker --preload` that makes the worker run another version of the package."""


@pytest.mark.parametrize("preloaded, says", [
    (NO_PACKAGE, "cannot run squeeze_grasp_ros (ModuleNotFoundError"),
    (OTHER_VERSION, "runs squeeze_grasp_ros 0.0.1, this client "),
], ids=["no package", "other version"])
def test_a_worker_without_the_package_is_refused_before_any_task(tmp_path, preloaded, says):
    """A cluster whose worker cannot import the package, or runs another version of it: one
    line naming the worker, what it lacks and what to install, exit 2, no part written (a
    worker without the package gave a traceback and exit 1 before).
    """
    preload = tmp_path / "preload.py"
    preload.write_text(preloaded)
    address, procs = start_cluster(tmp_path, 1, "--preload", str(preload))
    out = tmp_path / "out"
    try:
        done = subprocess.run(sweep_command(write_spec(tmp_path, SMALL), out, "--scheduler",
                                            address, "--no-progress"),
                              capture_output=True, text=True, timeout=120)
    finally:
        stop(procs)
    assert done.returncode == ExitCode.USAGE, done.stderr
    assert "Traceback" not in done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("squeeze-grasp sweep: error: worker tcp://127.0.0.1:")
    assert says in last
    assert last.endswith("install the same version, with its sweep extra, on every worker")
    assert not list(out.glob("parts/*.parquet"))


def worker_processes(pgid: int) -> list[str]:
    """Live multiprocessing children (a local cluster's Dask workers) in process group
    ``pgid``: pid and command line of each (zombies have no command line).
    """
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            state, _ppid, pgrp = stat.read_text().rsplit(")", 1)[1].split()[:3]
            cmd = (stat.parent / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        if int(pgrp) == pgid and state != "Z" and "spawn_main" in cmd:
            found.append(f"{stat.parent.name} {cmd}")
    return found


TOO_FINE = {"shape": {"type": "disk", "radius": 0.04}, "mesh": {"max_area": 1e-10}}
"""An object whose mesh the worker refuses (about 4e7 nodes: max_area given in the wrong unit);
only the client-side plan is cheap, so its task fails as a whole on the worker."""


def test_a_task_that_fails_as_a_whole_exits_1_and_is_the_only_one_retried(tmp_path):
    """A real sweep (one-worker local cluster) with one object that cannot be meshed: the other
    four tasks are written and equal the in-process loop's rows, the manifest marks the fifth
    failed with the mesher's message, the command exits 1 naming the count on its last line,
    and a re-run submits that task alone (and, the input being the same, fails it again).
    """
    data = {
        **SMALL,
        "objects": SMALL["objects"] + [TOO_FINE],
        "placements": {"mode": "graspmap", "count": 2},
    }
    spec = write_spec(tmp_path, data)
    loaded = parse_sweep_spec(data, tmp_path)
    tasks = plan_tasks(loaded)
    bad = [t.id for t in tasks if t.obj.id == "03-disk"]
    good = sorted(t.id for t in tasks if t.obj.id != "03-disk")
    assert len(bad) == 1 and len(good) == 4
    out = tmp_path / "out"
    cmd = sweep_command(spec, out, "--workers", "1", "--no-progress")
    last = (
        f"squeeze-grasp sweep: 1 of 5 task(s) failed (errors in {out}/manifest.json). "
        "Re-run the same command to retry them."
    )

    first = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert first.returncode == 1, first.stderr
    assert first.stderr.splitlines()[-1] == last
    assert "4 written now (16 evaluations, 0 with an error), 1 failed" in first.stdout
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["counts"] == {"done": 4, "failed": 1, "pending": 0}
    assert manifest["tasks"][bad[0]]["status"] == "failed"
    error = manifest["tasks"][bad[0]]["error"]
    assert error.startswith("SceneError: object.mesh: mesh.max_area 1e-10 m^2 would give about")
    parts = out / "parts"
    assert sorted(p.stem for p in parts.glob("*.parquet")) == good
    clean = parse_sweep_spec({**data, "objects": SMALL["objects"]}, tmp_path)
    assert table_without_time(out).to_pylist() == bare_rows(clean)

    written = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in parts.glob("*.parquet")}
    again = subprocess.run(cmd + ["--json"], capture_output=True, text=True, timeout=300)
    assert again.returncode == 1, again.stderr
    assert again.stderr.splitlines()[-1] == last
    result = json.loads(again.stdout)
    assert (result["tasks"], result["skipped"], result["done"], result["failed"]) == (5, 4, 0, 1)
    assert result["evaluations"] == 0
    assert {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in parts.glob("*.parquet")} == (
        written
    )
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["tasks"][bad[0]] == {"status": "failed", "error": error}
    assert manifest["counts"] == {"done": 4, "failed": 1, "pending": 0}


def test_sweep_help_lists_the_exit_statuses(capsys):
    with pytest.raises(SystemExit) as done:
        main(["sweep", "--help"])
    assert done.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "exit status: 0 every task written (an evaluation that raised is a row" in text
    assert "the local workers of a sweep of at least 25,000 evaluations run compiled" in text
    assert "1 some tasks failed as a whole" in text and "retries only the failed ones" in text
    assert "130 stopped by Ctrl-C (SIGINT), 143 by SIGTERM" in text


def test_error_rows_are_results_and_leave_the_exit_status_0(tmp_path, capsys):
    """Every evaluation raises (the adversary on F1's node) but every task completes: exit 0,
    and the summary says how many rows carry an error.
    """
    data = {**SMALL, "objects": SMALL["objects"][:1], "adversary": {"position": 1e-6},
            "friction": [0.3]}
    spec = write_spec(tmp_path, data)
    out = tmp_path / "out"
    assert main(["sweep", str(spec), "--out", str(out), "--workers", "1", "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "1 written now (4 evaluations, 4 with an error), 0 failed" in text
    assert "every task written; 4 evaluation(s) raised and are rows with their error" in text
    assert table_without_time(out)["error"].null_count == 0


@pytest.mark.parametrize(
    "moment, signum, code",
    [
        ("manifest written", signal.SIGINT, 130),
        ("worker spawned", signal.SIGINT, 130),
        ("worker spawned + 1 s", signal.SIGINT, 130),
        ("worker spawned", signal.SIGTERM, 143),
    ],
)
def test_ctrl_c_during_start_up_stops_cleanly(tmp_path, moment, signum, code):
    """Ctrl-C (SIGINT to the process group, workers included) before the local cluster starts,
    while its two worker processes import, or while they register and the client connects:
    exit 130, the one-line stop message and no traceback, and no worker process left. SIGTERM
    to the group kills the starting workers: exit 143 all the same.
    """
    data = {**SMALL, "chunk": 2, "mesh": {"nodes": 600}, "relative_depth": [0.04, 0.08]}
    out = tmp_path / "out"
    cmd = sweep_command(write_spec(tmp_path, data), out, "--workers", "2")
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    try:
        deadline = time.monotonic() + 60
        while not (
            (out / "manifest.json").exists()
            if moment == "manifest written"
            else worker_processes(proc.pid)
        ):
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.01)
        if moment.endswith("+ 1 s"):
            time.sleep(1.0)
        os.killpg(proc.pid, signum)
        assert proc.wait(timeout=60) == code
        left = worker_processes(proc.pid)
        err = proc.stderr.read().decode()
    finally:
        stop([proc])
        for entry in worker_processes(proc.pid):
            os.kill(int(entry.split()[0]), signal.SIGKILL)
    assert "Traceback" not in err, err
    assert re.fullmatch(
        rf"squeeze-grasp sweep: stopped by {signum.name}; \d+ task\(s\) written this run\. "
        r"Re-run the same command to resume\.",
        err.splitlines()[-1],
    ), err
    assert left == []


def test_ctrl_c_while_connecting_to_a_scheduler_stops_at_once(tmp_path):
    """A scheduler address where nothing answers: Client() would wait out its 20 s timeout;
    Ctrl-C ends the connect at once with exit 130 and the stop message.
    """
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    out = tmp_path / "out"
    cmd = sweep_command(write_spec(tmp_path, SMALL), out, "--scheduler", f"tcp://127.0.0.1:{port}")
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    try:
        deadline = time.monotonic() + 60
        while not (out / "manifest.json").exists():
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.01)
        time.sleep(1.0)
        assert proc.poll() is None
        sent = time.monotonic()
        os.killpg(proc.pid, signal.SIGINT)
        assert proc.wait(timeout=60) == 130
        assert time.monotonic() - sent < 5
        err = proc.stderr.read().decode()
    finally:
        stop([proc])
    assert "Traceback" not in err, err
    assert err.splitlines()[-1] == (
        "squeeze-grasp sweep: stopped by SIGINT; 0 task(s) written this run. "
        "Re-run the same command to resume."
    )


def test_the_local_cluster_samples_its_housekeeping_every_few_seconds():
    """The local cluster's workers, nannies and scheduler run Dask's periodic housekeeping at
    the intervals of LOCAL_HOUSEKEEPING (not Dask's 20-100 ms) and without the profiler, in the
    worker processes themselves, not only in the client's configuration.
    """
    import dask

    from squeeze_grasp_ros.sweep.engine import LOCAL_HOUSEKEEPING, StopSignals, _start

    client, cluster = _start(None, 1, StopSignals())
    try:
        workers = client.run(
            lambda dask_worker: {
                name: pc.callback_time for name, pc in dask_worker.periodic_callbacks.items()
            }
        )
        profile = client.run(lambda: dask.config.get("distributed.worker.profile.enabled"))
        nannies = [
            {name: pc.callback_time for name, pc in nanny.periodic_callbacks.items()}
            for nanny in cluster.workers.values()
        ]
        scheduler = {
            name: pc.callback_time for name, pc in cluster.scheduler.periodic_callbacks.items()
        }
    finally:
        client.close()
        cluster.close()
    assert LOCAL_HOUSEKEEPING["distributed.worker.profile.enabled"] is False
    assert list(profile.values()) == [False]
    for callbacks in [*workers.values(), *nannies]:
        assert callbacks["memory_monitor"] == 2000 and callbacks["tick"] == 1000
        assert callbacks["monitor"] == 5000
    assert scheduler["tick"] == 1000 and scheduler["monitor"] == 5000
    assert dask.config.get("distributed.admin.tick.interval") != "1s"


def test_a_local_cluster_beside_another_says_nothing_of_dasks_port_8787():
    """A second sweep on the machine (or any program on Dask's default dashboard port 8787)
    does not make the local cluster print Dask's four-line "Port 8787 is already in use"
    warning: the local cluster's HTTP server takes a free port of 127.0.0.1 with or without
    bokeh.
    """
    import socket
    import warnings

    from squeeze_grasp_ros.sweep.engine import StopSignals, _start

    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", 8787))
        holder.listen()
    except OSError:
        pass  # already held by another program: the same situation
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            client, cluster = _start(None, 1, StopSignals())
            client.close()
            cluster.close()
    finally:
        holder.close()
    assert [str(w.message) for w in caught if "8787" in str(w.message)] == []


def test_a_resume_keeps_the_manifests_creation_time(tmp_path):
    """Before: every re-run (even one with nothing to do) wrote its own time as ``created``."""
    from squeeze_grasp_ros.sweep.plan import plan_tasks as plan
    from squeeze_grasp_ros.sweep.store import Store, read_manifest

    loaded = parse_sweep_spec(SMALL, tmp_path)
    Store(tmp_path / "o", loaded, plan(loaded))
    manifest = tmp_path / "o" / "manifest.json"
    doc = json.loads(manifest.read_text())
    doc["created"] = "2001-02-03T04:05:06Z"
    manifest.write_text(json.dumps(doc))
    Store(tmp_path / "o", loaded, plan(loaded))
    assert read_manifest(tmp_path / "o")["created"] == "2001-02-03T04:05:06Z"


class Terminal(io.StringIO):
    """A stream that says it is a terminal; :meth:`screen` is what a terminal would show."""

    def isatty(self) -> bool:
        return True

    def screen(self) -> list[str]:
        rows, row, column = [], [], 0
        for char in self.getvalue():
            if char == "\n":
                rows.append("".join(row))
                row, column = [], 0
            elif char == "\r":
                column = 0
            else:
                row[column:column + 1] = [char]
                column += 1
        return [*rows, "".join(row)]


def test_the_progress_line_redrawn_shorter_leaves_nothing_of_the_longer_one(monkeypatch):
    """Before: a line redrawn shorter (the rate falling from 10.00 to 9.99 eval/s) kept the
    last characters of the previous one on the terminal.
    """
    from squeeze_grasp_ros.sweep.engine import Progress

    terminal = Terminal()
    bar = Progress(2, None, stream=terminal)
    lines = iter(["sweep 1/2, 10.00 eval/s, ETA 00:00:09", "sweep 2/2, 9.99 eval/s, ETA 00:00:00"])
    monkeypatch.setattr(bar, "line", lambda: next(lines))
    bar.update(1)
    assert terminal.screen() == ["sweep 1/2, 10.00 eval/s, ETA 00:00:09"]
    bar.update(1, final=True)
    assert [row.rstrip() for row in terminal.screen()] == [
        "sweep 2/2, 9.99 eval/s, ETA 00:00:00", ""]


def test_other_spec_in_the_same_directory_is_refused(tmp_path):
    from squeeze_grasp_ros.sweep.plan import plan_tasks as plan
    from squeeze_grasp_ros.sweep.store import Store

    one = parse_sweep_spec(SMALL, tmp_path)
    Store(tmp_path / "o", one, plan(one))
    two = parse_sweep_spec({**SMALL, "seed": 5}, tmp_path)
    with pytest.raises(SweepError, match="holds a sweep of another spec"):
        Store(tmp_path / "o", two, plan(two))


HOLD_STORE = """
import sys
from pathlib import Path
from squeeze_grasp_ros.sweep.plan import plan_tasks
from squeeze_grasp_ros.sweep.spec import load_sweep_spec
from squeeze_grasp_ros.sweep.store import Store
loaded = load_sweep_spec(sys.argv[1])
with Store(Path(sys.argv[2]), loaded, plan_tasks(loaded)):
    print("holding", flush=True)
    sys.stdin.read()
"""


def test_a_second_sweep_into_a_folder_being_written_is_refused_with_the_holders_pid(
        tmp_path, capsys):
    """Before: two sweeps into one --out both ran, each removing the other's temporary parts
    at its start and rewriting the manifest with its own counts. Now the second is refused
    before it touches the folder, and the folder is free again when the first ends.
    """
    spec = write_spec(tmp_path, {**SMALL, "objects": SMALL["objects"][:1]})
    out = tmp_path / "o"
    holder = subprocess.Popen([sys.executable, "-c", HOLD_STORE, str(spec), str(out)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "holding\n"
        temporary = out / "parts" / ".t0.parquet.tmp"  # a part the holder is writing
        temporary.write_text("")
        assert main(["sweep", str(spec), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert (f"another sweep is writing {out} (process {holder.pid} holds .sweep.lock): "
                "wait for it to end or give another --out") in err
        assert "Traceback" not in err and temporary.exists()
    finally:
        holder.communicate("", timeout=60)
    assert holder.returncode == 0
    assert main(["sweep", str(spec), "--out", str(out), "--workers", "1"]) == 0
    assert not temporary.exists()


def test_plots_of_a_folder_with_no_rows_yet_are_refused_in_words(tmp_path, capsys):
    """Before: ``--plot`` of a sweep folder whose tasks were all pending wrote nothing and said
    nothing (the summary showed no plot line).
    """
    from squeeze_grasp_ros.commands.sweep_report import NO_PLOTS
    from squeeze_grasp_ros.sweep.store import Store

    loaded = parse_sweep_spec(SMALL, tmp_path)
    Store(tmp_path / "o", loaded, plan_tasks(loaded)).close()
    assert main(["sweep-report", str(tmp_path / "o"), "--plot", str(tmp_path / "plots")]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"plots: {NO_PLOTS}"
    assert list((tmp_path / "plots").iterdir()) == []
    assert main(["sweep-report", str(tmp_path / "o"), "--json", "--plot",
                 str(tmp_path / "plots")]) == 0
    assert json.loads(capsys.readouterr().out)["plots"] == []


@pytest.mark.parametrize("missing", ["distributed", "pyarrow"])
def test_without_the_extra_both_verbs_say_how_to_install_and_exit_4(tmp_path, monkeypatch, capsys,
                                                                     missing):
    """A missing extra is the environment's failure (status 4, as for ``run`` without ROS and
    ``outline`` without scikit-image), not invalid input, and nothing is written.
    ``sweep-report`` needs pyarrow only (:func:`test_sweep_report_needs_pyarrow_only`).
    """
    spec = write_spec(tmp_path, SMALL)
    monkeypatch.setitem(sys.modules, missing, None)
    for argv in (["sweep", str(spec), "--out", str(tmp_path / "o")],
                 *([["sweep-report", str(tmp_path / "o")]] if missing == "pyarrow" else [])):
        assert main(argv) == ExitCode.INTERNAL == 4
        assert f"error: needs {missing}, which is not installed: pip install '.[sweep]'" \
            in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
    from squeeze_grasp_ros.commands.sweep import EPILOG  # what `sweep --help` says of it
    assert "; 4 the sweep extra missing" in EPILOG and "sweep extra missing;" not in EPILOG


def test_dry_run_and_report(tmp_path, capsys):
    spec = write_spec(tmp_path, SMALL)
    assert main(["sweep", str(spec), "--dry-run", "--json"]) == 0
    dry = json.loads(capsys.readouterr().out)
    loaded = parse_sweep_spec(SMALL, tmp_path)
    tasks = plan_tasks(loaded)
    assert dry["tasks"] == len(tasks) and dry["evaluations"] == sum(t.evaluations for t in tasks)
    assert dry["objects"] == 4 and dry["parameters"] == 2 and dry["estimate_s"] > 0
    assert dry["kernel"] == dry["sample_kernel"] == "numpy"  # a small sweep, variable unset
    from squeeze_grasp_ros.sweep.store import Store

    store = Store(tmp_path / "o", loaded, tasks)
    rows = []
    for task in tasks:
        res = run_task(task)
        store.write(task, res["rows"], res["outline"])
        rows += res["rows"]
    from squeeze_grasp_ros.sweep.store import read_outlines

    outlines = read_outlines(tmp_path / "o")
    assert sorted(outlines) == sorted({t.obj.id for t in tasks})
    xy = np.array(outlines[tasks[0].obj.id])
    assert np.allclose(np.hypot(xy[:, 0] / 0.05, xy[:, 1] / 0.035), 1.0, atol=1e-3)
    assert (
        main(["sweep-report", str(tmp_path / "o"), "--json", "--plot", str(tmp_path / "plots")])
        == 0
    )
    rep = json.loads(capsys.readouterr().out)
    assert rep["evaluations"] == len(rows)
    per = {(c["object"], c["material"]): c for c in rep["by_object_material"]}
    for (obj, mat), c in per.items():
        mine = [r for r in rows if r["object_id"] == obj]
        assert c["evaluations"] == len(mine)
        assert c["success"] == sum(1 for r in mine if r["picked_up"])
    q = [r["stiffness"] for r in rows]
    assert rep["distributions"]["stiffness"]["quantiles"]["median"] == pytest.approx(np.median(q))
    assert rep["quality"] == "resist_min"
    for obj, best in rep["best"].items():
        assert best[0]["success_rate"] >= best[-1]["success_rate"]
    assert all(Path(p).stat().st_size > 10_000 for p in rep["plots"])


def test_outline_file_objects_travel_with_the_task(tmp_path):
    """An outline file is read by the client: a worker without the file computes the same rows."""
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    csv = tmp_path / "blob.csv"
    np.savetxt(
        csv,
        np.column_stack([0.05 * np.cos(t), 0.03 * np.sin(t) * (1 + 0.2 * np.cos(t))]),
        delimiter=",",
    )
    loaded = parse_sweep_spec(
        {**SMALL, "objects": [{"outline": "blob.csv"}], "friction": [0.5]}, tmp_path
    )
    task = plan_tasks(loaded)[0]
    assert task.obj.id == "00-blob"
    first = run_task(task)["rows"]
    csv.unlink()
    from squeeze_grasp_ros.sweep.evaluate import clear_cache

    clear_cache()
    again = run_task(task)["rows"]
    strip = [{k: v for k, v in r.items() if k != "time_s"} for r in first]
    assert strip == [{k: v for k, v in r.items() if k != "time_s"} for r in again]
    assert all(r["error"] is None for r in first)


def test_a_failed_task_is_recorded_and_redone(tmp_path):
    from squeeze_grasp_ros.sweep.store import Store

    loaded = parse_sweep_spec(SMALL, tmp_path)
    tasks = plan_tasks(loaded)
    store = Store(tmp_path / "o", loaded, tasks)
    store.fail(tasks[0], "InvalidInputError: boom")
    manifest = json.loads((tmp_path / "o" / "manifest.json").read_text())
    assert manifest["tasks"][tasks[0].id] == {
        "status": "failed",
        "error": "InvalidInputError: boom",
    }
    assert manifest["counts"] == {"done": 0, "failed": 1, "pending": len(tasks) - 1}
    again = Store(tmp_path / "o", loaded, tasks)
    assert not again.done(tasks[0].id)
    res = run_task(tasks[0])
    again.write(tasks[0], res["rows"], res["outline"])
    manifest = json.loads((tmp_path / "o" / "manifest.json").read_text())
    assert manifest["tasks"][tasks[0].id]["status"] == "done"


# ----------------------------------------------------------------- the material model


FOAM = {"E": 5.0e4, "nu": 0.3, "thickness": 0.0254}


def test_a_sweep_computes_the_material_model_of_its_spec(tmp_path):
    """Issue 34 item 1, its reproduction: the foam square on 400 nodes, one grasp-map placement,
    mu 0.8, tip 0.02 m, 12 %, two materials equal but for ``model``. The rows differ, each
    records its model, and each equals the mechanics' own event-driven squeeze of that model on
    an independently built mesh.
    """
    from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
    from squeeze_grasp_ros.mechanics.elastic.material import Material
    from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
    from squeeze_grasp_ros.mechanics.elastic.shapes import rectangle
    from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze

    loaded = parse_sweep_spec({
        "base": BASE, "mesh": {"nodes": 400}, "friction": [0.8], "tip_radius": [0.02],
        "relative_depth": [0.12], "placements": {"mode": "graspmap", "count": 1},
        "materials": {"lin": FOAM, "nh": {**FOAM, "model": "neo_hookean"}},
    }, tmp_path)
    rows = {r["material_id"]: r for t in plan_tasks(loaded) for r in run_task(t)["rows"]}
    lin, nh = rows["lin"], rows["nh"]
    assert lin["error"] is None and nh["error"] is None
    assert (lin["material_model"], nh["material_model"]) == ("linear", "neo_hookean")
    assert (lin["node_F1"], lin["node_F2"]) == (nh["node_F1"], nh["node_F2"])
    assert abs(nh["force_F1_end"] / lin["force_F1_end"] - 1) > 1e-3
    outline = rectangle(0.1, 0.1)
    obj = ElasticObject(generate_mesh(outline, target_max_area(outline, 400), min_angle=30.0),
                        Material(**FOAM)).precompute()
    for row, model in ((lin, "linear"), (nh, "neo_hookean")):
        res = event_squeeze(obj, (row["node_F1"], row["node_F2"]), 0.02, 0.8,
                            relative_depth=0.12, material_model=model)
        assert row["force_F1_end"] == pytest.approx(res.finger_force["F1"][1], rel=1e-9)
        assert row["energy"] == pytest.approx(res.energy, rel=1e-9)
        assert row["termination"] == res.termination


def test_a_sweep_refuses_what_the_scene_refuses(tmp_path):
    """``nu: 0.5`` with the neo-Hookean model is refused by the sweep spec as by a scene."""
    spec = {"base": BASE, "materials": {"nh": {**FOAM, "nu": 0.5, "model": "neo_hookean"}}}
    with pytest.raises(SweepError, match=r"materials\.nh\.nu must be in \[-0\.3, 0\.4999\] "
                       r"for the neo_hookean model, got 0\.5"):
        parse_sweep_spec(spec, tmp_path)
    scene = yaml.safe_load(Path(BASE).read_text())
    scene["object"]["material"].update(nu=0.5, model="neo_hookean")
    from squeeze_grasp_ros.scene import SceneError, parse_scene
    with pytest.raises(SceneError, match=r"object\.material\.nu must be in \[-0\.3, 0\.4999\] "
                       r"for the neo_hookean model, got 0\.5"):
        parse_scene(scene)
    spec["materials"]["nh"]["model"] = "linear"
    assert parse_sweep_spec(spec, tmp_path).materials["nh"].nu == 0.5


def test_a_tasks_rows_do_not_depend_on_the_processs_blas_threads():
    """The example's tasks in this process with two BLAS threads and with one give the same
    rows bit for bit (Dask's workers run one; before run_task held one itself, a plain
    process's rows of one superellipse differed from theirs in the last place of some forces
    and energies).
    """
    import threadpoolctl

    from squeeze_grasp_ros.sweep import evaluate

    spec = Path(__file__).resolve().parents[1] / "config" / "sweeps" / "example.yaml"
    loaded = parse_sweep_spec(yaml.safe_load(spec.read_text()), spec.parent)
    rows = {}
    for threads in (2, 1):
        evaluate._CACHE.clear()  # every group prepared again under this setting
        with threadpoolctl.threadpool_limits(threads, user_api="blas"):
            rows[threads] = [{k: v for k, v in r.items() if k != "time_s"}
                             for task in plan_tasks(loaded) for r in run_task(task)["rows"]]
    assert len(rows[1]) == 288 and rows[2] == rows[1]


def test_sweep_report_needs_pyarrow_only(tmp_path, capsys, monkeypatch):
    """``sweep-report`` reads Parquet: without Dask distributed it reports (before, it refused:
    "squeeze-grasp sweep-report: error: needs distributed"); ``sweep`` still needs both.
    """
    from squeeze_grasp_ros.sweep.store import Store

    loaded = parse_sweep_spec(SMALL, tmp_path)
    Store(tmp_path / "o", loaded, plan_tasks(loaded)).close()
    monkeypatch.setitem(sys.modules, "distributed", None)   # import distributed fails
    assert main(["sweep-report", str(tmp_path / "o")]) == 0
    capsys.readouterr()
    assert main(["sweep", str(write_spec(tmp_path, SMALL)), "--out", str(tmp_path / "p")]) == 4
    assert "squeeze-grasp sweep: error: needs distributed, which is not installed" in \
        capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    assert main(["sweep-report", str(tmp_path / "o")]) == 4
    assert "squeeze-grasp sweep-report: error: needs pyarrow, which is not installed" in \
        capsys.readouterr().err
