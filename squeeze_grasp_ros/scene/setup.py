# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Where a scene becomes mechanics: :class:`GraspSetup`.

scene -> object (mesh and material, or ring model) -> initial contact nodes -> finger motion
(squeeze directions and relative depth per depth) -> contact model -> the squeeze, and after
it the adversary's resistance (Algorithm 2). Every front end builds its mechanics here: the
CLI verbs, the planner, the simulated world, the launch file, the sweeps and the benchmarks
(``test/test_layers.py`` checks that nothing outside the ``scene`` package calls the
builders of :mod:`.build`).

>>> from squeeze_grasp_ros.api import GraspSetup, load_scene, scene_file
>>> setup = GraspSetup.build(load_scene(scene_file("foam_square")))
>>> setup.model, setup.contacts
('solid', (114, 49))
>>> result = setup.event_squeeze()
>>> print(result.termination, f"{result.relative_depth:.2f}")
depth_reached 0.12
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.mesh import MAX_MESH_NODES
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline
from squeeze_grasp_ros.mechanics.resistance.frictional import (
    FrictionalResistance,
    add_adversary,
    frictional_resistance,
)
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    ResistanceGrasp,
    contact_segments,
    resistance_grasp,
)
from squeeze_grasp_ros.mechanics.ring.model import RingModel
from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    ContactModel,
    SolveOptions,
    TerminationLimits,
)
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze, event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.fingertips import Fingertip, place_fingertip
from squeeze_grasp_ros.mechanics.squeeze.nonlinear_model import contact_model
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import FingerMotion, finger_motion
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipShape
from squeeze_grasp_ros.mechanics.vocabulary import (
    SQUEEZING_FINGERS,
    ContactKind,
    Effect,
    Finger,
    MaterialModel,
    ObjectModel,
    SqueezeKind,
    StrainCriterion,
)
from squeeze_grasp_ros.scene.build import (
    build_mesh,
    build_ring,
    finger_nodes,
    placement_node,
    scene_material,
)
from squeeze_grasp_ros.scene.checks import check_material
from squeeze_grasp_ros.scene.specs import Scene, SceneError

__all__ = ["RING_STAGES", "SOLID_STAGES", "GraspSetup", "Progress", "check_adversary_node",
           "check_event_squeeze", "event_squeeze_scene", "scene_limits"]

SOLID_STAGES: tuple[str, ...] = ("mesh", "stiffness", "factorisation", "boundary compliance")
"""The stages of building a solid, in order (:meth:`GraspSetup.precompute` reports 1-3)."""
RING_STAGES: tuple[str, ...] = ("ring model", "compliance")
"""The stages of building a ring model, in order (:meth:`GraspSetup.precompute` reports 1)."""

Progress = Callable[[str, int, int, int], None]
"""Called as ``progress(stage, index, count, num_nodes)`` when a stage starts; may raise to
stop the computation."""


def scene_limits(scene: Scene) -> TerminationLimits:
    """Strain limit (effect ``strain_limit``) and pickup weight (effect ``pickup``: the weight
    the plan takes, ``pickup.planned_weight`` when given) of a scene.
    """
    strain = scene.strain_limit if scene.has(Effect.STRAIN_LIMIT) else None
    return TerminationLimits(
        strain.epsilon if strain else None,
        strain.criterion if strain else StrainCriterion.PRINCIPAL,
        scene.pickup.believed_weight if scene.has(Effect.PICKUP) else None,
    )


def check_adversary_node(contacts: Sequence[int], node: int,
                         where: str = "adversary.placement") -> int:
    """``node`` if it is not the initial contact node of F1 or F2; every route to the
    adversary (scenes, the planner's requests, sweeps) checks it here.

    Raises
    ------
    SceneError
        If the adversary would touch F1's or F2's node (naming ``where``).
    """
    if int(node) in (int(c) for c in contacts):
        raise SceneError(f"{where} is on the same boundary node as F1 or F2")
    return int(node)


def check_event_squeeze(scene: Scene) -> Scene:
    """``scene`` if the event-driven squeeze can run it: a solid with rounded fingertips (point
    fingers have no polar angle).

    Raises
    ------
    SceneError
        Naming ``object.model`` or the finger's ``tip_radius``.
    """
    if scene.object.model != ObjectModel.SOLID:
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
    return scene


@dataclass(frozen=True)
class GraspSetup:
    """A scene made mechanics: its object, the fingers' initial contact nodes and everything
    derived from them. Build it with :meth:`build`; derived parts are computed once, when
    first asked for.

    Attributes
    ----------
    scene : Scene
        The validated scene.
    body : ElasticObject or RingModel
        The meshed solid (``object.model: solid``) or the curved-beam ring model.
    """

    scene: Scene
    body: ElasticObject | RingModel

    @classmethod
    def build(cls, scene: Scene, *, route: str = "factorized", outline: Outline | None = None,
              max_nodes: int = MAX_MESH_NODES) -> GraspSetup:
        """Mesh (or build the ring model of) ``scene`` and place its fingers.

        Parameters
        ----------
        scene : Scene
        route : {"factorized", "spectral"}
            Contact-compliance route of a solid (rings ignore it).
        outline : Outline, optional
            The object's outline when it was read already (a sweep reads outline files on
            its client); default built from ``object.shape``.
        max_nodes : int
            Largest mesh, nodes: a larger one is refused before meshing (the planner passes
            its limit).

        Raises
        ------
        SceneError
            For a shape, mesh or placement the mechanics refuses (naming the key).
        """
        if scene.object.model == ObjectModel.RING:
            return cls(scene, build_ring(scene))
        mesh = build_mesh(scene, outline=outline, max_nodes=max_nodes)
        return cls(scene, ElasticObject(mesh, scene_material(scene), route))

    def on(self, scene: Scene) -> GraspSetup:
        """``scene`` on this setup's body: a scene that differs from this one only in what is
        not the object (fingers, squeeze, friction, limits), without building the body again.
        """
        if scene.object != self.scene.object:
            raise SceneError("object: GraspSetup.on needs a scene of the same object")
        return GraspSetup(scene, self.body)

    @cached_property
    def contacts(self) -> tuple[int, int]:
        """Initial contact nodes of F1 and F2 (mesh nodes of the outer boundary, or ring
        nodes).

        Raises
        ------
        SceneError
            For a placement off the boundary, or both fingers on one node.
        """
        return finger_nodes(self.scene, self.body if self.is_ring else self.body.mesh)

    # ----------------------------------------------------------------- the body
    @property
    def model(self) -> ObjectModel:
        """Mechanical model of the object: solid or ring."""
        return self.scene.object.model

    @property
    def is_ring(self) -> bool:
        """True for the curved-beam ring model (Sec. 7)."""
        return self.model == ObjectModel.RING

    @property
    def solid(self) -> ElasticObject:
        """The meshed solid; SceneError for a ring."""
        if not isinstance(self.body, ElasticObject):
            raise SceneError("object.model is ring: the curved-beam model of Sec. 7 has no "
                             "solid mesh; this needs object.model: solid (rings: "
                             "`squeeze-grasp ring` and `graspmap`)")
        return self.body

    @property
    def ring(self) -> RingModel:
        """The ring model; SceneError for a solid."""
        if not isinstance(self.body, RingModel):
            raise SceneError("object.model is solid: this needs a ring (object.model: ring)")
        return self.body

    @property
    def num_nodes(self) -> int:
        """Mesh nodes (solid) or ring nodes."""
        return int(self.body.n) if self.is_ring else int(self.body.mesh.n)

    @property
    def boundary(self) -> np.ndarray:
        """Nodes a finger can touch: the outer boundary loop (solid) or every ring node."""
        return self.body.boundary if self.is_ring else self.body.mesh.boundary

    def precompute(self, progress: Progress | None = None) -> GraspSetup:
        """Factorise the solid and compute its boundary compliance (or the ring's compliance),
        reporting the stages after the first of :data:`SOLID_STAGES` / :data:`RING_STAGES`.
        """
        report = progress or (lambda *args: None)
        n = self.num_nodes
        if self.is_ring:
            report(RING_STAGES[1], 1, len(RING_STAGES), n)
            self.body.precompute()
            return self
        report(SOLID_STAGES[1], 1, len(SOLID_STAGES), n)
        _ = self.body.stiffness
        report(SOLID_STAGES[2], 2, len(SOLID_STAGES), n)
        _ = self.body.solver
        report(SOLID_STAGES[3], 3, len(SOLID_STAGES), n)
        self.body.precompute()
        return self

    # ----------------------------------------------------------------- the squeeze
    @property
    def limits(self) -> TerminationLimits:
        """The termination limits the scene declares (:func:`scene_limits`)."""
        return scene_limits(self.scene)

    @property
    def tip_radii(self) -> dict[Finger, float]:
        """Finger (F1, F2) -> fingertip radius (a pad's edge radius), m."""
        return {n: self.scene.fingers[n].tip_radius for n in SQUEEZING_FINGERS}

    @property
    def tip_shapes(self) -> dict[Finger, TipShape]:
        """Finger (F1, F2) -> fingertip shape (``fingers.<F>.tip``, else a circle of
        ``tip_radius``).
        """
        return {n: self.scene.fingers[n].tip_shape() for n in SQUEEZING_FINGERS}

    @property
    def given_directions(self) -> dict[Finger, tuple[float, float]] | None:
        """The scene's ``fingers.<F>.direction`` (both or none), else None."""
        if self.scene.fingers[Finger.F1].direction is None:
            return None
        return {n: self.scene.fingers[n].direction for n in SQUEEZING_FINGERS}

    def fingertips(self) -> list[Fingertip]:
        """F1's and F2's fingertips touching their contact nodes: circles on the outward
        normals, pads facing the inward normals and moved along them until they touch
        (:func:`~squeeze_grasp_ros.mechanics.squeeze.fingertips.place_fingertip`).
        """
        mesh, shapes = self.solid.mesh, self.tip_shapes
        return [place_fingertip(mesh, name, node, shapes[name])
                for name, node in zip(SQUEEZING_FINGERS, self.contacts)]

    @cached_property
    def motion(self) -> FingerMotion:
        """The fingers' translations per unit depth and the relative depth per depth of the
        scene's squeeze (its type, or its given directions) at :attr:`contacts`.
        """
        return finger_motion(self.solid, self.contacts, kind=self.scene.squeeze.type,
                             directions=self.given_directions)

    def _material_model(self, material_model: MaterialModel | str | None) -> MaterialModel | str:
        """``material_model``, default the scene's; another known model than the scene's is
        held to its Poisson's ratio range with the scene's field named (an unknown one is
        refused by name where it is used).
        """
        if material_model is None:
            return self.scene.object.material.model
        if material_model in MaterialModel.values():
            check_material(replace(self.scene.object.material,
                                   model=MaterialModel(material_model)))
        return material_model

    def contact_model(self, *, terminations: bool = True,
                      material_model: MaterialModel | str | None = None) -> ContactModel:
        """The contact model of the object, the scene's friction and material model.

        Parameters
        ----------
        terminations : bool
            Check the scene's termination limits (strain, pickup); Algorithm 2 checks none.
        material_model : MaterialModel or str, optional
            Default the scene's ``object.material.model``.
        """
        limits = self.limits if terminations else TerminationLimits()
        return contact_model(self._material_model(material_model), self.solid, self.scene.mu,
                             limits, max_events_per_depth=self.scene.squeeze.max_events_per_depth)

    def event_squeeze(
        self,
        *,
        contacts: tuple[int, int] | None = None,
        kind: SqueezeKind | None = None,
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
        """The scene's squeeze with rounded fingertips (Algorithm 1); arguments override the
        scene's values.

        Parameters
        ----------
        contacts : (int, int), optional
            Initial contact nodes of F1 and F2; default :attr:`contacts`.
        kind : {"stable", "pure"}, optional
            Default the scene's ``squeeze.type`` (given directions win over either).
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
            Called before every substep and every fixed-set solve; may raise to abandon the
            squeeze (a cancellation).
        options : SolveOptions, optional
            Switches of the large-deformation savings (see
            :func:`~squeeze_grasp_ros.mechanics.squeeze.events.event_squeeze`).

        Raises
        ------
        SceneError
            If the object is not a solid, a fingertip radius is 0 (point fingers have no polar
            angle) or no depth is given.
        InvalidInputError
            For a bad override (both depths, an unknown kind or model, contacts that are not
            two outer-boundary nodes), as
            :func:`~squeeze_grasp_ros.mechanics.squeeze.events.event_squeeze` raises it.
        """
        scene = check_event_squeeze(self.scene)
        sq = scene.squeeze
        if depth is None and relative_depth is None:
            depth, relative_depth = sq.depth, sq.relative_depth
        if depth is None and relative_depth is None:
            raise SceneError(
                "no squeeze depth: give squeeze.depth or squeeze.relative_depth in the "
                "scene, or --depth / --relative-depth"
            )
        return event_squeeze(
            self.solid,
            self.contacts if contacts is None else contacts,
            self.tip_shapes,
            scene.mu,
            kind=sq.type if kind is None else kind,
            depth=depth,
            relative_depth=relative_depth,
            limits=self.limits,
            step=sq.step if step is None else step,
            event_tol=sq.event_tol if event_tol is None else event_tol,
            reference=reference,
            max_events_per_depth=sq.max_events_per_depth,
            directions=self.given_directions,
            progress=progress,
            material_model=self._material_model(material_model),
            checkpoint=checkpoint,
            options=options,
        )

    # ----------------------------------------------------------------- the adversary
    @cached_property
    def adversary_node(self) -> int:
        """The adversary's initial contact node (distinct from F1's and F2's).

        Raises
        ------
        SceneError
            If the scene has no adversary or A would touch F1's or F2's node.
        """
        adv = self.scene.adversary
        if adv is None:
            raise SceneError(
                "the scene has no adversary section (declare effect 'adversary'); "
                "see config/scenes/resist_fig9.yaml"
            )
        node = placement_node(self.solid.mesh, adv.placement, str(Effect.ADVERSARY))
        return check_adversary_node(self.contacts, node)

    def adversary_tip(self) -> Fingertip:
        """A's fingertip touching :attr:`adversary_node` of the undeformed object."""
        return place_fingertip(self.solid.mesh, Finger.A, self.adversary_node,
                               self.scene.adversary.tip_radius)

    def resistance_grasp(self, contacts: ContactKind, *, half_width: float | None = None,
                         nodes: Sequence[int] | None = None) -> ResistanceGrasp:
        """The fixed-contact resistance problem (Sec. 6.1-6.2) of F1, F2 and A.

        Parameters
        ----------
        contacts : ContactKind
            Each finger on its node, or on the boundary nodes within ``half_width`` of it.
        half_width : float, optional
            Segment arc length on each side of a node, m (default: the node and its two
            neighbours).
        nodes : (int, int, int), optional
            F1, F2 and A nodes; default :attr:`contacts` and :attr:`adversary_node`.
        """
        if nodes is None:
            nodes = [*self.contacts, self.adversary_node]
        else:
            nodes = [int(n) for n in nodes]
            check_adversary_node(nodes[:2], nodes[2])
        if contacts == ContactKind.POINT:
            sets = [[n] for n in nodes]
        else:
            sets = contact_segments(self.solid.mesh, nodes, half_width)
        return resistance_grasp(self.solid, dict(zip(tuple(Finger), sets)))

    def frictional_resistance(
        self,
        squeeze: EventSqueeze,
        *,
        mode: SqueezeKind | None = None,
        a: Sequence[float] | None = None,
        tip_radius: float | None = None,
        adversary_node: int | None = None,
        checkpoint: Callable[[], None] | None = None,
    ) -> FrictionalResistance:
        """Algorithm 2 after ``squeeze`` (Sec. 6.3): A touches the squeezed object and pushes,
        F1 and F2 resist with frictional segment contacts.

        Parameters
        ----------
        squeeze : EventSqueeze
            The squeeze of F1 and F2 (e.g. :meth:`event_squeeze`).
        mode : {"stable", "pure"}, optional
            Resistance type; default the scene's ``adversary.mode``.
        a : (x, y), optional
            A's translation, m; default the scene's ``adversary.a``.
        tip_radius : float, optional
            A's fingertip radius, m; default the scene's.
        adversary_node : int, optional
            A's contact node; default :attr:`adversary_node`.
        checkpoint : callable, optional
            Called before every substep and every fixed-set solve; may raise to abandon the
            resistance.
        """
        if None in (mode, a, tip_radius, adversary_node):
            adv = self.scene.adversary
            if adv is None:
                _ = self.adversary_node  # raises: the scene has no adversary section
            mode = adv.mode if mode is None else mode
            a = adv.a if a is None else a
            tip_radius = adv.tip_radius if tip_radius is None else tip_radius
        if adversary_node is None:
            node = self.adversary_node
        else:
            node = check_adversary_node(squeeze.contacts, adversary_node)
        model = self.contact_model(terminations=False)
        state = add_adversary(squeeze.state, model, squeeze.displacement, node, tip_radius)
        return frictional_resistance(model, state, a, mode=mode, step=squeeze.step,
                                     event_tol=squeeze.event_tol,
                                     contacts=[*squeeze.contacts, node], checkpoint=checkpoint)


def event_squeeze_scene(scene: Scene, obj: ElasticObject | None = None,
                        contacts: tuple[int, int] | None = None, **overrides) -> EventSqueeze:
    """The scene's event-driven squeeze in one call: :meth:`GraspSetup.event_squeeze` of
    ``scene`` on ``obj`` (default: built from the scene) from ``contacts`` (default: the
    scene's placements); ``overrides`` as there.

    >>> from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
    >>> scene = load_scene(scene_file("disk"))
    >>> print(event_squeeze_scene(scene, scene_solid(scene), relative_depth=0.02).termination)
    depth_reached
    """
    check_event_squeeze(scene)
    setup = GraspSetup.build(scene) if obj is None else GraspSetup(scene, obj)
    return setup.event_squeeze(contacts=contacts, **overrides)
