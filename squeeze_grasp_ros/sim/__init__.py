# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated world behind ``sim_hardware``: devices, sensors and the mechanics, without ROS.

:class:`~.world.SimWorld` advances the event-driven stepper (:mod:`..mechanics.stepper`) by the
per-tick translations of the simulated devices (:mod:`.devices`) and renders the fingertip
sensors (:mod:`.sensors`). It composes only the effects the scene declares; every piece of
optional work increments a counter in ``SimWorld.work`` so tests can prove that an undeclared
effect costs nothing.
"""
