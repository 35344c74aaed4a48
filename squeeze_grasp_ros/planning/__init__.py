# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner's requests without ROS: validation, the object cache and one call per computation.

The planner node (:mod:`squeeze_grasp_ros.ros.nodes.planner`) turns each service request into one
call of this module and the result into a response with :mod:`squeeze_grasp_ros.ros.messages`.
Everything here is plain Python and numpy, so it is tested without ROS and shared by the
node's services and actions.

Bad requests raise :class:`PlannerError` with an :class:`ErrorCode` and a message naming the
field; :func:`classify` maps the mechanics' and the scene parser's exceptions onto the same
codes. Long computations take a :data:`Progress` callback that is called at each stage and may
raise :class:`Cancelled`.

Units are SI and coordinates are in the object frame of the scene (x right, y up).
"""

from squeeze_grasp_ros.mechanics.resistance.optimal import MAX_DIRECTIONS
from squeeze_grasp_ros.planning.checks import (
    best_count,
    check_number,
    check_step,
    choice,
    contact_nodes,
)
from squeeze_grasp_ros.planning.errors import (
    ERROR_CODES,
    Cancelled,
    ErrorCode,
    PlannerError,
    classify,
    invalid,
)
from squeeze_grasp_ros.planning.gripper import gripper_grasp_plan, read_gripper
from squeeze_grasp_ros.planning.object_ids import (
    MAX_ID_CHARS,
    check_digest,
    check_object_id,
    shown,
)
from squeeze_grasp_ros.planning.objects import (
    CONTACT_MODELS,
    MAX_BEST_COUNT,
    RING_STAGES,
    SOLID_STAGES,
    LoadedObject,
    ObjectCache,
    ObjectKey,
    PlannerLimits,
    Progress,
    SceneSource,
    check_size,
    load_cached,
    load_object,
    no_progress,
    object_key,
    read_scene,
    requested_nodes,
    resident_bytes,
    solver_route,
)
from squeeze_grasp_ros.planning.requests import (
    ResistancePlan,
    RingTest,
    SqueezePlan,
    event_squeeze_run,
    friction_resistance,
    object_grasp_map,
    resistance_plan,
    ring_grasp_test,
    squeeze_fields,
    squeeze_plan,
)
from squeeze_grasp_ros.planning.typed_objects import (
    FramePose,
    TypedMaterial,
    TypedObject,
    object_source,
    typed_scene,
)

__all__ = [
    "CONTACT_MODELS",
    "Cancelled",
    "ERROR_CODES",
    "ErrorCode",
    "FramePose",
    "PlannerLimits",
    "LoadedObject",
    "MAX_BEST_COUNT",
    "MAX_ID_CHARS",
    "MAX_DIRECTIONS",
    "ObjectCache",
    "ObjectKey",
    "PlannerError",
    "Progress",
    "RING_STAGES",
    "ResistancePlan",
    "RingTest",
    "SOLID_STAGES",
    "SceneSource",
    "SqueezePlan",
    "TypedMaterial",
    "TypedObject",
    "best_count",
    "check_digest",
    "check_number",
    "check_object_id",
    "check_size",
    "check_step",
    "choice",
    "classify",
    "contact_nodes",
    "event_squeeze_run",
    "friction_resistance",
    "gripper_grasp_plan",
    "invalid",
    "load_cached",
    "load_object",
    "no_progress",
    "object_grasp_map",
    "object_key",
    "object_source",
    "read_gripper",
    "read_scene",
    "requested_nodes",
    "resident_bytes",
    "resistance_plan",
    "ring_grasp_test",
    "shown",
    "solver_route",
    "squeeze_fields",
    "squeeze_plan",
    "typed_scene",
]
