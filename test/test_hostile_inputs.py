# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Hostile and careless inputs: each case ends in a clean error (or the right outcome), the node
stays up, and no error message quotes a file's contents.

Cases: polygons that are not simple (they crashed the mesher), paths outside the planner's
allowed folders, files whose contents must not leak, YAML alias bombs, oversized and non-UTF-8
files.
"""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from planner_support import BLOB, Harness
from rclpy.context import Context

from squeeze_grasp_interfaces.srv import LoadObject
from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.inputs import MAX_FILE_BYTES
from squeeze_grasp_ros.planning import ErrorCode
from squeeze_grasp_ros.scene import SceneError, build_mesh, parse_scene

SPIKE = [[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [0.0, 0.0], [-0.05, 0.05], [0.0, 0.0]]
"""A square with a vertex repeated at a non-adjacent position: a zero-width spike that made the
``triangle`` mesher segfault in about half the calls."""
SECRET = "SECRET-MARKER-7f3a9c"
"""Text planted in files that must never appear in an error message."""
ALIAS_BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + k)}: &{chr(98 + k)} [*{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, "
    f"*{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, "
    f"*{chr(97 + k)}]\n"
    for k in range(8)
)
"""Nine levels of nine-fold aliases: 9^9 strings once expanded, under 1 kB of text."""


def scene_with_shape(shape: dict) -> dict:
    data = yaml.safe_load(BLOB)
    data["object"]["shape"] = shape
    return data


@pytest.fixture()
def planner(ros_context: Context, tmp_path: Path) -> Iterator[Harness]:
    """A planner whose allowed folder is ``tmp_path/allowed``."""
    from rclpy.parameter import Parameter

    (tmp_path / "allowed").mkdir()
    harness = Harness(
        ros_context,
        parameter_overrides=[Parameter("allowed_roots", value=[str(tmp_path / "allowed")])],
    )
    try:
        yield harness
    finally:
        harness.close()


def load(harness: Harness, **fields) -> LoadObject.Response:
    return harness.call(LoadObject, "load_object", LoadObject.Request(**fields))


def assert_alive(harness: Harness) -> None:
    response = load(harness, scene_yaml=BLOB, object_id="alive")
    assert response.success, response.message


def test_spike_polygon_is_refused_before_meshing():
    with pytest.raises(SceneError, match="self-intersecting"):
        build_mesh(parse_scene(scene_with_shape({"type": "polygon", "points": SPIKE})))


def test_random_grid_polygons_never_crash_the_mesher():
    """300 random polygons on a coarse grid (repeated vertices, collinear runs and touching
    edges are frequent) are either refused or meshed, in a child process that must not die.
    """
    child = """
import numpy as np
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
rng = np.random.default_rng(2014)
meshed = refused = 0
for _ in range(300):
    pts = rng.integers(0, 5, size=(rng.integers(3, 9), 2)) * 0.01
    try:
        outline = shapes.polygon(pts.tolist())
    except InvalidInputError:
        refused += 1
        continue
    mesh = generate_mesh(outline, outline.area / 40, min_angle=25.0)
    assert mesh.n >= 3
    meshed += 1
print(meshed, refused)
"""
    done = subprocess.run(
        [sys.executable, "-c", child], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    meshed, refused = map(int, done.stdout.split())
    assert meshed > 20 and refused > 20


def test_planner_survives_spike_polygons_and_answers(planner):
    text = yaml.safe_dump(scene_with_shape({"type": "polygon", "points": SPIKE}))
    for _ in range(20):
        response = load(planner, scene_yaml=text)
        assert response.error_code == ErrorCode.INVALID_ARGUMENT
        assert "self-intersecting" in response.message
    assert_alive(planner)


def test_planner_refuses_paths_outside_its_folders(planner, tmp_path):
    secret = tmp_path / "secret.csv"
    secret.write_text(f"{SECRET},1\n")
    inside = tmp_path / "allowed" / "scene.yaml"
    inside.write_text(yaml.safe_dump(scene_with_shape({"type": "file", "path": str(secret)})))
    escape = tmp_path / "allowed" / "link.yaml"
    escape.symlink_to(secret)
    cases = [
        dict(scene_path=str(secret)),
        dict(scene_path=str(escape)),
        dict(scene_path=str(tmp_path / "allowed" / ".." / "secret.csv")),
        dict(scene_path="/proc/self/environ"),
        dict(scene_path=str(inside)),
        dict(scene_yaml=yaml.safe_dump(scene_with_shape({"type": "file", "path": str(secret)}))),
    ]
    for fields in cases:
        response = load(planner, **fields)
        assert response.error_code == ErrorCode.INVALID_ARGUMENT, fields
        assert "outside the allowed folders" in response.message, response.message
        assert SECRET not in response.message
    assert_alive(planner)


def test_no_error_quotes_a_files_contents(planner, tmp_path):
    allowed = tmp_path / "allowed"
    (allowed / "bad_yaml.yaml").write_text(f"object: [{SECRET}: {{\n")
    (allowed / "not_scene.yaml").write_text(f"{SECRET}\n")
    (allowed / "bad_outline.csv").write_text(f"0,0\n{SECRET},1\n1,1\n")
    (allowed / "bad_outline.json").write_text(f'{{"outline": [[0, 0], "{SECRET}"]}}')
    (allowed / "binary.yaml").write_bytes(b"object:\n  " + SECRET.encode() + b"\xff\xfe\n")
    outline_scenes = []
    for name in ("bad_outline.csv", "bad_outline.json"):
        path = allowed / f"scene_{name}.yaml"
        path.write_text(
            yaml.safe_dump(scene_with_shape({"type": "file", "path": str(allowed / name)}))
        )
        outline_scenes.append(path)
    paths = [
        allowed / "bad_yaml.yaml",
        allowed / "not_scene.yaml",
        allowed / "binary.yaml",
        *outline_scenes,
    ]
    for path in paths:
        response = load(planner, scene_path=str(path))
        assert response.error_code == ErrorCode.INVALID_ARGUMENT, path
        assert SECRET not in response.message, response.message
    for path in paths:
        code = main(["mesh", str(path)])
        assert code == 2, path
    assert_alive(planner)


def test_cli_errors_do_not_quote_contents(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(f"object: [{SECRET}: {{\n")
    outline = tmp_path / "o.csv"
    outline.write_text(f"0,0\n{SECRET},1\n")
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(scene_with_shape({"type": "file", "path": str(outline)})))
    for path in (bad, scene):
        assert main(["mesh", str(path)]) == 2
        err = capsys.readouterr().err
        assert SECRET not in err and "error" in err


def test_yaml_alias_bomb_is_refused_quickly(planner, tmp_path):
    start = time.perf_counter()
    response = load(planner, scene_yaml=ALIAS_BOMB)
    assert response.error_code == ErrorCode.INVALID_ARGUMENT
    assert "aliases" in response.message and len(response.message) < 300
    path = tmp_path / "allowed" / "bomb.yaml"
    path.write_text(ALIAS_BOMB)
    assert "aliases" in load(planner, scene_path=str(path)).message
    assert main(["plan", str(path)]) == 2
    assert time.perf_counter() - start < 30  # the expanded document would take minutes
    assert_alive(planner)


def test_oversized_and_huge_text_inputs_are_refused(planner, tmp_path):
    big = tmp_path / "allowed" / "big.yaml"
    with open(big, "wb") as fh:
        fh.truncate(MAX_FILE_BYTES + 1)
    response = load(planner, scene_path=str(big))
    assert response.error_code == ErrorCode.INVALID_ARGUMENT
    assert "larger than" in response.message
    response = load(planner, scene_yaml="# " + "x" * (2 * 1024 * 1024))
    assert response.error_code == ErrorCode.INVALID_ARGUMENT
    assert "larger than" in response.message
    assert main(["mesh", str(big)]) == 2
    assert_alive(planner)


def test_scene_yaml_at_the_size_limit_loads_and_one_byte_more_is_refused(planner):
    """``scene_yaml`` of exactly MAX_TEXT_BYTES bytes (UTF-8; the padding a comment of
    two-byte characters) loads; one byte more is refused naming the field and the limit.
    """
    from squeeze_grasp_ros.inputs import MAX_TEXT_BYTES

    def padded(size: int) -> str:
        head = BLOB + "# "
        room = size - len(head.encode())
        return head + "\u00e9" * (room // 2) + "x" * (room % 2)

    at, beyond = padded(MAX_TEXT_BYTES), padded(MAX_TEXT_BYTES + 1)
    assert (len(at.encode()), len(beyond.encode())) == (MAX_TEXT_BYTES, MAX_TEXT_BYTES + 1)
    response = load(planner, scene_yaml=at, object_id="at_limit")
    assert response.success, response.message
    response = load(planner, scene_yaml=beyond, object_id="beyond")
    assert response.error_code == ErrorCode.INVALID_ARGUMENT
    assert f"scene_yaml: YAML text is larger than the {MAX_TEXT_BYTES}-byte limit" in \
        response.message, response.message
    assert_alive(planner)


def scene_variant(tmp_path: Path, name: str, change) -> str:
    data = yaml.safe_load((SCENES / "foam_square.yaml").read_text())
    change(data)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)


SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
CARELESS = {
    "side: true": (
        lambda d: d["object"]["shape"].__setitem__("side", True),
        "object.shape.side must be a positive number",
    ),
    "path: null": (
        lambda d: d["object"].__setitem__("shape", {"type": "file", "path": None}),
        "object.shape.path must be a file path",
    ),
    "path: 5": (
        lambda d: d["object"].__setitem__("shape", {"type": "file", "path": 5}),
        "object.shape.path must be a file path",
    ),
    "ragged points": (
        lambda d: d["object"].__setitem__(
            "shape", {"type": "polygon", "points": [[0, 0], [1], [1, 1]]}
        ),
        "object.shape.points must be a list of [x, y] number pairs",
    ),
    "huge integer": (
        lambda d: d["squeeze"].__setitem__("max_events_per_depth", 10**30),
        "squeeze.max_events_per_depth must be an integer of at most",
    ),
    "10 million nodes": (
        lambda d: d["object"]["mesh"].__setitem__("nodes", 10**7),
        "mesh.nodes must be in [10, 250000]",
    ),
    "max_area 1e-12": (
        lambda d: d["object"].__setitem__("mesh", {"max_area": 1e-12}),
        "at most 250000 are allowed",
    ),
}


@pytest.mark.parametrize("case", sorted(CARELESS))
def test_careless_scenes_end_in_a_clean_error(case, tmp_path, capfd):
    change, message = CARELESS[case]
    start = time.perf_counter()
    assert main(["squeeze", scene_variant(tmp_path, case.replace(" ", "_"), change)]) == 2
    err = capfd.readouterr().err
    assert message in err and "Traceback" not in err
    assert time.perf_counter() - start < 20


@pytest.mark.parametrize(
    "argv, message",
    [
        (["squeeze", "{foam}", "--save-boundary", "{tmp}"], "is a folder"),
        (["squeeze", "{foam}", "--plot", "/nonexistent/x.png"], "does not exist"),
        (["run", "{foam}", "--record", ""], "needs a folder name"),
        (["run", "{foam}", "--record", "{foam}"], "is a file"),
    ],
)
def test_bad_output_paths_are_refused_before_any_work(argv, message, tmp_path, capfd):
    argv = [a.format(foam=SCENES / "foam_square.yaml", tmp=tmp_path) for a in argv]
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    assert message in capfd.readouterr().err


def test_numbers_that_would_be_silently_wrong_are_refused(tmp_path, capfd):
    trials = tmp_path / "trials.csv"
    trials.write_text("angle_deg,slid\n60,0\n95,1\n")
    assert main(["calibrate", "--slope-trials", str(trials)]) == 2
    assert "[0, 90] deg" in capfd.readouterr().err
    same = tmp_path / "same.csv"
    same.write_text("x,y\n1,1\n1,1\n1,1\n")
    assert main(["match", str(same), str(same)]) == 2
    capfd.readouterr()
    for text, message in (("x,y,z\n0,0,0\n1,0,0\n0,1,0\n", "must be x,y, got x,y,z"),
                          ("0,0\n1,0,5\n0,1\n", "data row 2 has 3 cells")):
        cloud = tmp_path / "cloud.csv"
        cloud.write_text(text)  # a z column was silently dropped
        assert main(["match", str(cloud), str(cloud)]) == 2
        assert message in capfd.readouterr().err
    foam = str(SCENES / "foam_square.yaml")
    for argv in (
        ["plan", foam, "--depth", "1e308"],
        ["squeeze", foam, "--depth", "1e308"],
        ["plan", foam, "--relative-depth", "1.0"],
    ):
        assert main(argv) == 2, argv
        assert "fingers would meet" in capfd.readouterr().err
    for name, change, message in (
        ("rel1", lambda d: d["squeeze"].__setitem__("relative_depth", 1.0),
         "squeeze.relative_depth must be in [0.0, 1.0) (at 1 the fingers would meet), got 1.0"),
        ("step", lambda d: d["squeeze"].__setitem__("step", 1e-12),
         "step must be finite and >= 1e-06"),
    ):
        path = scene_variant(tmp_path, name, change)
        assert main(["squeeze", path]) == 2
        assert message in capfd.readouterr().err
        assert main(["run", path, "--no-planner", "--quiet"]) == 2
        assert message in capfd.readouterr().err


def test_plan_squeeze_service_refuses_an_absurd_depth(planner):
    from squeeze_grasp_interfaces.srv import PlanSqueeze

    load(planner, scene_yaml=BLOB, object_id="blob")
    response = planner.call(
        PlanSqueeze,
        "plan_squeeze",
        PlanSqueeze.Request(object_id="blob", squeeze_type="stable", depth=1e308),
    )
    assert response.error_code == ErrorCode.INVALID_ARGUMENT
    assert "fingers would meet" in response.message


def test_json_errors_and_non_finite_results_are_valid_json(tmp_path, capfd):
    import json

    from squeeze_grasp_ros.cli import finite_json

    path = scene_variant(
        tmp_path, "side", lambda d: d["object"]["shape"].__setitem__("side", True)
    )
    assert main(["mesh", path, "--json"]) == 2
    error = json.loads(capfd.readouterr().out)
    assert error["field"] == "object.shape.side" and error["code"] == 2
    assert "positive number" in error["error"]
    bad: list[str] = []
    clean = finite_json({"a": [1.0, float("inf")], "b": {"c": float("nan")}, "d": "x"}, "", bad)
    assert clean == {"a": [1.0, None], "b": {"c": None}, "d": "x"}
    assert bad == ["a[1]", "b.c"]


def send_and_wait(harness: Harness, calls: list, timeout: float = 120.0) -> list:
    """Send every (client, request) at once; spin until all are answered; the responses."""
    deadline = time.monotonic() + 30
    while not all(c.service_is_ready() for c, _ in calls):
        assert time.monotonic() < deadline
        harness.executor.spin_once(0.05)
    futures = [c.call_async(r) for c, r in calls]
    deadline = time.monotonic() + timeout
    while not all(f.done() for f in futures):
        assert time.monotonic() < deadline, sum(f.done() for f in futures)
        harness.executor.spin_once(0.05)
    return [f.result() for f in futures]


def test_thirty_concurrent_requests_all_get_an_answer(planner):
    """30 clients send one load each at once: every one is answered, loaded or BUSY beyond
    max_pending (16). With rclpy's default queue depth of 10, 20 of them went unanswered; the
    queues now keep every request (planner parameter service_queue_depth 0; bursts of 200:
    test_planner_clients.py).
    """

    def scene(k: int) -> str:  # distinct meshes: no request is a cache hit
        data = yaml.safe_load(BLOB)
        data["object"]["mesh"] = {"nodes": 300 + 10 * k}
        return yaml.safe_dump(data)

    calls = [
        (
            planner.node.create_client(LoadObject, f"{planner.planner_name}/load_object"),
            LoadObject.Request(scene_yaml=scene(k), object_id=f"o{k}"),
        )
        for k in range(30)
    ]
    responses = send_and_wait(planner, calls)
    codes = [r.error_code for r in responses]
    assert set(codes) <= {ErrorCode.OK, ErrorCode.BUSY} and codes.count(ErrorCode.OK) >= 16
    assert all("max_pending" in r.message for r in responses if r.error_code == ErrorCode.BUSY)
    assert_alive(planner)


def test_long_requests_beyond_max_pending_are_answered_busy(ros_context: Context):
    """With max_pending 0 every long request is refused BUSY at once, with the reason; quick
    requests (plan_squeeze on a cached object) are still served.
    """
    from rclpy.parameter import Parameter

    from squeeze_grasp_interfaces.srv import GraspMap, PlanSqueeze

    harness = Harness(ros_context, parameter_overrides=[Parameter("max_pending", value=0)])
    try:
        for request in (LoadObject.Request(scene_yaml=BLOB, object_id="blob"),):
            response = harness.call(LoadObject, "load_object", request)
            assert response.error_code == ErrorCode.BUSY and "max_pending" in response.message
        response = harness.call(GraspMap, "grasp_map", GraspMap.Request(object_id="x", mu=0.4))
        assert response.error_code == ErrorCode.BUSY
        response = harness.call(
            PlanSqueeze,
            "plan_squeeze",
            PlanSqueeze.Request(object_id="nope", squeeze_type="stable"),
        )
        assert response.error_code == ErrorCode.UNKNOWN_OBJECT  # quick path, not queued
    finally:
        harness.close()


def test_unknown_object_error_does_not_list_other_clients_objects(planner):
    from squeeze_grasp_interfaces.srv import PlanSqueeze

    load(planner, scene_yaml=BLOB, object_id="someone_elses_secret_object")
    response = planner.call(
        PlanSqueeze, "plan_squeeze", PlanSqueeze.Request(object_id="nope", squeeze_type="stable")
    )
    assert response.error_code == ErrorCode.UNKNOWN_OBJECT
    assert "unknown object_id 'nope'" in response.message
    assert "someone_elses_secret_object" not in response.message


def test_quick_requests_are_answered_while_a_long_one_runs(planner):
    """A plan_squeeze sent after a long event_squeeze is answered before it (each long request
    used to hold the node's mutually exclusive callback group until it finished).
    """
    from squeeze_grasp_interfaces.srv import EventSqueeze, PlanSqueeze

    data = yaml.safe_load(BLOB)
    data["object"]["mesh"] = {"nodes": 3000}
    load(planner, scene_yaml=yaml.safe_dump(data), object_id="blob")
    slow = planner.node.create_client(EventSqueeze, f"{planner.planner_name}/event_squeeze")
    quick = planner.node.create_client(PlanSqueeze, f"{planner.planner_name}/plan_squeeze")
    while not (slow.service_is_ready() and quick.service_is_ready()):
        planner.executor.spin_once(0.05)
    long_one = slow.call_async(
        EventSqueeze.Request(object_id="blob", relative_depth=0.3, step=2e-5)
    )
    answered = 0
    while not long_one.done() and answered < 5:
        future = quick.call_async(PlanSqueeze.Request(object_id="blob", squeeze_type="stable"))
        while not future.done():
            planner.executor.spin_once(0.01)
        assert future.result().success
        answered += 1
    assert answered == 5 and not long_one.done()
    while not long_one.done():
        planner.executor.spin_once(0.05)
    assert long_one.result().success


def test_a_long_request_whose_client_leaves_is_stopped(planner):
    """ROS 2 services have no cancel: a client that gives up and destroys its client leaves
    the graph, and the planner stops that request's work at its next progress report or
    stepper substep instead of computing an answer nobody can take; later requests are served
    as before.
    """
    from squeeze_grasp_interfaces.srv import EventSqueeze, PlanSqueeze

    data = yaml.safe_load(BLOB)
    data["object"]["mesh"] = {"nodes": 3000}
    load(planner, scene_yaml=yaml.safe_dump(data), object_id="blob")
    node = planner.node
    slow = node.create_client(EventSqueeze, f"{planner.planner_name}/event_squeeze")
    while not slow.service_is_ready():
        planner.executor.spin_once(0.05)
    slow.call_async(EventSqueeze.Request(object_id="blob", relative_depth=0.3, step=2e-5))
    while planner.planner._pending == 0:
        planner.executor.spin_once(0.01)
    node.destroy_client(slow)
    while planner.planner._pending:
        planner.executor.spin_once(0.05)
    (progress,) = planner.planner.abandoned  # the last progress report before it stopped
    print(f"stopped after the progress report {progress}")
    assert progress == () or progress[0] < 1.0  # stepper substeps are checkpoints too
    quick = planner.call(PlanSqueeze, "plan_squeeze",
                         PlanSqueeze.Request(object_id="blob", squeeze_type="stable"))
    assert quick.success
