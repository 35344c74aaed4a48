# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Scene -> the goal an executor runs: the squeeze directions and depth, the pure directions
for a slip reaction, and the resistance waypoints of Algorithm 2 (Sec. 6.3). No ROS.

``squeeze-grasp run --no-planner`` plans with :func:`plan_scene`; with the planner node, the
directions come from its services and only :func:`resistance_goal` runs here.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.control.motion import GraspGoal
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import (
    SQUEEZING_FINGERS,
    ContactKind,
    Finger,
    SqueezeKind,
)
from squeeze_grasp_ros.scene.setup import GraspSetup
from squeeze_grasp_ros.scene.specs import Scene

__all__ = ["ScenePlan", "plan_scene", "resistance_goal", "resists"]


@dataclass(frozen=True)
class ScenePlan:
    """The goal of a scene and the squeeze it was planned from.

    Attributes
    ----------
    goal : GraspGoal
        What the executor runs (object frame, SI).
    squeeze : EventSqueeze
        The predicted event-driven squeeze (events, termination, depth).
    seconds : float
        Wall-clock time of the planning, s.
    """

    goal: GraspGoal
    squeeze: EventSqueeze
    seconds: float


def resists(scene: Scene, *, resist: bool = True) -> bool:
    """True if the scene has a frictional adversary and resistance is asked for."""
    adv = scene.adversary
    return resist and adv is not None and adv.contacts == ContactKind.FRICTION


def resistance_goal(setup: GraspSetup, squeeze: EventSqueeze | None = None) -> dict:
    """The resistance fields of a :class:`GraspGoal` after the scene's squeeze (Algorithm 2).

    The adversary is sent as far as Algorithm 2 got (all of a, or until it slipped).
    ``squeeze`` defaults to the setup's; pass it to reuse a squeeze.
    """
    if squeeze is None:
        squeeze = setup.event_squeeze()
    plan = setup.frictional_resistance(squeeze)
    travel = np.array([s.end for s in plan.stages])
    keep = np.concatenate([[True], np.diff(travel) > 0]) & (travel > 0)
    waypoints = np.stack([plan.trajectories[f][1:] for f in SQUEEZING_FINGERS], axis=1)
    a = np.asarray(setup.scene.adversary.a, float)
    travel = travel[keep]
    return {
        "adversary": Finger.A,
        "adversary_translation": a * (travel[-1] / np.hypot(*a)),
        "resist_travel": travel,
        "resist_waypoints": waypoints[keep],
    }


def plan_scene(scene: Scene, *, on_slip_alarm: str = "hold", resist: bool = True,
               setup: GraspSetup | None = None) -> ScenePlan:
    """Plan the scene's grasp with the mechanics: one event-driven squeeze, the pure directions
    at the same contacts and, for a frictional adversary, the resistance waypoints. ``setup`` is
    the scene's :class:`GraspSetup` if it was built already (default: built here).
    """
    t0 = time.perf_counter()
    setup = GraspSetup.build(scene) if setup is None else setup
    result = setup.event_squeeze()
    directions = np.array([result.directions[f] for f in SQUEEZING_FINGERS])
    rpd = result.relative_depth / result.depth if result.depth > 0 else 0.0
    pure = plan_squeeze(setup.solid, list(setup.contacts),
                        kind=SqueezeKind.PURE).displacement.reshape(2, 2)
    resistance = resistance_goal(setup, result) if resists(scene, resist=resist) else {}
    goal = GraspGoal(SQUEEZING_FINGERS, directions, result.target_depth, rpd, on_slip_alarm,
                     pure, **resistance)
    return ScenePlan(goal, result, time.perf_counter() - t0)
