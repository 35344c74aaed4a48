# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Whether this process's rclpy side has shut down (what lets the console script end at once,
:func:`squeeze_grasp_ros.entry.end_after_ros`).
"""
from __future__ import annotations

from rclpy import context

__all__ = ["contexts_shut_down"]


def contexts_shut_down() -> bool:
    """True when no rclpy context of this process still holds ROS logging: every context that
    started it has shut down, which also finished rcl's logging (its log file flushed and
    closed). rclpy counts those contexts in ``rclpy.context.g_logging_ref_count``.
    """
    return context.g_logging_ref_count == 0
