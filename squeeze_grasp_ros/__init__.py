# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Two-finger squeeze grasps of deformable planar objects (Jia, Guo, Lin, IJRR 2014).

Start at :mod:`squeeze_grasp_ros.api`, the typed front door of the ROS-free mechanics and
scenes. Importing the package has no side effects; the executables it installs configure their
process in :mod:`squeeze_grasp_ros.entry`.
"""

__version__ = "0.1.0"
