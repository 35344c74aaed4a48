# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Parallel-jaw gripper device files: two jaws on one line closing symmetrically.

A device file (YAML, ``config/devices/``) declares the opening range, the largest jaw force,
the pads and the transmission between the jaws and the controller's joints. The transmission
is linear, as for the common grippers::

    joint position = position_offset + position_per_aperture * aperture     (rad or m)
    joint effort   = effort_per_force * jaw force                            (N or N m)

(a Franka Hand: two prismatic joints at half the aperture each, position_per_aperture 0.5,
effort_per_force 1; a Robotiq 2F-85 under its ros2_control driver: one revolute joint from
0 rad open at 0.085 m to about 0.8 rad closed, position_per_aperture -9.41 rad/m, offset 0.8).

>>> from squeeze_grasp_ros.resources import device_file
>>> gripper = load_gripper(device_file("generic_85mm"))
>>> [round(p, 4) for p in gripper.joint_positions(0.05)]
[0.3294]
>>> round(gripper.aperture(gripper.joint_positions(0.05)[0]), 12)
0.05
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.gripper_grasp import ParallelJaws
from squeeze_grasp_ros.scene.checks import check_tip
from squeeze_grasp_ros.scene.files import read_yaml
from squeeze_grasp_ros.scene.schema import SchemaError, parse_section, spec
from squeeze_grasp_ros.scene.specs import TipSpec

__all__ = ["MAX_JOINT_POSITION", "MAX_LENGTH", "GripperError", "GripperSpec", "OpeningSpec",
           "TransmissionSpec", "load_gripper", "parse_gripper"]

MAX_LENGTH = 1.0
"""Largest opening and pad size of a device, m: a parallel gripper's stroke and pads are below
a metre, so a larger value is a length in mm."""
MAX_JOINT_POSITION = 2.0 * np.pi
"""Largest joint position over the opening range, rad or m: a gripper's revolute joint turns
less than a turn, its prismatic joint moves less than a metre; degrees or mm give more."""
_UNITS = "a gripper's stroke is below 1 m: a length in mm?"


class GripperError(SchemaError):
    """A gripper device file entry is unknown, of the wrong type, out of range or
    contradictory.
    """


@dataclass(frozen=True)
class OpeningSpec:
    """The range of the distance between the two pad faces."""

    max: float = spec("largest aperture (fully open)", "m", lo=0.0, lo_open=True,
                      hi=MAX_LENGTH, why=_UNITS)
    min: float = spec("smallest aperture (fully closed)", "m", lo=0.0, hi=MAX_LENGTH,
                      why=_UNITS, default=0.0)


@dataclass(frozen=True)
class TransmissionSpec:
    """Jaws to joints, linear: position = offset + gain * aperture, effort = k * force."""

    joints: tuple[str, ...] = spec("the controller's joint names (each takes the same "
                                   "position and effort)")
    position_per_aperture: float = spec("joint position per m of aperture (rad/m or m/m; "
                                        "negative when the joint closes with a larger "
                                        "position)", "")
    position_offset: float = spec("joint position at aperture 0", "", default=0.0)
    effort_per_force: float = spec("joint effort per N of jaw force (N/N or N m/N)", "",
                                   lo=0.0, lo_open=True, default=1.0)
    position_limits: Optional[tuple[float, float]] = spec(
        "the joint's [lower, upper] position limits (the URDF's, rad or m); the joints' "
        "positions over the opening range must lie within (a transmission closing the wrong "
        "way does not)", default=None)


@dataclass(frozen=True)
class GripperSpec:
    """A parallel-jaw gripper device."""

    name: str = spec("device name")
    opening: OpeningSpec = spec("aperture range")
    max_force: float = spec("largest grip force of one jaw", "N", lo=0.0, lo_open=True)
    pad: TipSpec = spec("each jaw's pad: {shape: pad, width, edge_radius} (or a circle), each "
                        "length at most 1 m")
    transmission: TransmissionSpec = spec("jaw position and force to joint position and "
                                          "effort")
    max_speed: float = spec("largest closing speed of the aperture", "m/s", lo=0.0,
                            lo_open=True, hi=10.0, default=0.1)
    description: str = spec("free text", default="")

    def jaws(self) -> ParallelJaws:
        """What the mechanics needs: opening range, largest force, pad."""
        return ParallelJaws(self.opening.min, self.opening.max, self.max_force,
                            self.pad.shape_of())

    def joint_positions(self, aperture: float) -> tuple[float, ...]:
        """Each joint's position at ``aperture`` (m), in the controller's convention."""
        t = self.transmission
        return (t.position_offset + t.position_per_aperture * float(aperture),) * len(t.joints)

    def joint_efforts(self, force: float) -> tuple[float, ...]:
        """Each joint's effort for a jaw force ``force`` (N)."""
        t = self.transmission
        return (t.effort_per_force * float(force),) * len(t.joints)

    def aperture(self, position: float) -> float:
        """The aperture (m) at a joint ``position``."""
        t = self.transmission
        return (float(position) - t.position_offset) / t.position_per_aperture

    def jaw_force(self, effort: float) -> float:
        """The jaw force (N) a joint ``effort`` exerts (the monitor's reading without a
        wrench sensor).
        """
        return float(effort) / self.transmission.effort_per_force


def parse_gripper(data, where: str = "gripper") -> GripperSpec:
    """Validate a gripper device given as a mapping (e.g. from YAML).

    Raises
    ------
    GripperError
        Naming the first offending key (``gripper.opening.max``).
    """
    g = parse_section(GripperSpec, data, where, error=GripperError)
    check_tip(g.pad, f"{where}.pad", GripperError)
    if not g.opening.max > g.opening.min:
        raise GripperError(f"{where}.opening.max must be > {where}.opening.min "
                           f"({g.opening.min:g} m), got {g.opening.max:g} m")
    t = g.transmission
    if not t.joints or any(not j for j in t.joints):
        raise GripperError(f"{where}.transmission.joints must name at least one joint")
    if len(set(t.joints)) != len(t.joints):
        raise GripperError(f"{where}.transmission.joints repeats a joint: {list(t.joints)}")
    if not (np.isfinite(t.position_per_aperture) and t.position_per_aperture != 0):
        raise GripperError(f"{where}.transmission.position_per_aperture must be a nonzero "
                           f"number, got {t.position_per_aperture}")
    _check_joint_range(g, where)
    return g


def _check_joint_range(g: GripperSpec, where: str) -> None:
    """The pad below :data:`MAX_LENGTH`; the joint positions over the opening range within
    :data:`MAX_JOINT_POSITION` and ``transmission.position_limits``.
    """
    pad = g.pad
    for key in ("radius", "width", "edge_radius"):
        value = getattr(pad, key)
        if value is not None and value > MAX_LENGTH:
            raise GripperError(f"{where}.pad.{key} must be <= {MAX_LENGTH:g} m ({_UNITS}), "
                               f"got {value:g} m")
    t = g.transmission
    ends = (g.joint_positions(g.opening.min)[0], g.joint_positions(g.opening.max)[0])
    span = (f"{where}.transmission.position_offset + position_per_aperture * aperture puts the "
            f"joints at {ends[0]:g} closed and {ends[1]:g} open (opening [{g.opening.min:g}, "
            f"{g.opening.max:g}] m)")
    if max(abs(e) for e in ends) > MAX_JOINT_POSITION:
        raise GripperError(f"{span}, beyond +-{MAX_JOINT_POSITION:.4g}: joint positions are in "
                           "rad or m, not degrees or mm")
    if t.position_limits is not None:
        lower, upper = t.position_limits
        if not lower < upper:
            raise GripperError(f"{where}.transmission.position_limits must be [lower, upper] "
                               f"with lower < upper, got {[lower, upper]}")
        if not all(lower - 1e-9 * (upper - lower) <= e <= upper + 1e-9 * (upper - lower)
                   for e in ends):
            raise GripperError(f"{span}, outside {where}.transmission.position_limits "
                               f"[{lower:g}, {upper:g}]: position_per_aperture's sign (negative "
                               "when the joint closes with a larger position) or the offset is "
                               "wrong")


def load_gripper(path: str | Path) -> GripperSpec:
    """Read and validate a gripper device file; errors name the file and the field."""
    data = read_yaml(path, what="gripper device")
    try:
        return parse_gripper(data)
    except GripperError as exc:
        raise GripperError(f"gripper device {path}: {exc}") from None
