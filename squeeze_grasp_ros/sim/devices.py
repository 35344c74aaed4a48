# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Simulated devices that carry the fingertips: Barrett BH8 fingers, a Cobra-style arm, a pusher.

Every device is commanded by Cartesian fingertip-centre setpoints in the object frame (m) and
reports the measured fingertip centre. A real Barrett finger moves its tip on an arc and needs
joint-space inverse kinematics to follow a straight line; that is out of scope here (and of the
hardware contract): the simulated devices follow Cartesian setpoints directly.

Dynamics per tick of length dt (s):

- without the ``actuator_lag`` effect the device reaches its setpoint within the tick (ideal
  position control);
- with it, a first-order lag of time constant tau, integrated exactly over the tick:
  x <- s + (x - s) exp(-dt / tau) for setpoint s;
- in both cases the tip moves at most ``max_speed * dt`` per tick (the device's speed limit).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

KIND_MAX_SPEED: dict[str, float] = {"barrett": 0.1, "cobra": 0.25, "pusher": 0.05}
"""Largest fingertip speed of each device kind, m/s (plausible values: the BH8's fingers close
in about a second over ~0.1 m of tip travel; the arm and the pusher are assumed)."""


@dataclass(frozen=True)
class DeviceModel:
    """A simulated device.

    Attributes
    ----------
    name : str
        Device name (``scene.DEVICES``), e.g. "barrett_f1".
    kind : {"barrett", "cobra", "pusher"}
    max_speed : float
        Largest tip speed, m/s.
    time_constant : float
        First-order lag time constant, s; 0 = ideal position control.
    """

    name: str
    kind: str
    max_speed: float
    time_constant: float = 0.0

    @property
    def lagged(self) -> bool:
        """True if the device has a first-order lag."""
        return self.time_constant > 0.0


def device_model(name: str, time_constant: float = 0.0) -> DeviceModel:
    """The model of device ``name`` ("barrett_f1" -> kind "barrett", "cobra", "pusher")."""
    kind = name.split("_", 1)[0]
    if kind not in KIND_MAX_SPEED:
        raise ValueError(f"unknown device {name!r} (kinds: {sorted(KIND_MAX_SPEED)})")
    return DeviceModel(name, kind, KIND_MAX_SPEED[kind], float(time_constant))


def follow(
    device: DeviceModel, position: np.ndarray, setpoint: np.ndarray, dt: float
) -> np.ndarray:
    """Tip centre (2,) after one tick of ``dt`` s from ``position`` toward ``setpoint`` (m)."""
    target = np.asarray(setpoint, float)
    if device.lagged:
        target = target + (position - target) * np.exp(-dt / device.time_constant)
    step = target - position
    length = float(np.hypot(step[0], step[1]))
    cap = device.max_speed * dt
    if length > cap:
        return position + step * (cap / length)
    return target
