# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""ROS-free mechanics of squeeze grasping: pure numpy/scipy, no files, no printing."""
