# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Outline extraction from top-down camera images, the simulated camera and shape matching.

ROS-free: masks and depth images in, outlines in metres out (:mod:`.extract`); outlines in,
anti-aliased mask and depth images out (:mod:`.render`); an observed outline against a
predicted deformed boundary (:mod:`.shape_match`, App. C). Contour tracing needs the
``perception`` extra (scikit-image); rendering and matching need only the core.
"""
