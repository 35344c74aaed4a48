# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Real ROS 2 from PyPI: rclpy and our interfaces work with nothing sourced; ros-setup is safe.

These tests need the ``ros`` extra and ``python -m squeeze_grasp_ros.buildtool.interfaces`` to
have run (CI does both); they fail rather than skip without them. Under the colcon route
(``colcon test`` in a workspace whose overlay provides ``squeeze_grasp_interfaces``) the tests
about *this environment's* ros-setup build are skipped: there the interfaces come from the
workspace, not from ``sys.prefix``, and ros-setup is not how they were built.
"""
from __future__ import annotations

import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from squeeze_grasp_ros.buildtool import interfaces as ros_setup

WAIT_S = 10.0
CMAKE_TEMPLATE = """\
set_target_properties(pkg__rosidl_generator_py PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "{python};{numpy};${{_IMPORT_PREFIX}}/include"
)
"""
WHEEL_PYTHON = "/opt/python/cp312-cp312/include/python3.12"
WHEEL_NUMPY = "/opt/python/cp312-cp312/lib/python3.12/site-packages/numpy/_core/include"


def _interfaces_from_a_colcon_overlay() -> str | None:
    """Where ``squeeze_grasp_interfaces`` comes from when that is not this environment, else None.

    A missing package returns None, so the pip-route tests still fail (not skip) without it.
    """
    import importlib.util

    spec = importlib.util.find_spec("squeeze_grasp_interfaces")
    if spec is None or spec.origin is None:
        return None
    origin = Path(spec.origin).resolve()
    return None if origin.is_relative_to(Path(sys.prefix).resolve()) else str(origin.parent)


_OVERLAY = _interfaces_from_a_colcon_overlay()
pip_route_only = pytest.mark.skipif(
    _OVERLAY is not None,
    reason=f"colcon route: squeeze_grasp_interfaces comes from {_OVERLAY}, not from this "
           "environment's ros-setup build",
)


def spin_until(executor, condition: Callable[[], bool], timeout: float = WAIT_S) -> bool:
    """Spin ``executor`` one callback at a time until ``condition()`` holds or time runs out."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            return False
        executor.spin_once(timeout_sec=0.05)
    return True


# --------------------------------------------------------------------------- real rclpy


@pip_route_only
def test_rclpy_and_interfaces_import_from_this_environment() -> None:
    import rclpy

    import squeeze_grasp_interfaces.msg
    import squeeze_grasp_interfaces.srv

    prefix = Path(sys.prefix).resolve()
    for module in (rclpy, squeeze_grasp_interfaces.msg, squeeze_grasp_interfaces.srv):
        assert Path(module.__file__).resolve().is_relative_to(prefix)


def test_session_is_isolated(ros_context) -> None:
    domain_id = int(os.environ["ROS_DOMAIN_ID"])
    assert 1 <= domain_id <= 101
    assert os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert ros_context.get_domain_id() == domain_id


def test_interface_constants() -> None:
    from squeeze_grasp_interfaces.msg import ContactEvent, ContactNode
    from squeeze_grasp_interfaces.srv import LoadObject, PlanSqueeze

    assert (ContactNode.STICK, ContactNode.SLIP) == (0, 1)
    assert ContactEvent.NEW_CONTACT == "A" and ContactEvent.SLIP_TO_STICK == "D"
    codes = ("OK", "INVALID_ARGUMENT", "UNKNOWN_OBJECT", "NOT_FEASIBLE", "INTERNAL_ERROR",
             "CANCELLED")
    for response in (LoadObject.Response, PlanSqueeze.Response):
        assert [getattr(response, name) for name in codes] == list(range(6))
        assert {"success", "error_code", "message"} <= set(response.get_fields_and_field_types())


def test_nested_message_serialization_round_trip() -> None:
    from geometry_msgs.msg import Vector3
    from rclpy.serialization import deserialize_message, serialize_message

    from squeeze_grasp_interfaces.msg import ContactNode, SimState

    state = SimState(fingers=["F1", "F2"], termination="finger_slip")
    state.header.frame_id = "object"
    state.forces = [Vector3(x=1.5, y=-0.25), Vector3(x=-1.5, y=0.25)]
    contacts = state.contacts
    contacts.depth, contacts.relative_depth = 2e-3, 0.04
    contacts.fingers, contacts.nodes, contacts.modes = ["F1", "F2"], [3, 17], [0, 1]
    contacts.forces_x = [1.5, 0.0]
    assert list(contacts.modes) == [ContactNode.STICK, ContactNode.SLIP]
    assert deserialize_message(serialize_message(state), SimState) == state


def test_contact_event_publish_subscribe(ros_context) -> None:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from squeeze_grasp_interfaces.msg import ContactEvent

    node = rclpy.create_node("test_contact_events", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    received: list[ContactEvent] = []
    node.create_subscription(ContactEvent, "contact_events", received.append, 10)
    publisher = node.create_publisher(ContactEvent, "contact_events", 10)
    assert spin_until(executor, lambda: publisher.get_subscription_count() == 1)

    sent = ContactEvent(type=ContactEvent.STICK_TO_SLIP, node=7, finger="F2", depth=1.25e-3,
                        relative_depth=0.05)
    sent.header.frame_id = "object"
    sent.header.stamp.sec = 3
    publisher.publish(sent)
    assert spin_until(executor, lambda: len(received) == 1)
    assert received == [sent]
    executor.shutdown()
    node.destroy_node()


def test_plan_squeeze_service_round_trip(ros_context) -> None:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from squeeze_grasp_interfaces.srv import PlanSqueeze

    def reject(request: PlanSqueeze.Request, response: PlanSqueeze.Response):
        response.success = False
        response.error_code = PlanSqueeze.Response.UNKNOWN_OBJECT
        response.message = f"no object {request.object_id!r}"
        return response

    node = rclpy.create_node("test_plan_squeeze", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    node.create_service(PlanSqueeze, "plan_squeeze", reject)
    client = node.create_client(PlanSqueeze, "plan_squeeze")
    assert spin_until(executor, client.service_is_ready)

    request = PlanSqueeze.Request(object_id="disk", contacts=[0, 12],
                                  squeeze_type=PlanSqueeze.Request.STABLE)
    future = client.call_async(request)
    assert spin_until(executor, future.done)
    response = future.result()
    assert (response.success, response.error_code) == (False, PlanSqueeze.Response.UNKNOWN_OBJECT)
    assert response.message == "no object 'disk'"
    executor.shutdown()
    node.destroy_node()


# --------------------------------------------------------------------------- CMake path repair


def make_prefix(root: Path) -> dict[str, Path]:
    """Create a fake environment with broken, clean, non-CMake and out-of-prefix files."""
    broken = CMAKE_TEMPLATE.format(python=WHEEL_PYTHON, numpy=WHEEL_NUMPY)
    cmake_dir = root / "env" / "share" / "pkg" / "cmake"
    cmake_dir.mkdir(parents=True)
    files = {
        "broken": cmake_dir / "export_pkg__rosidl_generator_pyExport.cmake",
        "clean": cmake_dir / "pkgConfig.cmake",
        "not_cmake": cmake_dir / "notes.txt",
        "outside": root / "elsewhere" / "foreign.cmake",
        "link": cmake_dir / "link.cmake",
    }
    files["broken"].write_text(broken)
    files["clean"].write_text("set(pkg_FOUND TRUE)\n")
    files["not_cmake"].write_text(broken)
    files["outside"].parent.mkdir()
    files["outside"].write_text(broken)
    files["link"].symlink_to(files["outside"])
    return files


def test_repair_rewrites_only_cmake_files_inside_the_prefix(tmp_path: Path) -> None:
    files = make_prefix(tmp_path)
    before = {name: path.read_text() for name, path in files.items()}
    prefix = (tmp_path / "env").resolve()

    changed = ros_setup.repair_cmake_paths(prefix, "/env/include/py", "/env/numpy/include")

    assert changed == [files["broken"].resolve()]
    assert files["broken"].read_text() == CMAKE_TEMPLATE.format(
        python="/env/include/py", numpy="/env/numpy/include")
    for name in ("clean", "not_cmake", "outside"):
        assert files[name].read_text() == before[name]


def test_repair_is_idempotent_and_dry_run_writes_nothing(tmp_path: Path) -> None:
    files = make_prefix(tmp_path)
    prefix = (tmp_path / "env").resolve()
    broken = files["broken"].read_text()

    assert ros_setup.repair_cmake_paths(prefix, "/a", "/b", dry_run=True) == [
        files["broken"].resolve()]
    assert files["broken"].read_text() == broken
    assert len(ros_setup.repair_cmake_paths(prefix, "/a", "/b")) == 1
    repaired = files["broken"].read_text()
    assert ros_setup.repair_cmake_paths(prefix, "/a", "/b") == []
    assert files["broken"].read_text() == repaired


@pip_route_only
def test_this_environment_needs_no_repair() -> None:
    prefix = Path(sys.prefix)
    assert ros_setup.repair_cmake_paths(
        prefix, ros_setup.python_include_dir(), ros_setup.numpy_include_dir(), dry_run=True
    ) == []


def test_previous_install_is_removed_only_inside_the_prefix(tmp_path: Path) -> None:
    layout = ros_setup.Layout.for_prefix(tmp_path / "env")
    inside = layout.prefix / "share" / "pkg" / "msg" / "Old.msg"
    outside = tmp_path / "elsewhere" / "Old.msg"
    for path in (inside, outside):
        path.parent.mkdir(parents=True)
        path.write_text("float64 old\n")
    layout.state_dir.mkdir(parents=True)
    layout.manifest_file.write_text(f"{inside}\n{outside}\n{layout.prefix / 'gone.txt'}\n")

    ros_setup.remove_previous_install(layout)

    assert not inside.exists()
    assert outside.exists()


# --------------------------------------------------------------------------- prerequisites


@pip_route_only
def test_prerequisites_of_this_environment_hold() -> None:
    assert ros_setup.find_problems(Path(sys.prefix)) == []


def test_missing_prerequisites_are_named(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(sys, "prefix", sys.base_prefix)
    monkeypatch.setattr(shutil, "which", lambda name: None)
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.delenv("CXX", raising=False)

    problems = "\n".join(ros_setup.find_problems(tmp_path))

    for needle in ("virtual environment", "cmake", "C compiler", "C++ compiler",
                   "rosidl_default_generators", "pip install -e '.[ros]'"):
        assert needle in problems


def test_main_fails_clearly_outside_a_venv(monkeypatch, capsys) -> None:
    monkeypatch.setattr(sys, "prefix", sys.base_prefix)
    assert ros_setup.main(["--check"]) == 4  # the environment failed: the exit table's 4
    assert "not running in a virtual environment" in capsys.readouterr().err


def test_a_missing_cmake_exits_4_with_the_install_line(monkeypatch, capsys) -> None:
    real_which = shutil.which
    monkeypatch.setattr(shutil, "which", lambda name, *a, **k: None if name == "cmake"
                        else real_which(name, *a, **k))
    assert ros_setup.main([]) == 4
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["ros-setup: error: cmake not found on PATH: install it (e.g. apt-get install "
                   "cmake)"]


# --------------------------------------------------------------------------- idempotence


@pip_route_only
def test_second_run_is_a_no_op(capsys) -> None:
    assert ros_setup.main([]) == 0
    layout = ros_setup.Layout.for_prefix(Path(sys.prefix))
    import squeeze_grasp_interfaces.msg

    watched = [layout.stamp_file, Path(squeeze_grasp_interfaces.msg.__file__)]
    mtimes = [path.stat().st_mtime_ns for path in watched]
    capsys.readouterr()

    assert ros_setup.main([]) == 0
    assert "is up to date" in capsys.readouterr().out
    assert [path.stat().st_mtime_ns for path in watched] == mtimes
    assert ros_setup.main(["--check"]) == 0


def test_changed_interface_sources_are_detected(tmp_path: Path) -> None:
    source = ros_setup.default_source()
    copy = tmp_path / "msg_defs"
    shutil.copytree(source, copy)
    layout = ros_setup.Layout.for_prefix(Path(sys.prefix))
    settings = ros_setup.build_settings(layout, source)
    stamp = {"settings": settings, "sources": ros_setup.source_digest(source)}

    assert ros_setup.source_digest(copy) == stamp["sources"]
    assert ros_setup.rebuild_reason(stamp, settings, stamp["sources"], True) is None
    assert "missing" in ros_setup.rebuild_reason(stamp, settings, stamp["sources"], False)
    assert "not built" in ros_setup.rebuild_reason(None, settings, stamp["sources"], True)

    with (copy / "msg" / "ContactEvent.msg").open("a") as handle:
        handle.write("float64 extra\n")
    changed = ros_setup.source_digest(copy)
    assert changed != stamp["sources"]
    assert "sources changed" in ros_setup.rebuild_reason(stamp, settings, changed, True)
    other_folder = ros_setup.build_settings(layout, copy)
    assert "settings changed" in ros_setup.rebuild_reason(stamp, other_folder, changed, True)


@pip_route_only
def test_check_reports_a_changed_source_folder_of_this_environment(tmp_path: Path,
                                                                    capsys) -> None:
    copy = tmp_path / "msg_defs"
    shutil.copytree(ros_setup.default_source(), copy)
    assert ros_setup.main(["--check", "--source", str(copy)]) == 1
    assert "settings changed" in capsys.readouterr().out


@pip_route_only
def test_the_default_source_is_the_repository_s_from_any_folder(tmp_path: Path,
                                                                 monkeypatch) -> None:
    """``squeeze-grasp ros-setup`` of an editable install finds ``msg_defs/`` next to the
    package wherever it is run (the interface build once looked inside the package folder).
    """
    monkeypatch.chdir(tmp_path)
    source = ros_setup.default_source()
    assert (source / "package.xml").is_file() and source.parent == Path(ros_setup.__file__
                                                                        ).parents[2]


def test_hidden_files_do_not_change_the_digest(tmp_path: Path) -> None:
    copy = tmp_path / "msg_defs"
    shutil.copytree(ros_setup.default_source(), copy)
    digest = ros_setup.source_digest(copy)
    (copy / "msg" / ".ContactEvent.msg.swp").write_text("editor state")
    assert ros_setup.source_digest(copy) == digest


@pytest.mark.parametrize("missing", ["package.xml", "CMakeLists.txt"])
def test_source_without_package_files_is_rejected(tmp_path: Path, missing: str) -> None:
    for name in ("package.xml", "CMakeLists.txt"):
        if name != missing:
            (tmp_path / name).write_text("")
    with pytest.raises(ros_setup.SetupError, match=missing):
        ros_setup.resolve_source(tmp_path)


# --------------------------------------------------------------------------- control_msgs
def fake_control_msgs(root: Path, *, parallel: bool = True) -> Path:
    """A control_msgs package folder with the gripper interfaces (and one more)."""
    from squeeze_grasp_ros.buildtool import control_msgs

    package = root / "control_msgs"
    package.mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>control_msgs</name></package>")
    for name in (*control_msgs.INTERFACES, "msg/JointJog.msg"):
        if parallel or "Parallel" not in name:
            (package / name).parent.mkdir(parents=True, exist_ok=True)
            (package / name).write_text(f"# {name}\n")
    return package


def test_control_msgs_stages_only_the_gripper_interfaces(tmp_path):
    from squeeze_grasp_ros.buildtool import control_msgs

    package = fake_control_msgs(tmp_path / "checkout")
    for given in (tmp_path / "checkout", package):    # the checkout or its package folder
        assert control_msgs.package_folder(given) == package
    staged = control_msgs.stage(package, tmp_path / "staged")
    files = sorted(p.relative_to(staged).as_posix() for p in staged.rglob("*") if p.is_file())
    assert files == sorted(["CMakeLists.txt", "package.xml", *control_msgs.INTERFACES])
    cmake = (staged / "CMakeLists.txt").read_text()
    assert "project(control_msgs)" in cmake and "JointJog" not in cmake
    assert all(name in cmake for name in control_msgs.INTERFACES)
    digest = ros_setup.source_digest(staged)
    control_msgs.stage(package, tmp_path / "staged")   # staged again: the same build stamp
    assert ros_setup.source_digest(staged) == digest


def test_control_msgs_sources_that_are_not_jazzy_are_refused_exit_2(tmp_path, capsys):
    from squeeze_grasp_ros.buildtool import control_msgs

    with pytest.raises(ros_setup.SourceError, match="no control_msgs package.xml"):
        control_msgs.package_folder(tmp_path)
    old = fake_control_msgs(tmp_path / "humble", parallel=False)
    with pytest.raises(ros_setup.SourceError, match="is not Jazzy's control_msgs \\(missing "
                       "action/ParallelGripperCommand.action\\)"):
        control_msgs.package_folder(old)
    if not ros_setup.find_problems(Path(sys.prefix)):
        assert ros_setup.main(["--control-msgs", str(tmp_path / "nothing")]) == 2
        assert "no control_msgs package.xml" in capsys.readouterr().err


def test_without_sources_ros_setup_says_why_control_msgs_is_not_built(monkeypatch, capsys,
                                                                       tmp_path):
    from squeeze_grasp_ros.buildtool import control_msgs

    monkeypatch.delenv(control_msgs.ENV_VAR, raising=False)
    assert control_msgs.source_argument(None) is None
    monkeypatch.setenv(control_msgs.ENV_VAR, str(tmp_path))
    assert control_msgs.source_argument(None) == tmp_path
    monkeypatch.setitem(sys.modules, "control_msgs", None)   # as on a fresh machine
    control_msgs.setup(tmp_path, None, force=False, verbose=False)
    assert "control_msgs: not built (no sources given: --control-msgs DIR or " \
           "SQUEEZE_GRASP_CONTROL_MSGS=DIR" in capsys.readouterr().out
