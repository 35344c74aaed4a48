# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The in-process pipeline run behind ``squeeze-grasp run``: options, the goal client, the
summary and the runner that starts the nodes in lockstep.
"""
