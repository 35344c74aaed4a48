# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Outline extraction from top-down camera images, the simulated camera and shape matching.

ROS-free: masks and depth images in, outlines in metres out (:mod:`.extract`); outlines in,
anti-aliased mask and depth images out (:mod:`.render`); an observed outline against a
predicted deformed boundary (:mod:`.shape_match`, App. C). Contour tracing needs the
``perception`` extra (scikit-image); rendering and matching need only the core. The functions
that use ``scipy.ndimage`` import it when called: the pipeline's nodes import these modules on
every run, and a run without a camera never needs it (0.02-0.18 s of a start, with the load).
"""
