# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ROS 2 nodes: thin rclpy wiring around the mechanics, one console script each."""
