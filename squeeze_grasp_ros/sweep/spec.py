# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Sweep spec: strict YAML -> frozen, validated :class:`SweepSpec` (``squeeze-grasp sweep-help``).

A sweep names a base scene (defaults for everything not swept: material, mesh, friction,
fingertip, squeeze, strain limit, event tolerances), the objects, the axes (materials, friction,
fingertip radius, squeeze type, depth), the placements per object, an optional pickup weight and
an optional adversary. The parser is the scene parser
(:func:`~squeeze_grasp_ros.scene.schema.parse_section`):
unknown keys, wrong types and values out of range raise :class:`SweepError` naming the key.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

from squeeze_grasp_ros.mechanics.errors import FINGERS_MEET
from squeeze_grasp_ros.mechanics.resistance.optimal import MAX_DIRECTIONS
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import MAX_TIP_SIZE
from squeeze_grasp_ros.mechanics.vocabulary import (
    ContactKind,
    Effect,
    Finger,
    ObjectModel,
    ShapeType,
    SqueezeKind,
)
from squeeze_grasp_ros.scene import (
    MaterialSpec,
    MeshSpec,
    Scene,
    SceneError,
    build_outline,
    load_scene,
    read_yaml,
)
from squeeze_grasp_ros.scene.checks import check_material, check_shape
from squeeze_grasp_ros.scene.schema import key_reference, parse_section, spec


class SweepError(SceneError):
    """A sweep spec entry is unknown, of the wrong type, out of range or contradictory, or the
    sweep cannot run (missing extra, output directory of another spec).
    """


FAMILIES: dict[ShapeType, tuple[str, ...]] = {
    ShapeType.SUPERELLIPSE: ("a", "b", "exponent"),
    ShapeType.FOURIER_BLOB: ("radius",),
}
"""Random shape families and their required parameter ranges."""


@dataclass(frozen=True)
class FamilySpec:
    """Seeded random shapes: every parameter drawn uniformly from its [low, high] range."""

    type: ShapeType = spec("shape family", choices=tuple(FAMILIES))
    count: int = spec("number of shapes drawn", lo=1)
    a: Optional[tuple[float, float]] = spec(
        "superellipse: half-width range [low, high]", "m", lo=0.0, lo_open=True, default=None
    )
    b: Optional[tuple[float, float]] = spec(
        "superellipse: half-height range [low, high]", "m", lo=0.0, lo_open=True, default=None
    )
    exponent: Optional[tuple[float, float]] = spec(
        "superellipse: exponent range [low, high]", "", lo=2.0, default=None
    )
    radius: Optional[tuple[float, float]] = spec(
        "fourier_blob: mean radius range [low, high]", "m", lo=0.0, lo_open=True, default=None
    )
    harmonics: int = spec("fourier_blob: number of harmonics k = 1..H", lo=1, default=4)
    amplitude: float = spec(
        "fourier_blob: coefficients of harmonic k drawn from [-amplitude/k, amplitude/k]",
        "",
        lo=0.0,
        hi=0.3,
        default=0.1,
    )


@dataclass(frozen=True)
class ObjectEntry:
    """One entry of ``objects``: exactly one of scene, outline, shape, family."""

    name: str = spec(
        "name used in ids (default: file stem, shape type or family type)", default=""
    )
    scene: Optional[str] = spec("scene file: its object's shape and mesh settings", default=None)
    outline: Optional[str] = spec(
        "outline file: CSV 'x,y' per line or JSON {outline: [...]}", "m", default=None
    )
    shape: Optional[Mapping[str, Any]] = spec("shape mapping as in scenes (object.shape)",
                                              default=None)
    family: Optional[FamilySpec] = spec("seeded random shapes", default=None)
    mesh: Optional[MeshSpec] = spec(
        "mesh settings of this entry (default: the sweep's mesh)", default=None
    )


PLACEMENT_FILTERS = ("inward", "force_closure")
MAX_NAME_BYTES = 100
"""Longest object or material name (UTF-8 bytes): a task id holds both and names a part file,
``.<task id>.parquet.<pid>.tmp`` while it is written, and a file name is at most 255 bytes."""


def name_too_long(name: str) -> str | None:
    """Why ``name`` cannot name an object or a material (too long for the sweep's file
    names), or None.
    """
    size = len(name.encode("utf-8", "surrogatepass"))
    if size <= MAX_NAME_BYTES:
        return None
    return (f"is {size} bytes long; at most {MAX_NAME_BYTES} (object and material names name "
            "the sweep's files)")


@dataclass(frozen=True)
class PlacementsSpec:
    """Initial contact pairs (F1, F2) per object, over outer-boundary nodes."""

    mode: str = spec(
        "all: every boundary-node pair; sample: a seeded sample of `count` pairs "
        "(per repeat); graspmap: the `count` stiffest pairs of the point-contact "
        "grasp map passing `require`",
        choices=("all", "sample", "graspmap"),
        default="sample",
    )
    count: int = spec("pairs per object (sample: per repeat; graspmap: top N)", lo=1, default=20)
    require: tuple[str, ...] = spec(
        "graspmap: filters the pairs must pass",
        choices=PLACEMENT_FILTERS,
        default=PLACEMENT_FILTERS,
    )
    mu: Optional[float] = spec(
        "graspmap: friction coefficient of the force-closure test "
        "(default: the smallest of the sweep)",
        "",
        lo=0.0,
        default=None,
    )


@dataclass(frozen=True)
class SweepAdversarySpec:
    """Optimal resistance W*_F to an adversary finger A at the initial contacts (Sec. 6)."""

    position: float = spec(
        "where A touches: fraction of the boundary loop counter-clockwise from F1 to F2",
        "",
        lo=0.0,
        hi=1.0,
        lo_open=True,
        default=0.5,
    )
    mode: SqueezeKind = spec("resistance type", choices=SqueezeKind.planned(),
                             default=SqueezeKind.STABLE)
    contacts: ContactKind = spec(
        "point: the three nodes; segment: each node and its two neighbours",
        choices=(ContactKind.POINT.value, ContactKind.SEGMENT.value),
        default=ContactKind.POINT,
    )
    directions: int = spec(
        "push directions over which W*_F per unit push is minimised and maximised",
        lo=1,
        hi=MAX_DIRECTIONS,
        default=72,
    )


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep. Build it with :func:`load_sweep_spec`."""

    base: str = spec("base scene file (defaults for everything not swept)")
    name: str = spec("sweep name", default="")
    description: str = spec("free text", default="")
    seed: int = spec(
        "root seed of every random draw (shapes, sampled placements)", lo=0, default=0
    )
    repeat: int = spec(
        "independent draws of the sampled placements (placements.mode: sample)", lo=1, default=1
    )
    objects: Optional[tuple[ObjectEntry, ...]] = spec(
        "objects (default: the base scene's)", default=None
    )
    materials: Optional[Mapping[str, Any]] = spec(
        "name -> {E, nu, thickness[, model]} (default: the base scene's, named 'base')",
        default=None,
    )
    mesh: Optional[MeshSpec] = spec("mesh settings (default: the base scene's)", default=None)
    friction: Optional[tuple[float, ...]] = spec(
        "friction coefficients mu", "", lo=0.0, hi=1e3, default=None
    )
    tip_radius: Optional[tuple[float, ...]] = spec(
        "fingertip radii (both fingers)", "m", lo=0.0, lo_open=True, hi=MAX_TIP_SIZE,
        default=None
    )
    squeeze: Optional[tuple[SqueezeKind, ...]] = spec(
        "squeeze types", choices=SqueezeKind.planned(), default=None
    )
    depth: Optional[tuple[float, ...]] = spec(
        "squeeze depths rho", "m", lo=0.0, lo_open=True, default=None
    )
    relative_depth: Optional[tuple[float, ...]] = spec(
        "relative depths (finger approach / initial contact distance)",
        "",
        lo=0.0,
        hi=1.0,
        lo_open=True,
        hi_open=True,
        why=FINGERS_MEET,
        default=None,
    )
    weight: Optional[float] = spec(
        "object weight for pickup: the squeeze stops when friction "
        "can lift it (default: the base scene's pickup)",
        "N",
        lo=0.0,
        lo_open=True,
        default=None,
    )
    adversary: Optional[SweepAdversarySpec] = spec(
        "optimal resistance per placement", default=None
    )
    placements: PlacementsSpec = spec("placements per object", default_factory=PlacementsSpec)
    chunk: int = spec(
        "most evaluations per Dask task (tasks of one object and material share "
        "its mesh and factorisation on each worker)",
        lo=1,
        default=64,
    )
    time_limit: Optional[float] = spec(
        "CPU time one evaluation's squeeze may use; beyond it the squeeze stops within one "
        "solve and the row carries the error (default: none; such rows depend on the machine)",
        "s",
        lo=0.0,
        lo_open=True,
        default=None,
    )


@dataclass(frozen=True)
class LoadedSpec:
    """A sweep spec with its base scene, resolved axes and identity.

    Attributes
    ----------
    spec : SweepSpec
        Paths made absolute (relative to the spec file).
    base : Scene
    materials : dict
        Name -> MaterialSpec.
    mesh : MeshSpec
    friction, tip_radius : tuple of float
    squeeze : tuple of str
    depths : tuple of (float or None, float or None)
        (depth m, relative depth) pairs, exactly one of each pair set.
    weight : float or None
    hash : str
        SHA-256 of the spec as written and the bytes of every file it reads (not of where
        they are, so a moved checkout resumes its sweeps).
    raw : dict
        The YAML mapping as given.
    """

    spec: SweepSpec
    base: Scene
    materials: Mapping[str, MaterialSpec]
    mesh: MeshSpec
    friction: tuple[float, ...]
    tip_radius: tuple[float, ...]
    squeeze: tuple[str, ...]
    depths: tuple[tuple[Optional[float], Optional[float]], ...]
    weight: Optional[float]
    hash: str
    raw: Mapping[str, Any]


def _absolute(path: Optional[str], base_dir: Path) -> Optional[str]:
    if path is None or Path(path).is_absolute():
        return path
    return str(base_dir / path)


def _check_entry(entry: ObjectEntry, where: str) -> None:
    given = [k for k in ("scene", "outline", "shape", "family") if getattr(entry, k) is not None]
    if len(given) != 1:
        raise SweepError(
            f"{where} needs exactly one of scene, outline, shape, family; got {given or 'none'}"
        )
    if entry.name and not all(c.isalnum() or c in "_.-" for c in entry.name):
        raise SweepError(
            f"{where}.name must use letters, digits, '_', '.', '-', got {entry.name!r}"
        )
    if entry.name and (problem := name_too_long(entry.name)):
        raise SweepError(f"{where}.name {problem}")
    fam = entry.family
    if fam is not None:
        for key in FAMILIES[fam.type]:
            value = getattr(fam, key)
            if value is None:
                raise SweepError(f"missing required key {where}.family.{key} for type {fam.type}")
            if value[0] > value[1]:
                raise SweepError(
                    f"{where}.family.{key} must be [low, high] with low <= high, got {list(value)}"
                )
        other = [
            k
            for f, keys in FAMILIES.items()
            if f != fam.type
            for k in keys
            if getattr(fam, k) is not None
        ]
        if other:
            raise SweepError(
                f"{where}.family.{other[0]} does not apply to type {fam.type} "
                f"(allowed: {list(FAMILIES[fam.type])})"
            )
    if entry.shape is not None:
        try:
            check_shape(entry.shape)
            build_outline(entry.shape)
        except SceneError as exc:
            raise SweepError(f"{where}: {exc}".replace("object.shape", "shape")) from None


def _file_digest(path: str, where: str) -> str:
    p = Path(path)
    if not p.is_file():
        raise SweepError(f"{where}: file not found: {p}")
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _axis(values, default, where: str) -> tuple:
    if values is None:
        return (default,)
    if len(values) == 0:
        raise SweepError(f"{where} must list at least one value")
    if len(set(values)) != len(values):
        raise SweepError(f"{where} lists a value twice: {list(values)}")
    return tuple(values)


def parse_sweep_spec(data: Any, base_dir: Path) -> LoadedSpec:
    """Validate a sweep given as a mapping; relative paths are relative to ``base_dir``."""
    if not isinstance(data, dict):
        raise SweepError("a sweep spec must be a YAML mapping")
    sw = parse_section(SweepSpec, data, "", error=SweepError)
    sw = dataclasses.replace(sw, base=_absolute(sw.base, base_dir))
    files = {"base": _file_digest(sw.base, "base")}
    try:
        base = load_scene(sw.base)
    except SceneError as exc:
        raise SweepError(f"base: {exc}") from None
    if base.object.model != ObjectModel.SOLID:
        raise SweepError("base: the sweep needs a solid object (object.model: solid)")
    entries = []
    for k, entry in enumerate(sw.objects or ()):
        where = f"objects[{k}]"
        entry = dataclasses.replace(
            entry,
            scene=_absolute(entry.scene, base_dir),
            outline=_absolute(entry.outline, base_dir),
        )
        _check_entry(entry, where)
        for key in ("scene", "outline"):
            if getattr(entry, key) is not None:
                files[f"{where}.{key}"] = _file_digest(getattr(entry, key), f"{where}.{key}")
        if entry.scene is not None:
            try:
                scene = load_scene(entry.scene)
            except SceneError as exc:
                raise SweepError(f"{where}.scene: {exc}") from None
            if scene.object.model != ObjectModel.SOLID:
                raise SweepError(f"{where}.scene: the sweep needs solid objects")
        if entry.shape is not None and entry.shape.get("type") == ShapeType.FILE:
            path = _absolute(entry.shape["path"], base_dir)
            entry = dataclasses.replace(entry, shape={**entry.shape, "path": path})
            files[f"{where}.shape.path"] = _file_digest(path, f"{where}.shape.path")
        entries.append(entry)
    if sw.objects is not None:
        if not entries:
            raise SweepError("objects must list at least one object")
        sw = dataclasses.replace(sw, objects=tuple(entries))
    if sw.materials is None:
        materials = {"base": base.object.material}
    else:
        if not sw.materials:
            raise SweepError("materials must name at least one material")
        materials = {}
        for name, value in sw.materials.items():
            if (
                not isinstance(name, str)
                or not name
                or not all(c.isalnum() or c in "_.-" for c in name)
            ):
                raise SweepError(
                    f"materials: name {name!r} must use letters, digits, '_', '.', '-'"
                )
            if problem := name_too_long(name):
                raise SweepError(f"materials: name {name!r} {problem}")
            materials[name] = parse_section(MaterialSpec, value, f"materials.{name}",
                                            error=SweepError)
            try:
                check_material(materials[name], f"materials.{name}")
            except SceneError as exc:
                raise SweepError(str(exc)) from None
    fingers = base.fingers
    tip = fingers[Finger.F1].tip_radius
    if sw.tip_radius is None and not (tip > 0 and fingers[Finger.F2].tip_radius == tip):
        raise SweepError(
            "tip_radius is not swept and the base scene's fingertips are not one "
            "radius > 0 m: give tip_radius (the event-driven squeeze needs rounded "
            "fingertips)"
        )
    if sw.depth is not None and sw.relative_depth is not None:
        raise SweepError("depth and relative_depth are exclusive; give one")
    if sw.depth is not None:
        depths = tuple((d, None) for d in _axis(sw.depth, None, "depth"))
    elif sw.relative_depth is not None:
        depths = tuple((None, r) for r in _axis(sw.relative_depth, None, "relative_depth"))
    elif base.squeeze.depth is not None or base.squeeze.relative_depth is not None:
        depths = ((base.squeeze.depth, base.squeeze.relative_depth),)
    else:
        raise SweepError(
            "no squeeze depth: give depth or relative_depth (or squeeze.depth / "
            "squeeze.relative_depth in the base scene)"
        )
    if sw.adversary is not None and sw.adversary.position >= 1.0:
        raise SweepError("adversary.position must be < 1 (1 is F2's node)")
    if sw.repeat > 1 and sw.placements.mode != "sample":
        raise SweepError(
            f"repeat is {sw.repeat} but placements.mode is {sw.placements.mode}: "
            "only sampled placements are random (placements.mode: sample)"
        )
    if sw.placements.mode == "graspmap" and len(set(sw.placements.require)) != len(
        sw.placements.require
    ):
        raise SweepError("placements.require lists a filter twice")
    weight = (
        sw.weight
        if sw.weight is not None
        else (base.pickup.weight if base.has(Effect.PICKUP) else None)
    )
    ident = {"spec": data, "files": files}
    digest = hashlib.sha256(json.dumps(ident, sort_keys=True, default=str).encode()).hexdigest()
    return LoadedSpec(
        spec=sw,
        base=base,
        materials=materials,
        mesh=sw.mesh or base.object.mesh,
        friction=_axis(sw.friction, base.mu, "friction"),
        tip_radius=_axis(sw.tip_radius, tip, "tip_radius"),
        squeeze=_axis(sw.squeeze, base.squeeze.type, "squeeze"),
        depths=depths,
        weight=weight,
        hash=digest,
        raw=data,
    )


def load_sweep_spec(path: str | Path) -> LoadedSpec:
    """Read and validate a sweep YAML file."""
    try:
        data = read_yaml(path, "sweep spec")
    except SceneError as exc:
        raise SweepError(str(exc)) from None
    return parse_sweep_spec(data, Path(path).parent)


def sweep_help() -> str:
    """Human-readable reference of every sweep key, unit and range."""
    lines = key_reference(
        SweepSpec, width=30, nested={"materials": (MaterialSpec, "materials.<name>.")}
    )
    lines += [
        "",
        "Axes not given take the base scene's value; the evaluations of an object are "
        "placements x materials x friction x tip_radius x squeeze x depth.",
        "families: " + "; ".join(f"{k}({', '.join(v)})" for k, v in FAMILIES.items()),
        "Scene keys (base scene, objects[].scene): `squeeze-grasp scene-help`.",
    ]
    return "\n".join(lines)
