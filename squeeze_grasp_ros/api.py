# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The front door: the public, ROS-free Python API in one import.

Scenes and shipped files, meshes and elastic objects, stable and pure squeezes, the
event-driven squeeze with rounded fingertips (Algorithm 1), grasp maps, resistance, rings,
calibration, objects seen by a camera (outline extraction needs the ``perception`` extra), the
domain vocabulary and the error kinds. SI units throughout; lengths in m,
forces in N, the object frame x right, y up. Everything else in the package is internal and
may move.

A scene, meshed, squeezed, and its contact events:

>>> from squeeze_grasp_ros.api import event_squeeze_scene, load_scene, scene_file, scene_solid
>>> scene = load_scene(scene_file("foam_square"))
>>> result = event_squeeze_scene(scene, scene_solid(scene))
>>> for event in result.events[:2]:
...     print(event.type, event.finger, f"{event.relative_depth:.4f}")
A F1 0.0110
A F2 0.0113
>>> print(result.termination, f"{result.relative_depth:.2f}")
depth_reached 0.12

Every strain and stress names its measure (the model's own; the peak in every measure too):

>>> h = result.health
>>> print(f"{h.max_strain:.4f}", h.strain_measure, f"{h.max_von_mises:.0f} Pa", h.stress_measure)
0.2644 small 12923 Pa small_strain
>>> print({str(m): round(v, 4) for m, v in h.max_principal_strain.items()})
{'small': 0.2644, 'biot': 0.2615, 'log': 0.3031, 'green_lagrange': 0.2273}

Every front end makes a scene mechanics in one place, a :class:`GraspSetup`: the object, the
fingers' initial contact nodes and finger motion, the contact model, the squeeze and Algorithm 2:

>>> setup = GraspSetup.build(load_scene(scene_file("resist_fig10")))
>>> squeeze = setup.event_squeeze()
>>> print(setup.motion.kind, squeeze.termination, setup.frictional_resistance(squeeze).reason)
custom depth_reached F2 slips

The same from its parts: the mesh, the fingers' initial contact nodes, the squeeze:

>>> mesh = build_mesh(scene)
>>> obj = ElasticObject(mesh, Material(E=1e5, nu=0.3, thickness=0.01))
>>> i, j = finger_nodes(scene, mesh)
>>> squeeze = event_squeeze(obj, (i, j), 0.02, 0.4, kind=SqueezeKind.PURE, relative_depth=0.02)
>>> print(squeeze.termination, squeeze.events[0].type)
depth_reached A

An object of your own, with no scene: a polygon (m, either orientation; checked to be simple),
meshed, and squeezed at the boundary nodes nearest two points of your choosing; anything but
an outline is refused by name:

>>> import numpy as np
>>> square = polygon([[0, 0], [0.04, 0], [0.04, 0.04], [0, 0.04]])
>>> mesh = generate_mesh(square, 2e-5)
>>> def nearest(point):
...     return int(mesh.boundary[np.argmin(np.hypot(*(mesh.nodes[mesh.boundary] - point).T))])
>>> obj = ElasticObject(mesh, Material(E=1e5, nu=0.3, thickness=0.01))
>>> squeeze = event_squeeze(obj, (nearest([0, 0.02]), nearest([0.04, 0.02])), 0.01, 0.4,
...                         kind=SqueezeKind.PURE, relative_depth=0.05)
>>> print(f"{square.area * 1e4:.1f} cm^2", squeeze.termination)
16.0 cm^2 depth_reached
>>> try:
...     generate_mesh([[0, 0], [0.04, 0], [0, 0.04]], 2e-5)
... except InvalidInputError as error:
...     print(error)
outline must be an Outline (e.g. polygon(points)), got list
"""
from __future__ import annotations

from squeeze_grasp_ros.mechanics.calibration.hyperelastic_fit import (
                                                                   CompressionCurve,
                                                                   fit_compression,
)
from squeeze_grasp_ros.mechanics.calibration.matching import match_similarity
from squeeze_grasp_ros.mechanics.calibration.material_fit import Cuboid, calibrate_elasticity
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import Mesh, generate_mesh
from squeeze_grasp_ros.mechanics.elastic.reduced import ReducedStiffness, reduced_stiffness
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline, polygon
from squeeze_grasp_ros.mechanics.errors import (
                                                                   InfeasibleError,
                                                                   InternalError,
                                                                   InvalidInputError,
                                                                   NumericalError,
                                                                   SqueezeGraspError,
)
from squeeze_grasp_ros.mechanics.resistance.frictional import (
                                                                   FrictionalResistance,
                                                                   frictional_resistance,
)
from squeeze_grasp_ros.mechanics.resistance.optimal import optimal_resistance, resistance_grasp
from squeeze_grasp_ros.mechanics.ring.grasp_map import ring_grasp_map
from squeeze_grasp_ros.mechanics.ring.model import RingModel
from squeeze_grasp_ros.mechanics.ring.squeeze import ring_grasp
from squeeze_grasp_ros.mechanics.squeeze.contact_model import SolveOptions, TerminationLimits
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, Event
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze, event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap, grasp_map
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import Squeeze, plan_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import (
                                                                   ContactMode,
                                                                   Effect,
                                                                   EventType,
                                                                   Finger,
                                                                   ImageEncoding,
                                                                   MaterialModel,
                                                                   RingLimit,
                                                                   ShapeFit,
                                                                   SqueezeKind,
                                                                   StrainCriterion,
                                                                   StrainMeasure,
                                                                   StressMeasure,
                                                                   Termination,
)
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.camera_info import camera_from_info
from squeeze_grasp_ros.perception.extract import ObjectOutline, extract_outline
from squeeze_grasp_ros.perception.render import CameraViews, render_views
from squeeze_grasp_ros.perception.shape_match import ShapeMatch, deformed_outline, shape_residual
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.scene import (
                                                                   GraspSetup,
                                                                   Scene,
                                                                   build_mesh,
                                                                   event_squeeze_scene,
                                                                   finger_nodes,
                                                                   load_scene,
                                                                   scene_solid,
)

__all__ = [
    # scenes
    "Scene", "load_scene", "scene_file", "GraspSetup", "build_mesh", "scene_solid",
    "finger_nodes", "event_squeeze_scene",
    # elastic objects
    "Outline", "polygon", "Material", "Mesh", "generate_mesh", "ElasticObject",
    "ReducedStiffness", "reduced_stiffness",
    # squeezes
    "Squeeze", "plan_squeeze", "TerminationLimits", "SolveOptions", "EventSqueeze", "Event",
    "ContactState",
    "event_squeeze", "GraspMap", "grasp_map",
    # resistance, rings, calibration
    "resistance_grasp", "optimal_resistance", "FrictionalResistance", "frictional_resistance",
    "RingModel", "ring_grasp", "ring_grasp_map", "Cuboid", "calibrate_elasticity",
    "match_similarity", "CompressionCurve", "fit_compression",
    # objects seen by a camera
    "CameraModel", "CameraPose", "camera_from_info", "CameraViews", "render_views",
    "ObjectOutline", "extract_outline", "ShapeMatch", "deformed_outline", "shape_residual",
    # vocabulary
    "Finger", "EventType", "ContactMode", "Termination", "SqueezeKind", "StrainCriterion",
    "MaterialModel", "StrainMeasure", "StressMeasure", "ImageEncoding", "ShapeFit", "Effect",
    "RingLimit",
    # errors
    "SqueezeGraspError", "InvalidInputError", "InfeasibleError", "NumericalError",
    "InternalError",
]
