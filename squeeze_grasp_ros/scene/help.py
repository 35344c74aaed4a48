# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp scene-help``: every scene key (unit, range, default), shape type and effect."""

from __future__ import annotations

from squeeze_grasp_ros.scene.schema import key_reference
from squeeze_grasp_ros.scene.specs import EFFECTS, SHAPES, FingerSpec, Scene


def scene_help() -> str:
    """Human-readable reference of every scene key, unit and range."""
    lines = key_reference(Scene, nested={"fingers": (FingerSpec, "fingers.F1|F2.")})
    lines.append("")
    lines.append("shape types: " + "; ".join(f"{k}({', '.join(v)})" for k, v in SHAPES.items()))
    lines.append("effects: " + "; ".join(f"{k}: {v}" for k, v in EFFECTS.items()))
    return "\n".join(lines)
