# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Where the package's installed data lives: node configuration, scenes, launch files, viewers.

Every route installs the same tree, ``share/squeeze_grasp_ros/`` (``config/``,
``config/scenes/``, ``config/viewers/``, ``launch/``); this module finds it, in this order:

1. the ament index (``ament_index_python``), as every ROS 2 tool does: the colcon route, and any
   environment whose ``AMENT_PREFIX_PATH`` names the install;
2. the source tree next to this package, for editable installs (``pip install -e .``);
3. ``<sys.prefix>/share/squeeze_grasp_ros``, where ``pip install .`` puts the data files.

>>> (share_dir() / "config" / "executor.yaml").is_file()
True
"""
from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["PACKAGE", "ResourceError", "config_dir", "scene_file", "share_dir", "viewer_file"]

PACKAGE = "squeeze_grasp_ros"
MARKER = Path("config") / "executor.yaml"
"""A file every complete share tree holds."""


class ResourceError(FileNotFoundError):
    """The package's data files are not installed where any route puts them."""


def _ament_share() -> Path | None:
    try:
        from ament_index_python.packages import get_package_share_directory
        return Path(get_package_share_directory(PACKAGE))
    except (ImportError, LookupError, OSError, ValueError):
        return None


def candidates() -> list[Path]:
    """The share folders tried, in order (see the module docstring)."""
    found = [_ament_share(), Path(__file__).resolve().parents[1],
             Path(sys.prefix) / "share" / PACKAGE]
    return [p for p in found if p is not None]


def share_dir() -> Path:
    """``share/squeeze_grasp_ros`` of this installation (or the source tree of an editable one).

    Raises
    ------
    ResourceError
        If no candidate holds the node configuration; the message lists where it looked.
    """
    tried = candidates()
    for path in tried:
        if (path / MARKER).is_file():
            return path
    raise ResourceError(f"the data files of {PACKAGE} are not installed: no {MARKER} in "
                        f"{[str(p) for p in tried]} (ament index, source tree, sys.prefix)")


def config_dir() -> Path:
    """Folder of the node parameter files (``<share>/config``)."""
    return share_dir() / "config"


def _shipped(folder: str, kind: str, name: str) -> Path:
    """``<config>/<folder>/<name>.yaml``, or ResourceError listing the shipped ``kind``s."""
    path = config_dir() / folder / f"{name}.yaml"
    if not path.is_file():
        shipped = sorted(p.stem for p in (config_dir() / folder).glob("*.yaml"))
        raise ResourceError(f"no shipped {kind} {name!r}; shipped {kind}s: {', '.join(shipped)}")
    return path


def scene_file(name: str) -> Path:
    """A shipped scene by name, e.g. ``scene_file("foam_square")``, m/kg/s SI scene YAML.

    Raises :class:`ResourceError` (a ``FileNotFoundError``, not an ``InvalidInputError``) for a
    name that is not shipped; its message lists the shipped scenes.
    """
    return _shipped("scenes", "scene", name)


def device_file(name: str) -> Path:
    """A shipped gripper device file by name, e.g. ``device_file("generic_85mm")``."""
    return _shipped("devices", "device", name)


def viewer_file(name: str) -> Path:
    """A shipped viewer configuration (``<share>/config/viewers/<name>``)."""
    path = config_dir() / "viewers" / name
    if not path.is_file():
        raise ResourceError(f"viewer configuration {name!r} is not installed in {path.parent}")
    return path
