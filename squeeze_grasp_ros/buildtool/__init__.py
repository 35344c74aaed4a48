# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Build tools: programs that build parts of the installation (the ROS 2 interface package)
with cmake and a compiler. They import nothing of ROS or of the package's other layers, so they
run before the interfaces exist (``ros-setup``).
"""
