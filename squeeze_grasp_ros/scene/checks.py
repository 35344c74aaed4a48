# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The cross-field checks of a parsed scene, one concern per function.

The schema (:mod:`.specs`, parsed by :mod:`.schema`) checks each key alone: type, range,
choices. The rules that relate keys live here: exactly the fingers F1 and F2, one placement
per finger, a section exactly for each declared effect, a material the constitutive model can
represent. :func:`validate` runs them all; :func:`check_shape` and :func:`check_material` are
also what sweep specs use for their objects and materials.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.material import Material, require_poisson_ratio
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import (
    SQUEEZING_FINGERS,
    Effect,
    Finger,
    MaterialModel,
    ObjectModel,
    TipKind,
)
from squeeze_grasp_ros.scene.schema import MAX_INT, SchemaError
from squeeze_grasp_ros.scene.specs import (
    SHAPES,
    MaterialSpec,
    PlacementSpec,
    Scene,
    SceneError,
    SensorsSpec,
    TipSpec,
    finger_devices,
    named_placements,
)

SECTION_EFFECT: dict[str, Effect] = {
    "friction": Effect.FRICTION,
    "strain_limit": Effect.STRAIN_LIMIT,
    "pickup": Effect.PICKUP,
    "adversary": Effect.ADVERSARY,
    "actuators": Effect.ACTUATOR_LAG,
    "camera": Effect.CAMERA,
}
"""Sections of a scene that exist exactly when their effect is declared."""
SENSOR_FIELD_EFFECT: dict[str, Effect] = {"noise_std": Effect.SENSOR_NOISE,
                                          "dropout": Effect.SENSOR_DROPOUT}
"""Fields of the ``sensors`` section that exist exactly when their effect is declared."""
SENSING_EFFECTS: tuple[Effect, ...] = (Effect.FORCE_SENSING, Effect.TACTILE_SENSING)


def check_shape(shape: Mapping[str, Any], where: str = "object.shape") -> None:
    """A shape mapping names a known type (:data:`~.specs.SHAPES`) and exactly its parameters,
    each of the right type; errors name ``where.<key>``.
    """
    kind = shape.get("type")
    if not isinstance(kind, str) or kind not in SHAPES:
        raise SceneError(f"{where}.type must be one of {sorted(SHAPES)}, got {kind!r}")
    allowed = set(SHAPES[kind]) | {"type"}
    unknown = sorted(set(shape) - allowed, key=str)
    if unknown:
        raise SceneError(
            f"unknown key {where}.{unknown[0]} for type {kind} "
            f"(allowed: {sorted(allowed - {'type'})})"
        )
    optional = {"cos", "sin", "holes", "corners"}
    for key in SHAPES[kind]:
        if key not in shape and key not in optional:
            raise SceneError(f"missing required key {where}.{key} for type {kind}")
        if key in shape:
            _check_shape_value(key, shape[key], f"{where}.{key}")


def _is_number(value: Any) -> bool:
    return (
        isinstance(value, (int, float))
        and not isinstance(value, bool)
        and abs(value) <= MAX_INT
        and bool(np.isfinite(float(value)))
    )


def _check_shape_value(key: str, value: Any, where: str) -> None:
    """Types of the shape parameters: lengths are positive numbers (m), ``points`` a list of
    [x, y] number pairs, ``holes`` a list of such lists, ``corners`` a list of vertex indices,
    ``cos``/``sin`` lists of numbers,
    ``path`` a non-empty string.
    """
    if key == "path":
        if not isinstance(value, str) or not value:
            raise SceneError(f"{where} must be a file path (a non-empty string), got {value!r}")
    elif key == "points":
        if not isinstance(value, list) or not all(
            isinstance(p, (list, tuple)) and len(p) == 2 and all(map(_is_number, p)) for p in value
        ):
            raise SceneError(f"{where} must be a list of [x, y] number pairs (m), each number "
                             f"finite and within +-{MAX_INT:.4g} (2^53)")
    elif key == "holes":
        if not isinstance(value, list):
            raise SceneError(f"{where} must be a list of polygons, each a list of [x, y] number "
                             "pairs (m)")
        for k, hole in enumerate(value):
            _check_shape_value("points", hole, f"{where}[{k}]")
    elif key == "corners":
        if not isinstance(value, list) or not all(
                isinstance(k, int) and not isinstance(k, bool) and k >= 0 for k in value):
            raise SceneError(f"{where} must be a list of vertex indices of points (integers "
                             f">= 0), got {value!r}")
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
    for name, finger in scene.fingers.items():
        if finger.tip is not None:
            check_tip(finger.tip, f"fingers.{name}.tip")
            if finger.tip_radius not in (0.0, finger.tip.contact_radius):
                raise SceneError(f"fingers.{name}: give tip or tip_radius, not both")


def check_tip(tip: TipSpec, where: str, error: type[SchemaError] = SceneError) -> None:
    """A circle has a radius and nothing else; a pad a width and an edge radius, w >= 2 r_e
    (``error``: the document's error class).
    """
    need = ("radius",) if tip.shape == TipKind.CIRCLE else ("width", "edge_radius")
    for key in ("radius", "width", "edge_radius"):
        value = getattr(tip, key)
        if key in need and value is None:
            raise error(f"{where}.{key} is required for shape: {tip.shape.value}")
        if key not in need and value is not None:
            raise error(f"{where}.{key} does not apply to shape: {tip.shape.value} "
                             f"(give {', '.join(need)})")
    if tip.shape == TipKind.PAD and tip.width < 2.0 * tip.edge_radius:
        raise error(f"{where}.width must be >= 2 {where}.edge_radius "
                         f"({2.0 * tip.edge_radius:g} m), got {tip.width:g} m")


def with_tip_radii(scene: Scene) -> Scene:
    """The scene with ``tip_radius`` filled from ``tip`` where a finger declares one (a pad's
    edge radius), so every reader of ``tip_radius`` sees the radius that touches.
    """
    fingers = {name: dataclasses.replace(f, tip_radius=f.tip.contact_radius)
               if f.tip is not None else f for name, f in scene.fingers.items()}
    return dataclasses.replace(scene, fingers=fingers)


def _validate_placements(scene: Scene) -> None:
    """Every placement (fingers, adversary) names exactly one of point, angle_deg, node."""
    keys = [f.name for f in dataclasses.fields(PlacementSpec)]
    for where, p in named_placements(scene):
        given = [k for k in keys if getattr(p, k) is not None]
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
    """At most one of depth and relative_depth (the schema keeps a relative depth below 1)."""
    sq = scene.squeeze
    if sq.depth is not None and sq.relative_depth is not None:
        raise SceneError("squeeze.depth and squeeze.relative_depth are exclusive; give one")


def _validate_effects(scene: Scene) -> None:
    """Each effect once, and a section exactly for each declared effect (the schema admits
    only the effects of :data:`~.specs.EFFECTS`).
    """
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
    if scene.pickup is not None and scene.pickup.planned_weight is not None \
            and scene.controller is None:
        raise SceneError("pickup.planned_weight needs a controller: section (only the lift after "
                         "a gripper's squeeze can meet a weight other than the planned one)")


def check_material(material: MaterialSpec, where: str = "object.material") -> None:
    """The material is one its constitutive model can represent (a plane-stress
    :class:`Material`, and the model's range of Poisson's ratio,
    :func:`~squeeze_grasp_ros.mechanics.elastic.material.require_poisson_ratio`: the
    neo-Hookean model's Lame lambda is infinite at nu = 0.5); errors name ``where.<key>``.
    """
    try:
        Material(material.E, material.nu, material.thickness)
        require_poisson_ratio(material.nu, material.model)
    except InvalidInputError as exc:
        raise SceneError(str(exc).replace("material.", f"{where}.", 1)) from None


def _validate_object(scene: Scene) -> None:
    """Model and its sections agree; the material is valid for its constitutive model; a ring
    is the linear curved-beam model (Sec. 7), so it takes no other material model.
    """
    obj = scene.object
    ring = obj.model == ObjectModel.RING
    if ring and obj.ring is None:
        raise SceneError("object.model is ring but object.ring is missing")
    if not ring and obj.ring is not None:
        raise SceneError("object.ring is given but object.model is solid")
    if not ring and obj.mesh.max_area is not None and obj.mesh.nodes is not None:
        raise SceneError("object.mesh.max_area and object.mesh.nodes are exclusive; give one")
    if ring and obj.material.model != MaterialModel.LINEAR:
        raise SceneError(
            f"object.material.model is {obj.material.model}, but a ring (object.model: ring) "
            "is the linear curved-beam model of Sec. 7: remove object.material.model or "
            "give linear"
        )
    check_material(obj.material)


def validate(scene: Scene) -> Scene:
    """Run every cross-field check of a parsed scene; return it with the fingers'
    ``tip_radius`` filled from their ``tip`` (:func:`with_tip_radii`).

    Raises
    ------
    SceneError
        Naming the first offending key.
    """
    check_shape(scene.object.shape)
    for check in (_validate_fingers, _validate_placements, _validate_adversary,
                  _validate_squeeze, _validate_effects, _validate_sensors, _validate_devices,
                  _validate_object):
        check(scene)
    return with_tip_radii(scene)


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
    if changed and not scene.has(Effect.TACTILE_SENSING):
        raise SceneError(
            f"sensors.{changed[0]} is given but effect 'tactile_sensing' is not "
            "declared in effects"
        )
    if not randomised and not changed:
        raise SceneError("section sensors is given but sets nothing the declared effects use")


def _validate_devices(scene: Scene) -> None:
    """No two fingers on one device."""
    seen: dict[str, Finger] = {}
    for name, device in finger_devices(scene).items():
        if device in seen:
            raise SceneError(
                f"fingers {seen[device]} and {name} are both mapped to device "
                f"{device!r}; give each finger its own device"
            )
        seen[device] = name


