# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The domain vocabulary: one string enum per kind of name.

Each member *is* its string: JSON, YAML scenes, CSV columns and ROS messages carry the exact
strings they always had, and ``str(member)`` and f-strings give the bare value. Most members
also compare equal to their plain string (``Finger.F1 == "F1"``, same hash), so code that
receives a string from a file or a message works unchanged.

Two vocabularies share strings with others: the event letters (``EventType.A`` and the
adversary ``Finger.A``) and the effects (``Effect.STRAIN_LIMIT`` and the termination
``Termination.STRAIN_LIMIT``, ``Effect.FRICTION`` and the contact kind ``ContactKind.FRICTION``).
Their members are *codes*, not strings: equal only to themselves, with a hash of their own, so
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

__all__ = ["ContactKind", "ContactMode", "Effect", "EventType", "Finger", "MaterialModel",
           "ObjectModel", "RingLimit", "SQUEEZING_FINGERS", "ShapeType", "SqueezeKind",
           "StrainCriterion", "Termination"]


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


class StrainCriterion(_Name):
    """How the strain limit eps* is tested per element (eq. 45)."""

    PRINCIPAL = "principal"
    """max(|eps_1|, |eps_2|) <= eps* (frame invariant; the default)."""
    COMPONENTWISE = "componentwise"
    """|eps_x|, |eps_y| <= eps* in the object frame (eq. 45 literally)."""


class MaterialModel(_Name):
    """Constitutive model of a solid object."""

    LINEAR = "linear"
    """Small-strain linear elasticity (the paper's model)."""
    COROTATIONAL = "corotational"
    """Linear stress in the element's rotated frame: exact under rigid rotation."""
    NEO_HOOKEAN = "neo_hookean"
    """Compressible neo-Hookean hyperelasticity in exact plane stress."""


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


class RingLimit(_Name):
    """What bounds a ring squeeze's depth (Sec. 7.1), in the order ties resolve."""

    FRICTION_CONE_F1 = "friction_cone_F1"
    """F1's contact force reaches an edge of its friction cone."""
    FRICTION_CONE_F2 = "friction_cone_F2"
    """F2's contact force reaches an edge of its friction cone."""
    STRAIN = "strain"
    """The most strained element reaches the proportional limit."""
    NONE = "none"
    """Nothing before the fingers meet (relative depth 1)."""
