# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Scene validation (errors name the field) and the foundation CLI verbs' JSON."""
import copy
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from executables import script, wait_until_caught

from squeeze_grasp_ros import cli
from squeeze_grasp_ros.scene import SceneError, load_scene, parse_scene

SCENES = sorted((Path(__file__).parents[1] / "config" / "scenes").glob("*.yaml"))
FOAM = Path(__file__).parents[1] / "config" / "scenes" / "foam_square.yaml"
BASE = yaml.safe_load(FOAM.read_text())


def test_every_shipped_scene_validates():
    assert len(SCENES) >= 5
    for path in SCENES:
        scene = load_scene(path)
        assert scene.name, path


def mutate(path: str, value):
    data = copy.deepcopy(BASE)
    keys = path.split(".")
    node = data
    for k in keys[:-1]:
        node = node.setdefault(k, {})
    if value is KeyError:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value
    return data


@pytest.mark.parametrize("path,value,message", [
    ("object.material.E", -5.0, "object.material.E must be in \\[0.001, 1e\\+13\\] Pa"),
    ("object.material.nu", 0.7, "object.material.nu must be in"),
    ("object.material.colour", "red", "unknown key object.material.colour"),
    ("object.mesh.min_angle", 40, "object.mesh.min_angle must be in"),
    ("object.shape.type", "hexagon", "object.shape.type must be one of"),
    ("object.shape.radius", 0.1, "unknown key object.shape.radius"),
    ("fingers.F1.tip_radius", -0.01, r"fingers.F1.tip_radius must be in \[0.0, 1000.0\] m"),
    # before, 1e308 was taken and overflowed the contact geometry (a numerical failure)
    ("fingers.F1.tip_radius", 1e308, r"fingers.F1.tip_radius must be in \[0.0, 1000.0\] m, "
                                     r"got 1e\+308"),
    ("fingers.F1.placement", {"point": [0, 0], "node": 3}, "exactly one of"),
    ("fingers.F3", {"placement": {"node": 1}}, "unknown finger fingers.F3"),
    ("squeeze.depth", 0.01, "exclusive"),
    ("squeeze.type", "gentle", "squeeze.type must be one of"),
    ("friction", KeyError, "effect 'friction' is declared but section friction is missing"),
    ("effects", ["friction", "levitation"], r"effects\[1\] must be one of .* got 'levitation'"),
    ("strain_limit", {"epsilon": 0.1}, "section strain_limit is given but effect"),
    ("object.material.E", "soft", "object.material.E must be a number"),
    ("object.material", KeyError, "missing required key object.material"),
    # a misspelt key is named with the key it is closest to, if one is close
    ("object.materal", {"E": 5e4}, r"unknown key object.materal: did you mean 'material'\? "),
    ("object.shape.sid", 0.1, r"unknown key object.shape.sid for type square: did you mean "
                              r"'side'\? (allowed: \['side'\]"),
    ("xyzzy", 1, r"unknown key xyzzy (allowed: \['actuators'"),
])
def test_scene_errors_name_the_field(path, value, message):
    with pytest.raises(SceneError, match=message.replace("(", r"\(")):
        parse_scene(mutate(path, value))


def run_json(capsys, *argv):
    assert cli.main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_mesh_verb_json(capsys):
    out = run_json(capsys, "mesh", str(SCENES[0]))
    nodes, tris, boundary = np.array(out["nodes"]), np.array(out["triangles"]), out["boundary"]
    assert nodes.shape[1] == 2 and tris.shape[1] == 3
    assert tris.min() == 0 and tris.max() == len(nodes) - 1
    p = nodes[boundary]
    area = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    assert area > 0  # counter-clockwise
    assert set(out["material"]) == {"E", "nu", "thickness"}


def test_plan_verb_json_is_consistent_with_theorem10(capsys, tmp_path):
    png = tmp_path / "plan.png"
    out = run_json(capsys, "plan", str(FOAM), "--plot", str(png))
    assert png.stat().st_size > 0
    i, j = out["contacts"]
    s, p = out["stable"], out["pure"]
    for block in (s, p):
        assert len(block["displacement"]) == 4 and len(block["forces"]) == 4
        assert np.isclose(np.linalg.norm(block["displacement"]), 1.0)
    ratio = np.linalg.norm(p["forces"]) / np.linalg.norm(s["forces"])
    assert np.isclose(np.dot(s["displacement"], p["displacement"]), ratio, rtol=1e-9)
    # the requested 12 % relative squeeze of a stable squeeze: sqrt(2) rho / |p_i - p_j|
    pts = np.array(out["contact_points"])
    assert np.isclose(np.sqrt(2) * out["depth"] / np.linalg.norm(pts[0] - pts[1]), 0.12)
    mesh = run_json(capsys, "mesh", str(FOAM))
    assert len(out["boundary_displacement"]["stable"]) == len(mesh["boundary"])
    k_i = mesh["boundary"].index(i)
    assert np.allclose(out["boundary_displacement"]["stable"][k_i],
                       out["depth"] * np.array(s["displacement"][:2]), atol=1e-12)


def test_graspmap_verb_json(capsys):
    out = run_json(capsys, "graspmap", str(FOAM))
    b = len(out["boundary"])
    assert out["pairs"] == b * (b - 1) // 2
    assert 0 < out["feasible_pairs"] <= out["force_closure_pairs"]
    assert out["best"][0]["stiffness"] >= out["best"][-1]["stiffness"]


def test_cli_reports_bad_scene_with_exit_code_2(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(mutate("object.material.nu", 0.9)))
    assert cli.main(["plan", str(bad)]) == 2
    assert "object.material.nu" in capsys.readouterr().err


def test_graspmap_verb_serves_ring_scenes(capsys):
    ring_scene = next(p for p in SCENES if p.name == "ring_ellipse.yaml")
    out = run_json(capsys, "graspmap", str(ring_scene))
    assert out["model"] == "ring"
    assert out["pairs"] == out["elements"] * (out["elements"] - 1) // 2
    assert sum(out["limits"].values()) == out["pairs"]


def test_cli_builds_and_runs_mechanics_verbs_without_ros(tmp_path):
    """`squeeze-grasp ros-setup` runs before the interfaces exist, and the mechanics verbs work
    with `pip install .` alone: building the parser must not import rclpy or our interfaces.
    """
    import subprocess

    code = ("import sys\n"
            "for name in ('rclpy', 'squeeze_grasp_interfaces'):\n"
            "    sys.modules[name] = None\n"
            "from squeeze_grasp_ros import cli\n"
            "cli.build_parser()\n"
            f"sys.exit(cli.main(['mesh', {str(FOAM)!r}, '--json']))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert '"boundary"' in out.stdout


IMPORTED = ("import sys\n"
            "from squeeze_grasp_ros import cli\n"
            "try:\n"
            "    cli.main(sys.argv[1:])\n"
            "except SystemExit:\n"
            "    pass\n"
            "verbs = sorted(m.rsplit('.', 1)[1] for m in sys.modules\n"
            "               if m.startswith('squeeze_grasp_ros.commands.')\n"
            "               and m.rsplit('.', 1)[1] in cli.VERBS)\n"
            "sys.stderr.write(repr((verbs, 'numpy' in sys.modules)))\n")
"""Run the CLI with the arguments given, then report on stderr which verb modules it imported
and whether numpy was loaded."""


@pytest.mark.parametrize(("argv", "verbs", "numpy"), [
    (["--help"], [], False),
    (["plan", "--help"], ["plan"], True),
    (["scene-help"], ["scene_help"], True),
    (["plan", str(FOAM), "--json"], ["plan"], True),
    (["nope"], [], False),
], ids=["help", "plan-help", "scene-help", "plan", "unknown-verb"])
def test_the_parser_imports_only_the_chosen_verb(argv, verbs, numpy):
    """Listing the verbs imports none of them (nor numpy); running one imports only it (the
    parser once imported all verb modules, about 110 package modules, before any verb ran).
    """
    out = subprocess.run([sys.executable, "-c", IMPORTED, *argv], capture_output=True,
                         text=True, timeout=120)
    assert out.stderr.rsplit("\n", 1)[-1] == repr((verbs, numpy)), out.stderr[-2000:]


@pytest.mark.parametrize("delay", [0.0, 0.1, 0.25, 0.5])
def test_ctrl_c_while_the_program_starts_is_one_line_not_a_traceback(delay, tmp_path):
    """The installed ``squeeze-grasp`` interrupted while it is still importing (numpy, scipy,
    Dask for ``sweep``) or starting its cluster: exit 130 and one line, at any moment from its
    first statement on.

    Before that statement the interpreter itself is starting (its ``site`` imports): a Ctrl-C
    there is Python's own traceback, whatever the program. At load 9-10 on the 2-core machine
    that took longer than 0.25 s, so the delay counts from the console script's first statement
    (it installs the SIGTERM handler: ``SigCgt``).
    """
    pytest.importorskip("distributed", reason="the sweep extra is not installed (this test "
                                              "interrupts a starting sweep): pip install "
                                              "'.[sweep]'")
    proc = subprocess.Popen([script("squeeze-grasp"), "sweep", str(cli_sweep_spec()), "--out",
                             str(tmp_path / "out"), "--workers", "1"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=terminal_sigint)
    wait_until_caught(proc.pid, signal.SIGTERM)
    time.sleep(delay)  # the moment of the signal is the test's subject
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert "interrupted" in err or "stopped by SIGINT" in err


def terminal_sigint() -> None:
    """SIGINT as a terminal leaves it to a foreground program (in the child, before exec).

    A job started in the background of a non-interactive shell (``cmd &``, a CI runner, some
    ``colcon test`` launches) inherits SIGINT ignored, and Python then installs no
    KeyboardInterrupt handler: Ctrl-C during the imports would be lost, whatever the program.
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def cli_sweep_spec() -> Path:
    """The shipped example sweep spec."""
    return Path(__file__).resolve().parents[1] / "config" / "sweeps" / "example.yaml"


def test_every_range_the_help_prints_is_the_range_the_check_keeps():
    """For every bounded number of a scene and of a sweep spec, the bracket ``scene-help`` and
    ``sweep-help`` print at each end says what the check does with the bound itself: kept
    where closed, refused where open (at 1 a relative depth is refused, and the help says
    so: the help printed a closed bracket there while the check refused it).
    """
    import dataclasses

    from squeeze_grasp_ros.scene import gripper, schema, specs
    from squeeze_grasp_ros.sweep import spec as sweep_spec

    bounded = [(cls.__name__, f) for module in (specs, sweep_spec, gripper)
               for cls in vars(module).values()
               if dataclasses.is_dataclass(cls) and isinstance(cls, type)
               for f in dataclasses.fields(cls)
               if f.metadata.get("lo") is not None and f.metadata.get("hi") is not None]
    for owner, field in bounded:
        meta = dict(field.metadata)
        said = schema.describe_range(meta)
        for bound, open_ in ((meta["lo"], said[3] == "("), (meta["hi"], said[-1] == ")")):
            try:
                schema._check_range(bound, meta, field.name, SceneError)
                kept = True
            except SceneError:
                kept = False
            assert kept is not open_, (owner, field.name, said, bound)
    names = {(owner, field.name) for owner, field in bounded}
    assert {("SqueezeSpec", "relative_depth"), ("SweepSpec", "relative_depth"),
            ("OpeningSpec", "max"), ("GripperSpec", "max_speed")} <= names
    assert all(field.metadata["hi_open"] for _, field in bounded if field.name == "relative_depth")
    assert len(bounded) >= 10


def test_the_help_lists_the_device_files_keys_with_their_defaults():
    """``scene-help`` lists every key of a gripper device file (before, only docs/grippers.md's
    example showed them, without which are optional), and a device file without its optional
    keys gets the printed defaults.
    """
    import re

    from squeeze_grasp_ros.scene.gripper import parse_gripper
    from squeeze_grasp_ros.scene.help import scene_help

    printed = {line.split()[0]: line for line in scene_help().splitlines()
               if line.startswith("gripper.")}
    minimal = {"name": "g", "opening": {"max": 0.05}, "max_force": 10.0,
               "pad": {"shape": "pad", "width": 0.01, "edge_radius": 0.001},
               "transmission": {"joints": ["j"], "position_per_aperture": 1.0}}
    for key in ("opening.max", "max_force", "pad", "transmission.joints",
                "transmission.position_per_aperture"):
        assert printed[f"gripper.{key}"].endswith("required]"), key
    g = parse_gripper(minimal)
    for key in ("opening.min", "max_speed", "transmission.position_offset",
                "transmission.effort_per_force"):
        value = g
        for part in key.split("."):
            value = getattr(value, part)
        default = re.search(r"default ([^,\]]+)\]$", printed[f"gripper.{key}"]).group(1)
        assert value == float(default), key
    assert g.transmission.position_limits is None
    assert "gripper.transmission.position_limits" in printed


def test_the_defaults_the_help_prints_are_what_a_scene_without_the_key_gets():
    """``scene-help`` prints each optional key's default: the foam square's scene, which sets
    none of the squeeze's numerical keys, with a camera, sensors, pickup, strain limit and
    adversary given only their required keys, holds exactly the printed values.
    """
    import re

    from squeeze_grasp_ros.scene.help import scene_help

    printed = {}
    for line in scene_help().splitlines():
        found = re.search(r"default ([^,\]]+)\]$", line)
        if found:
            printed[line.split()[0]] = found.group(1)
    raw = yaml.safe_load(FOAM.read_text())
    assert not {"step", "event_tol", "max_events_per_depth"} & set(raw["squeeze"])
    raw.update({"camera": {}, "sensors": {"noise_std": 0.001, "seed": 1},
                "pickup": {"weight": 1.0}, "strain_limit": {"epsilon": 0.1},
                "adversary": {"placement": {"angle_deg": 90}, "a": [0.0, -0.01]}})
    raw["effects"] += ["camera", "sensor_noise", "pickup", "strain_limit", "adversary"]
    scene = parse_scene(raw, FOAM.parent)
    compared = set()
    for path, text in printed.items():
        value = scene
        for part in path.replace("F1|F2", "F1").split("."):
            value = value.get(part) if isinstance(value, dict) else getattr(value, part, None)
            if value is None:
                break
        if value is None or path.endswith("tip_radius") or path == "object.mesh.min_angle":
            continue  # a section the foam square leaves out, or a key it sets
        if isinstance(value, (bool, int, float)) and not isinstance(value, str):
            assert value == (text == "true" if isinstance(value, bool) else float(text)), path
        else:
            assert str(value) == text, path
        compared.add(path)
    assert {"squeeze.step", "squeeze.event_tol", "squeeze.max_events_per_depth", "squeeze.type",
            "object.model", "object.material.model", "camera.fx", "camera.frame_id",
            "camera.plan_from_images", "sensors.taxels", "pickup.lift_after",
            "strain_limit.criterion", "adversary.contacts"} <= compared, compared
    assert len(compared) >= 25
    assert (printed["squeeze.step"], printed["squeeze.event_tol"]) == ("0.001", "1e-09")
