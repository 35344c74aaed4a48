# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A sweep spec -> objects, parameter grid and Dask tasks, with seeds derived from ids.

Scenes. Every evaluation is a scene: the base scene with the object, material and parameters
of the evaluation substituted (:func:`group_scene`, :func:`evaluation_scene`), made mechanics
by the same :class:`~squeeze_grasp_ros.scene.setup.GraspSetup` as every other front end, so a
sweep computes what a scene file with the same values would (material model included).

Grouping. The costly shared step of an evaluation is meshing, assembling and factorising the
object and computing its boundary compliance (0.3-1 s for 1-2k nodes, against 0.05-0.5 s for a
squeeze); it depends on the object, its mesh settings and its material only. Evaluations are
therefore grouped by (object, mesh, material); a group's placements are chosen on the worker
from its mesh (the grasp map needs the factorised object). Groups are cut into tasks of at most
``chunk`` evaluations (whole placements) so that two workers share the work of a sweep with
few objects, a killed task loses little and the progress bar moves; each worker process keeps
the prepared groups it has seen (:mod:`.evaluate`), so a group is meshed and factorised once per
worker, not once per task.

Determinism. Every random draw takes its generator from ``SeedSequence(seed, spawn_key=...)``
whose spawn key is derived from the id of what is drawn (object id, group id and repeat), never
from a worker, an order of execution or Python's salted ``hash``.
"""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
from squeeze_grasp_ros.mechanics.vocabulary import Effect, Finger, ShapeType
from squeeze_grasp_ros.scene import (
    FingerSpec,
    FrictionSpec,
    GraspSetup,
    MaterialSpec,
    MeshSpec,
    ObjectSpec,
    PickupSpec,
    PlacementSpec,
    Scene,
    SceneError,
    build_outline,
    load_scene,
)
from squeeze_grasp_ros.scene.checks import validate
from squeeze_grasp_ros.sweep.limits import check_evaluations, check_objects, check_parameter_sets
from squeeze_grasp_ros.sweep.spec import LoadedSpec, ObjectEntry, SweepError, name_too_long


def id_key(*parts: str | int) -> tuple[int, ...]:
    """A stable SeedSequence spawn key (four 32-bit words of BLAKE2b) of an id."""
    digest = hashlib.blake2b("/".join(str(p) for p in parts).encode(), digest_size=16).digest()
    return tuple(int.from_bytes(digest[i:i + 4], "little") for i in range(0, 16, 4))


def rng_for(seed: int, *parts: str | int) -> np.random.Generator:
    """The generator of the draw identified by ``parts`` under root ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=id_key(*parts)))


@dataclass(frozen=True)
class ObjectItem:
    """One object of the sweep.

    Attributes
    ----------
    id : str
        ``NN-name`` (NN: entry index; families ``NN-name-KKK``).
    shape : dict
        Scene-style shape mapping (``object.shape``).
    mesh : MeshSpec
    outline : Outline or None
        Outline read from a file by the client (``shape.type: file``), so that workers need
        no access to the spec's files.
    """

    id: str
    shape: Mapping[str, Any]
    mesh: MeshSpec
    outline: Optional[Outline] = None


@dataclass(frozen=True)
class Params:
    """One point of the parameter grid (ids ``qNNNN`` in grid order)."""

    id: str
    mu: float
    tip_radius: float
    kind: str
    depth: Optional[float]
    relative_depth: Optional[float]


@dataclass(frozen=True)
class Task:
    """One Dask task: placements [start, stop) of a group, every parameter for each.

    Attributes
    ----------
    id : str
        ``<object id>~<material>~cNNNN``; also the Parquet part name.
    group : str
        ``<object id>~<material>``.
    spec_hash : str
        Hash of the sweep (workers cache prepared groups under it).
    obj : ObjectItem
    material : str
        The material's name.
    scene : Scene
        The group's scene (:func:`group_scene`): its object and material, the base scene's
        squeeze settings and limits; each evaluation places the fingers and sets the
        parameters (:func:`evaluation_scene`).
    placement_mode : str
    placement_count : int
    placement_filters : tuple of str
    placement_mu : float
    seed, repeat : int
    start, stop : int
        Placement index range of this task.
    params : tuple of Params
    adversary : tuple or None
        (position, mode, contacts, directions).
    time_limit : float or None
        CPU seconds an evaluation's squeeze may use (the spec's ``time_limit``).
    """

    id: str
    group: str
    spec_hash: str
    obj: ObjectItem
    material: str
    scene: Scene
    placement_mode: str
    placement_count: int
    placement_filters: tuple
    placement_mu: float
    seed: int
    repeat: int
    start: int
    stop: int
    params: tuple
    adversary: Optional[tuple]
    time_limit: Optional[float] = None

    @property
    def evaluations(self) -> int:
        """Upper bound of the evaluations of the task (graspmap may find fewer pairs)."""
        return (self.stop - self.start) * len(self.params)


def _family_shapes(entry: ObjectEntry, seed: int, name: str) -> list[tuple[str, dict]]:
    fam = entry.family
    out = []
    for k in range(fam.count):
        oid = f"{name}-{k:03d}"
        rng = rng_for(seed, "shape", oid)
        if fam.type == ShapeType.SUPERELLIPSE:
            shape = {"type": ShapeType.SUPERELLIPSE, "a": float(rng.uniform(*fam.a)),
                     "b": float(rng.uniform(*fam.b)),
                     "exponent": float(rng.uniform(*fam.exponent))}
        else:
            h = np.arange(1, fam.harmonics + 1)
            bound = fam.amplitude / h
            shape = {"type": ShapeType.FOURIER_BLOB, "radius": float(rng.uniform(*fam.radius)),
                     "cos": rng.uniform(-bound, bound).tolist(),
                     "sin": rng.uniform(-bound, bound).tolist()}
        out.append((oid, shape))
    return out


def object_count(loaded: LoadedSpec) -> int:
    """Number of objects of the sweep, counted without drawing the families."""
    entries = loaded.spec.objects
    if entries is None:
        return 1
    return sum(e.family.count if e.family is not None else 1 for e in entries)


def objects(loaded: LoadedSpec) -> list[ObjectItem]:
    """Every object of the sweep, in spec order (at most :data:`~.limits.MAX_OBJECTS`)."""
    check_objects(object_count(loaded))
    sw = loaded.spec
    if sw.objects is None:
        name = loaded.base.name or "base"
        problem = ("has a '/' or a NUL, which no file name can hold"
                   if "/" in name or "\0" in name else name_too_long(name))
        if problem:
            raise SweepError(f"base: the scene's name {name!r} {problem}: it names the sweep's "
                             "object; give objects with a name")
        shape = loaded.base.object.shape
        return [ObjectItem(f"00-{name}", shape, loaded.mesh, _file_outline(shape, "base"))]
    items = []
    for k, entry in enumerate(sw.objects):
        mesh = entry.mesh or loaded.mesh
        if entry.scene is not None:
            scene = load_scene(entry.scene)
            name = entry.name or _stem(entry.scene, f"objects[{k}].scene")
            pairs = [(name, scene.object.shape)]
            mesh = entry.mesh or scene.object.mesh
        elif entry.outline is not None:
            pairs = [(entry.name or _stem(entry.outline, f"objects[{k}].outline"),
                      {"type": ShapeType.FILE, "path": entry.outline})]
        elif entry.shape is not None:
            pairs = [(entry.name or entry.shape["type"], entry.shape)]
        else:
            pairs = _family_shapes(entry, sw.seed, entry.name or entry.family.type)
        where = (f"objects[{k}].outline" if entry.outline is not None
                 else f"objects[{k}].scene {Path(entry.scene).name}" if entry.scene is not None
                 else f"objects[{k}]")
        items += [ObjectItem(f"{k:02d}-{oid}", shape, mesh, _file_outline(shape, where))
                  for oid, shape in pairs]
    return items


def _stem(path: str, where: str) -> str:
    """The object name a file gives an entry without ``name``: its stem.

    Raises
    ------
    SweepError
        The stem is too long for the sweep's file names (:func:`~.spec.name_too_long`).
    """
    stem = Path(path).stem
    if problem := name_too_long(stem):
        raise SweepError(f"{where}: the file's name {stem!r} {problem}: give "
                         f"{where.rsplit('.', 1)[0]}.name")
    return stem


def _file_outline(shape: Mapping[str, Any], where: str) -> Optional[Outline]:
    """The outline a ``file`` shape reads (None for any other shape).

    Raises
    ------
    SweepError
        The file is no usable outline, named by ``where``, the spec's entry (an outline entry
        is not a scene's ``object.shape``).
    """
    if shape["type"] != ShapeType.FILE:
        return None
    try:
        return build_outline(shape)
    except SceneError as exc:
        text = str(exc)
        if where.endswith(".outline"):
            text = text.removeprefix("object.shape: ")
        raise SweepError(f"{where}: {text}") from None


def parameter_axes(loaded: LoadedSpec) -> dict[str, int]:
    """Length of each parameter axis, in grid order."""
    return {"friction": len(loaded.friction), "tip_radius": len(loaded.tip_radius),
            "squeeze": len(loaded.squeeze), "depth": len(loaded.depths)}


def parameter_grid(loaded: LoadedSpec) -> tuple[Params, ...]:
    """Friction x tip_radius x squeeze x depth, ids in that order (refused beyond
    :data:`~.limits.MAX_TASK_EVALUATIONS` sets before any is made).
    """
    check_parameter_sets(parameter_axes(loaded))
    grid = itertools.product(loaded.friction, loaded.tip_radius, loaded.squeeze, loaded.depths)
    return tuple(Params(f"q{k:04d}", float(mu), float(r), kind, d, rel)
                 for k, (mu, r, kind, (d, rel)) in enumerate(grid))


UNPLACED: dict = {Finger.F1: FingerSpec(PlacementSpec(angle_deg=180.0)),
                  Finger.F2: FingerSpec(PlacementSpec(angle_deg=0.0))}
"""Fingers of a group's scene before an evaluation places them on its nodes (angle placements
insert no mesh vertex, so the group's mesh is the object's own)."""


def group_scene(loaded: LoadedSpec, item: ObjectItem, material: MaterialSpec) -> Scene:
    """The scene of an (object, material) group: the base scene's squeeze settings, strain
    limit and the sweep's pickup weight, on ``item`` made of ``material``; friction is set
    per evaluation.
    """
    base = loaded.base
    strain = base.strain_limit if base.has(Effect.STRAIN_LIMIT) else None
    pickup = PickupSpec(loaded.weight) if loaded.weight is not None else None
    effects = (Effect.FRICTION,) + ((Effect.STRAIN_LIMIT,) if strain else ()) + (
        (Effect.PICKUP,) if pickup else ())
    scene = Scene(object=ObjectSpec(item.shape, material, mesh=item.mesh),
                  fingers=UNPLACED, name=item.id, squeeze=base.squeeze,
                  friction=FrictionSpec(min(loaded.friction)), strain_limit=strain,
                  pickup=pickup, effects=effects)
    try:
        return validate(scene)
    except SceneError as exc:
        raise SweepError(f"object {item.id}, material: {exc}") from None


def evaluation_scene(scene: Scene, nodes: tuple[int, int], params: Params) -> Scene:
    """The group's ``scene`` with the fingers on ``nodes`` (F1, F2) and the parameters of one
    evaluation: friction, fingertip radius, squeeze type and depth.
    """
    tip = params.tip_radius
    return dataclasses.replace(
        scene,
        fingers={Finger.F1: FingerSpec(PlacementSpec(node=nodes[0]), tip_radius=tip),
                 Finger.F2: FingerSpec(PlacementSpec(node=nodes[1]), tip_radius=tip)},
        friction=FrictionSpec(params.mu),
        squeeze=dataclasses.replace(scene.squeeze, type=params.kind, depth=params.depth,
                                    relative_depth=params.relative_depth),
    )


def group_setup(task: Task) -> GraspSetup:
    """The mechanics of the task's group: its scene meshed (the outline read by the client for
    an outline file), not yet precomputed.
    """
    return GraspSetup.build(task.scene, outline=task.obj.outline)


def placement_total(loaded: LoadedSpec, item: ObjectItem) -> int:
    """Number of placement indices of an object (meshes it for placements.mode: all)."""
    pl = loaded.spec.placements
    if pl.mode == "all":
        try:
            b = len(GraspSetup.build(group_scene(loaded, item, next(iter(
                loaded.materials.values()))), outline=item.outline).boundary)
        except Exception as exc:
            raise SweepError(f"object {item.id}: meshing failed: {exc}") from None
        return b * (b - 1) // 2
    return pl.count * (loaded.spec.repeat if pl.mode == "sample" else 1)


def plan_tasks(loaded: LoadedSpec) -> list[Task]:
    """Every task of the sweep, sorted by id.

    The sweep's size is checked from its counts first (:mod:`~.limits`): parameter sets and
    objects before they are made, evaluations and tasks before any task is.
    """
    sw = loaded.spec
    params = parameter_grid(loaded)
    per_task = max(1, sw.chunk // len(params))
    items = objects(loaded)
    totals = [placement_total(loaded, item) for item in items]
    check_evaluations(sum(totals), len(loaded.materials), len(params),
                      len(loaded.materials) * sum(-(-t // per_task) for t in totals))
    adversary = None
    if sw.adversary is not None:
        a = sw.adversary
        adversary = (a.position, a.mode, a.contacts, a.directions)
    pl = sw.placements
    mu_filter = pl.mu if pl.mu is not None else min(loaded.friction)
    tasks = []
    for item, total in zip(items, totals):
        for mat_name, m in loaded.materials.items():
            group = f"{item.id}~{mat_name}"
            scene = group_scene(loaded, item, m)
            for c, start in enumerate(range(0, total, per_task)):
                tasks.append(Task(
                    f"{group}~c{c:04d}", group, loaded.hash, item, mat_name, scene, pl.mode,
                    pl.count, tuple(pl.require), float(mu_filter), sw.seed, sw.repeat, start,
                    min(start + per_task, total), params, adversary, sw.time_limit))
    return sorted(tasks, key=lambda t: t.id)
