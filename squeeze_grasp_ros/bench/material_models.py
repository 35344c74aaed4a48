# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The linear model's error against the finite-deformation models as the squeeze deepens, and
what a nonlinear squeeze costs (Newton iterations, factorisations, time against linear).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from squeeze_grasp_ros import plots
from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.mechanics.elastic.contact_response import factorization_reuse
from squeeze_grasp_ros.mechanics.elastic.strain_measures import COMMON_STRAIN_MEASURE
from squeeze_grasp_ros.mechanics.squeeze.stepper import substep_adaptation
from squeeze_grasp_ros.mechanics.vocabulary import Finger, MaterialModel
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.scene import GraspSetup, load_scene

TITLE = "Large deformation: the linear model's error against squeeze depth, and its cost"
OBJECTS = ("foam_square", "disk", "nonconvex_blob")
NONLINEAR = (MaterialModel.COROTATIONAL, MaterialModel.NEO_HOOKEAN)
TARGET_RATIO = 10.0
VARIANTS = (("", True, True), (", full Newton", False, True), (", step grid", True, False))
"""Nonlinear cost rows: (label suffix, factorisation reuse, adaptive substeps)."""
NONLINEAR_REPEATS = 2
"""The default nonlinear rows are the best of this many runs (the variants one run each)."""
LINEAR_REPEATS = 3
"""The linear squeeze's time is the best of this many runs: the first also fills the object's
per-node gradient cache of the inversion check (about 1 ms per contact node, once per
object), which is precompute, not squeeze."""


def _setup(name: str, nodes: int) -> GraspSetup:
    """The shipped scene ``name`` re-meshed to about ``nodes`` nodes, precomputed."""
    scene = load_scene(scene_file(name))
    obj = dataclasses.replace(scene.object, mesh=dataclasses.replace(scene.object.mesh,
                                                                     nodes=nodes))
    return GraspSetup.build(dataclasses.replace(scene, object=obj)).precompute()


def _run(setup: GraspSetup, model: MaterialModel, relative_depth: float):
    start = time.perf_counter()
    res = setup.event_squeeze(relative_depth=relative_depth, material_model=model)
    return res, time.perf_counter() - start


def _best(setup: GraspSetup, model: MaterialModel, repeats: int):
    """(result, best time) of ``repeats`` 12 % squeezes."""
    runs = [_run(setup, model, 0.12) for _ in range(repeats)]
    return runs[0][0], min(t for _, t in runs)


def _verdict(cost: list, quick: bool) -> str:
    """The target sentence: neo-Hookean under 10x linear on the scene's 2,000-node mesh."""
    ratio = next(row[2] for row in cost if row[0] == str(MaterialModel.NEO_HOOKEAN))
    if quick:
        return (f"Quick run on about 800 nodes: neo-Hookean at {ratio:.1f}x linear; the target "
                f"(< {TARGET_RATIO:g}x) is stated for the scene's 2,000-node mesh (full run).")
    if ratio < TARGET_RATIO:
        return f"Target (< {TARGET_RATIO:g}x linear) met: neo-Hookean at {ratio:.1f}x."
    return (f"Target (< {TARGET_RATIO:g}x linear) not met: neo-Hookean at {ratio:.1f}x. Each "
            "evaluation still ends in a sparse factorisation of the whole object (about 4 ms "
            "at 2,054 nodes), where the linear route gathers a cached boundary compliance.")


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """Force, energy and strain differences from linear at increasing depth; cost of one
    squeeze.
    """
    label = COMMON_STRAIN_MEASURE.label
    depths = (0.02, 0.08, 0.16) if quick else (0.02, 0.04, 0.08, 0.12, 0.20, 0.30)
    nodes = 400 if quick else 1200
    rows, curves = [], {}
    for name in OBJECTS:
        setup = _setup(name, nodes)
        for rel in depths:
            progress(f"material_models: {name} at {100 * rel:g} %")
            linear, _ = _run(setup, MaterialModel.LINEAR, rel)
            common = linear.health.max_principal_strain[COMMON_STRAIN_MEASURE]
            row = [name, 100 * rel, linear.finger_force[Finger.F1][1], common]
            for model in NONLINEAR:
                res, _ = _run(setup, model, rel)
                df = res.finger_force[Finger.F1][1] / linear.finger_force[Finger.F1][1] - 1
                de = res.energy / linear.energy - 1
                ds = res.health.max_principal_strain[COMMON_STRAIN_MEASURE] / common - 1
                row += [100 * df, 100 * de, 100 * ds, res.termination]
                curves.setdefault((name, model), []).append((100 * rel, 100 * df))
            rows.append(row)
    png = "material_models_error.png"
    fig, (ax,) = plots.figure(size=5.0)
    for (name, model), points in curves.items():
        x, y = zip(*points)
        ax.plot(x, y, "o-" if model == MaterialModel.NEO_HOOKEAN else "s--",
                label=f"{name}, {model}")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_aspect("auto")
    ax.set_xlabel("relative depth [%]")
    ax.set_ylabel("finger force vs linear [%]")
    ax.set_title("finite deformation vs linear")
    ax.legend(fontsize=7)
    plots.save(fig, out_dir / png)
    progress("material_models: cost of a 12 % foam-square squeeze")
    cost = []
    setup = _setup("foam_square", 800 if quick else 2000)
    linear, t_lin = _best(setup, MaterialModel.LINEAR, LINEAR_REPEATS)
    cost.append([str(MaterialModel.LINEAR), t_lin, 1.0, linear.diagnostics["substeps"],
                 linear.diagnostics["root_evaluations"], "-", "-", "-",
                 linear.finger_force[Finger.F1][1]])
    for model in NONLINEAR:
        for variant, reuse, adapt in VARIANTS:
            with factorization_reuse(reuse), substep_adaptation(adapt):
                res, t = _best(setup, model, 1 if variant else NONLINEAR_REPEATS)
            nl = res.diagnostics["nonlinear"]
            cost.append([str(model) + variant, t, t / t_lin, res.diagnostics["substeps"],
                         res.diagnostics["root_evaluations"],
                         f"{nl['evaluations']} ({nl['look_ups']})",
                         nl["newton_iterations"] / max(nl["evaluations"], 1),
                         nl["factorizations"], res.finger_force[Finger.F1][1]])
    return [
        Table(TITLE, ["object", "rel. depth [%]", "linear F1 [N]", f"linear max {label} strain",
                      "corot. dF [%]", "corot. dE [%]", f"corot. d{label} [%]", "corot. end",
                      "neo-H. dF [%]", "neo-H. dE [%]", f"neo-H. d{label} [%]", "neo-H. end"],
              rows,
              f"Shipped scenes re-meshed to about {nodes} nodes; the same event-driven squeeze "
              "(events to the scene's event_tol) under each model. dF, dE: F1's force along its "
              "motion and the strain energy relative to linear. "
              f"d{label}: the largest principal {label} strain U - I of the model's field "
              "relative to that of the linear field: the same measure of both fields, so the "
              "difference is the solution's, not the measures' (each model's own measure, "
              "small, Biot or log, differs from the others by up to a third at these "
              "strains).",
              (png,)),
        Table("Cost of a nonlinear squeeze (foam square, 12 %, events to 1e-9 L)",
              ["model", "time [s]", "x linear", "substeps", "root evaluations",
               "evaluations (look-ups)", "Newton its / evaluation", "factorisations",
               "F1 [N]"],
              cost,
              "An evaluation is one equilibrium of the contact set at one finger position "
              "(interior Newton from a first-order predictor off the nearest kept state, "
              "backtracking, load sub-steps if needed); each ends with one sparse LDL^T of the "
              "interior tangent (QDLDL, one ordering per object), and dF/d delta is applied to "
              "the finger motion by one solve with it. Newton re-uses the factorisation held "
              "while the residual falls by 4x per iteration ('full Newton': refactor at every "
              "iteration); a response keeps its last 4 states, so a return to a solved point is "
              "a look-up. The linear model steps on the scene's step grid (1e-3 L), where an "
              "evaluation is a small dense product; the nonlinear models adapt their substeps "
              "between events (up to 4 grid steps while "
              "the force slope changes little; 'step grid': the linear model's grid), and every "
              "model locates gap, force and cone events on cubic Hermite interpolants. Same "
              "forces to the Newton tolerance in every row. The linear row is the best of "
              f"{LINEAR_REPEATS} runs and includes the element-inversion check; the default "
              f"nonlinear rows are the best of {NONLINEAR_REPEATS}, the variants one run each. "
              + _verdict(cost, quick)),
    ]
