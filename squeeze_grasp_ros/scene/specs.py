# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The scene schema: one frozen dataclass per section, each field declared with its
documentation, unit and range (:func:`~squeeze_grasp_ros.scene.schema.spec`).

A scene names the object (shape, material, mesh or ring model), the fingers (tip radius,
placement, device), the squeeze (type, depth), friction, optional sections for later effects,
and an explicit ``effects:`` list. Adding a section = adding a dataclass here and a field of
:class:`Scene`; its cross-field rules go to :mod:`.checks`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Optional

from squeeze_grasp_ros.mechanics.elastic.material import E_RANGE, THICKNESS_RANGE
from squeeze_grasp_ros.mechanics.elastic.mesh import MAX_MESH_NODES
from squeeze_grasp_ros.mechanics.errors import FINGERS_MEET
from squeeze_grasp_ros.mechanics.ring.model import MAX_RING_ELEMENTS
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import MAX_TIP_SIZE, TipShape
from squeeze_grasp_ros.mechanics.vocabulary import (
    ContactKind,
    ControllerKind,
    Effect,
    Finger,
    MaterialModel,
    ObjectModel,
    ShapeType,
    SqueezeKind,
    StrainCriterion,
    TipKind,
)
from squeeze_grasp_ros.scene.schema import SchemaError, spec


class SceneError(SchemaError):
    """A scene entry is unknown, of the wrong type, out of range or contradictory."""


EFFECTS: dict[Effect, str] = {
    Effect.FRICTION: "Coulomb friction at the fingertips (needs friction.mu)",
    Effect.STRAIN_LIMIT: "stop at the proportional limit (needs strain_limit.epsilon)",
    Effect.PICKUP: "stop when friction can lift the object's weight (needs pickup.weight)",
    Effect.ADVERSARY: "a third finger pushes after the squeeze (needs adversary)",
    Effect.FORCE_SENSING: "fingertip wrench sensors",
    Effect.TACTILE_SENSING: "fingertip tactile arrays",
    Effect.SENSOR_NOISE: "Gaussian noise on sensor readings (needs sensors.noise_std, "
                         "sensors.seed)",
    Effect.ACTUATOR_LAG: "first-order lag of the finger actuators (needs "
                         "actuators.time_constant)",
    Effect.SENSOR_DROPOUT: "sensor messages dropped at random (needs sensors.dropout)",
    Effect.CAMERA: "a top-down camera renders the deformed object into mask and depth images "
                   "(needs camera)",
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

DEFAULT_DEVICES: dict[Finger, str] = {Finger.F1: "barrett_f1", Finger.F2: "barrett_f3",
                                      Finger.A: "pusher"}
"""Device of a finger whose scene entry leaves ``device`` empty (Sec. 5.5: both squeezing
fingers on the Barrett hand; Sec. 6.4: the adversary on the pusher)."""

SHAPES: dict[ShapeType, tuple[str, ...]] = {
    ShapeType.RECTANGLE: ("width", "height"),
    ShapeType.SQUARE: ("side",),
    ShapeType.DISK: ("radius",),
    ShapeType.ELLIPSE: ("a", "b"),
    ShapeType.SUPERELLIPSE: ("a", "b", "exponent"),
    ShapeType.FOURIER_BLOB: ("radius", "cos", "sin"),
    ShapeType.POLYGON: ("points", "holes"),
    ShapeType.SPLINE: ("points", "holes", "corners"),
    ShapeType.FILE: ("path",),
    ShapeType.ANNULUS: ("outer_radius", "inner_radius"),
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

    E: float = spec("Young's modulus (gels to diamond)", "Pa", lo=E_RANGE[0], hi=E_RANGE[1])
    nu: float = spec("Poisson's ratio (neo_hookean: -0.3 to 0.4999)", "", lo=-0.9, hi=0.5)
    thickness: float = spec("out-of-plane thickness h (ring: width w)", "m",
                            lo=THICKNESS_RANGE[0], hi=THICKNESS_RANGE[1])
    model: MaterialModel = spec("constitutive model of a solid (event-driven squeeze): linear "
                                "(the paper's), corotational or neo_hookean (finite "
                                "deformation)", default=MaterialModel.LINEAR)


@dataclass(frozen=True)
class RingSpec:
    """Curved-beam model of a hollow object (Sec. 7): the shape is the middle curve."""

    wall_thickness: float = spec("in-plane wall thickness h", "m", lo=0.0, lo_open=True)
    elements: int = spec("number of beam elements along the middle curve", lo=8,
                         hi=MAX_RING_ELEMENTS, default=200)


@dataclass(frozen=True)
class ObjectSpec:
    """The grasped object."""

    shape: Mapping[str, Any] = spec("outline: {type: <one of SHAPES>, <its parameters>}")
    material: MaterialSpec = spec("material")
    model: ObjectModel = spec("mechanical model", default=ObjectModel.SOLID)
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
class TipSpec:
    """A fingertip's shape: the paper's circle, or a flat pad with rounded edges (a gripper's
    jaw; docs/events.md "Flat pads").
    """

    shape: TipKind = spec("tip shape", default=TipKind.CIRCLE)
    radius: Optional[float] = spec("circle radius (shape: circle)", "m", lo=0.0, lo_open=True,
                                   hi=MAX_TIP_SIZE, default=None)
    width: Optional[float] = spec("whole pad width w across the closing direction, at least "
                                  "2 edge_radius (shape: pad)", "m", lo=0.0, lo_open=True,
                                  hi=MAX_TIP_SIZE, default=None)
    edge_radius: Optional[float] = spec("radius r_e of the pad's two rounded edges; the flat "
                                        "face is w - 2 r_e wide (shape: pad)", "m", lo=0.0,
                                        lo_open=True, hi=MAX_TIP_SIZE, default=None)

    def shape_of(self) -> TipShape:
        """The mechanics' :class:`~squeeze_grasp_ros.mechanics.squeeze.tip_shapes.TipShape`
        (fields checked by :mod:`.checks`).
        """
        if self.shape == TipKind.CIRCLE:
            return TipShape.circle(self.radius)
        return TipShape.pad(width=self.width, edge_radius=self.edge_radius)

    @property
    def contact_radius(self) -> float:
        """The radius of the rounded part that touches, m: the circle's, or the pad's edge
        radius (what ``tip_radius`` holds for a finger declared with ``tip``).
        """
        return self.radius if self.shape == TipKind.CIRCLE else self.edge_radius


@dataclass(frozen=True)
class FingerSpec:
    """One finger."""

    placement: PlacementSpec = spec("initial contact")
    tip_radius: float = spec("fingertip radius (0 = point finger); with tip given, filled "
                             "with the tip's radius (a pad's edge radius)", "m", lo=0.0,
                             hi=MAX_TIP_SIZE, default=0.0)
    tip: Optional[TipSpec] = spec("fingertip shape instead of tip_radius: {shape: circle, "
                                  "radius} or {shape: pad, width, edge_radius}", default=None)
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

    def tip_shape(self) -> TipShape:
        """The fingertip as the mechanics takes it: ``tip``, else a circle of ``tip_radius``."""
        return self.tip.shape_of() if self.tip is not None else TipShape.circle(self.tip_radius)


@dataclass(frozen=True)
class SqueezeSpec:
    """The squeeze to perform."""

    type: SqueezeKind = spec("squeeze type", choices=SqueezeKind.planned(),
                             default=SqueezeKind.STABLE)
    depth: Optional[float] = spec("squeeze depth rho", "m", lo=0.0, default=None)
    relative_depth: Optional[float] = spec(
        "finger approach / initial contact distance", "", lo=0.0, hi=1.0, hi_open=True,
        why=FINGERS_MEET, default=None
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

    mu: float = spec("friction coefficient", "", lo=0.0, hi=1e3)


@dataclass(frozen=True)
class StrainLimitSpec:
    """Proportional limit (eq. 45), on the material model's own strain measure."""

    epsilon: float = spec(
        "strain limit epsilon*, on the material model's own strain: small strain sym(grad u) "
        "(linear), Biot U - I (corotational), log ln U (neo_hookean); rings: the largest fibre "
        "strain (small)", "", lo=0.0, lo_open=True)
    criterion: StrainCriterion = spec(
        "principal: max |eps_1|,|eps_2|; componentwise: |eps_x|,|eps_y| (literal eq. 45; "
        "linear model only)",
        default=StrainCriterion.PRINCIPAL,
    )


@dataclass(frozen=True)
class PickupSpec:
    """Lift the object against gravity."""

    weight: float = spec("object weight", "N", lo=0.0, lo_open=True)
    planned_weight: Optional[float] = spec(
        "the weight the plan and the monitor take (default: weight; below it: an object "
        "heavier than planned)", "N", lo=0.0, lo_open=True, default=None)
    lift_after: float = spec(
        "a scene with a controller: the simulated arm lifts once the jaws have stood still in "
        "contact this long", "s", lo=0.0, lo_open=True, default=0.005)

    @property
    def believed_weight(self) -> float:
        """The weight the plan and the monitor take, N."""
        return self.weight if self.planned_weight is None else self.planned_weight


@dataclass(frozen=True)
class AdversarySpec:
    """A third finger A that pushes the grasped object (Sec. 6)."""

    placement: PlacementSpec = spec("initial contact of A")
    a: tuple[float, float] = spec("translation of A", "m")
    tip_radius: float = spec("fingertip radius of A", "m", lo=0.0, hi=MAX_TIP_SIZE,
                             default=0.0)
    mode: SqueezeKind = spec("resistance type", choices=SqueezeKind.planned(),
                             default=SqueezeKind.STABLE)
    contacts: ContactKind = spec("contact model", default=ContactKind.POINT)
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
        "arc of a round fingertip covered by the tactile array, centred on the initial "
        "contact (a pad's array covers its whole face)",
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
class ControllerSpec:
    """Two fingers carried by the jaws of a parallel gripper, or by the Barrett hand (device
    ``bh8``), under a stock ros2_control controller (docs/grippers.md): the executor commands
    the controller, the simulated hardware stands in for it.
    """

    type: ControllerKind = spec("the controller's interface")
    name: str = spec("the controller's name (its topic is <name>/joint_trajectory, its action "
                     "<name>/gripper_cmd)")
    device: str = spec("the gripper device: a shipped device name (config/devices) or a "
                       "device file, relative to the scene")
    joints: tuple[str, ...] = spec("the controller's joints (empty: the device's "
                                   "transmission.joints)", default=())
    jaws: tuple[Finger, ...] = spec("the two fingers the jaws carry, F1's jaw first",
                                    default=(Finger.F1, Finger.F2))
    goal_tolerance: float = spec("gripper_action, parallel_gripper: a goal is reached within "
                                 "this distance of its joint position", "joint units", lo=0.0,
                                 default=0.01)
    stall_velocity_threshold: float = spec("gripper_action, parallel_gripper: slower than this "
                                           "the joint stands still", "joint units/s", lo=0.0,
                                           default=0.001)
    stall_timeout: float = spec("gripper_action, parallel_gripper: standing still this long "
                                "short of the goal is a stall", "s", lo=0.0, default=1.0)
    allow_stalling: bool = spec("gripper_action, parallel_gripper: a stall succeeds instead of "
                                "aborting", default=False)
    max_effort: float = spec("gripper_action, parallel_gripper: effort limit of a goal without "
                             "one and of the hold after a cancel (0: the device's max_force "
                             "through the transmission)", "joint effort", lo=0.0, default=0.0)
    max_velocity: float = spec("parallel_gripper: speed limit of a goal without one (the "
                               "GripperActionController has none: its command jumps to the goal)",
                               "joint units/s", lo=0.0, lo_open=True, default=0.1)
    palm: Optional[tuple[float, float, float]] = spec(
        "device bh8 (the Barrett hand): the palm's centre x, y (m) and the yaw of its x axis "
        "(deg) in the object frame", default=None)
    effort_margin: float = spec("gripper_action, parallel_gripper: the executor's effort limit "
                                "is the planned jaw force times this margin (below 1 the jaws "
                                "stall short of the planned depth)", "", lo=0.0, lo_open=True,
                                default=1.25)


@dataclass(frozen=True)
class CameraSpec:
    """A simulated top-down camera above the object (effect: camera): pinhole intrinsics,
    plumb-bob distortion and the pose of its optical frame (z along the view, x right, y down)
    in the object frame, whose z = 0 plane is the support.
    """

    width: int = spec("image width", "px", lo=16, hi=8192, default=640)
    height: int = spec("image height", "px", lo=16, hi=8192, default=480)
    fx: float = spec("focal length along u", "px", lo=0.0, lo_open=True, default=465.0)
    fy: float = spec("focal length along v", "px", lo=0.0, lo_open=True, default=465.0)
    cx: float = spec("principal point u (pixel centres at integers)", "px", default=319.5)
    cy: float = spec("principal point v", "px", default=239.5)
    distortion: tuple[float, float, float, float, float] = spec(
        "plumb-bob k1, k2, p1, p2, k3", "", default=(0.0, 0.0, 0.0, 0.0, 0.0))
    pose: tuple[float, float, float, float, float, float] = spec(
        "optical frame in the object frame: x y z roll pitch yaw (fixed axes, as tf2's "
        "static_transform_publisher); straight down from 0.5 m: [0, 0, 0.5, 3.14159265, 0, 0]",
        "m, rad", default=(0.0, 0.0, 0.5, 3.141592653589793, 0.0, 0.0))
    rate: float = spec("frame rate in sim time", "Hz", lo=0.0, lo_open=True, default=10.0)
    blur: float = spec("Gaussian blur (defocus) of the coverage, standard deviation", "px",
                       lo=0.0, hi=20.0, default=0.5)
    depth_noise: float = spec("Gaussian noise of every depth pixel, standard deviation", "m",
                              lo=0.0, hi=0.1, default=0.001)
    mask_noise: float = spec("Gaussian noise of the coverage before it is quantised into the "
                             "mask, fraction of full scale", "", lo=0.0, hi=1.0, default=0.0)
    seed: int = spec("seed of the noise draws (frame k draws with seed + k)", "", lo=0,
                     default=0)
    frame_id: str = spec("optical frame name of the images and CameraInfo",
                         default="camera_optical_frame")
    plan_from_images: bool = spec(
        "the planner sees the object instead of being given it: squeeze-grasp run extracts the "
        "first frame's mask outline and loads it through the typed load_object request",
        default=False)
    shape_mismatch_threshold: float = spec(
        "monitor: RMS distance of the predicted deformed boundary from the seen outline (after "
        "a rigid fit) that raises shape_mismatch", "m", lo=0.0, lo_open=True, default=5e-4)
    shape_at_force_threshold: float = spec(
        "monitor: RMS distance of the deformed boundary the model predicts for the measured "
        "finger force from the seen outline (after a rigid fit) that raises shape_mismatch "
        "(sees a wrong E, which the equal-depth residual cannot)", "m", lo=0.0, lo_open=True,
        default=1.5e-4)


@dataclass(frozen=True)
class Scene:
    """A validated scene. Build it with :func:`load_scene` or :func:`parse_scene`."""

    object: ObjectSpec = spec("the object")
    fingers: Mapping[Finger, FingerSpec] = spec("F1, F2: finger specs")
    name: str = spec("scene name", default="")
    description: str = spec("free text", default="")
    squeeze: SqueezeSpec = spec("the squeeze", default_factory=SqueezeSpec)
    friction: Optional[FrictionSpec] = spec("friction (effect: friction)", default=None)
    strain_limit: Optional[StrainLimitSpec] = spec(
        "strain limit (effect: strain_limit)", default=None
    )
    pickup: Optional[PickupSpec] = spec("pickup (effect: pickup)", default=None)
    adversary: Optional[AdversarySpec] = spec("adversary finger (effect: adversary)", default=None)
    effects: tuple[Effect, ...] = spec("declared effects, see EFFECTS", default=())
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
    controller: Optional[ControllerSpec] = spec(
        "the fingers' gripper under a stock ros2_control controller", default=None)
    camera: Optional[CameraSpec] = spec("top-down camera (effect: camera)", default=None)

    @property
    def mu(self) -> float:
        """Friction coefficient (0 without the friction effect)."""
        return self.friction.mu if self.friction is not None else 0.0

    def has(self, effect: Effect) -> bool:
        """True if the scene declares ``effect`` (an :class:`Effect`: a termination or a plain
        string is refused, not silently missed).
        """
        if not isinstance(effect, Effect):
            raise TypeError(f"Scene.has takes an Effect, got {effect!r}")
        return effect in self.effects


def named_placements(scene: Scene) -> list[tuple[str, PlacementSpec]]:
    """(field, placement) of the fingers, then the adversary: ``("fingers.F1", ...)``."""
    placements = [(f"fingers.{k}", v.placement) for k, v in scene.fingers.items()]
    if scene.adversary is not None:
        placements.append(("adversary", scene.adversary.placement))
    return placements


def finger_devices(scene: Scene) -> dict[Finger, str]:
    """Finger -> device name (``DEVICES``) of every finger of the scene, adversary included."""
    given = {Finger(name): spec_.device for name, spec_ in scene.fingers.items()}
    if scene.adversary is not None:
        given[Finger.A] = scene.adversary.device
    return {name: device or DEFAULT_DEVICES[name] for name, device in sorted(given.items())}
