# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Elastic objects (paper Sec. 2-3): shapes, meshes, the plane-stress material, the CST
stiffness, the boundary compliance and the reduced stiffness of a contact set.

Depends on nothing else in ``mechanics`` but ``errors``.
"""
