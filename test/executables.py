# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Where the package's console scripts are installed, on both routes.

The pip route puts them beside the environment's Python (``<venv>/bin``); the colcon route in
``<install prefix>/lib/squeeze_grasp_ros``, where ``ros2 run`` looks, found through the ament
index.
"""
from __future__ import annotations

import sys
from pathlib import Path

PACKAGE = "squeeze_grasp_ros"


def script(name: str) -> str:
    """The path of the installed console script ``name`` (planner, squeeze-grasp, ...)."""
    beside = Path(sys.executable).parent / name
    if beside.is_file():
        return str(beside)
    from ament_index_python.packages import get_package_prefix

    installed = Path(get_package_prefix(PACKAGE)) / "lib" / PACKAGE / name
    assert installed.is_file(), f"console script {name!r} is installed neither beside " \
                                f"{sys.executable} nor in {installed.parent}"
    return str(installed)
