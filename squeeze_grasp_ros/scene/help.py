# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp scene-help``: every scene key (unit, range, default), shape type and effect,
and every key of a gripper device file.
"""

from __future__ import annotations

from squeeze_grasp_ros.scene.gripper import GripperSpec
from squeeze_grasp_ros.scene.schema import key_reference
from squeeze_grasp_ros.scene.specs import EFFECTS, SHAPES, FingerSpec, Scene


def scene_help() -> str:
    """Human-readable reference of every scene key, unit and range."""
    lines = key_reference(Scene, nested={"fingers": (FingerSpec, "fingers.F1|F2.")})
    lines.append("")
    lines.append("shape types: " + "; ".join(f"{k}({', '.join(v)})" for k, v in SHAPES.items()))
    lines.append("effects: " + "; ".join(f"{k}: {v}" for k, v in EFFECTS.items()))
    lines += ["", "gripper device files (controller.device, gripper-plan --gripper; "
              "docs/grippers.md):", *key_reference(GripperSpec, "gripper.")]
    return "\n".join(lines)
