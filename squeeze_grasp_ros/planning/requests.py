# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""One call per computation: squeezes, grasp maps, resistance, ring tests, event squeezes."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.reduced import boundary_displacement, reduced_stiffness
from squeeze_grasp_ros.mechanics.errors import FINGERS_MEET
from squeeze_grasp_ros.mechanics.resistance.frictional import FrictionalResistance
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    MAX_DIRECTIONS,
    Resistance,
    ResistanceSweep,
    optimal_resistance,
    sweep_directions,
)
from squeeze_grasp_ros.mechanics.ring.grasp_map import RingGraspMap, ring_grasp_map
from squeeze_grasp_ros.mechanics.ring.squeeze import RingGrasp, ring_grasp
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import Squeeze, force_closure, plan_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import ContactKind, SqueezeKind
from squeeze_grasp_ros.planning.checks import check_number, check_step, choice, contact_nodes
from squeeze_grasp_ros.planning.errors import invalid
from squeeze_grasp_ros.planning.objects import CONTACT_MODELS, LoadedObject, PlannerLimits

# --------------------------------------------------------------------------- computations


@dataclass(frozen=True)
class SqueezePlan:
    """A stable or pure squeeze at point contacts, scaled to the requested depth.

    Attributes
    ----------
    squeeze : Squeeze
        The unit squeeze (mechanics API).
    scale : float
        rho, m, that multiplies the unit displacement and the forces per unit depth: the
        requested depth, or 1 for a unit squeeze (depth 0).
    boundary_displacement : (b, 2) ndarray
        Displacement of the outer-boundary nodes at ``scale``, m.
    force_closure : bool
        Two-finger force closure at the scene's mu (False unless there are 2 contacts).
    """

    squeeze: Squeeze
    scale: float
    boundary_displacement: np.ndarray
    force_closure: bool


def squeeze_fields(kind: str, depth: float) -> tuple[SqueezeKind, float]:
    """A squeeze request's own fields checked: (the kind, the depth scale in m, 1 for 0).

    Checked before the object is looked up, so that a bad field is refused the same way
    whether or not its object is loaded yet.
    """
    return (choice("squeeze_type", kind, SqueezeKind.planned()),
            check_number("depth", depth, 0.0) or 1.0)


def squeeze_plan(
    loaded: LoadedObject, contacts: Sequence[int], kind: str, depth: float
) -> SqueezePlan:
    """Plan a stable or pure squeeze (:func:`~.mechanics.squeeze.plan_squeeze`).

    Parameters
    ----------
    loaded : LoadedObject
        A solid.
    contacts : sequence of int
        Contact nodes (2 or more); empty = the scene's F1, F2.
    kind : {"stable", "pure"}
    depth : float
        rho, m, >= 0; 0 = unit squeeze.
    """
    kind, scale = squeeze_fields(kind, depth)
    obj = loaded.solid()
    nodes = contact_nodes(loaded, contacts, default=loaded.finger_nodes)
    red = reduced_stiffness(obj, nodes)
    sq = plan_squeeze(obj, nodes, kind=kind, red=red)
    relative = sq.relative_depth(scale)
    if depth and len(nodes) == 2 and not relative < 1.0:
        raise invalid(
            f"depth {depth:.6g} m is a relative depth of {relative:.6g}: it must be "
            f"below 1 ({FINGERS_MEET})"
        )
    closure = False
    if len(nodes) == 2:
        mesh = obj.mesh
        i, j = (int(n) for n in nodes)
        closure = force_closure(
            mesh.nodes[i], mesh.normal_at(i), mesh.nodes[j], mesh.normal_at(j), loaded.scene.mu
        )
    return SqueezePlan(
        sq, scale, boundary_displacement(obj, red, scale * sq.displacement), closure
    )


def object_grasp_map(loaded: LoadedObject, mu: float) -> GraspMap:
    """All-pairs grasp map of a solid (:func:`~.mechanics.graspmap.grasp_map`), mu >= 0;
    cached with the object (:meth:`~.objects.LoadedObject.grasp_map`).
    """
    return loaded.grasp_map(check_number("mu", mu, 0.0))


@dataclass(frozen=True)
class ResistancePlan:
    """An optimal resistance and, when asked, the sweep over push directions.

    Attributes
    ----------
    resistance : Resistance or FrictionalResistance
        Fixed contacts (Sec. 6.1-6.2) or Algorithm 2 under friction (Sec. 6.3).
    sweep : ResistanceSweep or None
    """

    resistance: Resistance | FrictionalResistance
    sweep: ResistanceSweep | None


def resistance_plan(
    loaded: LoadedObject,
    contacts: Sequence[int],
    a: Sequence[float],
    mode: str,
    contact_model: str,
    half_width: float,
    directions: int,
    tip_radius: float,
    limits: PlannerLimits,
    checkpoint: Callable[[], None] | None = None,
) -> ResistancePlan:
    """Optimal resistance to the adversary translation ``a`` (Sec. 6).

    Parameters
    ----------
    loaded : LoadedObject
        A solid.
    contacts : sequence of int
        Initial contact nodes of F1, F2, A.
    a : (x, y, z)
        Adversary translation, m; z must be 0.
    mode : {"stable", "pure"}
    contact_model : {"point", "segment", "friction"} (:class:`ContactKind`)
    half_width : float
        Segment half width, m (>= 0; 0 = the node and its two neighbours).
    directions : int
        Push directions to sweep (0 = none; fixed contacts only).
    tip_radius : float
        Friction: A's fingertip radius, m (0 = the scene's adversary tip radius).
    limits : PlannerLimits
        Friction: the scene's squeeze step must be >= ``limits.min_step``.
    checkpoint : callable, optional
        Friction: called before every stepper substep and fixed-set solve; may raise
        :class:`Cancelled`.
    """
    loaded.solid()  # INVALID_ARGUMENT for a ring
    mode = choice("mode", mode, SqueezeKind.planned())
    contact_model = ContactKind(choice("contact_model", contact_model, CONTACT_MODELS))
    x, y, z = (check_number(f"a.{k}", v) for k, v in zip("xyz", a))
    if z != 0.0:
        raise invalid(f"a.z must be 0 (planar objects), got {z}")
    width = check_number("segment_half_width", half_width, 0.0)
    count = int(check_number("directions", directions, 0, MAX_DIRECTIONS))
    nodes = contact_nodes(loaded, contacts, count=3)
    if contact_model == ContactKind.FRICTION:
        if count:
            raise invalid("directions: the sweep needs point or segment contacts")
        return ResistancePlan(
            friction_resistance(loaded, nodes, (x, y), mode, tip_radius, limits, checkpoint),
            None,
        )
    grasp = loaded.setup.resistance_grasp(contact_model, half_width=width or None, nodes=nodes)
    sweep = sweep_directions(grasp, mode, count) if count else None
    return ResistancePlan(optimal_resistance(grasp, (x, y), mode=mode), sweep)


def friction_resistance(
    loaded: LoadedObject,
    nodes: np.ndarray,
    a: tuple[float, float],
    mode: str,
    tip_radius: float,
    limits: PlannerLimits,
    checkpoint: Callable[[], None] | None = None,
) -> FrictionalResistance:
    """Algorithm 2 after the scene's event-driven squeeze at F1, F2 (Sec. 6.3); ``checkpoint``
    is called before every stepper substep and fixed-set solve of both.
    """
    scene = loaded.scene
    radius = check_number("adversary_tip_radius", tip_radius, 0.0)
    radius = radius or (scene.adversary.tip_radius if scene.adversary is not None else 0.0)
    if not radius > 0:
        raise invalid(
            "adversary_tip_radius must be > 0 m for friction contacts (the scene "
            "gives no adversary tip radius)"
        )
    check_step(scene.squeeze.step, limits)
    loaded.solid()  # INVALID_ARGUMENT for a ring
    i, j, k = (int(n) for n in nodes)
    setup = loaded.setup
    squeeze = setup.event_squeeze(contacts=(i, j), checkpoint=checkpoint)
    return setup.frictional_resistance(squeeze, mode=mode, a=a, tip_radius=radius,
                                       adversary_node=k, checkpoint=checkpoint)


@dataclass(frozen=True)
class RingTest:
    """A ring grasp test at one placement and, when asked, the map of every placement.

    Attributes
    ----------
    grasp : RingGrasp
    depth : float
        rho at the requested relative depth, m.
    feasible : bool
        The squeeze is feasible up to that depth.
    map : RingGraspMap or None
    """

    grasp: RingGrasp
    depth: float
    feasible: bool
    map: RingGraspMap | None


def ring_grasp_test(
    loaded: LoadedObject,
    contacts: Sequence[int],
    kind: str,
    mu: float,
    strain_limit: float,
    relative_depth: float,
    all_pairs: bool,
) -> RingTest:
    """Grasp test of a ring (:func:`~.mechanics.ring_squeeze.ring_grasp`, Sec. 7).

    Parameters
    ----------
    loaded : LoadedObject
        A ring.
    contacts : sequence of int
        Ring nodes of F1, F2; empty = the scene's placements.
    kind : {"stable", "pure"}
    mu : float
        Friction coefficient, >= 0.
    strain_limit : float
        epsilon* > 0, or 0 for none.
    relative_depth : float
        Requested relative depth in [0, 1].
    all_pairs : bool
        Also map every placement (:func:`~.mechanics.ring_map.ring_grasp_map`).
    """
    ring = loaded.ring()
    kind = choice("squeeze_type", kind, SqueezeKind.planned())
    mu = check_number("mu", mu, 0.0)
    epsilon = check_number("strain_limit", strain_limit, 0.0) or None
    relative = check_number("relative_depth", relative_depth, 0.0, 1.0)
    nodes = contact_nodes(loaded, contacts, count=2, default=loaded.finger_nodes)
    grasp = ring_grasp(ring, nodes, mu, epsilon=epsilon, kind=kind)
    depth = grasp.depth_for_relative(relative)
    gmap = (
        ring_grasp_map(
            ring, mu, epsilon=epsilon, kind=kind, requested_relative_depth=relative or None
        )
        if all_pairs
        else None
    )
    return RingTest(grasp, depth, grasp.feasible_at(depth), gmap)


def event_squeeze_run(
    loaded: LoadedObject,
    contacts: Sequence[int],
    kind: str,
    depth: float,
    relative_depth: float,
    step: float,
    event_tol: float,
    limits: PlannerLimits,
    progress: Callable[[float], None] | None = None,
    checkpoint: Callable[[], None] | None = None,
) -> EventSqueeze:
    """The scene's event-driven squeeze (Algorithm 1) with the request's overrides.

    Parameters
    ----------
    loaded : LoadedObject
        A solid whose scene has rounded fingertips.
    contacts : sequence of int
        F1, F2 initial contact nodes; empty = the scene's placements.
    kind : str
        "stable", "pure", or "" for the scene's squeeze type.
    depth, relative_depth : float
        At most one > 0 (rho in m, or the fraction); both 0 = the scene's depth.
    step, event_tol : float
        Relative to the object size; 0 = the scene's. ``step`` must be >= ``limits.min_step``.
    limits : PlannerLimits
    progress : callable, optional
        Called with the completed fraction; may raise :class:`Cancelled`.
    checkpoint : callable, optional
        Called before every stepper substep and fixed-set solve; may raise
        :class:`Cancelled`.
    """
    loaded.solid()  # INVALID_ARGUMENT for a ring
    scene = loaded.scene
    kind = choice("squeeze_type", kind, SqueezeKind.planned(), scene.squeeze.type)
    depth = check_number("depth", depth, 0.0)
    relative_depth = check_number("relative_depth", relative_depth, 0.0, 1.0)
    if depth and relative_depth:
        raise invalid("give at most one of depth and relative_depth (0 = the scene's)")
    step = check_step(check_number("step", step, 0.0) or scene.squeeze.step, limits)
    event_tol = check_number("event_tol", event_tol, 0.0) or scene.squeeze.event_tol
    nodes = contact_nodes(loaded, contacts, count=2, default=loaded.finger_nodes)
    return loaded.setup.event_squeeze(
        contacts=(int(nodes[0]), int(nodes[1])),
        kind=kind,
        depth=depth or None,
        relative_depth=relative_depth or None,
        step=step,
        event_tol=event_tol,
        progress=progress,
        checkpoint=checkpoint,
    )
