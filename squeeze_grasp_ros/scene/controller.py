# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A scene's gripper under a stock ros2_control controller (``controller:``, docs/grippers.md).

The section maps two fingers (the jaws) to a parallel-gripper device and names the controller
that drives its joints::

    controller: {type: joint_trajectory, name: gripper_controller, device: generic_85mm}
    controller: {type: parallel_gripper, name: gripper_controller, device: generic_85mm,
                 goal_tolerance: 1.0e-6, stall_timeout: 0.05}

:func:`scene_controller` resolves the device (a shipped name or a file relative to the scene)
and checks it against the scene: the jaws are two distinct squeezing fingers whose tips are
the device's pad, and the controller's joints (default: the device's
``transmission.joints``) are as many as the transmission has.

>>> from squeeze_grasp_ros.resources import scene_file
>>> from squeeze_grasp_ros.scene import load_scene
>>> path = scene_file("sponge_gripper")
>>> jtc = scene_controller(load_scene(path), path)
>>> jtc.topic, jtc.joints, [round(p, 4) for p in jtc.joint_positions(0.05)]
('gripper_controller/joint_trajectory', ('finger_joint',), [0.3294])
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from squeeze_grasp_ros.control.barrett import JOINTS, BarrettFinger, BarrettHand, HandPose
from squeeze_grasp_ros.control.gripper_action import GripperParameters
from squeeze_grasp_ros.control.joint_trajectory import JawLine
from squeeze_grasp_ros.mechanics.vocabulary import ControllerKind, Effect, Finger
from squeeze_grasp_ros.resources import ResourceError, device_file
from squeeze_grasp_ros.scene.gripper import GripperSpec, load_gripper
from squeeze_grasp_ros.scene.schema import SchemaError
from squeeze_grasp_ros.scene.specs import ControllerSpec, Scene, SceneError, finger_devices

__all__ = ["HAND_DEVICE", "HandController", "JawController", "JawReading", "JointReadingError",
           "scene_controller"]

HAND_DEVICE = "bh8"
"""``controller.device`` of the Barrett hand (its joints: :mod:`..control.barrett`)."""


class JointReadingError(ValueError):
    """A joint state that cannot be read as jaw feedback; the message says why."""


@dataclass(frozen=True)
class JawReading:
    """One joint state as jaw feedback (:meth:`JawController.reading`).

    Attributes
    ----------
    aperture : float
        Distance between the pad faces, m.
    force : float
        Each jaw's push on the object along the closing line, N (> 0 squeezing).
    """

    aperture: float
    force: float


@dataclass(frozen=True)
class JawController:
    """A resolved ``controller:`` section: the spec, its gripper device and joint names."""

    spec: ControllerSpec
    gripper: GripperSpec
    joints: tuple[str, ...]

    @property
    def jaws(self) -> tuple[Finger, Finger]:
        """The fingers the jaws carry, F1's jaw (the closing direction's origin) first."""
        return self.spec.jaws[0], self.spec.jaws[1]

    def jaw_line(self, positions: Mapping[str, np.ndarray]) -> JawLine:
        """The jaw line through the jaws' tip reference points ``positions[finger]`` (m), with
        the pad's contact radius as each jaw's reach.
        """
        first, second = self.jaws
        return JawLine.between(positions[first], positions[second],
                               reach=self.gripper.pad.contact_radius)

    @property
    def kind(self) -> ControllerKind:
        """The controller's interface."""
        return ControllerKind(self.spec.type)

    @property
    def topic(self) -> str:
        """The controller's command topic or action, relative: ``<name>/joint_trajectory`` or
        ``<name>/gripper_cmd``.
        """
        name = self.spec.name
        return f"{name}/gripper_cmd" if self.kind.is_action else f"{name}/joint_trajectory"

    @property
    def effort_limit(self) -> float:
        """The largest joint effort of the device (its ``max_force`` through the
        transmission).
        """
        return abs(self.gripper.joint_efforts(self.gripper.max_force)[0])

    def parameters(self) -> GripperParameters:
        """The gripper action controller's parameters (joint units); ``max_effort`` 0 is the
        device's limit, and the GripperActionController's command jumps to the goal.
        """
        s = self.spec
        return GripperParameters(
            goal_tolerance=s.goal_tolerance, stall_velocity_threshold=s.stall_velocity_threshold,
            stall_timeout=s.stall_timeout, allow_stalling=s.allow_stalling,
            max_effort=s.max_effort or self.effort_limit,
            max_velocity=(s.max_velocity if self.kind is ControllerKind.PARALLEL_GRIPPER
                          else float("inf")))

    def opening_problem(self, line: JawLine, start: Mapping[str, np.ndarray],
                        end: Mapping[str, np.ndarray]) -> str | None:
        """Why a squeeze of the jaws from tips ``start`` to ``end`` (m; a jaw missing from
        ``end`` stays) on ``line`` cannot be commanded, or None: its end aperture outside the
        device's opening range (a controller refuses or clamps such a command, and the jaws
        stand short of it until the stall watch).
        """
        first, second = self.jaws
        before = line.aperture(start[first], start[second])
        after = line.aperture(end.get(first, start[first]), end.get(second, start[second]))
        lo, hi = self.gripper.opening.min, self.gripper.opening.max
        if lo - 1e-12 <= after <= hi + 1e-12:
            return None
        return (f"the goal's squeeze takes the aperture from {before * 1e3:.4g} mm to "
                f"{after * 1e3:.4g} mm, outside {self.gripper.name}'s opening [{lo * 1e3:.4g}, "
                f"{hi * 1e3:.4g}] mm (its device file's opening): the controller cannot take the "
                "jaws there; plan a shallower squeeze or another gripper")

    def tolerance_problem(self, closing: float) -> str | None:
        """Why a gripper action controller would take a squeeze closing the aperture by
        ``closing`` (m) as reached before it squeezes, or None: its ``goal_tolerance`` (joint
        units) is, through the transmission, at least that closing (the stock controllers end a
        goal once the joint is within the tolerance of its position). A goal that does not close
        (depth 0) is rightly reached where it starts: None.
        """
        tolerance = self.spec.goal_tolerance
        gain = abs(self.gripper.transmission.position_per_aperture)
        if not closing > 0 or tolerance / gain < closing:
            return None
        return (f"controller.goal_tolerance {tolerance:g} (joint units) is "
                f"{tolerance / gain * 1e3:.4g} mm of aperture on {self.gripper.name} "
                f"(/ |transmission.position_per_aperture| {gain:g}), not below the squeeze's "
                f"closing of {closing * 1e3:.4g} mm: the {self.spec.type} controller would "
                f"report the goal reached before the jaws squeeze; set controller.goal_tolerance "
                f"below {closing * gain:.4g}")

    def joint_positions(self, aperture: float) -> tuple[float, ...]:
        """Each controller joint's position at ``aperture`` (m), through the transmission."""
        return self.gripper.joint_positions(aperture)[:1] * len(self.joints)

    def joint_efforts(self, force: float) -> tuple[float, ...]:
        """Each controller joint's effort for a jaw force ``force`` (N)."""
        return self.gripper.joint_efforts(force)[:1] * len(self.joints)

    def reading(self, names: Sequence[str], positions: Sequence[float],
                efforts: Sequence[float]) -> JawReading:
        """The aperture and jaw force of a joint state (``sensor_msgs/JointState`` fields)
        through the transmission: the mean over the controller's joints; other joints in the
        message are ignored.

        Raises
        ------
        JointReadingError
            A controller joint missing, positions or efforts not one per name, or not finite.
        """
        names = list(names)
        if len(positions) != len(names) or len(efforts) != len(names):
            raise JointReadingError(f"{len(names)} names, {len(positions)} positions and "
                                    f"{len(efforts)} efforts: one of each per joint expected")
        missing = [j for j in self.joints if j not in names]
        if missing:
            raise JointReadingError(f"the controller's joints {missing} are missing (got "
                                    f"{names})")
        index = [names.index(j) for j in self.joints]
        p = np.array([positions[i] for i in index], float)
        e = np.array([efforts[i] for i in index], float)
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(e))):
            raise JointReadingError(f"positions {p.tolist()} or efforts {e.tolist()} are not "
                                    "finite")
        return JawReading(float(np.mean([self.gripper.aperture(v) for v in p])),
                          float(np.mean([self.gripper.jaw_force(v) for v in e])))


@dataclass(frozen=True)
class HandController:
    """A resolved ``controller:`` section of the Barrett hand (``device: bh8``): the scene's
    fingers it carries, each a finger of the hand (by its device), and the hand's kinematics at
    the declared palm pose.
    """

    spec: ControllerSpec
    hand: BarrettHand
    fingers: dict[Finger, BarrettFinger]

    @property
    def jaws(self) -> tuple[Finger, ...]:
        """The scene's fingers the hand carries (the controller's command replaces their
        setpoint topics).
        """
        return tuple(self.fingers)

    @property
    def joints(self) -> tuple[str, ...]:
        """The hand's joints, in its drivers' order."""
        return JOINTS

    @property
    def kind(self) -> ControllerKind:
        """The controller's interface (a JointTrajectoryController)."""
        return ControllerKind.JOINT_TRAJECTORY

    @property
    def topic(self) -> str:
        """The controller's command topic, relative: ``<name>/joint_trajectory``."""
        return f"{self.spec.name}/joint_trajectory"


def _hand(scene: Scene, spec: ControllerSpec) -> HandController:
    """The Barrett hand's controller of a scene, checked; errors name the field."""
    if ControllerKind(spec.type) is not ControllerKind.JOINT_TRAJECTORY:
        raise SceneError(f"controller.type: the {HAND_DEVICE} hand is driven by a "
                         f"joint_trajectory controller, got {spec.type}")
    if spec.palm is None:
        raise SceneError(f"controller.palm: the {HAND_DEVICE} hand needs its palm's pose "
                         "[x m, y m, yaw deg] in the object frame")
    devices = finger_devices(scene)
    fingers = {}
    for jaw in spec.jaws:
        if jaw not in scene.fingers:
            raise SceneError(f"controller.jaws: {jaw} is not a finger of the scene "
                             f"({sorted(scene.fingers)})")
        try:
            fingers[Finger(jaw)] = BarrettFinger(devices[jaw])
        except ValueError:
            raise SceneError(f"controller.jaws: {jaw}'s device {devices[jaw]} is not a finger "
                             f"of the {HAND_DEVICE} hand "
                             f"({[f.value for f in BarrettFinger]})") from None
    if not (scene.has(Effect.FORCE_SENSING) or scene.has(Effect.TACTILE_SENSING)) and (
            len(fingers) != 2 or BarrettFinger.F3 in fingers.values()):
        raise SceneError(f"controller.jaws: without force_sensing or tactile_sensing the monitor "
                         f"reads the {HAND_DEVICE} hand's fingers from their joint efforts, which "
                         "determine the tip forces of fingers 1 and 2 only (the thumb has no "
                         "spread joint): carry two fingers on barrett_f1 and barrett_f2, got "
                         f"{ {f: h.value for f, h in fingers.items()} }")
    x, y, yaw = spec.palm
    return HandController(spec, BarrettHand(pose=HandPose((float(x), float(y)),
                                                          float(np.deg2rad(yaw)))), fingers)


def _device(spec: ControllerSpec, base: Path) -> GripperSpec:
    """The gripper of ``controller.device``: a device file (.yaml, relative to ``base``) or a
    shipped name; errors prefixed with the field.
    """
    path = Path(spec.device)
    try:
        if path.suffix in (".yaml", ".yml"):
            return load_gripper(path if path.is_absolute() else base / path)
        return load_gripper(device_file(spec.device))
    except (ResourceError, SchemaError) as exc:
        raise SceneError(f"controller.device: {exc}") from None


def scene_controller(scene: Scene, scene_path: str | Path
                     ) -> JawController | HandController | None:
    """The scene's resolved ``controller:`` section, or None without one.

    Raises
    ------
    SceneError
        Naming the field: jaws not two distinct squeezing fingers, a jaw's tip other than the
        device's pad, joints not as many as the transmission's.
    """
    spec = scene.controller
    if spec is None:
        return None
    if spec.device == HAND_DEVICE:
        return _hand(scene, spec)
    gripper = _device(spec, Path(scene_path).parent)
    jaws = spec.jaws
    if len(jaws) != 2 or jaws[0] == jaws[1] or any(j not in scene.fingers for j in jaws):
        raise SceneError(f"controller.jaws must be two distinct fingers of the scene "
                         f"({sorted(scene.fingers)}), got {list(jaws)}")
    pad = gripper.pad.shape_of()
    for jaw in jaws:
        if scene.fingers[jaw].tip_shape() != pad:
            raise SceneError(f"fingers.{jaw}.tip must be the device's pad ({gripper.name}: "
                             f"{pad.to_json()}), got {scene.fingers[jaw].tip_shape().to_json()}")
    joints = spec.joints or gripper.transmission.joints
    if len(joints) != len(gripper.transmission.joints) or len(set(joints)) != len(joints):
        raise SceneError(f"controller.joints must be {len(gripper.transmission.joints)} distinct "
                         f"names (as {gripper.name}'s transmission.joints), got {list(joints)}")
    if ControllerKind(spec.type).is_action and len(joints) != 1:
        raise SceneError(f"controller.joints: a {spec.type} controller drives one joint (its "
                         f"'joint' parameter), {gripper.name}'s transmission has {list(joints)}")
    return JawController(spec, gripper, tuple(joints))

