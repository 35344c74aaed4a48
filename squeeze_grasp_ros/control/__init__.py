# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""ROS-free logic of the monitor and the executor nodes.

:mod:`.tracker` reconstructs the contact configuration from tactile arrays and wrenches and
tracks contact events and alarms (the monitor); :mod:`.motion` turns a grasp goal into
rate-limited fingertip setpoints, one observation at a time, with holds and the reactive
redirection (the executor). The nodes wrap these classes with one call per callback, so the
same logic runs in lockstep simulation, on hardware and in plain unit tests.
"""
