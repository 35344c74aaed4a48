# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Scenes: YAML files -> typed, validated, frozen configuration -> mechanics.

The package holds, one job per module:

- :mod:`.schema`: the typed-YAML schema engine (also used by sweep specs);
- :mod:`.specs`: the scene's sections as frozen dataclasses (:class:`Scene`);
- :mod:`.checks`: the cross-field checks;
- :mod:`.files`: reading and validating (:func:`load_scene`, :func:`parse_scene`);
- :mod:`.build`: the builders (outline, mesh, material, ring, finger nodes);
- :mod:`.setup`: :class:`GraspSetup`, where a scene becomes mechanics for every front end;
- :mod:`.goal`: the goal an executor runs (squeeze, slip reaction, resistance waypoints);
- :mod:`.help`: the key reference of ``squeeze-grasp scene-help``.

Parsing is strict: unknown keys, wrong types, values out of range and contradictions raise
:class:`SceneError` naming the field (``fingers.F1.tip_radius``).
"""

from squeeze_grasp_ros.scene.build import (
    build_mesh,
    build_outline,
    build_ring,
    finger_nodes,
    placement_node,
    placement_points,
    requested_nodes,
    scene_material,
    scene_solid,
)
from squeeze_grasp_ros.scene.files import load_scene, parse_scene, read_yaml
from squeeze_grasp_ros.scene.help import scene_help
from squeeze_grasp_ros.scene.setup import GraspSetup, event_squeeze_scene, scene_limits
from squeeze_grasp_ros.scene.specs import (
    DEFAULT_DEVICES,
    DEVICES,
    EFFECTS,
    SHAPES,
    ActuatorsSpec,
    AdversarySpec,
    CameraSpec,
    FingerSpec,
    FrictionSpec,
    MaterialSpec,
    MeshSpec,
    ObjectSpec,
    PickupSpec,
    PlacementSpec,
    RingSpec,
    Scene,
    SceneError,
    SensorsSpec,
    SimSpec,
    SqueezeSpec,
    StrainLimitSpec,
    finger_devices,
)

__all__ = [
    "DEFAULT_DEVICES", "DEVICES", "EFFECTS", "SHAPES", "ActuatorsSpec", "AdversarySpec",
    "CameraSpec", "FingerSpec", "FrictionSpec", "MaterialSpec", "MeshSpec", "ObjectSpec",
    "PickupSpec", "PlacementSpec", "RingSpec", "Scene", "SceneError", "SensorsSpec", "SimSpec",
    "SqueezeSpec", "StrainLimitSpec", "build_mesh", "build_outline", "build_ring",
    "finger_devices", "finger_nodes", "load_scene", "parse_scene", "placement_node",
    "placement_points", "read_yaml", "requested_nodes", "scene_help", "scene_limits",
    "scene_material", "scene_solid", "GraspSetup", "event_squeeze_scene",
]
