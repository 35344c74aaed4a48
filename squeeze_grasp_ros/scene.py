# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""YAML scene files -> typed, validated, frozen configuration.

A scene names the object (shape, material, mesh or ring model), the fingers (tip radius,
placement, device), the squeeze (type, depth), friction, optional sections for later effects,
and an explicit ``effects:`` list. Parsing is strict: unknown keys, wrong types, values out of
range and contradictions raise :class:`SceneError` naming the field (``fingers.F1.tip_radius``).

Each section is a frozen dataclass; its fields carry their documentation, unit and range in
``metadata`` so the parser, the error messages and ``squeeze-grasp scene-help`` share one
source of truth. Adding a section = adding a dataclass and a field of :class:`Scene`.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

import numpy as np

from squeeze_grasp_ros.inputs import InputError, load_yaml, read_text
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import (
    MAX_MESH_NODES,
    Mesh,
    generate_mesh,
    target_max_area,
)
from squeeze_grasp_ros.mechanics.ring.model import RingModel, ring_from_outline
from squeeze_grasp_ros.mechanics.vocabulary import SQUEEZING_FINGERS, Finger, MaterialModel


class SceneError(InvalidInputError):
    """A scene entry is unknown, of the wrong type, out of range or contradictory."""


def spec(
    doc: str,
    unit: str = "",
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    choices: tuple = (),
    **kw,
) -> Any:
    """A dataclass field with documentation, unit, range and allowed choices for the parser."""
    meta = {"doc": doc, "unit": unit, "lo": lo, "hi": hi, "lo_open": lo_open, "choices": choices}
    return field(metadata=meta, **kw)


EFFECTS: dict[str, str] = {
    "friction": "Coulomb friction at the fingertips (needs friction.mu)",
    "strain_limit": "stop at the proportional limit (needs strain_limit.epsilon)",
    "pickup": "stop when friction can lift the object's weight (needs pickup.weight)",
    "adversary": "a third finger pushes after the squeeze (needs adversary)",
    "force_sensing": "fingertip wrench sensors",
    "tactile_sensing": "fingertip tactile arrays",
    "sensor_noise": "Gaussian noise on sensor readings (needs sensors.noise_std, sensors.seed)",
    "actuator_lag": "first-order lag of the finger actuators (needs actuators.time_constant)",
    "sensor_dropout": "sensor messages dropped at random (needs sensors.dropout)",
}
"""Every effect a scene may declare, with what it requires."""

DEVICES: dict[str, str] = {
    "barrett_f1": "finger 1 of the Barrett BH8 hand",
    "barrett_f2": "finger 2 of the Barrett BH8 hand",
    "barrett_f3": "finger 3 (the thumb) of the Barrett BH8 hand",
    "cobra": "Cobra-style arm carrying a rounded fingertip",
    "pusher": "linear pusher carrying the adversary fingertip",
}
"""Devices a finger may be mapped to (``fingers.<F>.device``, ``adversary.device``)."""

DEFAULT_DEVICES: dict[str, str] = {"F1": "barrett_f1", "F2": "barrett_f3", "A": "pusher"}
"""Device of a finger whose scene entry leaves ``device`` empty (Sec. 5.5: both squeezing
fingers on the Barrett hand; Sec. 6.4: the adversary on the pusher)."""

SHAPES: dict[str, tuple[str, ...]] = {
    "rectangle": ("width", "height"),
    "square": ("side",),
    "disk": ("radius",),
    "ellipse": ("a", "b"),
    "superellipse": ("a", "b", "exponent"),
    "fourier_blob": ("radius", "cos", "sin"),
    "polygon": ("points", "holes"),
    "spline": ("points",),
    "file": ("path",),
    "annulus": ("outer_radius", "inner_radius"),
}
"""Shape types and their parameters (lengths in m; fourier coefficients relative)."""


@dataclass(frozen=True)
class MeshSpec:
    """Triangulation controls: the accuracy knobs of the solid model."""

    max_area: Optional[float] = spec(
        "largest element area", "m^2", lo=0.0, lo_open=True, default=None
    )
    nodes: Optional[int] = spec(
        "approximate node count (instead of max_area)", lo=10, hi=MAX_MESH_NODES, default=None
    )
    min_angle: float = spec(
        "smallest element angle", "deg", lo=0.0, hi=34.0, lo_open=True, default=30.0
    )


@dataclass(frozen=True)
class MaterialSpec:
    """Material of the object (plane stress)."""

    E: float = spec("Young's modulus", "Pa", lo=0.0, lo_open=True)
    nu: float = spec("Poisson's ratio", "", lo=-1.0, hi=0.5, lo_open=True)
    thickness: float = spec("out-of-plane thickness h (ring: width w)", "m", lo=0.0, lo_open=True)
    model: str = spec("constitutive model of a solid (event-driven squeeze): linear (the "
                      "paper's), corotational or neo_hookean (finite deformation)",
                      choices=MaterialModel.values(), default=MaterialModel.LINEAR.value)


@dataclass(frozen=True)
class RingSpec:
    """Curved-beam model of a hollow object (Sec. 7): the shape is the middle curve."""

    wall_thickness: float = spec("in-plane wall thickness h", "m", lo=0.0, lo_open=True)
    elements: int = spec("number of beam elements along the middle curve", lo=8, default=200)


@dataclass(frozen=True)
class ObjectSpec:
    """The grasped object."""

    shape: dict = spec("outline: {type: <one of SHAPES>, <its parameters>}")
    material: MaterialSpec = spec("material")
    model: str = spec("mechanical model", choices=("solid", "ring"), default="solid")
    mesh: MeshSpec = spec("solid-model triangulation", default_factory=MeshSpec)
    ring: Optional[RingSpec] = spec("ring-model parameters (model: ring)", default=None)


@dataclass(frozen=True)
class PlacementSpec:
    """Where a finger first touches the boundary: exactly one of point, angle_deg, node."""

    point: Optional[tuple[float, float]] = spec(
        "this point's projection on the boundary, made a mesh node", "m", default=None
    )
    angle_deg: Optional[float] = spec(
        "boundary node in this polar direction from the centroid", "deg", default=None
    )
    node: Optional[int] = spec("mesh node index on the outer boundary", lo=0, default=None)


@dataclass(frozen=True)
class FingerSpec:
    """One finger."""

    placement: PlacementSpec = spec("initial contact")
    tip_radius: float = spec("fingertip radius (0 = point finger)", "m", lo=0.0, default=0.0)
    device: str = spec(
        "device driving this finger (empty: DEFAULT_DEVICES)",
        choices=("",) + tuple(DEVICES),
        default="",
    )
    direction: Optional[tuple[float, float]] = spec(
        "translation direction for the event-driven squeeze (both F1 and F2 or neither; "
        "overrides squeeze.type; normalised)",
        "",
        default=None,
    )


@dataclass(frozen=True)
class SqueezeSpec:
    """The squeeze to perform."""

    type: str = spec("squeeze type", choices=("stable", "pure"), default="stable")
    depth: Optional[float] = spec("squeeze depth rho", "m", lo=0.0, default=None)
    relative_depth: Optional[float] = spec(
        "finger approach / initial contact distance", "", lo=0.0, hi=1.0, default=None
    )
    step: float = spec(
        "depth step of the event-driven squeeze, relative to the object size (corotational "
        "and neo-Hookean objects adapt their substeps between events, from one to four steps)",
        "",
        lo=0.0,
        lo_open=True,
        default=1e-3,
    )
    event_tol: float = spec(
        "event location tolerance, relative to the object size",
        "",
        lo=0.0,
        lo_open=True,
        default=1e-9,
    )
    max_events_per_depth: int = spec(
        "chattering bound: most events of one contact node within "
        "one depth step; more freeze its mode for a step (reported)",
        lo=1,
        default=4,
    )


@dataclass(frozen=True)
class FrictionSpec:
    """Coulomb friction between fingertips and object."""

    mu: float = spec("friction coefficient", "", lo=0.0)


@dataclass(frozen=True)
class StrainLimitSpec:
    """Proportional limit (eq. 45), on the material model's own strain measure."""

    epsilon: float = spec(
        "strain limit epsilon*, on the material model's own strain: small strain sym(grad u) "
        "(linear), Biot U - I (corotational), log ln U (neo_hookean); rings: the largest fibre "
        "strain (small)", "", lo=0.0, lo_open=True)
    criterion: str = spec(
        "principal: max |eps_1|,|eps_2|; componentwise: |eps_x|,|eps_y| (literal eq. 45; "
        "linear model only)",
        choices=("principal", "componentwise"),
        default="principal",
    )


@dataclass(frozen=True)
class PickupSpec:
    """Lift the object against gravity."""

    weight: float = spec("object weight", "N", lo=0.0, lo_open=True)


@dataclass(frozen=True)
class AdversarySpec:
    """A third finger A that pushes the grasped object (Sec. 6)."""

    placement: PlacementSpec = spec("initial contact of A")
    a: tuple[float, float] = spec("translation of A", "m")
    tip_radius: float = spec("fingertip radius of A", "m", lo=0.0, default=0.0)
    mode: str = spec("resistance type", choices=("stable", "pure"), default="stable")
    contacts: str = spec(
        "contact model", choices=("point", "segment", "friction"), default="point"
    )
    device: str = spec(
        "device driving A (empty: DEFAULT_DEVICES)", choices=("",) + tuple(DEVICES), default=""
    )
    segment_half_width: Optional[float] = spec(
        "contacts: segment: each finger's fixed segment is the boundary nodes within this arc "
        "length of its contact node (default: the node and its two neighbours)",
        "m",
        lo=0.0,
        default=None,
    )
    compare_direction: Optional[tuple[float, float]] = spec(
        "line of F1's translation d1 of a user-given resistance to compare with the optimum "
        "(Table 4); d2 and the length of d1 follow from the resistance constraints",
        "",
        default=None,
    )


@dataclass(frozen=True)
class SensorsSpec:
    """Fingertip sensors of the simulated hardware (effects: force_sensing, tactile_sensing,
    sensor_noise, sensor_dropout).
    """

    noise_std: Optional[float] = spec(
        "std of the Gaussian noise on every force reading (wrench "
        "force components and taxel forces; torques get "
        "noise_std * tip radius) (effect: sensor_noise)",
        "N",
        lo=0.0,
        lo_open=True,
        default=None,
    )
    dropout: Optional[float] = spec(
        "probability that a wrench or tactile message of a tick is "
        "dropped (effect: sensor_dropout)",
        "",
        lo=0.0,
        hi=1.0,
        default=None,
    )
    seed: Optional[int] = spec(
        "seed of the noise and dropout draws (required with either)", "", lo=0, default=None
    )
    taxels: int = spec(
        "taxels per fingertip tactile array (effect: tactile_sensing)", "", lo=2, default=96
    )
    taxel_span_deg: float = spec(
        "arc of the fingertip covered by the tactile array, centred on the initial contact",
        "deg",
        lo=0.0,
        hi=360.0,
        lo_open=True,
        default=150.0,
    )


@dataclass(frozen=True)
class ActuatorsSpec:
    """Dynamics of the finger actuators (effect: actuator_lag)."""

    time_constant: float = spec(
        "first-order lag time constant of every finger actuator", "s", lo=0.0, lo_open=True
    )


@dataclass(frozen=True)
class SimSpec:
    """The simulated world's clock (no effect needed)."""

    dt: float = spec(
        "lockstep tick: sim-time step of the simulated hardware",
        "s",
        lo=0.0,
        hi=1.0,
        lo_open=True,
        default=1e-3,
    )


@dataclass(frozen=True)
class Scene:
    """A validated scene. Build it with :func:`load_scene` or :func:`parse_scene`."""

    object: ObjectSpec = spec("the object")
    fingers: dict = spec("F1, F2: finger specs")
    name: str = spec("scene name", default="")
    description: str = spec("free text", default="")
    squeeze: SqueezeSpec = spec("the squeeze", default_factory=SqueezeSpec)
    friction: Optional[FrictionSpec] = spec("friction (effect: friction)", default=None)
    strain_limit: Optional[StrainLimitSpec] = spec(
        "strain limit (effect: strain_limit)", default=None
    )
    pickup: Optional[PickupSpec] = spec("pickup (effect: pickup)", default=None)
    adversary: Optional[AdversarySpec] = spec("adversary finger (effect: adversary)", default=None)
    effects: tuple[str, ...] = spec("declared effects, see EFFECTS", default=())
    sensors: Optional[SensorsSpec] = spec(
        "fingertip sensors (effects: sensor_noise, "
        "sensor_dropout;"
        " taxel layout with tactile_sensing)",
        default=None,
    )
    actuators: Optional[ActuatorsSpec] = spec(
        "actuator dynamics (effect: actuator_lag)", default=None
    )
    sim: SimSpec = spec("simulated clock", default_factory=SimSpec)

    @property
    def mu(self) -> float:
        """Friction coefficient (0 without the friction effect)."""
        return self.friction.mu if self.friction is not None else 0.0

    def has(self, effect: str) -> bool:
        """True if the scene declares ``effect``."""
        return effect in self.effects


SECTION_EFFECT = {
    "friction": "friction",
    "strain_limit": "strain_limit",
    "pickup": "pickup",
    "adversary": "adversary",
    "actuators": "actuator_lag",
}

SENSOR_FIELD_EFFECT = {"noise_std": "sensor_noise", "dropout": "sensor_dropout"}
"""Fields of the ``sensors`` section that exist exactly when their effect is declared."""
SENSING_EFFECTS = ("force_sensing", "tactile_sensing")


def _describe(meta: dict) -> str:
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is not None and hi is not None:
        return f"in {'(' if meta.get('lo_open') else '['}{lo}, {hi}]"
    if lo is not None:
        return f"{'>' if meta.get('lo_open') else '>='} {lo}"
    if hi is not None:
        return f"<= {hi}"
    return "a finite number"


MAX_INT = 2**53
"""Largest integer a scene entry may hold (exactly representable as a float)."""


def _check_range(value: float, meta: dict, where: str) -> None:
    lo, hi = meta.get("lo"), meta.get("hi")
    unit = f" {meta['unit']}" if meta.get("unit") else ""
    if abs(value) > MAX_INT and isinstance(value, int):
        raise SceneError(f"{where} must be an integer of at most {MAX_INT}, got {value!r}")
    if not np.isfinite(float(value)):
        raise SceneError(f"{where} must be a finite number{unit}, got {value!r}")
    bad = (lo is not None and (value < lo or (meta.get("lo_open") and value == lo))) or (
        hi is not None and value > hi
    )
    if bad:
        raise SceneError(f"{where} must be {_describe(meta)}{unit}, got {value!r}")


def _yaml11_float(text: str, where: str) -> float:
    """Accept exponents such as ``5.0e4`` that YAML 1.1 (PyYAML) leaves as strings."""
    try:
        return float(text)
    except ValueError:
        raise SceneError(f"{where} must be a number, got {text!r}") from None


def _convert(tp: Any, value: Any, meta: dict, where: str) -> Any:
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        return None if value is None else _convert(args[0], value, meta, where)
    if dataclasses.is_dataclass(tp):
        return parse_section(tp, value, where)
    if origin is tuple:
        args = typing.get_args(tp)
        if not isinstance(value, (list, tuple)):
            raise SceneError(f"{where} must be a list, got {value!r}")
        if args[-1] is not Ellipsis and len(value) != len(args):
            raise SceneError(f"{where} must have {len(args)} entries, got {len(value)}")
        inner = args[0]
        return tuple(_convert(inner, v, meta, f"{where}[{k}]") for k, v in enumerate(value))
    if tp is float:
        if isinstance(value, str):
            value = _yaml11_float(value, where)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SceneError(f"{where} must be a number, got {value!r}")
        value = float(value)
        _check_range(value, meta, where)
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise SceneError(f"{where} must be an integer, got {value!r}")
        _check_range(value, meta, where)
        return value
    if tp is str:
        if not isinstance(value, str):
            raise SceneError(f"{where} must be a string, got {value!r}")
        if meta.get("choices") and value not in meta["choices"]:
            raise SceneError(f"{where} must be one of {list(meta['choices'])}, got {value!r}")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise SceneError(f"{where} must be true or false, got {value!r}")
        return value
    if tp is dict:
        if not isinstance(value, dict):
            raise SceneError(f"{where} must be a mapping, got {value!r}")
        return value
    raise TypeError(f"unsupported scene field type {tp!r} at {where}")


def parse_section(cls: type, data: Any, where: str) -> Any:
    """Parse mapping ``data`` into dataclass ``cls``; errors name ``where.<field>``."""
    if not isinstance(data, dict):
        raise SceneError(f"{where} must be a mapping, got {data!r}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise SceneError(f"unknown key {where}.{unknown[0]} (allowed: {sorted(fields)})")
    kwargs = {}
    for name, f in fields.items():
        path = f"{where}.{name}" if where else name
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise SceneError(f"missing required key {path}")
            continue
        kwargs[name] = _convert(hints[name], data[name], dict(f.metadata), path)
    return cls(**kwargs)


def _validate_shape(shape: dict) -> None:
    kind = shape.get("type")
    if kind not in SHAPES:
        raise SceneError(f"object.shape.type must be one of {sorted(SHAPES)}, got {kind!r}")
    allowed = set(SHAPES[kind]) | {"type"}
    unknown = sorted(set(shape) - allowed)
    if unknown:
        raise SceneError(
            f"unknown key object.shape.{unknown[0]} for type {kind} "
            f"(allowed: {sorted(allowed - {'type'})})"
        )
    optional = {"cos", "sin", "holes"}
    for key in SHAPES[kind]:
        if key not in shape and key not in optional:
            raise SceneError(f"missing required key object.shape.{key} for type {kind}")
        if key in shape:
            _check_shape_value(key, shape[key], f"object.shape.{key}")


def _is_number(value: Any) -> bool:
    return (
        isinstance(value, (int, float))
        and not isinstance(value, bool)
        and abs(value) <= MAX_INT
        and bool(np.isfinite(float(value)))
    )


def _check_shape_value(key: str, value: Any, where: str) -> None:
    """Types of the shape parameters: lengths are positive numbers (m), ``points`` a list of
    [x, y] number pairs, ``holes`` a list of such lists, ``cos``/``sin`` lists of numbers,
    ``path`` a non-empty string.
    """
    if key == "path":
        if not isinstance(value, str) or not value:
            raise SceneError(f"{where} must be a file path (a non-empty string), got {value!r}")
    elif key == "points":
        if not isinstance(value, list) or not all(
            isinstance(p, (list, tuple)) and len(p) == 2 and all(map(_is_number, p)) for p in value
        ):
            raise SceneError(f"{where} must be a list of [x, y] number pairs (m)")
    elif key == "holes":
        if not isinstance(value, list):
            raise SceneError(f"{where} must be a list of polygons, each a list of [x, y] number "
                             "pairs (m)")
        for k, hole in enumerate(value):
            _check_shape_value("points", hole, f"{where}[{k}]")
    elif key in ("cos", "sin"):
        if not isinstance(value, list) or not all(map(_is_number, value)):
            raise SceneError(f"{where} must be a list of numbers (relative to the radius)")
    elif not _is_number(value) or value <= 0:
        unit = "" if key == "exponent" else " (m)"
        raise SceneError(f"{where} must be a positive number{unit}, got {value!r}")


def _validate_fingers(scene: Scene) -> None:
    """F1 and F2 exactly; directions for every finger or none."""
    for name in scene.fingers:
        if name not in SQUEEZING_FINGERS:
            raise SceneError(
                f"unknown finger fingers.{name} (allowed: F1, F2; the adversary is "
                "the 'adversary' section)"
            )
    if set(scene.fingers) != {Finger.F1, Finger.F2}:
        raise SceneError("fingers must define both F1 and F2")
    given = [k for k, v in scene.fingers.items() if v.direction is not None]
    if given and len(given) != len(scene.fingers):
        raise SceneError(
            f"fingers.{given[0]}.direction is given: give direction for every finger or for none"
        )


def _validate_placements(scene: Scene) -> None:
    """Every placement (fingers, adversary) names exactly one of point, angle_deg, node."""
    placements = [(f"fingers.{k}", v.placement) for k, v in scene.fingers.items()]
    if scene.adversary is not None:
        placements.append(("adversary", scene.adversary.placement))
    for where, p in placements:
        given = [k for k in ("point", "angle_deg", "node") if getattr(p, k) is not None]
        if len(given) != 1:
            raise SceneError(
                f"{where}.placement needs exactly one of point, angle_deg, node; "
                f"got {given or 'none'}"
            )


def _validate_adversary(scene: Scene) -> None:
    """The adversary's translation and comparison direction are nonzero."""
    adv = scene.adversary
    if adv is None:
        return
    for name in ("a", "compare_direction"):
        value = getattr(adv, name)
        if value is not None and not np.hypot(*value) > 0:
            raise SceneError(f"adversary.{name} must be a nonzero vector, got {list(value)}")


def _validate_squeeze(scene: Scene) -> None:
    """At most one of depth and relative_depth; a relative depth below 1."""
    sq = scene.squeeze
    if sq.depth is not None and sq.relative_depth is not None:
        raise SceneError("squeeze.depth and squeeze.relative_depth are exclusive; give one")
    if sq.relative_depth is not None and not sq.relative_depth < 1:
        raise SceneError(
            f"squeeze.relative_depth must be < 1 (at 1 the fingers would meet), "
            f"got {sq.relative_depth}"
        )


def _validate_effects(scene: Scene) -> None:
    """Known effects, each once, and a section exactly for each declared effect."""
    for effect in scene.effects:
        if effect not in EFFECTS:
            raise SceneError(f"unknown effect {effect!r} in effects (allowed: {sorted(EFFECTS)})")
    if len(set(scene.effects)) != len(scene.effects):
        raise SceneError("effects lists an effect twice")
    for section, effect in SECTION_EFFECT.items():
        present = getattr(scene, section) is not None
        if present and not scene.has(effect):
            raise SceneError(
                f"section {section} is given but effect {effect!r} is not declared in effects"
            )
        if scene.has(effect) and not present:
            raise SceneError(f"effect {effect!r} is declared but section {section} is missing")


def _validate_object(scene: Scene) -> None:
    """Model and its sections agree; the material is valid for its constitutive model."""
    obj = scene.object
    if obj.model == "ring" and obj.ring is None:
        raise SceneError("object.model is ring but object.ring is missing")
    if obj.model == "solid" and obj.ring is not None:
        raise SceneError("object.ring is given but object.model is solid")
    if obj.model == "solid" and obj.mesh.max_area is not None and obj.mesh.nodes is not None:
        raise SceneError("object.mesh.max_area and object.mesh.nodes are exclusive; give one")
    try:
        Material(obj.material.E, obj.material.nu, obj.material.thickness)
    except InvalidInputError as exc:
        raise SceneError(f"object.{exc}") from None
    if obj.material.model == MaterialModel.NEO_HOOKEAN and not obj.material.nu < 0.5:
        raise SceneError(f"object.material.nu must be < 0.5 for the neo_hookean model (its "
                         f"lambda is infinite at 0.5), got {obj.material.nu}")


def _validate(scene: Scene) -> Scene:
    """Cross-field checks of a parsed scene, one concern per function."""
    _validate_shape(scene.object.shape)
    for check in (_validate_fingers, _validate_placements, _validate_adversary,
                  _validate_squeeze, _validate_effects, _validate_sensors, _validate_devices,
                  _validate_object):
        check(scene)
    return scene


def _validate_sensors(scene: Scene) -> None:
    """``sensors`` fields exist exactly with their effects; noise and dropout need a sensor."""
    sensors = scene.sensors
    for name, effect in SENSOR_FIELD_EFFECT.items():
        present = sensors is not None and getattr(sensors, name) is not None
        if present and not scene.has(effect):
            raise SceneError(
                f"sensors.{name} is given but effect {effect!r} is not declared in effects"
            )
        if scene.has(effect) and not present:
            raise SceneError(f"effect {effect!r} is declared but sensors.{name} is missing")
        if scene.has(effect) and not any(scene.has(e) for e in SENSING_EFFECTS):
            raise SceneError(
                f"effect {effect!r} needs a sensor to act on: declare "
                "force_sensing or tactile_sensing"
            )
    if sensors is None:
        return
    randomised = any(getattr(sensors, name) is not None for name in SENSOR_FIELD_EFFECT)
    if randomised and sensors.seed is None:
        raise SceneError(
            "sensors.seed is required with sensors.noise_std or sensors.dropout "
            "(runs must be reproducible)"
        )
    if sensors.seed is not None and not randomised:
        raise SceneError("sensors.seed is given but there is no sensor_noise or sensor_dropout")
    defaults = SensorsSpec()
    changed = [
        f for f in ("taxels", "taxel_span_deg") if getattr(sensors, f) != getattr(defaults, f)
    ]
    if changed and not scene.has("tactile_sensing"):
        raise SceneError(
            f"sensors.{changed[0]} is given but effect 'tactile_sensing' is not "
            "declared in effects"
        )
    if not randomised and not changed:
        raise SceneError("section sensors is given but sets nothing the declared effects use")


def finger_devices(scene: Scene) -> dict[str, str]:
    """Finger name -> device name (``DEVICES``) of every finger of the scene, adversary
    included.
    """
    given = {name: spec_.device for name, spec_ in scene.fingers.items()}
    if scene.adversary is not None:
        given["A"] = scene.adversary.device
    return {name: device or DEFAULT_DEVICES[name] for name, device in sorted(given.items())}


def _validate_devices(scene: Scene) -> None:
    """No two fingers on one device."""
    seen: dict[str, str] = {}
    for name, device in finger_devices(scene).items():
        if device in seen:
            raise SceneError(
                f"fingers {seen[device]} and {name} are both mapped to device "
                f"{device!r}; give each finger its own device"
            )
        seen[device] = name


def parse_scene(data: Any, base_dir: Path | None = None) -> Scene:
    """Validate a scene given as a mapping (e.g. from YAML); relative file paths use
    ``base_dir``.
    """
    if not isinstance(data, dict):
        raise SceneError("a scene must be a YAML mapping")
    if isinstance(data.get("fingers"), dict):
        data = dict(data)
        data["fingers"] = {
            k: parse_section(FingerSpec, v, f"fingers.{k}") for k, v in data["fingers"].items()
        }
    scene = _validate(parse_section(Scene, data, ""))
    shape = scene.object.shape
    if shape["type"] == "file" and base_dir is not None and not Path(shape["path"]).is_absolute():
        shape = {**shape, "path": str(Path(base_dir) / shape["path"])}
        scene = dataclasses.replace(scene, object=dataclasses.replace(scene.object, shape=shape))
    return scene


def read_yaml(path: str | Path, what: str = "scene") -> Any:
    """The YAML document of a ``what`` file; SceneError if it is missing or not YAML."""
    try:
        return load_yaml(read_text(path, what=what), what=f"{what} {path}")
    except InputError as exc:
        raise SceneError(str(exc)) from None


def load_scene(path: str | Path) -> Scene:
    """Read and validate a YAML scene file."""
    return parse_scene(read_yaml(path), base_dir=Path(path).parent)


def build_outline(shape: dict) -> shapes.Outline:
    """The :class:`~squeeze_grasp_ros.mechanics.elastic.shapes.Outline` of a validated shape
    mapping.
    """
    kind = shape["type"]
    try:
        if kind == "square":
            return shapes.rectangle(shape["side"], shape["side"])
        if kind == "file":
            return shapes.load_outline(shape["path"])
        builder = getattr(shapes, kind)
        return builder(**{k: v for k, v in shape.items() if k != "type"})
    except InvalidInputError as exc:
        raise SceneError(f"object.shape: {exc}") from None
    except TypeError as exc:
        raise SceneError(f"object.shape ({kind}): {exc}") from None


def scene_material(scene: Scene) -> Material:
    """The object's :class:`Material`."""
    m = scene.object.material
    return Material(m.E, m.nu, m.thickness)


def placement_points(scene: Scene) -> list[tuple[float, float]]:
    """The placements given as points (fingers, then the adversary), m."""
    placements = [f.placement for f in scene.fingers.values()]
    if scene.adversary is not None:
        placements.append(scene.adversary.placement)
    return [p.point for p in placements if p.point is not None]


def build_mesh(scene: Scene) -> Mesh:
    """Triangulate the scene's solid object with its mesh settings.

    A placement given as a point becomes a boundary node exactly (its projection on the
    outline is a kept vertex of the mesh), so the finger touches where the scene says.
    """
    outline = shapes.with_boundary_points(build_outline(scene.object.shape),
                                          placement_points(scene))
    ms = scene.object.mesh
    if ms.max_area is not None:
        area = ms.max_area
    else:
        area = target_max_area(outline, ms.nodes if ms.nodes is not None else 600)
    try:
        return generate_mesh(outline, area, min_angle=ms.min_angle)
    except InvalidInputError as exc:
        raise SceneError(f"object.mesh: {exc}") from None


def scene_solid(scene: Scene) -> ElasticObject:
    """The scene's solid object: its mesh (:func:`build_mesh`) and plane-stress material."""
    return ElasticObject(build_mesh(scene), scene_material(scene))


def build_ring(scene: Scene) -> RingModel:
    """The curved-beam model of a ring scene (``object.model: ring``): the shape is the middle
    curve, ``material.thickness`` the out-of-plane width w, ``ring.wall_thickness`` the wall h.

    Its nodes act as boundary nodes, so :func:`finger_nodes` places fingers on it.
    """
    obj = scene.object
    if obj.model != "ring":
        raise SceneError(f"object.model must be ring for the ring model, got {obj.model!r}")
    try:
        return ring_from_outline(
            build_outline(obj.shape),
            scene_material(scene),
            obj.ring.wall_thickness,
            obj.ring.elements,
        )
    except InvalidInputError as exc:
        raise SceneError(f"object.ring: {exc}") from None


def placement_node(
    mesh: Mesh, placement: PlacementSpec, where: str, positions: np.ndarray | None = None
) -> int:
    """Mesh node index of a finger placement on the outer boundary (or ``positions`` loop)."""
    loop = mesh.boundary
    pts = mesh.nodes[loop] if positions is None else positions
    if placement.node is not None:
        if placement.node >= mesh.n or placement.node not in set(loop.tolist()):
            raise SceneError(
                f"{where}.placement.node {placement.node} is not an outer-boundary "
                f"node (boundary has {len(loop)} nodes; see `squeeze-grasp mesh`)"
            )
        return int(placement.node)
    if placement.point is not None:
        k = np.argmin(np.linalg.norm(pts - np.asarray(placement.point), axis=1))
        return int(loop[k])
    c = mesh.centroid
    ang = np.arctan2(pts[:, 1] - c[1], pts[:, 0] - c[0])
    target = np.radians(placement.angle_deg)
    k = np.argmin(np.abs(np.angle(np.exp(1j * (ang - target)))))
    return int(loop[k])


def finger_nodes(scene: Scene, mesh: Mesh) -> tuple[int, int]:
    """Initial contact nodes (F1, F2) of the scene's fingers on ``mesh``."""
    i = placement_node(mesh, scene.fingers[Finger.F1].placement, "fingers.F1")
    j = placement_node(mesh, scene.fingers[Finger.F2].placement, "fingers.F2")
    if i == j:
        raise SceneError("fingers.F1 and fingers.F2 are placed on the same boundary node")
    return i, j


def key_reference(
    cls: type, prefix: str = "", width: int = 38, nested: dict[str, tuple[type, str]] | None = None
) -> list[str]:
    """One line per key of dataclass ``cls`` (and its sections): path, doc, unit, range.

    Lists of sections (``tuple[Section, ...]``) are shown as ``key[]``; ``nested`` maps a key
    path to (section class, prefix) for mappings whose values are sections.
    """
    nested = nested or {}
    lines: list[str] = []
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        meta = f.metadata
        tp = hints[f.name]
        inner = ([a for a in typing.get_args(tp) if a is not type(None)] or [tp])[0]
        path = f"{prefix}{f.name}"
        if typing.get_origin(inner) is tuple and dataclasses.is_dataclass(
            typing.get_args(inner)[0]
        ):
            inner, path = typing.get_args(inner)[0], path + "[]"
        req = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        ranged = meta.get("lo") is not None or meta.get("hi") is not None
        extra = [
            x
            for x in (
                meta.get("unit"),
                _describe(dict(meta)) if ranged else "",
                "one of " + "/".join(meta["choices"]) if meta.get("choices") else "",
                "required" if req else "",
            )
            if x
        ]
        lines.append(
            f"{path:{width}s} {meta.get('doc', '')}" + (f" [{', '.join(extra)}]" if extra else "")
        )
        if dataclasses.is_dataclass(inner):
            lines += key_reference(inner, path + ".", width, nested)
        if path in nested:
            lines += key_reference(nested[path][0], nested[path][1], width, nested)
    return lines


def scene_help() -> str:
    """Human-readable reference of every scene key, unit and range."""
    lines = key_reference(Scene, nested={"fingers": (FingerSpec, "fingers.F1|F2.")})
    lines.append("")
    lines.append("shape types: " + "; ".join(f"{k}({', '.join(v)})" for k, v in SHAPES.items()))
    lines.append("effects: " + "; ".join(f"{k}: {v}" for k, v in EFFECTS.items()))
    return "\n".join(lines)
