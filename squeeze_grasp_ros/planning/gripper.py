# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The ``plan_gripper_grasp`` request: a gripper device and a cached solid -> ranked grasps."""
from __future__ import annotations

import re

from squeeze_grasp_ros.inputs import InputError, load_yaml
from squeeze_grasp_ros.planning.checks import best_count, check_number
from squeeze_grasp_ros.planning.errors import invalid
from squeeze_grasp_ros.planning.objects import LoadedObject, PlannerLimits
from squeeze_grasp_ros.resources import ResourceError, device_file
from squeeze_grasp_ros.scene.gripper import GripperSpec, load_gripper, parse_gripper
from squeeze_grasp_ros.scene.gripper_plan import DEFAULT_MARGIN, GripperPlan, plan_gripper_grasp

__all__ = ["gripper_grasp_plan", "read_gripper"]

NAME = re.compile(r"[A-Za-z0-9_]{1,64}")
"""A shipped device's name (no path: requests cannot name files)."""


def read_gripper(gripper_yaml: str, gripper_name: str) -> GripperSpec:
    """The request's gripper: exactly one of a YAML document and a shipped device name.

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT for neither or both, an unknown name, bad YAML or a bad device (the
        message names the field).
    """
    if bool(gripper_yaml) == bool(gripper_name):
        raise invalid("give exactly one of gripper_yaml and gripper_name")
    if gripper_name:
        if not NAME.fullmatch(gripper_name):
            raise invalid("gripper_name must be a shipped device's name (letters, digits, _), "
                          f"got {gripper_name[:64]!r}")
        try:
            return load_gripper(device_file(gripper_name))
        except ResourceError as exc:
            raise invalid(f"gripper_name: {exc}") from None
    try:
        return parse_gripper(load_yaml(gripper_yaml, what="gripper_yaml"))
    except InputError as exc:
        raise invalid(str(exc)) from None


def gripper_grasp_plan(loaded: LoadedObject, gripper: GripperSpec, *, mu: float,
                       relative_closing: float, count: int, evaluate: int,
                       yaw_range: tuple[float, float] | None, weight: float,
                       force_margin: float, strain_limit: float,
                       limits: PlannerLimits) -> GripperPlan:
    """:func:`~squeeze_grasp_ros.scene.gripper_plan.plan_gripper_grasp` of a cached solid and
    its cached grasp map at ``mu``, the request's zeros meaning "none" / "default" as the
    service documents.
    """
    count = best_count(count, limits, "count")
    if not 0 <= evaluate <= count:
        raise invalid(f"evaluate must be in [0, count={count}], got {evaluate}")
    mu = check_number("mu", mu, 0.0)
    margin = check_number("force_margin", force_margin, 0.0) or DEFAULT_MARGIN
    if margin < 1.0:  # checked here, not only when a candidate is evaluated
        raise invalid(f"force_margin must be >= 1 (0: {DEFAULT_MARGIN:g}), got {force_margin}")
    return plan_gripper_grasp(
        loaded.solid(), gripper, mu, gmap=loaded.grasp_map(mu),
        relative_closing=check_number("relative_closing", relative_closing, 0.0, 1.0),
        count=count, evaluate=evaluate,
        yaw_range=None if yaw_range is None else tuple(
            check_number(name, v) for name, v in zip(("yaw_min", "yaw_max"), yaw_range)),
        weight=check_number("weight", weight, 0.0) or None,
        margin=margin,
        strain_limit=check_number("strain_limit", strain_limit, 0.0) or None,
        material_model=loaded.scene.object.material.model)
