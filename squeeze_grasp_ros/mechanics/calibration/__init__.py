# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Calibration against measurements (paper App. B and C): the linear material fit from
force-displacement data and the similarity matching of simulated and measured points.

Independent of the other mechanics subpackages.
"""
