# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The pip route without ROS: every mechanics verb and ``bench`` work when nothing of ROS 2 (nor
the ``ros`` and ``sweep`` extras) can be imported.

A child interpreter refuses every module a plain ``pip install .`` lacks (rclpy, the message
packages, the ament index, our interfaces, mcap, Dask, pyarrow) before importing the package,
then runs the CLI verbs in turn; the ROS-only verbs must say what to install.
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
EXAMPLES = SCENES.parent / "examples"
SWEEP = SCENES.parent / "sweeps" / "example.yaml"
ABSENT = (
    "rclpy",
    "rosidl",
    "rpyutils",
    "rcl_interfaces",
    "std_msgs",
    "geometry_msgs",
    "sensor_msgs",
    "visualization_msgs",
    "rosgraph_msgs",
    "action_msgs",
    "builtin_interfaces",
    "unique_identifier_msgs",
    "squeeze_grasp_interfaces",
    "ament_index_python",
    "mcap",
    "mcap_ros2",
    "dask",
    "distributed",
    "pyarrow",
)
"""Top-level modules of the ros and sweep extras (and what they pull in)."""

CHILD = """
import contextlib, importlib.abc, io, json, sys
ABSENT = {absent!r}

class Absent(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ABSENT:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
        return None

sys.meta_path.insert(0, Absent())
from squeeze_grasp_ros.cli import main

results = []
for argv in {runs!r}:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code
    results.append({{"argv": argv, "code": code, "stdout": out.getvalue(),
                     "stderr": err.getvalue()}})
leaked = sorted(m for m in sys.modules if m.split(".")[0] in ABSENT)
print(json.dumps({{"results": results, "leaked": leaked}}))
"""


def run_without_ros(runs: list[list[str]], cwd: Path, absent: tuple[str, ...] = ABSENT) -> dict:
    code = CHILD.format(absent=absent, runs=runs)
    done = subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.splitlines()[-1])


def test_mechanics_verbs_and_bench_work_without_ros(tmp_path):
    (tmp_path / "trials.csv").write_text("angle_deg,slid\n20,0\n25,0\n30,1\n35,1\n")
    disk, foam = str(SCENES / "disk.yaml"), str(SCENES / "foam_square.yaml")
    boundary = str(tmp_path / "boundary.csv")
    runs = [
        ["mesh", disk, "--json"],
        ["plan", disk, "--json"],
        ["squeeze", foam, "--save-boundary", boundary, "--json"],
        ["match", boundary, boundary, "--json"],
        ["calibrate", "--slope-trials", str(tmp_path / "trials.csv"), "--json"],
        ["graspmap", disk, "--json"],
        ["resist", str(SCENES / "resist_fig9.yaml"), "--json"],
        ["ring", str(SCENES / "ring_ring.yaml"), "--json"],
        ["gripper-plan", str(SCENES / "sponge_gripper.yaml"), "--count", "2", "--evaluate", "1",
         "--json"],
        ["render", foam, "--camera-info", str(EXAMPLES / "camera_top.yaml"), "--camera-pose",
         "0", "0", "0.5", "3.14159265", "0", "0", "--mask", str(tmp_path / "mask.png"), "--json"],
        ["scene-help"],
        ["sweep-help"],
        ["sweep", str(SWEEP), "--dry-run", "--json"],
        ["sweep", str(SWEEP), "--out", str(tmp_path / "sweep")],
        ["bench", "--quick", "--only", "convergence", "ros_services", "pipeline", "sweep",
         "--out", str(tmp_path / "bench")],
        ["run", foam],
    ]
    report = run_without_ros(runs, tmp_path)
    assert report["leaked"] == []
    by_verb = {" ".join(r["argv"][:1] + [a for a in r["argv"] if a == "--dry-run"]): r
               for r in report["results"]}
    for verb in ("mesh", "plan", "squeeze", "match", "calibrate", "graspmap", "resist", "ring",
                 "gripper-plan", "render", "sweep --dry-run"):
        result = by_verb[verb]
        assert result["code"] == 0, (verb, result["stderr"])
        assert isinstance(json.loads(result["stdout"]), dict)
    assert json.loads(by_verb["match"]["stdout"])["rms_error"] < 1e-12
    assert by_verb["scene-help"]["code"] == 0 and "object" in by_verb["scene-help"]["stdout"]
    assert by_verb["sweep-help"]["code"] == 0 and "objects" in by_verb["sweep-help"]["stdout"]
    sweep = by_verb["sweep"]
    assert sweep["code"] == 4 and "pip install '.[sweep]'" in sweep["stderr"], sweep["stderr"]
    # what README.md's pip route says a plain install gives: exactly what ran here
    readme = " ".join((SCENES.parents[1] / "README.md").read_text(encoding="utf-8").split())
    listed = readme[readme.index("`pip install .` gives every mechanics verb ("):]
    listed = re.findall(r"`([\w -]+)`", listed[:listed.index(") and `bench`")])
    assert sorted(listed) == sorted(
        v for v in by_verb if v not in ("bench", "run", "sweep")), listed

    bench = by_verb["bench"]
    assert bench["code"] == 0, bench["stderr"]
    for section in ("ros_services", "pipeline", "sweep"):
        assert f"skipped {section}: " in bench["stderr"]
    text = (tmp_path / "bench" / "report.md").read_text()
    assert "Skipped sections" in text
    assert "pip install '.[ros]'" in text and "pip install '.[sweep]'" in text

    run = by_verb["run"]
    assert run["code"] != 0
    assert "rclpy" in run["stderr"] and "Traceback" not in run["stderr"]


def test_without_qdldl_linear_squeezes_run_and_nonlinear_ones_say_what_to_install(tmp_path):
    """The package requires qdldl (setup.py installs it), but only the large-deformation
    models import it: where it is missing (a colcon install without the pip line) the linear
    mechanics still runs, and a nonlinear squeeze ends in one line saying what to install
    (without the cholmod extra's cvxopt too, which would factorise instead).
    """
    foam = str(SCENES / "foam_square.yaml")
    report = run_without_ros([["squeeze", foam, "--json"],
                              ["squeeze", foam, "--model", "neo_hookean", "--relative-depth",
                               "0.01"]], tmp_path, absent=("qdldl", "cvxopt"))
    linear, nonlinear = report["results"]
    assert linear["code"] == 0 and json.loads(linear["stdout"])["termination"] == "depth_reached"
    assert nonlinear["code"] == 4
    assert nonlinear["stderr"].strip().splitlines() == [
        "squeeze-grasp squeeze: error: needs qdldl, which is not installed: pip install qdldl (a "
        "required dependency of the corotational and neo-Hookean models that pip installs with "
        "the package; on the colcon route it has no rosdep key, see docs/ros.md)"]
