# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Optional parts of the package and how to install them.

``pip install .`` gives the mechanics; ROS 2 (nodes, ``run``, ``replay``, recordings), the
Dask sweeps and outline extraction from images (scikit-image) come with extras. Code that needs
an extra asks here, so that a missing one ends in a sentence saying what to install, never a
traceback.

>>> install_hint("rclpy").startswith("pip install '.[ros]'")
True
>>> install_hint("numpy") is None
True
>>> install_hint("qdldl").startswith("pip install qdldl")
True
"""
from __future__ import annotations

import importlib.util

__all__ = ["EXTRAS", "REQUIRED", "install_hint", "installed"]

EXTRAS: dict[str, tuple[tuple[str, ...], str]] = {
    "ros": (("rclpy", "squeeze_grasp_interfaces", "mcap", "ament_index_python", "std_msgs",
             "geometry_msgs", "sensor_msgs", "visualization_msgs", "rosgraph_msgs",
             "action_msgs", "builtin_interfaces", "unique_identifier_msgs"),
            "pip install '.[ros]' && squeeze-grasp ros-setup (or source a ROS 2 Jazzy "
            "workspace with squeeze_grasp_interfaces built)"),
    "sweep": (("dask", "distributed", "pyarrow"), "pip install '.[sweep]'"),
    "cholmod": (("cvxopt", "pymetis"),
                "pip install '.[cholmod]' (CHOLMOD through cvxopt, GPL-3.0; METIS: pymetis)"),
    "perception": (("skimage",), "pip install '.[perception]'"),
    "fast": (("numba",), "pip install '.[fast]'"),
    "control_msgs": (("control_msgs",),
                     "squeeze-grasp ros-setup --control-msgs DIR (DIR a jazzy checkout of "
                     "github.com/ros-controls/control_msgs; docs/grippers.md), or source a ROS 2 "
                     "Jazzy install that has it"),
}
"""Extra -> (top-level modules it provides, how to install it); control_msgs is no pip extra
(it has no wheel): ``ros-setup`` builds its gripper actions from sources."""

REQUIRED: dict[str, str] = {
    "qdldl": "pip install qdldl (a required dependency of the corotational and neo-Hookean "
             "models that pip installs with the package; on the colcon route it has no rosdep "
             "key, see docs/ros.md)",
}
"""Required modules imported only where they are needed -> how to install them."""


def installed(module: str) -> bool:
    """True if ``module`` can be found (without importing it)."""
    try:
        return importlib.util.find_spec(module) is not None
    except ImportError:
        return False


def install_hint(module: str) -> str | None:
    """How to install the extra that provides top-level ``module`` (None: not an extra's)."""
    root = module.split(".")[0]
    return REQUIRED.get(root) or next(
        (how for modules, how in EXTRAS.values() if root in modules), None)
