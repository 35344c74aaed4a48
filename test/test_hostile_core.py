# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Issue 34, the ROS-free items: silently wrong answers refused (a placement at 1e308 m, a 1 m
push on a 0.1 m object, a relative depth of 5), allocations bounded before they are made (ring
elements, push directions, sweep specs), tracebacks turned into one line with exit 2 or 4, and
the material ranges each constitutive model represents, auxetic side included.
"""
from __future__ import annotations

import socket
import threading
import warnings
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import numpy as np
import pytest
import yaml
from output_support import CLI, private_mount

from squeeze_grasp_ros.api import load_scene, scene_file
from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.analytic import disk_diameter_change_across
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import POISSON_RANGES, Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    MAX_RELATIVE_PUSH,
    MIN_RELATIVE_PUSH,
    optimal_resistance,
    resistance_grasp,
    sweep_directions,
)
from squeeze_grasp_ros.mechanics.ring.model import ring_from_outline
from squeeze_grasp_ros.scene import event_squeeze_scene, parse_scene, scene_solid

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
FOAM = str(SCENES / "foam_square.yaml")
RING = str(SCENES / "ring_ring.yaml")


def variant(tmp_path: Path, source: str, change, name: str = "scene.yaml") -> str:
    data = yaml.safe_load(Path(source).read_text())
    change(data)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return str(path)


def refused(argv: list[str], capfd, code: int = 2) -> str:
    """Run the CLI with every warning an error; it must exit ``code`` with one stderr line."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(argv) == code, argv
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    return err[0]


def usage_error(argv: list[str], capfd) -> str:
    """An argparse refusal: exit 2, the last stderr line is the error."""
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    return capfd.readouterr().err.strip().splitlines()[-1]


# ----------------------------------------------------------------------------- item 4


@pytest.mark.parametrize("source, finger", [(FOAM, "F1"), (RING, "F2")])
def test_a_placement_point_far_outside_the_object_is_refused(tmp_path, capfd, source, finger):
    path = variant(tmp_path, source, lambda d: d["fingers"][finger].__setitem__(
        "placement", {"point": [1e308, 0.0]}))
    line = refused(["ring" if source == RING else "squeeze", path], capfd)
    assert f"fingers.{finger}.placement.point (1e+308, 0) m is outside the object's reach" in line


def test_a_point_near_the_object_still_snaps_to_the_boundary(tmp_path):
    """Within the reach (the bounding box grown by the object size) a point outside the object
    is projected onto the boundary, as before: (-0.12, 0) m lands on the left side.
    """
    scene = parse_scene({**yaml.safe_load(Path(FOAM).read_text()), "fingers": {
        "F1": {"tip_radius": 0.02, "placement": {"point": [-0.12, 0.0]}},
        "F2": {"tip_radius": 0.02, "placement": {"point": [0.05, 0.0]}}}})
    from squeeze_grasp_ros.scene import build_mesh, finger_nodes

    mesh = build_mesh(scene)
    i, _ = finger_nodes(scene, mesh)
    assert np.allclose(mesh.nodes[i], [-0.05, 0.0])


@pytest.mark.parametrize("offset", [2e-10, 1e-9, 1e-8])
def test_a_placement_a_hair_from_a_corner_is_refused_naming_the_placement(tmp_path, capfd,
                                                                          offset):
    """A point 2e-10 to 1e-8 m from the foam square's corner (beyond the 1e-10 m within which
    it is the corner) made elements the mesh refuses: "object.mesh: mesh has degenerate
    (zero-area) elements" named neither the placement nor the distance. 3e-8 m meshes.
    """
    path = variant(tmp_path, FOAM, lambda d: d["fingers"]["F1"].__setitem__(
        "placement", {"point": [-0.05, -0.05 + offset]}))
    line = refused(["squeeze", path], capfd)
    assert (f"error: fingers.F1.placement.point: the outline has vertices {offset:.3g} m apart "
            "at (-0.05, -0.05) m") in line


def test_a_mesh_error_of_another_cause_is_not_blamed_on_a_placement_near_a_corner(tmp_path,
                                                                                  capfd):
    """3e-8 m from the corner meshes; asked for too many nodes, the refusal is the mesh's."""
    def change(d):
        d["fingers"]["F1"]["placement"] = {"point": [-0.05, -0.05 + 3e-8]}
        d["object"]["mesh"] = {"max_area": 1e-12}

    line = refused(["squeeze", variant(tmp_path, FOAM, change)], capfd)
    assert "error: object.mesh: mesh.max_area 1e-12 m^2 would give about" in line


def test_an_outline_with_vertices_a_hair_apart_is_refused_naming_them():
    with pytest.raises(InvalidInputError, match=r"the outline has vertices 1e-08 m apart at "
                                                r"\(0, 1e-08\) m \(1e-07 of its size 0.1 m\)"):
        generate_mesh(shapes.polygon([[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1], [0, 1e-8]]), 3e-5)
    assert generate_mesh(shapes.polygon([[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1], [0, 3e-8]]),
                         3e-5).n > 300


# ----------------------------------------------------------------------------- item 5


def test_a_push_far_beyond_the_small_deformation_range_is_refused(tmp_path, capfd):
    path = variant(tmp_path, str(SCENES / "resist_fig9.yaml"),
                   lambda d: d["adversary"].__setitem__("a", [-1.0, 0.0]))
    line = refused(["resist", path], capfd)
    assert "adversary.a is 1 m long, 8.89 times the object size 0.1125 m" in line
    assert f"|a| <= {MAX_RELATIVE_PUSH:g} of the size, 0.02812 m" in line
    friction = variant(tmp_path, str(SCENES / "resist_fig10.yaml"),
                       lambda d: d["adversary"].__setitem__("a", [0.24, 0.44]), "fig10.yaml")
    assert "adversary.a is 0.5012 m long" in refused(["resist", friction], capfd)


def test_the_bound_is_the_push_not_the_rate_per_unit_push():
    """The fixed-contact optimum is linear in a: at the bound it is the unit-push answer scaled,
    and Algorithm 2's per-unit-push stages are not bounded.
    """
    obj = scene_solid(load_scene(scene_file("disk")))
    b = [int(k) for k in obj.mesh.boundary]
    grasp = resistance_grasp(obj, {"F1": [b[0]], "F2": [b[len(b) // 2]], "A": [b[len(b) // 4]]})
    edge = np.array([-MAX_RELATIVE_PUSH * obj.scale, 0.0])
    at_bound = optimal_resistance(grasp, edge)
    unit = optimal_resistance(grasp, [-1.0, 0.0], per_unit_push=True)
    assert np.allclose(at_bound.d1, unit.d1 * np.hypot(*edge), rtol=1e-9)
    with pytest.raises(InvalidInputError, match="adversary.a is"):
        optimal_resistance(grasp, 1.001 * edge)


def test_a_push_too_short_for_the_float_range_is_refused_naming_the_floor(tmp_path, capfd):
    """The work is quadratic in a: at |a| = 1e-160 m it came out subnormal (1.4e-318 J, 6
    digits), and a = [1e-200, 0] was refused as "must be nonzero" (the norm underflowed). A
    push below MIN_RELATIVE_PUSH of the size is refused naming the floor, in both modes and
    for friction contacts; at the floor the answer is the unit-push one scaled, to 1e-9.
    """
    obj = scene_solid(load_scene(scene_file("disk")))
    b = [int(k) for k in obj.mesh.boundary]
    grasp = resistance_grasp(obj, {"F1": [b[0]], "F2": [b[len(b) // 2]], "A": [b[len(b) // 4]]})
    floor = rf"the resistance model takes \|a\| >= {MIN_RELATIVE_PUSH:g} of the size"
    for tiny in ([-1e-160, 0.0], [-1e-200, 0.0], [-5e-324, 0.0]):
        for per_unit_push in (False, True):
            with pytest.raises(InvalidInputError, match=floor):
                optimal_resistance(grasp, tiny, per_unit_push=per_unit_push)
    with pytest.raises(InvalidInputError, match="must be nonzero"):
        optimal_resistance(grasp, [0.0, -0.0])
    edge = np.array([-MIN_RELATIVE_PUSH * obj.scale, 0.0])
    at_floor = optimal_resistance(grasp, edge)
    unit = optimal_resistance(grasp, [-1.0, 0.0], per_unit_push=True)
    assert np.allclose(at_floor.d1, unit.d1 * np.hypot(*edge), rtol=1e-9)
    assert at_floor.work["total"] == pytest.approx(unit.work["total"] * edge @ edge, rel=1e-9)
    assert at_floor.work["total"] > np.finfo(float).tiny   # a normal float, full precision
    friction = variant(tmp_path, str(SCENES / "resist_fig10.yaml"),
                       lambda d: d["adversary"].__setitem__("a", [1e-200, 0.0]), "fig10.yaml")
    line = refused(["resist", friction], capfd)
    assert "adversary.a is 1e-200 m long" in line and f"|a| >= {MIN_RELATIVE_PUSH:g}" in line


# ----------------------------------------------------------------------------- item 6


def test_one_relative_depth_rule_for_plan_and_ring(capfd):
    plan = refused(["plan", FOAM, "--relative-depth", "5"], capfd)
    ring = refused(["ring", RING, "--relative-depth", "5"], capfd)
    rule = "relative depth must be in [0, 1) (at 1 the fingers would meet), got 5"
    assert plan.endswith(rule) and ring.endswith(rule)
    assert "it must be in [0, 1)" in refused(["ring", RING, "--depth", "1"], capfd)
    assert refused(["ring", RING, "--map", "--relative-depth", "1"], capfd).endswith(
        "got 1")
    assert "must be in [1, 10000], got -1" in usage_error(
        ["ring", RING, "--map", "--best", "-1"], capfd)


@pytest.mark.parametrize("options, named", [
    (["--best", "3"], "--best ranks the placements of --map"),
    (["--bench", "--plot", "bench.png"], "--bench takes only --elements and --json, got --plot"),
    (["--bench", "--map", "--depth", "0.001", "--best", "3"],
     "--bench takes only --elements and --json, got --map, --depth, --best"),
])
def test_ring_options_the_task_would_ignore_are_refused(tmp_path, capfd, options, named):
    """``ring --best 3`` (no ``--map``) and ``ring --bench --plot FILE`` exited 0, the first
    without the ranking asked for, the second without writing the plot.
    """
    options = [str(tmp_path / o) if o.endswith(".png") else o for o in options]
    assert named in refused(["ring", RING, *options], capfd)
    assert not (tmp_path / "bench.png").exists()


# ----------------------------------------------------------------------------- item 13


def test_allocations_are_refused_with_the_limit_named(tmp_path, capfd):
    assert "--elements: must be in [8, 2000], got 100000" in usage_error(
        ["ring", RING, "--elements", "100000"], capfd)
    assert "--directions: must be in [1, 100000], got 100000000" in usage_error(
        ["resist", str(SCENES / "resist_fig9.yaml"), "--directions", "100000000"], capfd)
    path = variant(tmp_path, RING, lambda d: d["object"]["ring"].__setitem__("elements", 10**5))
    assert "object.ring.elements must be in [8, 2000], got 100000" in refused(["ring", path],
                                                                            capfd)
    with pytest.raises(InvalidInputError, match=r"ring.elements must be in \[8, 2000\]"):
        ring_from_outline(shapes.disk(0.05), Material(1e9, 0.0, 0.01), 0.002, 2001)
    grasp_obj = scene_solid(load_scene(scene_file("disk")))
    b = [int(k) for k in grasp_obj.mesh.boundary]
    grasp = resistance_grasp(grasp_obj, {"F1": [b[0]], "F2": [b[len(b) // 2]],
                                         "A": [b[len(b) // 4]]})
    with pytest.raises(InvalidInputError, match=r"directions must be in \[1, 100,000\]"):
        sweep_directions(grasp, count=10**8)


# ----------------------------------------------------------------------------- item 16


def test_malformed_shapes_and_outline_files_are_one_line(tmp_path, capfd):
    typed = variant(tmp_path, FOAM, lambda d: d["object"]["shape"].__setitem__("type", ["square"]))
    assert "object.shape.type must be one of" in refused(["squeeze", typed], capfd)
    files = {
        "deep.json": '{"outline": ' + "[" * 100_000 + "]" * 100_000 + "}",
        "huge.json": '{"outline": [[0, 0], [1' + "0" * 5000 + ", 0], [1, 1]]}",
        "big.json": '{"outline": [[0, 0], [1' + "0" * 400 + ", 0], [1, 1]]}",
    }
    for name, text in files.items():
        (tmp_path / name).write_text(text)
        path = variant(tmp_path, FOAM, lambda d: d["object"].__setitem__(
            "shape", {"type": "file", "path": str(tmp_path / name)}), f"{name}.yaml")
        line = refused(["squeeze", path], capfd)
        assert f"outline file {name}" in line
    deep = tmp_path / "deep.yaml"
    deep.write_text("object:\n  shape: " + "[" * 100_000 + "]" * 100_000 + "\n")
    assert "YAML nested too deeply" in refused(["squeeze", str(deep)], capfd)


def test_bad_output_paths_are_refused_before_any_work(tmp_path, capfd):
    line = usage_error(["squeeze", FOAM, "--save-boundary", "/proc/x.csv"], capfd)
    assert "cannot create files in /proc" in line
    existing = tmp_path / "report"
    existing.write_text("")
    assert "exists and is not a folder" in usage_error(
        ["bench", "--only", "solvers", "--out", str(existing)], capfd)


def test_an_output_folder_is_made_when_the_command_runs_not_while_it_is_parsed(tmp_path,
                                                                              capfd):
    """Before, ``bench --out NEW`` and ``sweep-report --plot NEW`` made NEW while the command
    line was parsed: a mistake in a later argument left an empty folder behind.
    """
    new = tmp_path / "a" / "b"
    assert "invalid choice: 'bogus'" in usage_error(
        ["bench", "--out", str(new), "--only", "bogus"], capfd)
    assert "is not a sweep directory" in refused(
        ["sweep-report", str(tmp_path / "nowhere"), "--plot", str(new)], capfd)
    assert not (tmp_path / "a").exists()
    assert "cannot create files in /proc" in usage_error(
        ["bench", "--only", "solvers", "--out", "/proc/new/bench"], capfd)
    (tmp_path / "file").write_text("")
    assert "is not a folder" in usage_error(
        ["bench", "--only", "solvers", "--out", str(tmp_path / "file" / "x")], capfd)


def test_non_finite_calibration_input_is_shown_plainly(capfd):
    line = refused(["calibrate", "--slope-angle", "nan"], capfd)
    assert line.endswith("slope angle must be finite, got nan")


@pytest.mark.parametrize("where, value, message", [
    (("object", "material", "E"), 1e300, "object.material.E must be in [0.001, 1e+13] Pa"),
    (("friction", "mu"), 1e308, "friction.mu must be in [0.0, 1000.0]"),
    (("object", "material", "thickness"), 1e300, "object.material.thickness must be in"),
])
def test_absurd_magnitudes_are_refused_before_any_arithmetic(tmp_path, capfd, where, value,
                                                             message):
    def change(d):
        node = d
        for key in where[:-1]:
            node = node[key]
        node[where[-1]] = value

    assert message in refused(["squeeze", variant(tmp_path, FOAM, change)], capfd)


def test_a_plot_onto_a_full_disk_is_one_line_and_leaves_no_file(tmp_path):
    full = tmp_path / "full"
    done = private_mount(full, "size=16k", [*CLI, "plan", FOAM, "--plot", str(full / "p.png")])
    assert done.returncode == 4, done.stderr
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and "No space left on device (ENOSPC)" in err[0], err
    assert err[0].startswith("squeeze-grasp plan: error: cannot write plot")


# ----------------------------------------------------------------------------- item 17


@pytest.mark.parametrize("model, nu", [("neo_hookean", 0.49999), ("neo_hookean", 0.4999999999),
                                       ("neo_hookean", -0.5), ("linear", -0.99),
                                       ("corotational", -0.99999999)])
def test_poisson_ratios_a_model_cannot_represent_are_refused_up_front(tmp_path, capfd, model,
                                                                      nu):
    path = variant(tmp_path, FOAM, lambda d: d["object"]["material"].update(nu=nu, model=model))
    lo, hi = POISSON_RANGES[model]
    line = refused(["squeeze", path], capfd)
    assert f"object.material.nu must be in [{lo:g}, {hi:g}]" in line


def test_a_model_given_on_the_command_line_is_held_to_its_poisson_range(tmp_path, capfd):
    """The scene checks its own model's range; `--model` chose another after that check: a
    linear scene at nu = -0.5 squeezed with `--model neo_hookean` ran past a minute with a
    leaked RuntimeWarning. Every squeeze's contact model now checks the range it runs, a
    scene's naming the scene's field.
    """
    path = variant(tmp_path, FOAM, lambda d: d["object"]["material"].update(nu=-0.5))
    line = refused(["squeeze", path, "--model", "neo_hookean"], capfd)
    assert line.endswith("error: object.material.nu must be in [-0.3, 0.4999] for the "
                         "neo_hookean model, got -0.5: beyond, its solves fail or lose digits "
                         "(docs/reliability.md)")


def test_the_auxetic_side_against_the_analytic_disk():
    """Timoshenko's disk under diametral loads: the perpendicular diameter grows by about
    P / (E h) (4 / pi - 1 + nu), so below nu = 1 - 4 / pi it shrinks (an auxetic disk pulls in
    sideways). The FEM far field follows the closed form to 3 % down to the bound nu = -0.9;
    beyond it the triangles lock in shear (at -0.999 the change was 60 % too large).
    """
    R, P, outline = 0.05, 1.0, shapes.disk(0.05)
    mesh = generate_mesh(outline, outline.area / 1500 * 0.8)
    b = mesh.boundary
    angle = np.arctan2(mesh.nodes[b, 1], mesh.nodes[b, 0])
    pick = [b[np.argmin(np.abs(np.angle(np.exp(1j * (angle - a))))).item()]
            for a in (np.pi / 2, -np.pi / 2, np.pi, 0.0)]
    for nu in (0.3, -0.2, -0.5, POISSON_RANGES["linear"][0]):
        mat = Material(5e4, nu, 0.01)
        exact = disk_diameter_change_across(mat.E, nu, mat.thickness, R, P)
        d = ((ElasticObject(mesh, mat).compliance_block(pick) / mat.force_scale)
             @ np.array([0, -P, 0, P, 0, 0, 0, 0])).reshape(-1, 2)
        change = d[3, 0] - d[2, 0]
        assert np.sign(change) == np.sign(exact) == np.sign(4 / np.pi - 1 + nu)
        assert change == pytest.approx(exact, rel=0.03)
    mat = Material(5e4, -0.999, 0.01)
    exact = disk_diameter_change_across(mat.E, mat.nu, mat.thickness, R, P)
    d = ((ElasticObject(mesh, mat).compliance_block(pick) / mat.force_scale)
         @ np.array([0, -P, 0, P, 0, 0, 0, 0])).reshape(-1, 2)
    assert (d[3, 0] - d[2, 0]) / exact > 1.3  # why the range stops at -0.9


@pytest.mark.parametrize("model", ["linear", "corotational", "neo_hookean"])
def test_squeezes_hold_at_both_ends_of_each_range(model):
    """At either end of its range every model squeezes the foam square (400 nodes) to 12 %
    without a warning, and at 1 % (small strain) its energy is within 1 % of the linear
    model's at the same nu.
    """
    base = yaml.safe_load(Path(FOAM).read_text())
    base["object"]["mesh"] = {"nodes": 400}
    for nu in POISSON_RANGES[model]:
        energy = {}
        for m, depth in (("linear", 0.01), (model, 0.01), (model, 0.12)):
            data = yaml.safe_load(yaml.safe_dump(base))
            data["object"]["material"].update(nu=nu, model=m)
            data["squeeze"] = {"type": "stable", "relative_depth": depth}
            scene = parse_scene(data)
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                result = event_squeeze_scene(scene, scene_solid(scene))
            assert result.termination == "depth_reached", (model, nu, depth, result.termination)
            energy[m, depth] = result.energy
        assert energy[model, 0.01] == pytest.approx(energy["linear", 0.01], rel=0.01), (nu, energy)


# ----------------------------------------------------------------------------- sweeps


@pytest.fixture()
def sweep_spec(tmp_path):
    pytest.importorskip("distributed", reason="pip install -e '.[sweep]'")

    def write(**fields) -> str:
        path = tmp_path / "spec.yaml"
        path.write_text(yaml.safe_dump({"base": FOAM, **fields}))
        return str(path)

    return write


@pytest.mark.parametrize("fields, message", [
    ({"friction": [k * 1e-4 for k in range(3000)],
      "tip_radius": [0.001 + k * 1e-6 for k in range(3000)],
      "relative_depth": [0.001 + k * 1e-4 for k in range(3000)]},
     "27,000,000,000 parameter sets per placement (friction 3,000 x tip_radius 3,000 x "
     "squeeze 1 x depth 3,000); at most 100,000"),
    ({"placements": {"mode": "sample", "count": 10**9}},
     "1,000,000,000 evaluations (1,000,000,000 placements (over all objects) x 1 materials x "
     "1 parameter sets); at most 1,000,000"),
    ({"repeat": 10**12}, "20,000,000,000,000 evaluations"),
    ({"objects": [{"family": {"type": "superellipse", "count": 10**9, "a": [0.04, 0.06],
                              "b": [0.03, 0.05], "exponent": [2.5, 6]}}]},
     "1,000,000,000 objects (families included); at most 10,000"),
    ({"placements": {"mode": "sample", "count": 2}, "chunk": 1,
      "friction": [0.1, 0.2], "objects": [{"family": {
          "type": "superellipse", "count": 10_001, "a": [0.04, 0.06], "b": [0.03, 0.05],
          "exponent": [2.5, 6]}}]}, "10,001 objects"),
    ({"relative_depth": [0.1, 1.0]}, "relative_depth[1] must be in (0.0, 1.0) (at 1 the "
                                     "fingers would meet), got 1.0"),
])
def test_a_sweep_that_explodes_is_refused_by_its_counts(sweep_spec, capfd, fields, message):
    line = refused(["sweep", sweep_spec(**fields), "--dry-run"], capfd)
    assert message in line


def test_the_dry_run_reports_the_counts(sweep_spec, capsys):
    spec = sweep_spec(friction=[0.2, 0.5], relative_depth=[0.04],
                      placements={"mode": "sample", "count": 3}, mesh={"nodes": 150})
    assert main(["sweep", spec, "--dry-run", "--json"]) == 0
    import json

    dry = json.loads(capsys.readouterr().out)
    assert (dry["evaluations"], dry["parameters"], dry["tasks"]) == (6, 2, 1)


class _Silent(BaseHTTPRequestHandler):
    """An HTTP server that reads a request and never answers a Dask handshake."""

    def do_GET(self):  # noqa: N802 (http.server's hook name)
        self.send_response(200)
        self.end_headers()

    def log_message(self, *args):
        pass


def test_a_scheduler_address_that_is_not_a_scheduler_times_out():
    """The dashboard's HTTP port accepts TCP and never answers Dask's handshake; Client()
    waited for ever (100 s and more). The probe gives up after its timeout with one line.
    """
    pytest.importorskip("distributed", reason="pip install -e '.[sweep]'")
    from squeeze_grasp_ros.sweep.engine import probe_scheduler
    from squeeze_grasp_ros.sweep.spec import SweepError

    server = ThreadingHTTPServer(("127.0.0.1", 0), _Silent)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        port = server.server_address[1]
        with pytest.raises(SweepError, match="no Dask scheduler answered within 2 s"):
            probe_scheduler(f"tcp://127.0.0.1:{port}", 1.0, 1.0)
    finally:
        server.shutdown()
        server.server_close()
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        closed = sock.getsockname()[1]
    with pytest.raises(SweepError, match="cannot connect"):
        probe_scheduler(f"tcp://127.0.0.1:{closed}", 1.0, 1.0)


SQUARE = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]


@pytest.mark.parametrize("outline, says", [
    (shapes.Outline(np.array([[0, 0], [0.1, 0], [np.nan, 0.1]])),
     "outline.points has non-finite coordinates"),
    (shapes.Outline(np.array([[0, 0], [0, 0.1], [0.1, 0]], float)),
     "outline.points must run counter-clockwise around a positive area, got a signed area of "
     "-0.005 m^2 (polygon() orients and checks its points)"),
    (shapes.Outline(np.array([[0, 0], [0.1, 0], [0.2, 0]], float)),
     "outline.points must run counter-clockwise around a positive area, got a signed area of "
     "0 m^2 (polygon() orients and checks its points)"),
    (shapes.Outline(np.array([[0, 0], [0.1, 0]], float)),
     "outline.points must be an (N, 2) array of N >= 3 vertices (m), got shape (2, 2)"),
    (shapes.Outline(np.array(SQUARE), (np.array([[0.02, 0.02], [0.05, np.inf], [0.02, 0.05]]),)),
     "outline.holes[0] has non-finite coordinates"),
    (SQUARE, "outline must be an Outline (e.g. polygon(points)), got list"),
], ids=["nan", "clockwise", "flat", "two points", "hole inf", "a list"])
def test_generate_mesh_refuses_an_outline_built_by_hand_by_name(outline, says):
    """generate_mesh (public) checks an Outline the shape constructors did not make: before, a
    NaN gave "spacing nan m is too coarse", a clockwise loop "boundary is not manifold", a flat
    or two-point one a ZeroDivisionError, a list an AttributeError.
    """
    with pytest.raises(InvalidInputError) as refused:
        generate_mesh(outline, 1e-4)
    assert str(refused.value) == says

@pytest.mark.parametrize("value", ["inf", "nan", "0"])
def test_a_run_timeout_that_is_not_a_finite_positive_number_is_refused(value, capfd):
    """``run --timeout inf`` was refused with "--timeout must be > 0 s, got inf", which inf
    is: the message now states the range the check applies (before any node starts).
    """
    pytest.importorskip("rclpy", reason="run needs ROS 2")
    assert refused(["run", FOAM, "--timeout", value], capfd) == (
        f"squeeze-grasp run: error: --timeout must be a finite number > 0 s, got {float(value)}")


@pytest.mark.parametrize("argv, message", [
    (["squeeze", FOAM, "--step", "inf"],
     "step must be finite and >= 1e-06 (relative to the object size), got inf"),
    (["squeeze", FOAM, "--event-tol", "inf"],
     "event_tol must be finite and >= 1e-15 (relative to the object size), got inf"),
    (["gripper-plan", str(SCENES / "sponge_gripper.yaml"), "--weight", "inf"],
     "weight must be finite and > 0 N, got inf"),
    (["gripper-plan", str(SCENES / "sponge_gripper.yaml"), "--margin", "inf"],
     "force margin must be finite and >= 1, got inf"),
    (["resist", str(SCENES / "resist_fig9.yaml"), "--contacts", "segment",
      "--segment-half-width", "inf"], "segment half width must be finite and >= 0 m, got inf"),
])
def test_an_infinite_option_is_refused_as_not_finite(argv, message, capfd):
    """Each refused inf with a range inf is in ("step must be >= 1e-06 ..., got inf", "weight
    must be > 0 N, got inf"): the messages say finite.
    """
    assert refused(argv, capfd).endswith(message)


@pytest.mark.parametrize("radius", [1e6, 1e308])
def test_a_fingertip_larger_than_a_kilometre_is_refused_by_field(tmp_path, capfd, radius):
    """A tip radius of 1e308 m ended a squeeze with numpy warnings and "no contact mode ... can
    be solved" (exit 3); 1e10 m ran, with events that moved with the radius (the circle's gap
    loses about 1e-16 of the radius to round-off). Tips and pads are bounded at 1 km.
    """
    from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipShape

    path = variant(tmp_path, FOAM, lambda d: d["fingers"]["F1"].__setitem__("tip_radius",
                                                                               radius))
    assert refused(["squeeze", path], capfd).endswith(
        f"fingers.F1.tip_radius must be in [0.0, 1000.0] m, got {radius!r}")
    with pytest.raises(InvalidInputError, match=r"tip radius must be finite and in \[0, 1000\]"):
        TipShape.circle(radius)
    with pytest.raises(InvalidInputError, match=r"tip.width must be in \[2 tip.edge_radius"):
        TipShape.pad(width=radius, edge_radius=0.002)


def test_a_shape_size_beyond_the_integer_range_names_the_bound(tmp_path, capfd):
    """``side: 1e308`` was refused as "must be a positive number (m), got 1e+308", which it
    is: the bound (2**53, the largest integer a float holds exactly) is now in the message.
    """
    path = variant(tmp_path, FOAM, lambda d: d["object"]["shape"].__setitem__("side", 1e308))
    assert refused(["mesh", path], capfd).endswith(
        "object.shape.side must be a positive number (m) of at most 9.0072e+15, got 1e+308")
