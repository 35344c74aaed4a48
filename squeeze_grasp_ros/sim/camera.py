# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated top-down camera of a scene that declares the ``camera`` effect.

At its frame rate in sim time (frames at t = k / rate, the first at tick 0) it renders the
object's top face as the world has deformed it (outline and holes, anti-aliased,
:func:`~squeeze_grasp_ros.perception.render.render_views`) into a ``mono8`` mask and a ``32FC1``
depth image, with the scene's blur and noise (frame k draws with ``seed + k``, so runs repeat).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.render import CameraViews, render_views
from squeeze_grasp_ros.scene import CameraSpec

__all__ = ["CameraFrame", "SimCamera", "camera_of"]


@dataclass(frozen=True)
class CameraFrame:
    """One rendered frame.

    Attributes
    ----------
    index : int
        Frame number (0 = the first, at tick 0).
    stamp_ns : int
        Sim time of the tick it was taken at, ns.
    views : CameraViews
        Mask, depth and the noise-free coverage.
    outline : Outline
        The true (deformed) outline that was rendered, object frame, m.
    """

    index: int
    stamp_ns: int
    views: CameraViews
    outline: Outline


def camera_of(spec: CameraSpec) -> tuple[CameraModel, CameraPose]:
    """The camera model and the optical frame's pose (object frame) of a scene's camera."""
    model = CameraModel(spec.width, spec.height, fx=spec.fx, fy=spec.fy, cx=spec.cx,
                        cy=spec.cy, distortion=tuple(spec.distortion), frame_id=spec.frame_id)
    return model, CameraPose.from_xyz_rpy(*spec.pose)


class SimCamera:
    """Renders frames of the deformed object at the camera's rate.

    Parameters
    ----------
    spec : CameraSpec
    top_height : float
        Height of the object's top face above the support (its thickness), m.
    dt : float
        The world's tick, s.
    """

    def __init__(self, spec: CameraSpec, top_height: float, dt: float) -> None:
        self.spec = spec
        self.model, self.pose = camera_of(spec)
        self.top_height = float(top_height)
        self.dt = float(dt)
        self.frames = 0

    def due(self, tick: int) -> bool:
        """Whether tick ``tick`` (sim time tick * dt) takes a frame."""
        if tick == 0:
            return True
        now, before = tick * self.dt * self.spec.rate, (tick - 1) * self.dt * self.spec.rate
        return int(np.floor(now + 1e-9)) > int(np.floor(before + 1e-9))

    def render(self, outline: Outline, stamp_ns: int) -> CameraFrame:
        """The next frame of ``outline`` (object frame, m), taken at ``stamp_ns``."""
        spec = self.spec
        views = render_views(outline, self.model, self.pose, top_height=self.top_height,
                             blur_px=spec.blur, depth_noise_m=spec.depth_noise,
                             mask_noise=spec.mask_noise, seed=spec.seed + self.frames)
        frame = CameraFrame(self.frames, stamp_ns, views, outline)
        self.frames += 1
        return frame
