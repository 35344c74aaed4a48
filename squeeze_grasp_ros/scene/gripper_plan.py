# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``plan_gripper_grasp``: where a parallel-jaw gripper should grasp a soft object, to which
aperture it should close and which effort to command (issue: grippers).

The mechanics is :mod:`squeeze_grasp_ros.mechanics.squeeze.gripper_grasp` (ranking by the grasp
map's work quality, first contact of the pads, event-driven squeeze with pads); this module
adds the device (:mod:`.gripper`): the commanded aperture and force become joint positions and
efforts in the controller's convention.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.errors import InfeasibleError, InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap, grasp_map
from squeeze_grasp_ros.mechanics.squeeze.gripper_grasp import (
    GripperCandidate,
    GripperEvaluation,
    evaluate_candidate,
    gripper_candidates,
)
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel
from squeeze_grasp_ros.scene.gripper import GripperSpec
from squeeze_grasp_ros.scene.setup import GraspSetup

__all__ = ["GripperPlan", "plan_gripper_grasp", "scene_gripper_plan"]

DEFAULT_MARGIN = 1.25
"""Commanded jaw force / predicted jaw force: the effort limit sits 25 % above the force the
squeeze needs, so a position-controlled gripper reaches the planned aperture."""


@dataclass(frozen=True)
class GripperPlan:
    """Ranked gripper grasps of one object (object frame, SI).

    Attributes
    ----------
    gripper : GripperSpec
    mu : float
    relative_closing : float
        Planned closing / aperture at first contact.
    candidates : tuple of GripperCandidate
        Best first (grasp map work quality).
    evaluations : tuple of GripperEvaluation
        The first ``len(evaluations)`` candidates squeezed with the pads.
    weight : float or None
        The object's weight, N, if it is to be lifted.
    """

    gripper: GripperSpec
    mu: float
    relative_closing: float
    candidates: tuple[GripperCandidate, ...]
    evaluations: tuple[GripperEvaluation, ...]
    weight: float | None

    def command(self, evaluation: GripperEvaluation) -> dict:
        """The controller command of an evaluated candidate: aperture and jaw force, and the
        joints' positions and efforts (effort capped at the device's ``max_force``).
        """
        g = self.gripper
        force = min(evaluation.command_force, g.max_force)
        return {"aperture": evaluation.aperture, "jaw_force": force,
                "joints": list(g.transmission.joints),
                "positions": list(g.joint_positions(evaluation.aperture)),
                "efforts": list(g.joint_efforts(force))}

    def to_json(self) -> dict:
        """JSON-able plan: every candidate, the evaluated ones with their command."""
        evaluated = {e.candidate.rank: e for e in self.evaluations}
        rows = []
        for c in self.candidates:
            e = evaluated.get(c.rank)
            rows.append(c.to_json() if e is None else {**e.to_json(), "command": self.command(e)})
        return {"gripper": self.gripper.name, "mu": self.mu,
                "relative_closing": self.relative_closing, "weight": self.weight,
                "candidates": rows, "evaluated": len(self.evaluations)}


def plan_gripper_grasp(obj: ElasticObject, gripper: GripperSpec, mu: float, *,
                       relative_closing: float, count: int = 10, evaluate: int = 3,
                       yaw_range: tuple[float, float] | None = None,
                       weight: float | None = None, margin: float = DEFAULT_MARGIN,
                       strain_limit: float | None = None,
                       material_model: MaterialModel | str = MaterialModel.LINEAR,
                       gmap: GraspMap | None = None) -> GripperPlan:
    """Ranked grasps of ``obj`` by ``gripper`` at friction ``mu``.

    Parameters
    ----------
    relative_closing : float
        Planned closing beyond first contact, as a fraction of the aperture at first contact
        (0, 1).
    count : int
        Most candidates (ranked by the grasp map's work quality).
    evaluate : int
        How many of the best candidates to squeeze with the pads (0: none).
    yaw_range : (float, float), optional
        Allowed closing directions, rad, modulo pi.
    weight : float, optional
        The object's weight, N, if it is to be lifted.
    margin : float
        Commanded / predicted jaw force (>= 1).
    strain_limit : float, optional
        Strain limit epsilon* (the material model's measure).
    gmap : GraspMap, optional
        The object's grasp map at ``mu`` if already computed (a planner's cache).

    Raises
    ------
    InfeasibleError
        If no placement fits the gripper.

    Examples
    --------
    >>> from squeeze_grasp_ros.api import GraspSetup, load_scene, scene_file
    >>> from squeeze_grasp_ros.resources import device_file
    >>> from squeeze_grasp_ros.scene.gripper import load_gripper
    >>> setup = GraspSetup.build(load_scene(scene_file("sponge_gripper")))
    >>> plan = plan_gripper_grasp(setup.solid, load_gripper(device_file("generic_85mm")), 0.6,
    ...                           relative_closing=0.15, count=5, evaluate=1)
    >>> best = plan.evaluations[0]
    >>> bool(best.aperture < best.candidate.aperture), str(best.termination)
    (True, 'depth_reached')
    """
    if not (np.isfinite(relative_closing) and 0 < relative_closing < 1):
        raise InvalidInputError(f"relative closing must be in (0, 1), got {relative_closing}")
    if not (isinstance(evaluate, (int, np.integer)) and 0 <= evaluate <= count):
        raise InvalidInputError(f"evaluate must be an integer in [0, count={count}], "
                                f"got {evaluate!r}")
    jaws = gripper.jaws()
    gmap = grasp_map(obj, mu) if gmap is None else gmap
    candidates = gripper_candidates(obj, gmap, jaws, count=count, yaw_range=yaw_range)
    if not candidates:
        raise InfeasibleError(
            f"no inward, force-closing placement of the object fits {gripper.name}'s opening "
            f"[{jaws.min_aperture:g}, {jaws.max_aperture:g}] m"
            + ("" if yaw_range is None else " within the yaw range"))
    evaluations = tuple(
        evaluate_candidate(obj, c, jaws, mu,
                           closing=min(relative_closing * c.aperture,
                                       c.aperture - jaws.min_aperture),
                           margin=margin, weight=weight, strain_limit=strain_limit,
                           material_model=material_model)
        for c in candidates[:evaluate])
    return GripperPlan(gripper, float(mu), float(relative_closing), tuple(candidates),
                       evaluations, weight)


def scene_gripper_plan(setup: GraspSetup, gripper: GripperSpec, *,
                       relative_closing: float | None = None, **options) -> GripperPlan:
    """:func:`plan_gripper_grasp` of a scene's object: its mu, strain limit, weight (pickup)
    and material model; the closing defaults to the scene's ``squeeze.relative_depth``.
    """
    scene = setup.scene
    closing = scene.squeeze.relative_depth if relative_closing is None else relative_closing
    if closing is None:
        raise InvalidInputError("no closing: give squeeze.relative_depth in the scene or "
                                "--relative-closing")
    limits = setup.limits
    options.setdefault("weight", limits.weight)
    return plan_gripper_grasp(setup.solid, gripper, scene.mu, relative_closing=closing,
                              strain_limit=limits.strain,
                              material_model=scene.object.material.model, **options)
