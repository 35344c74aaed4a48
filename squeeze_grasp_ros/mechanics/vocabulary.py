# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The domain vocabulary: one string enum per kind of name.

Each member *is* its string: JSON, YAML scenes, CSV columns and ROS messages carry the exact
strings they always had, and ``str(member)`` and f-strings give the bare value. Most members
also compare equal to their plain string (``Finger.F1 == "F1"``, same hash), so code that
receives a string from a file or a message works unchanged.

Three vocabularies share strings with others: the event letters (``EventType.A`` and the
adversary ``Finger.A``), the effects (``Effect.STRAIN_LIMIT`` and the termination
``Termination.STRAIN_LIMIT``, ``Effect.FRICTION`` and the contact kind ``ContactKind.FRICTION``)
and the ring limits (``RingLimit.NONE`` and ``ShapeFit.NONE``). Their members are *codes*, not
strings: equal only to themselves, with a hash of their own, so
a finger is never taken for an event and a termination never for an effect. ``str()`` and
f-strings still give the bare string and ``.value`` is it (for JSON and messages); a plain
string converts with the enum (``EventType("A")``), as the parsers and message converters do.

>>> from squeeze_grasp_ros.mechanics.vocabulary import EventType, Finger, Termination
>>> Finger.F1 == "F1", f"{Termination.STRAIN_LIMIT}"
(True, 'strain_limit')
>>> Finger("F2") is Finger.F2
True
>>> Finger.A == EventType.A, hash(Finger.A) == hash(EventType.A), EventType.A == "A"
(False, False, False)
>>> EventType("A") is EventType.A, f"{EventType.A}", EventType.A.value
(True, 'A', 'A')
"""
from __future__ import annotations

from enum import Enum

__all__ = ["AlarmType", "ContactKind", "ContactMode", "ControllerKind", "DistortionModel",
           "Effect", "EventType", "Factorizer", "Finger", "ImageEncoding", "MaterialModel",
           "ObjectModel", "RingLimit", "SQUEEZING_FINGERS", "ShapeFit", "ShapeType", "SqueezeKind",
           "StrainCriterion",
           "StrainMeasure", "StressMeasure", "Termination", "TipKind"]


class _Name(str, Enum):
    """A string enum whose ``str()``, format and ``repr()`` are those of the bare value, so
    logs, reprs of results and JSON read as before.
    """

    __str__ = str.__str__
    __format__ = str.__format__
    __repr__ = str.__repr__

    @classmethod
    def values(cls) -> tuple[str, ...]:
        """All values, in declaration order."""
        return tuple(m.value for m in cls)


class _Code(Enum):
    """A name whose string another vocabulary uses too (see the module docstring): not a
    string, equal only to itself; ``str()``, format and ``repr()`` give the bare value.
    """

    def __str__(self) -> str:
        return self._value_

    def __format__(self, spec: str) -> str:
        return format(self._value_, spec)

    def __repr__(self) -> str:
        return repr(self._value_)

    def __hash__(self) -> int:
        return hash((type(self).__name__, self._value_))

    @classmethod
    def values(cls) -> tuple[str, ...]:
        """All values, in declaration order."""
        return tuple(m.value for m in cls)


class Finger(_Name):
    """Finger names: the two squeezing fingers and the adversary (paper Sec. 6)."""

    F1 = "F1"
    F2 = "F2"
    A = "A"


SQUEEZING_FINGERS: tuple[Finger, Finger] = (Finger.F1, Finger.F2)
"""The two fingers of a squeeze, in canonical order."""


class EventType(_Code):
    """Contact events of the event-driven squeeze (paper Sec. 5.3)."""

    A = "A"
    """New contact: a boundary node reaches a fingertip (eq. 48)."""
    B = "B"
    """Contact break: the normal force of a contact node reaches zero (eq. 49)."""
    C = "C"
    """Stick to slip: the force of a sticking node reaches a friction-cone edge (eq. 50)."""
    D = "D"
    """Slip to stick: a sliding node's slip rate reaches zero (eq. 51)."""


class ContactMode(_Name):
    """Mode of a contact node under Coulomb friction."""

    STICK = "stick"
    SLIP = "slip"


class Termination(_Name):
    """Why a squeeze ended: the paper's four criteria (Sec. 5.1) and a lost grasp."""

    DEPTH_REACHED = "depth_reached"
    STRAIN_LIMIT = "strain_limit"
    FINGER_SLIP = "finger_slip"
    PICKED_UP = "picked_up"
    CONTACT_LOST = "contact_lost"
    """A contact break (Event B) would leave a finger with no contact node; not applied."""
    ELEMENT_INVERTED = "element_inverted"
    """An element of the object turned inside out (det F <= 0): the material model has left
    its range, so the squeeze cannot go deeper. Always checked, whatever the scene declares."""
    WEIGHT_SLIP = "weight_slip"
    """Lifted, the object slips out of the grip: friction cannot carry its weight (the pickup
    criterion fails at the lift; the world of a gripper scene, docs/grippers.md)."""


class AlarmType(_Name):
    """The monitor's alarms (``squeeze_grasp_interfaces/msg/Alarm`` constants); the
    ``contact_lost`` and ``weight_slip`` alarms are :attr:`Termination.CONTACT_LOST` and
    :attr:`Termination.WEIGHT_SLIP`, the grasp's ends they signal.
    """

    SLIP_IMMINENT = "slip_imminent"
    STALE_SENSOR = "stale_sensor"
    PREDICTION_MISMATCH = "prediction_mismatch"
    SHAPE_MISMATCH = "shape_mismatch"
    FORCE_MISMATCH = "force_mismatch"


class SqueezeKind(_Name):
    """Stable or pure: the squeeze (paper Sec. 2.4) and the resistance built on it (Sec. 6.1);
    custom: an event-driven squeeze along user-given finger directions.
    """

    STABLE = "stable"
    PURE = "pure"
    CUSTOM = "custom"
    """Finger directions given by the user (``fingers.<F>.direction``), not planned."""

    @classmethod
    def planned(cls) -> tuple[str, ...]:
        """The kinds a planner computes (and a scene or request may ask for): stable, pure."""
        return (cls.STABLE.value, cls.PURE.value)


class TipKind(_Name):
    """Shape of a rigid fingertip (the face that touches the object)."""

    CIRCLE = "circle"
    """A circle of radius r: the paper's rounded fingertip (Sec. 5, Fig. 5)."""
    PAD = "pad"
    """A flat pad of width w whose two edges are rounded with radius r_e (a parallel
    gripper's jaw): the flat face is w - 2 r_e wide."""


class StrainCriterion(_Name):
    """How the strain limit eps* is tested per element (eq. 45)."""

    PRINCIPAL = "principal"
    """max(|eps_1|, |eps_2|) <= eps* (frame invariant; the default)."""
    COMPONENTWISE = "componentwise"
    """|eps_x|, |eps_y| <= eps* in the object frame (eq. 45 literally)."""


class StrainMeasure(_Name):
    """Measure of a strain, defined by the deformation gradient F = R U of an element.

    At small strain all four agree to first order; at the peak compression of the foam square
    (about 25 %) they differ by up to a third, so every reported strain names its measure.

    >>> [m.label for m in StrainMeasure]
    ['small', 'Biot', 'log', 'Green-Lagrange']
    """

    SMALL = "small"
    """Small (infinitesimal) strain sym(F) - I = sym(grad u): the linear model's; not frame
    indifferent (a rigid rotation by theta shows 1 - cos(theta))."""
    BIOT = "biot"
    """Biot (nominal, engineering) strain U - I: change of a fibre's length per reference
    length along the principal directions; the corotational model's."""
    LOG = "log"
    """Logarithmic (Hencky, true) strain ln U: the neo-Hookean model's."""
    GREEN_LAGRANGE = "green_lagrange"
    """Green-Lagrange strain (F^T F - I) / 2 = (U^2 - I) / 2."""

    @property
    def label(self) -> str:
        """Short human-readable name, for text output."""
        return {"small": "small", "biot": "Biot", "log": "log",
                "green_lagrange": "Green-Lagrange"}[self.value]


class StressMeasure(_Name):
    """Measure of a reported stress."""

    SMALL_STRAIN = "small_strain"
    """C : eps of the small strain: the linear model's stress, in which the reference and the
    deformed configuration are not told apart (Cauchy, Piola and Kirchhoff stresses
    coincide to first order)."""
    CAUCHY = "cauchy"
    """Cauchy (true) stress: force per deformed area, sigma = P F^T / J with the thickness
    stretch in J; the corotational and neo-Hookean models'."""

    @property
    def label(self) -> str:
        """Short human-readable name, for text output."""
        return {"small_strain": "small-strain", "cauchy": "Cauchy"}[self.value]


class MaterialModel(_Name):
    """Constitutive model of a solid object.

    Each model reports strains and tests its strain limit in its own measure, and reports its
    own stress:

    >>> [(str(m), str(m.strain_measure), str(m.stress_measure)) for m in MaterialModel]
    [('linear', 'small', 'small_strain'), ('corotational', 'biot', 'cauchy'), \
('neo_hookean', 'log', 'cauchy')]
    """

    LINEAR = "linear"
    """Small-strain linear elasticity (the paper's model)."""
    COROTATIONAL = "corotational"
    """Linear stress in the element's rotated frame: exact under rigid rotation."""
    NEO_HOOKEAN = "neo_hookean"
    """Compressible neo-Hookean hyperelasticity in exact plane stress."""

    @property
    def strain_measure(self) -> StrainMeasure:
        """The measure of the model's strain: its reports and its strain limit use it."""
        return {"linear": StrainMeasure.SMALL, "corotational": StrainMeasure.BIOT,
                "neo_hookean": StrainMeasure.LOG}[self.value]

    @property
    def stress_measure(self) -> StressMeasure:
        """The measure of the model's reported stresses."""
        return (StressMeasure.SMALL_STRAIN if self is MaterialModel.LINEAR
                else StressMeasure.CAUCHY)


class ObjectModel(_Name):
    """Mechanical model of an object (``object.model``)."""

    SOLID = "solid"
    """Plane-stress finite elements of the whole planar object (Sec. 2-6)."""
    RING = "ring"
    """Curved beam along the middle curve of a hollow object (Sec. 7)."""


class ShapeType(_Name):
    """Outline types of a scene's ``object.shape.type``."""

    RECTANGLE = "rectangle"
    SQUARE = "square"
    DISK = "disk"
    ELLIPSE = "ellipse"
    SUPERELLIPSE = "superellipse"
    FOURIER_BLOB = "fourier_blob"
    POLYGON = "polygon"
    SPLINE = "spline"
    FILE = "file"
    ANNULUS = "annulus"


class ContactKind(_Name):
    """How F1, F2 and A touch the object in a resistance (Sec. 6)."""

    POINT = "point"
    """At one node each, fixed (Sec. 6.1)."""
    SEGMENT = "segment"
    """On fixed boundary segments around each node (Sec. 6.2)."""
    FRICTION = "friction"
    """Rounded fingertips under Coulomb friction after the squeeze: Algorithm 2 (Sec. 6.3)."""


class Effect(_Code):
    """What a scene may switch on (``effects:``); an undeclared effect costs nothing."""

    FRICTION = "friction"
    STRAIN_LIMIT = "strain_limit"
    PICKUP = "pickup"
    ADVERSARY = "adversary"
    FORCE_SENSING = "force_sensing"
    TACTILE_SENSING = "tactile_sensing"
    SENSOR_NOISE = "sensor_noise"
    ACTUATOR_LAG = "actuator_lag"
    SENSOR_DROPOUT = "sensor_dropout"
    CAMERA = "camera"


class RingLimit(_Code):
    """What bounds a ring squeeze's depth (Sec. 7.1), in the order ties resolve."""

    FRICTION_CONE_F1 = "friction_cone_F1"
    """F1's contact force reaches an edge of its friction cone."""
    FRICTION_CONE_F2 = "friction_cone_F2"
    """F2's contact force reaches an edge of its friction cone."""
    STRAIN = "strain"
    """The most strained element reaches the proportional limit."""
    NONE = "none"
    """Nothing before the fingers meet (relative depth 1)."""


class ImageEncoding(_Name):
    """``sensor_msgs/Image`` encodings that outline extraction reads (perception)."""

    MONO8 = "mono8"
    """A segmentation mask: 0 background, > 0 object (0-255 as coverage: 127.5 is the edge)."""
    DEPTH_16UC1 = "16UC1"
    """Depth in mm (uint16); 0 marks an invalid pixel."""
    DEPTH_32FC1 = "32FC1"
    """Depth in m (float32); NaN or 0 marks an invalid pixel."""


class DistortionModel(_Name):
    """``sensor_msgs/CameraInfo.distortion_model`` values that perception reads."""

    PLUMB_BOB = "plumb_bob"
    """Radial k1, k2, k3 and tangential p1, p2 (Brown-Conrady, as OpenCV)."""
    RATIONAL_POLYNOMIAL = "rational_polynomial"
    """Accepted only when its extra coefficients k4-k6 are zero (it is then plumb-bob)."""


class ControllerKind(_Name):
    """Stock ros2_control controller interfaces a scene's gripper can be driven through."""

    JOINT_TRAJECTORY = "joint_trajectory"
    """A JointTrajectoryController: ``trajectory_msgs/JointTrajectory`` on
    ``<controller>/joint_trajectory``."""
    GRIPPER_ACTION = "gripper_action"
    """A GripperActionController: ``control_msgs/action/GripperCommand`` on
    ``<controller>/gripper_cmd``."""
    PARALLEL_GRIPPER = "parallel_gripper"
    """Jazzy's ParallelGripperController: ``control_msgs/action/ParallelGripperCommand`` on
    ``<controller>/gripper_cmd``."""

    @property
    def is_action(self) -> bool:
        """True for the gripper action controllers."""
        return self is not ControllerKind.JOINT_TRAJECTORY


class ShapeFit(_Name):
    """Transform fitted between an observed outline and a predicted boundary before the
    residual is measured (perception, App. C).
    """

    SIMILARITY = "similarity"
    """Scale, rotation and translation: App. C's least squares (eqs. 72-85)."""
    RIGID = "rigid"
    """Rotation and translation only (the scale of a calibrated camera is known)."""
    NONE = "none"
    """No transform: both curves are already in the same frame."""


class Factorizer(_Name):
    """Sparse factorisation of the interior tangent of the large-deformation models."""

    CHOLMOD = "cholmod"
    """Supernodal Cholesky LL^T (SuiteSparse CHOLMOD through cvxopt: the ``cholmod`` extra)."""
    QDLDL = "qdldl"
    """LDL^T without pivoting (QDLDL); also takes the tangents that are not positive definite."""
