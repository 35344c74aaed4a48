# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Two-finger squeeze grasps of deformable planar objects (Jia, Guo, Lin, IJRR 2014)."""

__version__ = "0.1.0"
