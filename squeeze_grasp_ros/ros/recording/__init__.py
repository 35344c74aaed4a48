# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Recordings of pipeline runs: rosbag2 bags with MCAP storage, written from raw CDR.

:mod:`.schema` builds the ``ros2msg`` message definitions and type hashes from the installed
interface files, :mod:`.bag` writes and reads bags (no rclpy needed), :mod:`.replay` plays a
recording's sensor topics into a fresh monitor on rclpy.
"""
