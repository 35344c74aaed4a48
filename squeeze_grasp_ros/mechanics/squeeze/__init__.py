# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Squeezes (paper Sec. 2.4, 3.4-5): stable and pure squeezes of point contacts, the one-shot
solve,
rounded fingertips, the contact model of a fixed contact set, the event-driven stepper
(Algorithm 1) and grasp maps.

Builds on ``elastic``.
"""
