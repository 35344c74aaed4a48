# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The package's layering, read from its import graph (every ``import``, also inside functions).

The layers, lowest first, are the ones docs/design.md draws:

- base: ``inputs``, ``exit_codes``, ``extras``, ``resources``, ``threads``, ``stdout``, and the
  build tools of ``buildtool`` (the interface build: cmake, never rclpy): no package imports;
- ``mechanics``: the ROS-free core, inside it ``vocabulary``/``errors`` < ``elastic`` <
  ``squeeze`` < ``resistance``, ``ring``; ``calibration`` stands alone;
- application: ``scene``, ``planning``, ``control``, ``sim``, ``plots``, ``outputs``,
  ``sweep``, ``perception`` and the front door ``api``;
- ``ros``: the only folder that imports rclpy, ROS messages or the interfaces;
- front ends: ``commands``, ``bench``, ``cli``, ``entry``.

A module may import its own layer and the layers below it, never one above.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

import squeeze_grasp_ros

PACKAGE = Path(squeeze_grasp_ros.__file__).parent
NAME = "squeeze_grasp_ros"
ROS_MODULES = ("rclpy", "rosidl", "rcl_interfaces", "builtin_interfaces", "std_msgs",
               "geometry_msgs", "sensor_msgs", "visualization_msgs", "rosgraph_msgs",
               "action_msgs", "squeeze_grasp_interfaces", "launch", "launch_ros", "rosbag2",
               "control_msgs", "trajectory_msgs")
LAYERS: tuple[tuple[str, ...], ...] = (
    ("inputs", "exit_codes", "extras", "resources", "threads", "stdout", "buildtool"),
    ("mechanics",),
    ("scene", "planning", "control", "sim", "plots", "outputs", "sweep", "perception", "api"),
    ("ros",),
    ("commands", "bench", "cli", "entry"),
)
MECHANICS_ORDER: dict[str, int] = {"vocabulary": 0, "errors": 0, "ties": 0, "elastic": 1,
                                   "squeeze": 2, "resistance": 3, "ring": 3, "calibration": 1}
"""Rank of each part of ``mechanics``: a part imports only parts of lower rank (and itself);
calibration imports nothing but the base parts."""


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path) -> set[str]:
    """Absolute names of every module ``path`` imports (relative imports resolved)."""
    name = module_name(path)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                found.add(".".join(base + ([node.module] if node.module else [])))
            else:
                found.add(node.module)
    return found


GRAPH: dict[str, set[str]] = {module_name(p): imports(p) for p in PACKAGE.rglob("*.py")}


def top(name: str) -> str:
    """First component below the package ("" for the package itself)."""
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else ""


def layer(name: str) -> int:
    part = top(name)
    for k, members in enumerate(LAYERS):
        if part in members:
            return k
    raise AssertionError(f"{name}: its folder/module {part!r} is in no layer; add it to "
                         "LAYERS here and to the diagram in docs/design.md")


def internal(targets: set[str]) -> set[str]:
    return {t for t in targets if t == NAME or t.startswith(NAME + ".")}


def test_the_graph_covers_the_package():
    assert len(GRAPH) > 80
    assert "squeeze_grasp_ros.mechanics.squeeze.stepper" in GRAPH
    assert "squeeze_grasp_ros.ros.nodes.planner" in GRAPH


@pytest.mark.parametrize("module", sorted(m for m in GRAPH if m != NAME))
def test_no_module_imports_a_higher_layer(module):
    here = layer(module)
    upward = sorted(t for t in internal(GRAPH[module]) if t != NAME and layer(t) > here)
    assert not upward, f"{module} (layer {LAYERS[here]}) imports higher layers: {upward}"


def test_only_the_ros_folder_imports_ros():
    offenders = {m: sorted(t for t in GRAPH[m] if t.split(".")[0] in ROS_MODULES)
                 for m in GRAPH if top(m) != "ros"}
    offenders = {m: ts for m, ts in offenders.items() if ts}
    assert not offenders, f"ROS imported outside squeeze_grasp_ros/ros: {offenders}"


def test_the_ros_folder_does_import_ros():
    """The check above is not vacuous: the nodes do import rclpy."""
    assert "rclpy" in GRAPH["squeeze_grasp_ros.ros.nodes.planner"] | {
        t.split(".")[0] for t in GRAPH["squeeze_grasp_ros.ros.nodes.planner"]}


def mechanics_part(name: str) -> str | None:
    parts = name.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "mechanics" else None


def test_mechanics_parts_follow_the_paper_order():
    """Elastic < squeeze < resistance, ring; no cycle between the parts."""
    bad = []
    for module, targets in GRAPH.items():
        part = mechanics_part(module)
        if part is None:
            continue
        for t in internal(targets):
            other = mechanics_part(t)
            if other is None or other == part:
                continue
            if MECHANICS_ORDER[other] >= MECHANICS_ORDER[part]:
                bad.append(f"{module} -> {t}")
    assert not bad, "mechanics parts import sideways or upwards:\n" + "\n".join(bad)


def test_the_module_graph_is_acyclic_at_module_level():
    """No import cycle among modules (module-level imports only)."""
    level: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        name = module_name(path)
        tree = ast.parse(path.read_text(encoding="utf-8"))
        top_level = ast.Module(body=[n for n in tree.body if isinstance(n, (ast.Import,
                                                                            ast.ImportFrom))],
                               type_ignores=[])
        targets = set()
        for node in top_level.body:
            if isinstance(node, ast.ImportFrom) and not node.level and node.module:
                targets.add(node.module)
            elif isinstance(node, ast.Import):
                targets.update(a.name for a in node.names)
        level[name] = {t for t in internal(targets) if t in GRAPH and t != name
                       and not name.startswith(t + ".")}
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in level.get(node, ()):
            if state.get(nxt) == 1:
                raise AssertionError("import cycle: " + " -> ".join(stack + [node, nxt]))
            if nxt not in state:
                visit(nxt, stack + [node])
        state[node] = 2

    for name in sorted(level):
        if name not in state:
            visit(name, [])


def test_importing_the_package_sets_no_environment_variable():
    """A library import has no side effects (the executables set BLAS threads themselves)."""
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    code = ("import os; before = dict(os.environ); import squeeze_grasp_ros.api; "
            "print(sorted(set(os.environ) ^ set(before)))")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


def test_the_design_diagram_matches_the_layers():
    """docs/design.md draws every top-level module and folder, higher layers above lower ones,
    and the mechanics parts in the order MECHANICS_ORDER checks.
    """
    text = (PACKAGE.parent / "docs" / "design.md").read_text(encoding="utf-8")
    section = text[text.index("## 1. Layers"):text.index("## 2.")]
    diagram = section[section.index("```\n") + 4:section.index("\n```", section.index("```\n"))]
    lines = diagram.splitlines()

    def row(name: str) -> int:
        for k, line in enumerate(lines):
            if f" {name}/" in f" {line}" or f" {name}.py" in f" {line}":
                return k
        raise AssertionError(f"{name} is not in the diagram of docs/design.md")

    tops = {top(m) for m in GRAPH if top(m)}
    for name in tops:
        row(name)
    rows = [[row(name) for name in members if name in tops] for members in LAYERS]
    for upper, lower in zip(rows[1:], rows[:-1]):
        assert max(upper) < min(lower), "a higher layer is drawn below a lower one"
    parts = {name: row(name) for name in MECHANICS_ORDER}
    for a, rank_a in MECHANICS_ORDER.items():
        for b, rank_b in MECHANICS_ORDER.items():
            if rank_a > rank_b and not {a, b} & {"calibration"}:
                assert parts[a] < parts[b], f"{a} must be drawn above {b}"


SCENE_BUILDERS = frozenset({"build_mesh", "build_ring", "finger_nodes", "placement_node",
                            "placement_points", "scene_material", "scene_solid"})
"""The builders of ``scene/build.py``: a scene's mesh, material, ring, finger nodes (an outline
is geometry, not mechanics: sweeps read outline files on their client with ``build_outline``,
and the planner estimates sizes with ``requested_nodes`` before building anything)."""
MECHANICS_BUILDERS = frozenset({"ElasticObject", "RingModel", "Material", "generate_mesh",
                                "ring_from_outline", "contact_model", "ContactModel",
                                "NonlinearContactModel", "event_squeeze", "finger_motion",
                                "place_fingertip"})
"""Constructors of the mechanics a scene becomes: object, material, mesh, ring, contact model,
finger motion, fingertips, the event-driven squeeze."""
API = f"{NAME}.api"
"""The front door re-exports the builders for users; it builds nothing itself."""


def scene_users() -> dict[str, ast.Module]:
    """Modules outside ``scene/`` and ``mechanics/`` that import from the scene package."""
    users = {}
    for path in PACKAGE.rglob("*.py"):
        name = module_name(path)
        if top(name) in ("scene", "mechanics") or name == API:
            continue
        if any(t == f"{NAME}.scene" or t.startswith(f"{NAME}.scene.") for t in GRAPH[name]):
            users[name] = ast.parse(path.read_text(encoding="utf-8"))
    return users


def test_only_the_scene_package_builds_mechanics_from_a_scene():
    """A scene becomes mechanics in one place (``scene.setup.GraspSetup``): no module outside
    ``scene/`` imports the scene builders, and no module that reads scenes calls a mechanics
    constructor itself (it asks its GraspSetup). Benchmarks that build objects from outlines
    of their own, without a scene, are not concerned.
    """
    users = scene_users()
    assert {f"{NAME}.planning.objects", f"{NAME}.sim.world", f"{NAME}.sweep.evaluate",
            f"{NAME}.commands.squeeze", f"{NAME}.bench.pipeline"} <= set(users), sorted(users)
    offenders = []
    for name, tree in users.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
                    f"{NAME}.scene"):
                offenders += [f"{name} imports {a.name}" for a in node.names
                              if a.name in SCENE_BUILDERS or node.module.endswith(".build")]
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
                if node.func.id in MECHANICS_BUILDERS:
                    offenders.append(f"{name}:{node.lineno} calls {node.func.id}")
    assert not offenders, "mechanics built from a scene outside scene/:\n" + "\n".join(
        sorted(offenders))


def test_the_scene_builders_are_found_by_the_check():
    """The check above is not vacuous: it sees the builders where they are allowed."""
    tree = ast.parse((PACKAGE / "scene" / "setup.py").read_text(encoding="utf-8"))
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)
                for a in n.names}
    called = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call)
              and isinstance(n.func, ast.Name)}
    assert {"build_mesh", "finger_nodes"} <= imported and "ElasticObject" in called


def test_the_scene_package_sits_below_the_other_application_parts():
    """``scene/`` imports only the base, ``mechanics`` and ``control`` (the executor's goal):
    planning, the simulated world, sweeps and every front end build on it, never the reverse.
    """
    allowed = {"inputs", "exit_codes", "extras", "resources", "threads", "mechanics", "scene",
               "control"}
    bad = sorted(f"{m} -> {t}" for m in GRAPH if top(m) == "scene"
                 for t in internal(GRAPH[m]) if t != NAME and top(t) not in allowed)
    assert not bad, "\n".join(bad)


def test_no_verb_imports_another_verb():
    """Verbs share helpers (``commands/common.py``, ``commands/ring_map.py``, ...) and the
    application layer, never each other (``graspmap`` used to import ``ring``).
    """
    from squeeze_grasp_ros.commands import VERBS

    verbs = {f"{NAME}.commands.{v}" for v in VERBS}
    bad = sorted(f"{m} -> {t}" for m in verbs for t in GRAPH[m] if t in verbs - {m})
    assert not bad, "\n".join(bad)
    assert f"{NAME}.commands.ring_map" in GRAPH[f"{NAME}.commands.graspmap"]
