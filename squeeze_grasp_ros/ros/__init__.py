# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Everything that needs ROS 2: the rclpy nodes, the message conversions, the rosbag2/MCAP
recording and replay, the in-process pipeline runner (the interface build is a build tool:
``squeeze_grasp_ros.buildtool``).

Nothing outside this folder (except the CLI commands and benchmark sections that run it)
imports it; ``test/test_layers.py`` checks that by reading the import graph.
"""
