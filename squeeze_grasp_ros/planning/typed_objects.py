# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Objects given as typed fields instead of YAML (``load_object``'s ``object`` field).

A :class:`TypedObject` holds what a robot has of its object: an outline in a frame (outer
boundary and holes, m) or a named shape with its parameters, the material, the mesh size and
where the two fingers first touch. :func:`typed_scene` turns it into the scene it stands for
and validates that scene exactly as a YAML scene is validated (ranges with units,
self-intersection, holes strictly inside, the planner's size limits later in
:func:`~.objects.check_requested`); an error names the message field (``object.material.
youngs_modulus``), not the scene key it maps to.

The outline's frame is placed in the planner's ``object`` frame by ``frame_pose`` (a planar
pose: a rotation about z and a translation; z is dropped). A robot with tf2 looks the transform
``object <- outline.header.frame_id`` up itself and passes it as ``frame_pose``, or transforms
the polygon before sending it (see docs/ros.md).

>>> square = TypedObject(outline=((0, 0), (0.1, 0), (0.1, 0.1), (0, 0.1)),
...                      material=TypedMaterial(5e4, 0.3, 0.0254))
>>> source = typed_scene(square)
>>> source.scene.object.shape["type"], len(source.scene.object.shape["points"])
('polygon', 4)
>>> typed_scene(TypedObject(shape="disk", shape_parameters={"radius": (0.05,)},
...                         material=TypedMaterial(-1.0, 0.3, 0.01)))
Traceback (most recent call last):
...
squeeze_grasp_ros.planning.errors.PlannerError: object.material.youngs_modulus must be in \
[0.001, 1e+13] Pa, got -1.0
"""
from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, unit_quaternion
from squeeze_grasp_ros.mechanics.vocabulary import Effect, Finger, MaterialModel, ShapeType
from squeeze_grasp_ros.planning.errors import invalid
from squeeze_grasp_ros.planning.objects import SceneSource, read_scene
from squeeze_grasp_ros.scene import SHAPES, Scene, SceneError, build_outline, parse_scene
from squeeze_grasp_ros.scene.schema import MAX_INT

__all__ = ["OBJECT_FRAME", "PLANAR_TOLERANCE", "TYPED_SHAPES", "FramePose", "TypedMaterial",
           "TypedObject", "object_source", "scene_data", "seen_object", "typed_scene"]

OBJECT_FRAME = "object"
"""The planner's frame: outlines in it (or in the unnamed frame "") need no ``frame_pose``."""

PLANAR_TOLERANCE = 1e-6
"""Largest tilt (rad) of ``frame_pose``'s z axis from the object's z that counts as planar."""

TYPED_SHAPES: tuple[ShapeType, ...] = tuple(
    s for s in SHAPES if s not in (ShapeType.POLYGON, ShapeType.SPLINE, ShapeType.FILE))
"""Shapes a typed request may name (a polygon is given as the outline; files and splines are
scene-only)."""

FIELDS: dict[str, str] = {
    "object.shape: polygon.holes": "object.holes",
    "object.shape: polygon": "object.outline.polygon.points",
    "object.material.E": "object.material.youngs_modulus",
    "object.material.nu": "object.material.poisson_ratio",
    "object.mesh.max_area": "object.mesh_max_area",
    "object.mesh.nodes": "object.mesh_nodes",
    "object.shape.points": "object.outline.polygon.points",
    "object.shape.holes": "object.holes",
    "object.shape.": "object.shape_parameters ",
    "object.shape": "object.outline / object.shape",
    "fingers.F1.placement.point": "object.placements[0]",
    "fingers.F2.placement.point": "object.placements[1]",
    "fingers.F1.tip_radius": "object.tip_radius",
    "fingers.F2.tip_radius": "object.tip_radius",
    "friction.mu": "object.mu",
}
"""Scene keys in validation messages and the message fields they came from (longest first
within a prefix family, applied in this order)."""


@dataclass(frozen=True)
class FramePose:
    """Pose of the outline's frame in the ``object`` frame (``geometry_msgs/Pose``).

    Attributes
    ----------
    position : (float, float, float)
        m; z is dropped (the object lies in the plane).
    orientation : (float, float, float, float)
        Quaternion (x, y, z, w), a rotation about z only; normalised here, within tf2's
        tolerance (:func:`~squeeze_grasp_ros.mechanics.errors.unit_quaternion`).
    """

    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def planar(self) -> tuple[np.ndarray, np.ndarray]:
        """(R, t): the 2 x 2 rotation and the translation (m) of the pose in the plane.

        Raises
        ------
        PlannerError
            INVALID_ARGUMENT for a non-finite position, an orientation that is not a unit
            quaternion, or a frame whose z axis is tilted from the object's by more than
            :data:`PLANAR_TOLERANCE`.
        """
        t = np.asarray(self.position, float)
        if not np.all(np.isfinite(t)):
            raise invalid(f"object.frame_pose.position must be finite (m), got "
                          f"{list(self.position)}")
        try:
            q = unit_quaternion("object.frame_pose.orientation", self.orientation)
        except InvalidInputError as error:
            raise invalid(str(error)) from None
        R = Rotation.from_quat(q).as_matrix()
        tilt = math.acos(min(1.0, abs(float(R[2, 2])))) if R[2, 2] > 0 else math.pi
        if tilt > PLANAR_TOLERANCE:
            raise invalid(f"object.frame_pose tilts the outline's plane by {tilt:.3g} rad from "
                          f"the object frame's x-y plane (at most {PLANAR_TOLERANCE:g} rad): "
                          "give the pose of a frame whose z axis is the object's z")
        return R[:2, :2], t[:2]


@dataclass(frozen=True)
class TypedMaterial:
    """A scene's ``object.material`` as typed fields (``Material.msg``).

    Attributes
    ----------
    youngs_modulus : float
        E, Pa.
    poisson_ratio : float
        nu.
    thickness : float
        m.
    model : str
        A :class:`~.vocabulary.MaterialModel` value; "" = linear.
    """

    youngs_modulus: float
    poisson_ratio: float
    thickness: float
    model: str = ""


@dataclass(frozen=True)
class TypedObject:
    """An object as typed fields (``ObjectDescription.msg``); see the module docstring.

    Attributes
    ----------
    outline : sequence of (x, y)
        Outer boundary, m, in ``frame_id``; empty to give ``shape`` instead.
    holes : sequence of sequences of (x, y)
        Holes, m, same frame.
    frame_id : str
        Frame of the outline and placements; "" or "object" = the planner's object frame.
    shape : str
        A shape of :data:`TYPED_SHAPES` when ``outline`` is empty; with an outline, ``spline``
        says its points (and its holes') sample smooth curves: closed cubic splines through
        them, no vertex kept as a corner unless declared in ``shape_parameters["corners"]``
        (empty: a polygon, every vertex a corner).
    shape_parameters : mapping of str to tuple of float
        The shape's parameters (``squeeze-grasp scene-help``), one value for a scalar; with a
        spline outline, ``corners``: indices of the outline's vertices kept as corners (a
        mixed outline: straight edges with real corners and curved stretches).
    frame_pose : FramePose
        Pose of ``frame_id`` in the object frame (ignored for the object frame).
    material : TypedMaterial
    mesh_max_area : float
        m^2; 0 = unset.
    mesh_nodes : int
        0 = unset.
    placements : sequence of (x, y)
        F1, F2 first contacts, m, in ``frame_id``; empty = the boundary nodes in the -x and +x
        directions from the centroid.
    tip_radius : float
        m, both fingertips.
    mu : float
        Friction coefficient; 0 = no friction effect.
    """

    material: TypedMaterial
    outline: Sequence[Sequence[float]] = ()
    holes: Sequence[Sequence[Sequence[float]]] = ()
    frame_id: str = ""
    shape: str = ""
    shape_parameters: Mapping[str, tuple[float, ...]] = field(default_factory=dict)
    frame_pose: FramePose = field(default_factory=FramePose)
    mesh_max_area: float = 0.0
    mesh_nodes: int = 0
    placements: Sequence[Sequence[float]] = ()
    tip_radius: float = 0.0
    mu: float = 0.0

    @property
    def given(self) -> bool:
        """Whether the request gave this object (an outline or a shape)."""
        return bool(len(self.outline) or self.shape)


def _points(points: Sequence[Sequence[float]], pose: tuple[np.ndarray, np.ndarray],
            name: str) -> list[list[float]]:
    """Points (m) of the outline's frame in the object frame, as a scene holds them.

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT naming ``name[k]`` for a point that is not an (x, y) pair of finite
        numbers (m): a 3-D point would otherwise be re-paired into other points; or that
        ``frame_pose`` places beyond the scenes' coordinate range (``MAX_INT`` m).
    """
    for k, point in enumerate(points):
        if not (isinstance(point, Sequence | np.ndarray) and len(point) == 2):
            raise invalid(f"{name}[{k}] must be an (x, y) pair (m), got {point!r}")
    try:
        xy = np.asarray(points, float).reshape(-1, 2) if len(points) else np.zeros((0, 2))
    except (TypeError, ValueError):
        raise invalid(f"{name} must be (x, y) pairs of numbers (m)") from None
    if not np.all(np.isfinite(xy)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(xy), axis=1))[0])
        raise invalid(f"{name}[{bad}] must be finite (m)")
    R, t = pose
    placed = xy @ R.T + t
    beyond = np.flatnonzero(~np.all(np.abs(placed) <= MAX_INT, axis=1))
    if len(beyond):  # a scene refused it naming object.shape_parameters, not this field
        k = int(beyond[0])
        raise invalid(f"{name}[{k}] lies at {placed[k].tolist()} m in the object frame (after "
                      f"object.frame_pose), beyond the scenes' range of +-{MAX_INT:.4g} m (2^53)")
    return placed.tolist()


def _shape(obj: TypedObject, pose: tuple[np.ndarray, np.ndarray]) -> dict:
    """The scene's ``object.shape`` of the request."""
    smooth = obj.shape == ShapeType.SPLINE.value
    if len(obj.outline) and obj.shape and not smooth:
        raise invalid("give either object.outline (points) or object.shape, not both (with an "
                      f"outline, object.shape may only be {ShapeType.SPLINE.value!r}: smooth)")
    if len(obj.outline):
        if len(obj.outline) < 3:
            raise invalid(f"object.outline.polygon.points has {len(obj.outline)} points; an "
                          "outline needs at least 3 (m)")
        kind = ShapeType.SPLINE if smooth else ShapeType.POLYGON
        shape: dict = {"type": kind.value,
                       "points": _points(obj.outline, pose, "object.outline.polygon.points")}
        shape.update(_spline_corners(obj, smooth))
        if len(obj.holes):
            shape["holes"] = [_points(h, pose, f"object.holes[{k}].points")
                              for k, h in enumerate(obj.holes)]
        return shape
    if obj.shape not in TYPED_SHAPES:
        raise invalid(f"object.shape must be one of {[s.value for s in TYPED_SHAPES]} (or give "
                      f"object.outline), got {obj.shape!r}")
    if len(obj.holes):
        raise invalid("object.holes go with object.outline; a named shape has none (annulus: "
                      "outer_radius and inner_radius)")
    kind = ShapeType(obj.shape)
    expected = SHAPES[kind]
    unknown = sorted(set(obj.shape_parameters) - set(expected))
    if unknown:
        raise invalid(f"object.shape_parameters: unknown parameter {unknown[0]!r} of shape "
                      f"{kind.value} (its parameters: {list(expected)})")
    shape = {"type": kind.value}
    for name, values in obj.shape_parameters.items():
        many = kind == ShapeType.FOURIER_BLOB and name in ("cos", "sin")
        if not many and len(values) != 1:
            raise invalid(f"object.shape_parameters {name} takes one value, got {len(values)}")
        shape[name] = [float(v) for v in values] if many else float(values[0])
    return shape


def _spline_corners(obj: TypedObject, smooth: bool) -> dict:
    """``{"corners": [...]}`` from the ``corners`` shape parameter of a spline outline (vertex
    indices of the outline), else {}; any other parameter with an outline is refused.
    """
    extra = sorted(set(obj.shape_parameters) - ({"corners"} if smooth else set()))
    if extra:
        raise invalid(f"object.shape_parameters: {extra[0]!r} does not go with object.outline "
                      "(a spline outline takes only 'corners', its corner vertices' indices)")
    values = obj.shape_parameters.get("corners", ())
    if not len(values):
        return {}
    index = [float(v) for v in values]
    if any(not v.is_integer() or v < 0 or v >= len(obj.outline) for v in index):
        raise invalid(f"object.shape_parameters corners must be indices of the outline's "
                      f"points (0 to {len(obj.outline) - 1}), got {index}")
    return {"corners": [int(v) for v in index]}


def _renamed(message: str) -> str:
    """A scene validation message with the scene keys replaced by the message fields."""
    for key, name in FIELDS.items():
        if key in message:
            return message.replace(key, name, 1)
    return message


def scene_data(obj: TypedObject) -> dict:
    """The scene mapping the typed object stands for (validated by :func:`typed_scene`)."""
    in_object = obj.frame_id in ("", OBJECT_FRAME)
    pose = (np.eye(2), np.zeros(2)) if in_object else obj.frame_pose.planar()
    material = {"E": float(obj.material.youngs_modulus),
                "nu": float(obj.material.poisson_ratio),
                "thickness": float(obj.material.thickness),
                "model": obj.material.model or MaterialModel.LINEAR.value}
    mesh: dict = {}
    if obj.mesh_max_area:
        mesh["max_area"] = float(obj.mesh_max_area)
    if obj.mesh_nodes:
        mesh["nodes"] = int(obj.mesh_nodes)
    if len(obj.placements) not in (0, 2):
        raise invalid(f"object.placements must be empty or 2 points (F1, F2), got "
                      f"{len(obj.placements)}")
    if len(obj.placements):
        where = [{"point": p} for p in _points(obj.placements, pose, "object.placements")]
    else:
        where = [{"angle_deg": 180.0}, {"angle_deg": 0.0}]
    fingers = {finger.value: {"placement": place, "tip_radius": float(obj.tip_radius)}
               for finger, place in zip((Finger.F1, Finger.F2), where)}
    data = {"object": {"shape": _shape(obj, pose), "material": material, "mesh": mesh},
            "fingers": fingers}
    if obj.mu:
        data["friction"] = {"mu": float(obj.mu)}
        data["effects"] = [Effect.FRICTION.value]
    return data


def typed_scene(obj: TypedObject) -> SceneSource:
    """The validated scene of a typed object, with its canonical text (JSON, sorted keys) for
    the object digest.

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT naming the message field, its unit and valid range.
    """
    data = scene_data(obj)
    try:
        scene = parse_scene(data)
        build_outline(scene.object.shape)
    except SceneError as exc:
        raise invalid(_renamed(str(exc))) from None
    return SceneSource(scene, json.dumps(data, sort_keys=True))


def object_source(scene_yaml: str, scene_path: str, typed: TypedObject,
                  roots: Sequence[str] | None = None) -> SceneSource:
    """The scene of a ``load_object`` request: exactly one of YAML text, a scene file and a
    typed object (:func:`~.objects.read_scene`, :func:`typed_scene`).

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT for none or several of them, or a bad scene or object.
    """
    if typed.given:
        if scene_yaml or scene_path:
            raise invalid("give exactly one of scene_yaml, scene_path and object (typed "
                          "fields); got object and a scene")
        return typed_scene(typed)
    if not (scene_yaml or scene_path):
        raise invalid("give exactly one of scene_yaml, scene_path and object (outline points "
                      "or shape)")
    return read_scene(scene_yaml, scene_path, roots)


def seen_object(scene: Scene, shape: Mapping[str, Any],
                frame_id: str = OBJECT_FRAME) -> TypedObject:
    """The typed object a robot describes after seeing ``shape`` (a scene's ``object.shape``,
    m, in ``frame_id``: a ``polygon`` or ``spline`` with its points and holes, or a named
    shape with its parameters): the seen shape with what it is told rather than sees, from
    ``scene`` (material, mesh size, the fingers' placement points, their radius, friction).

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT when the fingers are not placed by points or have different tip radii
        (a typed object has one radius, and an angle or node index refers to the true outline).
    """
    fingers = [scene.fingers[f] for f in (Finger.F1, Finger.F2)]
    if any(f.placement.point is None for f in fingers):
        raise invalid("planning from a seen outline needs fingers placed by point (m): an "
                      "angle or node index refers to the true outline, which is not seen")
    if any(f.tip is not None for f in fingers):
        raise invalid("planning from a seen outline takes round fingertips (tip_radius); a "
                      "typed object has no fingers.<F>.tip")
    if fingers[0].tip_radius != fingers[1].tip_radius:
        raise invalid("planning from a seen outline needs equal fingertip radii for F1 and F2")
    kind = ShapeType(shape["type"])
    if kind in (ShapeType.POLYGON, ShapeType.SPLINE):
        drawn = {"outline": np.asarray(shape["points"], float).tolist(),
                 "holes": [np.asarray(h, float).tolist() for h in shape.get("holes", ())],
                 "shape": ShapeType.SPLINE.value if kind == ShapeType.SPLINE else ""}
        if shape.get("corners"):
            drawn["shape_parameters"] = {"corners": tuple(float(k) for k in shape["corners"])}
    else:
        drawn = {"shape": kind.value, "shape_parameters": {
            k: tuple(np.atleast_1d(v).astype(float)) for k, v in shape.items() if k != "type"}}
    material = scene.object.material
    return TypedObject(
        material=TypedMaterial(material.E, material.nu, material.thickness,
                               material.model.value),
        frame_id=frame_id, mesh_nodes=scene.object.mesh.nodes or 0,
        placements=[f.placement.point for f in fingers], tip_radius=fingers[0].tip_radius,
        mu=scene.mu, **drawn)
