# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Worker side of a sweep: prepare a group once, then run the evaluations of a task.

:func:`run_task` is what Dask calls. It prepares the task's group (the group scene made
mechanics by :class:`~squeeze_grasp_ros.scene.setup.GraspSetup`: mesh, stiffness,
factorisation, boundary compliance; the point-contact grasp map; placements) or takes it from
the process's cache, then runs every (placement, parameter) evaluation of the task: the
evaluation's scene (:func:`~.plan.evaluation_scene`) on the group's body, squeezed by
:meth:`~squeeze_grasp_ros.scene.setup.GraspSetup.event_squeeze` (Algorithm 1), one row per
evaluation (:data:`COLUMNS`). An evaluation that raises becomes a row with its
``error``; the record of a squeeze is what the event engine reports (termination, events,
finger forces, work, energy, grasp health, slip margins); this module adds only the locations
of the strain and stress maxima, the pickup outcome, W*_F over push directions and the
point-contact stiffness. No Dask or pyarrow here: the loop is the bare mechanics loop too.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh
from squeeze_grasp_ros.mechanics.errors import NumericalError
from squeeze_grasp_ros.mechanics.resistance.optimal import sweep_directions
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap, grasp_map
from squeeze_grasp_ros.mechanics.vocabulary import Finger, StrainMeasure, Termination
from squeeze_grasp_ros.scene import GraspSetup
from squeeze_grasp_ros.scene.setup import check_adversary_node
from squeeze_grasp_ros.sweep.plan import Task, evaluation_scene, group_setup, rng_for
from squeeze_grasp_ros.threads import one_blas_thread

CACHE_GROUPS = 4
"""Prepared groups kept per worker process (a 2k-node group holds a few MB, and its object up
to SHARED_SET_BYTES of reduced contact sets shared by its evaluations)."""

COLUMNS: dict[str, str] = {
    "eval_id": "string",
    "task_id": "string",
    "object_id": "string",
    "material_id": "string",
    "placement_id": "string",
    "param_id": "string",
    "repeat": "int32",
    "node_F1": "int32",
    "node_F2": "int32",
    "x_F1": "float64",
    "y_F1": "float64",
    "x_F2": "float64",
    "y_F2": "float64",
    "mu": "float64",
    "tip_radius": "float64",
    "squeeze": "string",
    "target_depth": "float64",
    "target_relative_depth": "float64",
    "mesh_nodes": "int32",
    "boundary_nodes": "int32",
    "termination": "string",
    "depth": "float64",
    "relative_depth": "float64",
    "events_A": "int32",
    "events_B": "int32",
    "events_C": "int32",
    "events_D": "int32",
    "chatter": "int32",
    "contacts_F1": "int32",
    "contacts_F2": "int32",
    "force_F1_start": "float64",
    "force_F1_end": "float64",
    "force_F2_start": "float64",
    "force_F2_end": "float64",
    "work_F1": "float64",
    "work_F2": "float64",
    "energy": "float64",
    "material_model": "string",
    "max_strain": "float64",
    "strain_measure": "string",
    "max_strain_element": "int32",
    "max_strain_x": "float64",
    "max_strain_y": "float64",
    "max_strain_biot": "float64",
    "max_von_mises": "float64",
    "stress_measure": "string",
    "max_von_mises_element": "int32",
    "max_von_mises_x": "float64",
    "max_von_mises_y": "float64",
    "slip_margin_F1": "float64",
    "slip_margin_F2": "float64",
    "picked_up": "bool",
    "node_A": "int32",
    "resist_min": "float64",
    "resist_min_angle_deg": "float64",
    "resist_max": "float64",
    "resist_max_angle_deg": "float64",
    "stiffness": "float64",
    "time_s": "float64",
    "error": "string",
}
"""Dataset columns and their Arrow types (SI units; see docs/sweep.md). Every column but
``time_s`` is identical, bit for bit, however the sweep is distributed (but for the rows a
``time_limit`` cut: where the limit falls depends on the machine)."""


@dataclass(frozen=True)
class Group:
    """A prepared (object, mesh, material) group.

    Attributes
    ----------
    setup : GraspSetup
        The group's scene made mechanics: factorised, boundary compliance computed.
    gmap : GraspMap
        Point-contact grasp map (force closure at the task's ``placement_mu``).
    placements : list of (int, int, int)
        (repeat, node F1, node F2) per placement index.
    prepare_s : float
        Seconds spent preparing.
    """

    setup: GraspSetup
    gmap: GraspMap
    placements: list
    prepare_s: float


_CACHE: "OrderedDict[tuple, Group]" = OrderedDict()


def clear_cache() -> None:
    """Forget the prepared groups of this process (benchmarks start cold)."""
    _CACHE.clear()


def select_placements(task: Task, mesh: Mesh, gmap: GraspMap) -> list[tuple[int, int, int]]:
    """(repeat, F1 node, F2 node) of every placement index of the task's group."""
    loop = mesh.boundary
    b = len(loop)
    rows, cols = np.triu_indices(b, 1)
    if task.placement_mode == "all":
        return [(0, int(loop[i]), int(loop[j])) for i, j in zip(rows, cols)]
    if task.placement_mode == "sample":
        out = []
        for r in range(task.repeat):
            rng = rng_for(task.seed, "placements", task.group, r)
            pick = rng.choice(len(rows), size=min(task.placement_count, len(rows)), replace=False)
            out += [(r, int(loop[rows[k]]), int(loop[cols[k]])) for k in sorted(pick)]
        return out
    ok = np.ones((b, b), bool)
    for name in task.placement_filters:
        ok &= getattr(gmap, name)
    ok = ok[rows, cols]
    score = np.where(ok, gmap.stiffness[rows, cols], -np.inf)
    order = np.lexsort((np.arange(len(rows)), -score))[: task.placement_count]
    return [(0, int(loop[rows[k]]), int(loop[cols[k]])) for k in order if ok[k]]


def prepare(task: Task) -> Group:
    """The task's group from the cache, or mesh, factorise and select its placements."""
    key = (task.spec_hash, task.group)
    if key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key]
    start = time.perf_counter()
    setup = group_setup(task).precompute()
    gmap = grasp_map(setup.solid, task.placement_mu)
    group = Group(setup, gmap, select_placements(task, setup.solid.mesh, gmap),
                  time.perf_counter() - start)
    _CACHE[key] = group
    while len(_CACHE) > CACHE_GROUPS:
        _CACHE.popitem(last=False)
    return group


def _adversary(setup: GraspSetup, i: int, j: int, spec: tuple) -> dict:
    """W*_F per unit push, minimum and maximum over the push directions (J/m^2)."""
    position, mode, contacts, directions = spec
    mesh = setup.solid.mesh
    b = len(mesh.boundary)
    pi, pj = mesh.boundary_position(i), mesh.boundary_position(j)
    k = int(mesh.boundary[(pi + int(round(position * ((pj - pi) % b)))) % b])
    out = {"node_A": k}
    check_adversary_node((i, j), k, f"adversary.position {position}")
    grasp = setup.resistance_grasp(contacts, nodes=(i, j, k))
    ext = sweep_directions(grasp, mode, directions).extremes()
    for key in ("min", "max"):
        if ext[key] is not None:
            out[f"resist_{key}"] = ext[key]["unit_work"]
            out[f"resist_{key}_angle_deg"] = ext[key]["angle_deg"]
    return out


def _centroid(mesh: Mesh, element: int) -> tuple[float, float]:
    x, y = mesh.nodes[mesh.triangles[element]].mean(axis=0)
    return float(x), float(y)


def evaluate(task: Task, group: Group, index: int, params, resist: dict) -> dict:
    """One row: the event-driven squeeze of placement ``index`` with ``params``."""
    repeat, i, j = group.placements[index]
    setup = group.setup.on(evaluation_scene(task.scene, (i, j), params))
    mesh = setup.solid.mesh
    gpos = mesh.boundary_position(i), mesh.boundary_position(j)
    row = dict.fromkeys(COLUMNS)
    row.update(
        {
            "eval_id": f"{task.group}/p{index:05d}/{params.id}",
            "task_id": task.id,
            "object_id": task.obj.id,
            "material_id": task.material,
            "material_model": str(setup.scene.object.material.model),
            "placement_id": f"p{index:05d}",
            "param_id": params.id,
            "repeat": repeat,
            "node_F1": i,
            "node_F2": j,
            "x_F1": float(mesh.nodes[i, 0]),
            "y_F1": float(mesh.nodes[i, 1]),
            "x_F2": float(mesh.nodes[j, 0]),
            "y_F2": float(mesh.nodes[j, 1]),
            "mu": params.mu,
            "tip_radius": params.tip_radius,
            "squeeze": params.kind,
            "target_depth": params.depth,
            "target_relative_depth": params.relative_depth,
            "mesh_nodes": mesh.n,
            "boundary_nodes": len(mesh.boundary),
            "stiffness": float(group.gmap.stiffness[gpos]),
        }
    )
    start = time.perf_counter()
    try:
        res = setup.event_squeeze(checkpoint=_time_limit(task.time_limit))
        if task.adversary is not None:
            key = (i, j)
            if key not in resist:
                try:
                    resist[key] = _adversary(setup, i, j, task.adversary)
                except Exception as exc:  # noqa: BLE001 - recorded in the row
                    resist[key] = exc
            if isinstance(resist[key], Exception):
                raise resist[key]
            row.update(resist[key])
    except Exception as exc:  # noqa: BLE001 - an evaluation that raises becomes a row
        row["error"] = f"{type(exc).__name__}: {exc}"
        row["time_s"] = time.perf_counter() - start
        return row
    h = res.health
    row.update(
        {
            "termination": res.termination,
            "depth": res.depth,
            "relative_depth": res.relative_depth,
            **{f"events_{k}": n for k, n in res.event_counts.items()},
            "chatter": len(res.chatter),
            "contacts_F1": len(res.segments[Finger.F1]),
            "contacts_F2": len(res.segments[Finger.F2]),
            "force_F1_start": res.finger_force[Finger.F1][0],
            "force_F1_end": res.finger_force[Finger.F1][1],
            "force_F2_start": res.finger_force[Finger.F2][0],
            "force_F2_end": res.finger_force[Finger.F2][1],
            "work_F1": res.work[Finger.F1],
            "work_F2": res.work[Finger.F2],
            "energy": res.energy,
            "max_strain": h.max_strain,
            "strain_measure": str(h.strain_measure),
            "max_strain_element": h.max_strain_element,
            "max_strain_biot": h.max_principal_strain[StrainMeasure.BIOT],
            "max_von_mises": h.max_von_mises,
            "stress_measure": str(h.stress_measure),
            "max_von_mises_element": h.max_von_mises_element,
            "slip_margin_F1": h.slip_margin.get(Finger.F1),
            "slip_margin_F2": h.slip_margin.get(Finger.F2),
            "picked_up": (res.termination == Termination.PICKED_UP)
            if setup.limits.weight is not None
            else None,
        }
    )
    row["max_strain_x"], row["max_strain_y"] = _centroid(mesh, h.max_strain_element)
    row["max_von_mises_x"], row["max_von_mises_y"] = _centroid(mesh, h.max_von_mises_element)
    row["time_s"] = time.perf_counter() - start
    return row


class TimeLimitError(NumericalError):
    """An evaluation's squeeze used more CPU time than the sweep's ``time_limit``."""


def _time_limit(seconds: float | None) -> Callable[[], None] | None:
    """The squeeze's checkpoint of a ``time_limit``: raises :class:`TimeLimitError` once this
    thread has used more than ``seconds`` of CPU since the call (the stepper calls it before
    every substep and every solve, so the squeeze stops within one solve); None without one.
    """
    if seconds is None:
        return None
    start = time.thread_time()

    def check() -> None:
        if time.thread_time() - start > seconds:
            raise TimeLimitError(f"the squeeze used more than {seconds:g} s of CPU (the "
                                 "sweep's time_limit)")
    return check


def run_task(task: Task) -> dict:
    """Evaluate a task; returns ``{"rows": [...], "outline": [[x, y], ...], "prepare_s": s,
    "cached": bool, "evaluate_s": s}`` (rows sorted by ``eval_id``; the outline is the mesh's
    outer boundary loop, m, for the report's pictures).

    The task runs with one BLAS thread whatever the process's setting
    (:func:`~squeeze_grasp_ros.threads.one_blas_thread`), as Dask's nannies start workers:
    multithreaded OpenBLAS sums some products in another order, and the example sweep run in a
    plain Python process differed from the workers' rows in the last place of 88 values.
    """
    cached = (task.spec_hash, task.group) in _CACHE
    with one_blas_thread():  # the rows do not depend on the process's BLAS threads
        group = prepare(task)
        start = time.perf_counter()
        rows, resist = [], {}
        for index in range(task.start, min(task.stop, len(group.placements))):
            for params in task.params:
                rows.append(evaluate(task, group, index, params, resist))
    mesh = group.setup.solid.mesh
    return {
        "rows": sorted(rows, key=lambda r: r["eval_id"]),
        "outline": mesh.nodes[mesh.boundary].tolist(),
        "prepare_s": 0.0 if cached else group.prepare_s,
        "cached": cached,
        "evaluate_s": time.perf_counter() - start,
    }
