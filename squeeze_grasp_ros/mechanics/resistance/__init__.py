# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Resistance to an adversary finger (paper Sec. 6): the optimal resistance of a stable squeeze
measured by work, its quadratic forms, and the frictional resistance run by the event stepper.

Builds on ``elastic`` and ``squeeze``.
"""
