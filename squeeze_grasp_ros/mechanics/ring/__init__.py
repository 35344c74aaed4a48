# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Ring-like objects (paper Sec. 7): the thin-ring model, ring squeezes and ring grasp maps.

Builds on ``elastic`` and ``squeeze``.
"""
