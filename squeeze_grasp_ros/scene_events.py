# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Scene -> event-driven squeeze: friction, fingertips, limits and depth from a validated scene."""

from __future__ import annotations

from collections.abc import Callable

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel, Limits, SolveOptions
from squeeze_grasp_ros.mechanics.squeeze.nonlinear_model import contact_model
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze, event_squeeze
from squeeze_grasp_ros.scene import Scene, SceneError, finger_nodes, scene_solid
from squeeze_grasp_ros.mechanics.vocabulary import (
    MaterialModel,
    Finger,
    SQUEEZING_FINGERS,
    StrainCriterion,
    Termination,
)


def scene_limits(scene: Scene) -> Limits:
    """Strain limit (effect ``strain_limit``) and pickup weight (effect ``pickup``) of a scene."""
    strain = scene.strain_limit if scene.has(Termination.STRAIN_LIMIT) else None
    return Limits(
        strain.epsilon if strain else None,
        strain.criterion if strain else StrainCriterion.PRINCIPAL,
        scene.pickup.weight if scene.has("pickup") else None,
    )


def scene_contact_model(scene: Scene, obj: ElasticObject) -> ContactModel:
    """The contact model of the scene's object, friction and material model (for the stepper
    outside :func:`event_squeeze_scene`, e.g. the resistance of Algorithm 2).
    """
    return contact_model(scene.object.material.model, obj, scene.mu,
                         max_events_per_depth=scene.squeeze.max_events_per_depth)


def event_squeeze_scene(
    scene: Scene,
    obj: ElasticObject | None = None,
    contacts: tuple[int, int] | None = None,
    *,
    depth: float | None = None,
    relative_depth: float | None = None,
    step: float | None = None,
    event_tol: float | None = None,
    reference: bool = False,
    progress: Callable[[float], None] | None = None,
    material_model: MaterialModel | str | None = None,
    checkpoint: Callable[[], None] | None = None,
    options: SolveOptions | None = None,
) -> EventSqueeze:
    """Run the scene's squeeze with rounded fingertips; arguments override the scene's values.

    Parameters
    ----------
    scene : Scene
        A validated scene with a solid object.
    obj : ElasticObject, optional
        The meshed object; default :func:`~squeeze_grasp_ros.scene.scene_solid` of the scene.
    contacts : (int, int), optional
        Initial contact nodes of F1 and F2; default the scene's placements.
    depth, relative_depth : float, optional
        Squeeze depth rho, m, or the relative finger approach; default the scene's.
    step, event_tol : float, optional
        Substep and event tolerance relative to the object size; default the scene's.
    reference : bool
        The paper's literal route (fixed steps, no cached compliance).
    progress : callable, optional
        Called with the completed fraction of the depth.
    material_model : MaterialModel or str, optional
        Constitutive model; default the scene's ``object.material.model``.
    checkpoint : callable, optional
        Called before every substep; may raise to abandon the squeeze (a cancellation).
    options : SolveOptions, optional
        Switches of the large-deformation savings (see :func:`event_squeeze`).

    Raises
    ------
    SceneError
        If the object is not a solid, a fingertip radius is 0 (point fingers have no polar
        angle) or no depth is given.
    """
    if scene.object.model != "solid":
        raise SceneError(
            f"object.model is {scene.object.model}: the event-driven squeeze needs "
            "a solid object (rings: `squeeze-grasp ring`)"
        )
    for name, finger in scene.fingers.items():
        if not finger.tip_radius > 0:
            raise SceneError(
                f"fingers.{name}.tip_radius must be > 0 m for the event-driven "
                "squeeze (rounded fingertips)"
            )
    sq = scene.squeeze
    if depth is None and relative_depth is None:
        depth, relative_depth = sq.depth, sq.relative_depth
    if depth is None and relative_depth is None:
        raise SceneError(
            "no squeeze depth: give squeeze.depth or squeeze.relative_depth in the "
            "scene, or --depth / --relative-depth"
        )
    obj = scene_solid(scene) if obj is None else obj
    contacts = finger_nodes(scene, obj.mesh) if contacts is None else contacts
    directions = None
    if scene.fingers[Finger.F1].direction is not None:
        directions = {n: scene.fingers[n].direction for n in SQUEEZING_FINGERS}
    return event_squeeze(
        obj,
        contacts,
        {n: scene.fingers[n].tip_radius for n in SQUEEZING_FINGERS},
        scene.mu,
        kind=sq.type,
        depth=depth,
        relative_depth=relative_depth,
        limits=scene_limits(scene),
        step=sq.step if step is None else step,
        event_tol=sq.event_tol if event_tol is None else event_tol,
        reference=reference,
        max_events_per_depth=sq.max_events_per_depth,
        directions=directions,
        progress=progress,
        material_model=scene.object.material.model if material_model is None else material_model,
        checkpoint=checkpoint,
        options=options,
    )
