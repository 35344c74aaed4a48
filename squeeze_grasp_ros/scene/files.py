# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Scene files and mappings -> a validated, frozen :class:`~.specs.Scene`.

:func:`load_scene` reads a YAML file through the bounded readers of
:mod:`squeeze_grasp_ros.inputs` (size limit, no aliases); :func:`parse_scene` validates a mapping:
the schema first (:mod:`.schema`, every key typed and in range), then the cross-field checks
(:mod:`.checks`).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from squeeze_grasp_ros.inputs import InputError, load_yaml, read_text
from squeeze_grasp_ros.mechanics.vocabulary import Finger, ShapeType
from squeeze_grasp_ros.scene.checks import validate
from squeeze_grasp_ros.scene.schema import parse_section
from squeeze_grasp_ros.scene.specs import FingerSpec, Scene, SceneError

__all__ = ["load_scene", "parse_scene", "read_yaml"]


def parse_scene(data: Any, base_dir: Path | None = None) -> Scene:
    """Validate a scene given as a mapping (e.g. from YAML); relative file paths use
    ``base_dir``.
    """
    if not isinstance(data, dict):
        raise SceneError("a scene must be a YAML mapping")
    if isinstance(data.get("fingers"), dict):
        data = dict(data)
        data["fingers"] = {
            Finger(k) if k in Finger.values() else k:
                parse_section(FingerSpec, v, f"fingers.{k}", error=SceneError)
            for k, v in data["fingers"].items()}
    scene = validate(parse_section(Scene, data, "", error=SceneError))
    shape = scene.object.shape
    if (shape["type"] == ShapeType.FILE and base_dir is not None
            and not Path(shape["path"]).is_absolute()):
        shape = {**shape, "path": str(Path(base_dir) / shape["path"])}
        scene = dataclasses.replace(scene, object=dataclasses.replace(scene.object, shape=shape))
    return scene


def read_yaml(path: str | Path, what: str = "scene") -> Any:
    """The YAML document of a ``what`` file; SceneError if it is missing or not YAML."""
    try:
        return load_yaml(read_text(path, what=what), what=f"{what} {path}")
    except InputError as exc:
        raise SceneError(str(exc)) from None


def load_scene(path: str | Path) -> Scene:
    """Read and validate a YAML scene file (its ``controller:`` section against its device too).

    Raises :class:`SceneError` (an ``InvalidInputError``) naming the file or the entry.
    """
    from squeeze_grasp_ros.scene.controller import scene_controller  # it reads device files

    scene = parse_scene(read_yaml(path), base_dir=Path(path).parent)
    scene_controller(scene, path)
    return scene
