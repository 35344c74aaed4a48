# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The colcon route, as a ROS user takes it: build with colcon, source ``install/setup.bash``,
run the installed executables from a folder outside the repository.

colcon (from PyPI) builds ``msg_defs`` (the interface package) and ``.`` (this ament_python
package) against the ROS 2 of this environment. The interface package takes 2-3 minutes to
build, so it is built once per content of ``msg_defs/`` into a cache folder (an underlay, as a
ROS installation would be); this package is built into a fresh install base on every run (the
overlay). The environment is exactly what sourcing both ``setup.bash`` files gives; the test
checks that the package, its interfaces and its data files are the installed ones.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
CACHE = Path(
    os.environ.get(
        "SQUEEZE_GRASP_COLCON_CACHE",
        Path.home() / ".cache" / "squeeze_grasp_ros" / "colcon-interfaces",
    )
)


def colcon_build(paths: list[Path], base: Path, env: dict[str, str]) -> None:
    """``colcon build --paths PATHS`` with build, install and log folders under ``base``."""
    colcon = shutil.which("colcon", path=str(Path(sys.executable).parent)) or shutil.which(
        "colcon"
    )
    assert colcon, "colcon is not installed (pip install -e '.[test]' brings it)"
    prefix = sys.prefix
    env = {
        **env,
        "CMAKE_PREFIX_PATH": os.pathsep.join(
            filter(None, [env.get("CMAKE_PREFIX_PATH", ""), prefix])
        ),
    }
    done = subprocess.run(
        [
            colcon,
            "--log-base",
            str(base / "log"),
            "build",
            "--paths",
            *map(str, paths),
            "--build-base",
            str(base / "build"),
            "--install-base",
            str(base / "install"),
            "--cmake-args",
            "-DBUILD_TESTING=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
        ],
        cwd=base,
        env=env,
        capture_output=True,
        text=True,
        timeout=1200,
    )
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]


def sourced(setup_files: list[Path], env: dict[str, str]) -> dict[str, str]:
    """The environment after ``source``-ing each ``setup.bash`` in turn."""
    script = "".join(f"source '{f}' && " for f in setup_files) + "env -0"
    out = subprocess.run(["bash", "-c", script], env=env, capture_output=True, check=True).stdout
    return dict(item.split("=", 1) for item in out.decode().split("\0") if "=" in item)


def interfaces_underlay(env: dict[str, str]) -> Path:
    """``install/setup.bash`` of the interface package, built once per content into the cache."""
    digest = hashlib.sha256()
    for path in sorted((REPO / "msg_defs").rglob("*")):
        if path.is_file():
            digest.update(str(path.relative_to(REPO)).encode() + path.read_bytes())
    digest.update(f"{sys.prefix} {platform.python_version()}".encode())
    base = CACHE / digest.hexdigest()[:16]
    base.mkdir(parents=True, exist_ok=True)
    setup = base / "install" / "setup.bash"
    with open(base / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (base / "complete").is_file():
            shutil.rmtree(base / "install", ignore_errors=True)
            colcon_build([REPO / "msg_defs"], base, env)
            (base / "complete").write_text("built\n")
    return setup


@pytest.fixture(scope="module")
def workspace(tmp_path_factory) -> dict:
    """The colcon install and the environment its setup files give, outside the repository."""
    base = tmp_path_factory.mktemp("colcon_ws")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("AMENT_", "COLCON_"))}
    env["AMENT_PREFIX_PATH"] = sys.prefix
    underlay = interfaces_underlay(env)
    overlay_env = sourced([underlay], env)
    colcon_build([REPO], base, overlay_env)
    install = base / "install" / "squeeze_grasp_ros"
    return {
        "env": sourced([underlay, base / "install" / "setup.bash"], env),
        "install": install,
        "bin": install / "lib" / "squeeze_grasp_ros",
        "outside": tmp_path_factory.mktemp("user_folder"),
    }


def run_installed(ws: dict, *args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(ws["bin"] / args[0]), *args[1:]],
        cwd=ws["outside"],
        env=ws["env"],
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_installed_package_is_the_one_that_runs(workspace):
    probe = (
        "import json, squeeze_grasp_ros, squeeze_grasp_interfaces; "
        "from squeeze_grasp_ros.resources import share_dir; "
        "print(json.dumps([squeeze_grasp_ros.__file__, squeeze_grasp_interfaces.__file__, "
        "str(share_dir())]))"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe],
        cwd=workspace["outside"],
        env=workspace["env"],
        capture_output=True,
        text=True,
        check=True,
    )
    package, interfaces, share = json.loads(done.stdout.splitlines()[-1])
    assert Path(package).is_relative_to(workspace["install"])
    assert not Path(interfaces).is_relative_to(REPO)
    assert Path(share) == workspace["install"] / "share" / "squeeze_grasp_ros"
    for name in ("squeeze-grasp", "planner", "executor", "monitor", "sim_hardware", "recorder"):
        assert (workspace["bin"] / name).is_file(), name
    for name in ("sim_pipeline.launch.py", "hardware.launch.py", "planner.launch.py"):
        assert (Path(share) / "launch" / name).is_file(), name
    for name in ("squeeze_grasp.rviz", "foxglove_layout.json"):
        assert (Path(share) / "config" / "viewers" / name).is_file(), name


def test_run_and_replay_from_the_install(workspace):
    share = workspace["install"] / "share" / "squeeze_grasp_ros"
    bag = workspace["outside"] / "foam_run"
    run = run_installed(
        workspace,
        "squeeze-grasp",
        "run",
        str(share / "config" / "scenes" / "foam_square.yaml"),
        "--record",
        str(bag),
        "--json",
    )
    assert run.returncode == 0, run.stderr[-3000:]
    summary = json.loads(run.stdout)
    assert summary["success"] is True and summary["recording"] == str(bag)
    assert (bag / "metadata.yaml").is_file()
    replay = run_installed(workspace, "squeeze-grasp", "replay", str(bag))
    assert replay.returncode == 0, replay.stderr[-3000:]
    assert "reproduced exactly" in replay.stdout


def test_package_xml_declares_every_ros_package_the_code_imports():
    """What rosdep installs is what package.xml declares: every ROS interface package imported
    by the package or its launch files (``*_msgs``, ``*_interfaces``) is an ``exec_depend``
    (none is built against: the package is pure Python).
    """
    import re
    import xml.etree.ElementTree as ET

    imported = set()
    for folder in ("squeeze_grasp_ros", "launch"):
        for path in (REPO / folder).rglob("*.py"):
            imported |= set(re.findall(r"^\s*(?:from|import) ([a-z_]+(?:_msgs|_interfaces))\b",
                                       path.read_text(), flags=re.M))
    manifest = ET.parse(REPO / "package.xml").getroot()
    declared = {e.text for e in manifest.findall("exec_depend")}
    assert {"control_msgs", "trajectory_msgs", "sensor_msgs"} <= imported
    assert sorted(imported - declared) == []
    assert not {e.text for e in manifest.findall("build_depend")} & imported
