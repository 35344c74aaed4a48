# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Build the interface package ``squeeze_grasp_interfaces`` into the active virtual environment.

The ``ros`` extra of this project installs ROS 2 Jazzy from PyPI wheels. This module finishes
the job without anything sourced:

1. check the prerequisites (a virtual environment, Python 3.10-3.13, cmake, a C/C++ compiler,
   the ROS wheels);
2. repair the wheels' CMake files, which hard-code the include directories of the machine that
   built them (``/opt/python/cpXY-cpXY/...``), to this environment's own directories;
3. configure, build and install ``msg_defs/`` with plain cmake into ``sys.prefix``, so the
   generated Python package lands in the environment's site-packages and its libraries in
   ``<prefix>/lib``;
4. record a stamp (sources digest + build settings) so a second run is a fast no-op.

It never imports rclpy (it runs before rclpy can load our interfaces), so it is a build tool,
not part of ``ros/``. Run it as ``python -m squeeze_grasp_ros.buildtool.interfaces`` (or the
``squeeze-grasp ros-setup`` verb).
"""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import hashlib
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from squeeze_grasp_ros.exit_codes import ExitCode

INTERFACE_PACKAGE = "squeeze_grasp_interfaces"
INTERFACE_MODULES = (f"{INTERFACE_PACKAGE}.msg", f"{INTERFACE_PACKAGE}.srv")
"""What a build of the interfaces must make importable."""
INSTALL_HINT = "pip install -e '.[ros]'"
MIN_PYTHON = (3, 10)
MAX_PYTHON = (3, 13)
# CMake packages under <prefix>/share that the build needs; several come from wheels that the
# metadata of rosidl_default_generators / ament_cmake does not pull in.
REQUIRED_CMAKE_PACKAGES = (
    "ament_cmake",
    "ament_cmake_ros",
    "ament_cmake_include_directories",
    "ament_cmake_gtest",
    "ament_cmake_gmock",
    "ament_cmake_pytest",
    "python_cmake_module",
    "rosidl_default_generators",
    "rosidl_core_generators",
    "rosidl_default_runtime",
    "std_msgs",
    "geometry_msgs",
    "action_msgs",
)
REQUIRED_MODULES = ("rclpy", "ament_package", "catkin_pkg", "numpy")
C_COMPILERS = ("cc", "gcc", "clang")
CXX_COMPILERS = ("c++", "g++", "clang++")
# Paths of the wheel builder baked into the wheels' exported CMake targets.
_WHEEL_PYTHON_INCLUDE = re.compile(r"/opt/python/cp3\d+-cp3\d+t?/include/python3\.\d+t?")
_WHEEL_NUMPY_INCLUDE = re.compile(
    r"/opt/python/cp3\d+-cp3\d+t?/lib/python3\.\d+t?/site-packages/numpy/(?:_core|core)/include"
)
_CMAKE_DIRS = ("share", "lib/cmake")


class SetupError(RuntimeError):
    """A step of the setup failed; the message says what to do."""


class SourceError(SetupError):
    """A source folder given on the command line is not what it must be (exit 2)."""


@dataclass(frozen=True)
class Layout:
    """Where things go inside the environment.

    Attributes
    ----------
    prefix : Path
        ``sys.prefix`` of the active virtual environment (the install prefix).
    state_dir : Path
        ``<prefix>/var/squeeze_grasp_ros``: stamp, install manifest, lock, build tree.
    """

    prefix: Path
    state_dir: Path

    @classmethod
    def for_prefix(cls, prefix: Path) -> Layout:
        """Return the layout of the environment at ``prefix``."""
        return cls(prefix=prefix, state_dir=prefix / "var" / "squeeze_grasp_ros")

    @property
    def build_dir(self) -> Path:
        """CMake build tree (never inside the repository)."""
        return self.state_dir / "build"

    @property
    def stamp_file(self) -> Path:
        """JSON stamp of the last successful build."""
        return self.state_dir / "stamp.json"

    @property
    def manifest_file(self) -> Path:
        """Files installed by the last successful build (CMake's install manifest)."""
        return self.state_dir / "install_manifest.txt"

    @property
    def log_file(self) -> Path:
        """Output of cmake when not run with ``--verbose``."""
        return self.state_dir / "build.log"


def say(text: str) -> None:
    """Print one line of progress."""
    print(f"ros-setup: {text}", flush=True)


# --------------------------------------------------------------------------- prerequisites


def in_virtualenv() -> bool:
    """Return True when the running interpreter belongs to a virtual environment."""
    return sys.prefix != sys.base_prefix


def find_problems(prefix: Path) -> list[str]:
    """Check every prerequisite of the build.

    Parameters
    ----------
    prefix : Path
        Environment prefix expected to hold the ROS wheels.

    Returns
    -------
    list of str
        One message per missing prerequisite, naming it and the fix; empty when all is there.
    """
    problems: list[str] = []
    if not in_virtualenv():
        problems.append(
            "not running in a virtual environment: create one and activate it "
            "(python3 -m venv .venv && . .venv/bin/activate), then " + INSTALL_HINT
        )
    if not MIN_PYTHON <= sys.version_info[:2] <= MAX_PYTHON:
        problems.append(
            f"Python {sys.version_info.major}.{sys.version_info.minor} is not supported by the "
            "ROS 2 Jazzy wheels: use Python 3.10, 3.11, 3.12 or 3.13"
        )
    if shutil.which("cmake") is None:
        problems.append("cmake not found on PATH: install it (e.g. apt-get install cmake)")
    if _find_compiler("CC", C_COMPILERS) is None:
        problems.append("no C compiler found (cc, gcc, clang or $CC): install gcc")
    if _find_compiler("CXX", CXX_COMPILERS) is None:
        problems.append("no C++ compiler found (c++, g++, clang++ or $CXX): install g++")
    missing = missing_ros_parts(prefix)
    if missing:
        problems.append(
            f"ROS 2 wheels not installed in {prefix} (missing: {', '.join(missing)}): "
            f"run {INSTALL_HINT}"
        )
    return problems


def _find_compiler(variable: str, candidates: Sequence[str]) -> str | None:
    """Return the compiler named by ``$variable`` or the first candidate on PATH."""
    names = [os.environ[variable]] if os.environ.get(variable) else list(candidates)
    for name in names:
        found = shutil.which(name.split()[0])
        if found:
            return found
    return None


def missing_ros_parts(prefix: Path) -> list[str]:
    """Return the Python modules and CMake packages of the ROS wheels that are absent."""
    modules = [name for name in REQUIRED_MODULES if importlib.util.find_spec(name) is None]
    packages = [
        name
        for name in REQUIRED_CMAKE_PACKAGES
        if not (prefix / "share" / name / "cmake").is_dir()
    ]
    return modules + packages


# --------------------------------------------------------------------------- CMake path repair


def numpy_include_dir() -> str:
    """Return numpy's C include directory of this environment."""
    import numpy

    return numpy.get_include()


def python_include_dir() -> str:
    """Return the C include directory of the running Python (``Python.h``)."""
    return sysconfig.get_paths()["include"]


def rewrite_wheel_paths(text: str, python_include: str, numpy_include: str) -> str:
    """Replace the wheel builder's include paths in ``text`` with this environment's.

    Parameters
    ----------
    text : str
        Content of a CMake file.
    python_include, numpy_include : str
        Replacement directories.

    Returns
    -------
    str
        The repaired text (identical to ``text`` when nothing needed repair).
    """
    text = _WHEEL_NUMPY_INCLUDE.sub(lambda _: numpy_include, text)
    return _WHEEL_PYTHON_INCLUDE.sub(lambda _: python_include, text)


def repair_cmake_paths(
    prefix: Path, python_include: str, numpy_include: str, *, dry_run: bool = False
) -> list[Path]:
    """Repair the hard-coded include paths in the ``*.cmake`` files of an environment.

    Only regular files whose real path lies inside ``prefix`` are read or written: a symlink
    that leads out of the prefix is left alone. Running it twice changes nothing the second
    time.

    Parameters
    ----------
    prefix : Path
        Environment prefix; ``<prefix>/share`` and ``<prefix>/lib/cmake`` are searched.
    python_include, numpy_include : str
        This environment's include directories.
    dry_run : bool
        Only report the files that need repair.

    Returns
    -------
    list of Path
        Files that were (or, with ``dry_run``, would be) changed, sorted.
    """
    root = prefix.resolve()
    changed: list[Path] = []
    for path in _cmake_files(root):
        text = path.read_text(encoding="utf-8", errors="surrogateescape")
        repaired = rewrite_wheel_paths(text, python_include, numpy_include)
        if repaired == text:
            continue
        changed.append(path)
        if not dry_run:
            _replace_file(path, repaired)
    return sorted(changed)


def _cmake_files(root: Path) -> Iterator[Path]:
    """Yield the regular ``*.cmake`` files below ``root``'s CMake dirs that resolve inside it."""
    for sub in _CMAKE_DIRS:
        for path in (root / sub).rglob("*.cmake"):
            if path.is_file() and not path.is_symlink() and path.resolve().is_relative_to(root):
                yield path


def _replace_file(path: Path, text: str) -> None:
    """Atomically replace ``path``'s content, keeping its permissions."""
    tmp = path.with_name(path.name + ".sgr-tmp")
    tmp.write_text(text, encoding="utf-8", errors="surrogateescape")
    shutil.copymode(path, tmp)
    os.replace(tmp, path)


# --------------------------------------------------------------------------- stamp


def source_digest(source: Path) -> str:
    """Return a SHA-256 over the relative paths and contents of the files of ``source``.

    Hidden files and folders (editor and VCS leftovers) are ignored.
    """
    digest = hashlib.sha256()
    for path in sorted(source.rglob("*")):
        rel = path.relative_to(source)
        if not path.is_file() or any(part.startswith(".") for part in rel.parts):
            continue
        digest.update(rel.as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def venv_python() -> str:
    """The environment's ``bin/python``: the same whether we run as ``python -m`` or as a
    console script (whose ``sys.executable`` is ``bin/python3``).
    """
    candidate = Path(sys.prefix) / "bin" / "python"
    return str(candidate) if candidate.exists() else sys.executable


def build_settings(layout: Layout, source: Path) -> dict[str, object]:
    """Return everything besides the sources that determines the build's result."""
    return {
        "python": sys.version,
        "executable": venv_python(),
        "source": str(source),
        "cmake_args": cmake_configure_args(layout, source),
    }


def read_stamp(layout: Layout) -> dict[str, object] | None:
    """Return the stamp of the last successful build, or None."""
    try:
        return json.loads(layout.stamp_file.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def write_stamp(layout: Layout, settings: dict[str, object], digest: str) -> None:
    """Record a successful build."""
    stamp = {"settings": settings, "sources": digest}
    layout.stamp_file.write_text(json.dumps(stamp, indent=1, sort_keys=True), encoding="utf-8")


def rebuild_reason(
    stamp: dict[str, object] | None, settings: dict[str, object], digest: str, installed: bool,
    *, package: str = INTERFACE_PACKAGE,
) -> str | None:
    """Say why the interfaces must be built, or return None when they are current.

    Parameters
    ----------
    stamp : dict or None
        Stamp of the last successful build (see `write_stamp`).
    settings : dict
        Current `build_settings`.
    digest : str
        Current `source_digest` of the interface folder.
    installed : bool
        Whether the package is importable from the environment.
    package : str
        The package's name (for the message).

    Returns
    -------
    str or None
        The reason for a build, None when the installed interfaces are current.
    """
    if stamp is None:
        return "not built in this environment yet"
    if stamp.get("settings") != settings:
        return "build settings changed (Python, interface folder or CMake arguments)"
    if stamp.get("sources") != digest:
        return "interface sources changed"
    if not installed:
        return f"{package} is missing from the environment"
    return None


def interfaces_installed(prefix: Path, package: str = INTERFACE_PACKAGE) -> bool:
    """Return True when ``package`` is importable from inside ``prefix``."""
    spec = importlib.util.find_spec(package)
    origin = spec.origin if spec is not None else None
    return origin is not None and Path(origin).resolve().is_relative_to(prefix.resolve())


# --------------------------------------------------------------------------- build


def cmake_configure_args(layout: Layout, source: Path) -> list[str]:
    """Return the ``cmake`` configure command line."""
    purelib = Path(sysconfig.get_paths()["purelib"])
    return [
        "cmake",
        "-S",
        str(source),
        "-B",
        str(layout.build_dir),
        f"-DCMAKE_INSTALL_PREFIX={layout.prefix}",
        f"-DCMAKE_PREFIX_PATH={layout.prefix}",
        f"-DPython3_EXECUTABLE={venv_python()}",
        f"-DPYTHON_INSTALL_DIR={purelib.relative_to(layout.prefix).as_posix()}",
        "-DBUILD_TESTING=OFF",
    ]


def build_environment(prefix: Path) -> dict[str, str]:
    """Return the environment for cmake: this venv first on PATH, nothing else sourced."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(prefix / "bin"), env.get("PATH", "")])
    env["AMENT_PREFIX_PATH"] = str(prefix)
    env["CMAKE_PREFIX_PATH"] = str(prefix)
    return env


def run_command(command: Sequence[str], layout: Layout, verbose: bool) -> None:
    """Run one build command; output goes to the terminal or to the log file.

    Raises
    ------
    SetupError
        The command failed; the message holds the tail of its output.
    """
    env = build_environment(layout.prefix)
    if verbose:
        result = subprocess.run(command, env=env, check=False)
        if result.returncode != 0:
            raise SetupError(f"{' '.join(command[:2])} failed (exit {result.returncode})")
        return
    with layout.log_file.open("a", encoding="utf-8") as log:
        log.write(f"$ {' '.join(command)}\n")
        log.flush()
        result = subprocess.run(
            command, env=env, stdout=log, stderr=subprocess.STDOUT, check=False
        )
    if result.returncode != 0:
        tail = layout.log_file.read_text(encoding="utf-8", errors="replace").splitlines()[-25:]
        raise SetupError(
            f"{' '.join(command[:2])} failed (exit {result.returncode}); "
            f"last lines of {layout.log_file}:\n" + "\n".join(tail)
        )


def remove_previous_install(layout: Layout) -> None:
    """Delete the files the previous build installed (only those inside the prefix)."""
    if not layout.manifest_file.is_file():
        return
    root = layout.prefix.resolve()
    for line in layout.manifest_file.read_text(encoding="utf-8").splitlines():
        path = Path(line)
        if line and path.is_file() and path.resolve().is_relative_to(root):
            path.unlink()


def build_and_install(layout: Layout, source: Path, verbose: bool) -> None:
    """Configure, build and install ``source`` into the environment prefix.

    The build tree is always recreated: rosidl never deletes the generated files of a removed
    interface, and an incremental build saves almost nothing.
    """
    if layout.build_dir.exists():
        shutil.rmtree(layout.build_dir)
    layout.build_dir.mkdir(parents=True, exist_ok=True)
    layout.log_file.write_text("", encoding="utf-8")
    say(f"configuring {source} (log: {layout.log_file})")
    run_command(cmake_configure_args(layout, source), layout, verbose)
    jobs = str(os.cpu_count() or 1)
    say(f"building with {jobs} jobs")
    run_command(["cmake", "--build", str(layout.build_dir), "-j", jobs], layout, verbose)
    remove_previous_install(layout)
    say(f"installing into {layout.prefix}")
    run_command(["cmake", "--install", str(layout.build_dir)], layout, verbose)
    shutil.copyfile(layout.build_dir / "install_manifest.txt", layout.manifest_file)


def verify_import(prefix: Path, modules: Sequence[str] = INTERFACE_MODULES) -> None:
    """Import the generated ``modules`` in a fresh interpreter of the environment.

    Raises
    ------
    SetupError
        The import failed.
    """
    code = f"import {', '.join(modules)}"
    result = subprocess.run(
        [sys.executable, "-c", code],
        env=build_environment(prefix),
        capture_output=True,
        text=True,
        check=False,
    )
    if result.returncode != 0:
        raise SetupError(f"built, but `{code}` fails:\n{result.stderr.strip()}")


# --------------------------------------------------------------------------- command line


def default_source() -> Path:
    """Return ``msg_defs/`` next to the package (editable install) or in the working dir."""
    candidates = [Path(__file__).resolve().parents[2] / "msg_defs", Path.cwd() / "msg_defs"]
    for candidate in candidates:
        if (candidate / "package.xml").is_file():
            return candidate
    return candidates[-1]


DESCRIPTION = (
    "Repair the ROS 2 wheels' CMake files and build the interface package "
    f"{INTERFACE_PACKAGE} (msg_defs/) into the active virtual environment."
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``ros-setup`` (shared by this module's CLI and the ``squeeze-grasp`` verb)."""
    parser.add_argument(
        "--source",
        type=Path,
        default=None,
        metavar="DIR",
        help="interface package folder (default: the repository's msg_defs/)",
    )
    parser.add_argument(
        "--control-msgs",
        type=Path,
        default=None,
        metavar="DIR",
        help="also build control_msgs' gripper actions from its Jazzy sources in DIR (default: "
        "$SQUEEZE_GRASP_CONTROL_MSGS; without either, control_msgs is not built)",
    )
    parser.add_argument("--force", action="store_true", help="rebuild even when up to date")
    parser.add_argument("--verbose", action="store_true", help="show cmake's output")
    parser.add_argument(
        "--check", action="store_true", help="only report the state; exit 1 if work is due"
    )


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    parser = argparse.ArgumentParser(
        prog="squeeze-grasp ros-setup", description=DESCRIPTION,
        epilog="exit status: 0 ready; 1 (--check) something is due; 2 invalid option; 4 a "
               "prerequisite is missing (cmake, a compiler, the ROS wheels, a virtual "
               "environment) or the build failed")
    add_arguments(parser)
    return parser.parse_args(argv)


@contextlib.contextmanager
def state_lock(layout: Layout) -> Iterator[None]:
    """Hold an exclusive lock on the environment's state folder (one build at a time)."""
    layout.state_dir.mkdir(parents=True, exist_ok=True)
    with (layout.state_dir / "lock").open("w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def resolve_source(arg: Path | None) -> Path:
    """Return the absolute interface source folder, checking that it is one."""
    source = (arg if arg is not None else default_source()).resolve()
    for name in ("package.xml", "CMakeLists.txt"):
        if not (source / name).is_file():
            raise SetupError(
                f"{source} has no {name}: pass the interface folder with --source DIR"
            )
    return source


def report(layout: Layout, source: Path) -> int:
    """Print the state of the environment (``--check``); return 0 when nothing is due."""
    to_repair = repair_cmake_paths(
        layout.prefix, python_include_dir(), numpy_include_dir(), dry_run=True
    )
    reason = rebuild_reason(
        read_stamp(layout),
        build_settings(layout, source),
        source_digest(source),
        interfaces_installed(layout.prefix),
    )
    say(f"CMake files to repair: {len(to_repair)}")
    say(f"{INTERFACE_PACKAGE}: {reason or 'up to date'}")
    return 0 if not to_repair and reason is None else 1


def setup(layout: Layout, source: Path, force: bool, verbose: bool) -> None:
    """Repair the CMake files and build the interfaces when due."""
    repaired = repair_cmake_paths(layout.prefix, python_include_dir(), numpy_include_dir())
    if repaired:
        say(f"repaired wheel include paths in {len(repaired)} CMake files")
    build_package(layout, source, force=force, verbose=verbose)


def build_package(layout: Layout, source: Path, *, package: str = INTERFACE_PACKAGE,
                  modules: Sequence[str] = INTERFACE_MODULES, force: bool,
                  verbose: bool) -> None:
    """Build and install the interface package ``package`` from ``source`` when due (its
    stamp, build tree and manifest in ``layout.state_dir``), then import ``modules``.
    """
    settings = build_settings(layout, source)
    digest = source_digest(source)
    reason = rebuild_reason(
        read_stamp(layout), settings, digest, interfaces_installed(layout.prefix, package),
        package=package,
    )
    if reason is None and not force:
        say(f"{package} is up to date (--force rebuilds)")
        return
    say(f"building {package}: {reason or 'forced'}")
    start = time.monotonic()
    build_and_install(layout, source, verbose)
    verify_import(layout.prefix, modules)
    write_stamp(layout, settings, digest)
    say(f"built {package} in {time.monotonic() - start:.1f} s")


def main(argv: list[str] | None = None) -> int:
    """Run ``ros-setup``; return the process exit code."""
    return run(parse_args(argv))


def run(args: argparse.Namespace) -> int:
    """Run ``ros-setup`` with parsed options; return the process exit code."""
    from squeeze_grasp_ros.buildtool import control_msgs  # it builds on this module

    layout = Layout.for_prefix(Path(sys.prefix))
    problems = find_problems(layout.prefix)
    say(f"environment {layout.prefix} (Python {sys.version.split()[0]})")
    if problems:
        for problem in problems:
            print(f"ros-setup: error: {problem}", file=sys.stderr)
        return ExitCode.INTERNAL
    try:
        source = resolve_source(args.source)
        if args.check:
            code = report(layout, source)
            say(control_msgs.state(layout.prefix))
            return code
        with state_lock(layout):
            setup(layout, source, args.force, args.verbose)
            control_msgs.setup(layout.prefix, control_msgs.source_argument(args.control_msgs),
                               force=args.force, verbose=args.verbose)
    except SetupError as error:
        print(f"ros-setup: error: {error}", file=sys.stderr)
        return ExitCode.USAGE if isinstance(error, SourceError) else ExitCode.INTERNAL
    return ExitCode.OK


if __name__ == "__main__":
    sys.exit(main())
