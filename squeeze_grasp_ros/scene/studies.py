# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""What a front end asks of a scene, one call each, with results that have ``to_json``.

A CLI verb is: arguments -> :class:`~.setup.GraspSetup` -> one call here -> ``to_json`` ->
summary -> plot. The calls:

- :func:`point_squeezes`: the stable and pure squeezes at point contacts (Sec. 3-4);
- :func:`squeeze_run`: the event-driven squeeze (Algorithm 1), timed;
- :func:`compare_models`: that squeeze under every material model;
- :func:`resistance_study`: the optimal resistance to the adversary (Sec. 6), fixed contacts
  or Algorithm 2 after the squeeze;
- :func:`ring_placement`: a ring grasp at the scene's placement (Sec. 7);
- :func:`grasp_map_study`: every placement of a solid or a ring.

Timings (``timing`` in the JSON, seconds) are wall-clock times of the phases.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.reduced import boundary_displacement, reduced_stiffness
from squeeze_grasp_ros.mechanics.elastic.strain_measures import COMMON_STRAIN_MEASURE
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_relative_depth
from squeeze_grasp_ros.mechanics.resistance.frictional import FrictionalResistance
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    Resistance,
    ResistanceGrasp,
    ResistanceSweep,
    compare_resistances,
    optimal_resistance,
    resistance_along,
    sweep_directions,
)
from squeeze_grasp_ros.mechanics.ring.grasp_map import RingGraspMap, ring_grasp_map
from squeeze_grasp_ros.mechanics.ring.squeeze import RingGrasp, ring_grasp
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap, grasp_map
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import Squeeze, force_closure, plan_squeeze
from squeeze_grasp_ros.mechanics.vocabulary import (
    ContactKind,
    Effect,
    MaterialModel,
    ObjectModel,
    SqueezeKind,
)
from squeeze_grasp_ros.scene.setup import GraspSetup
from squeeze_grasp_ros.scene.specs import SceneError

__all__ = [
    "DEFAULT_RELATIVE_DEPTH", "GraspMapStudy", "ModelComparison", "PointSqueezes",
    "ResistanceStudy", "RingPlacement", "SqueezeRun", "compare_models", "grasp_map_study",
    "point_squeezes", "resistance_study", "ring_placement", "squeeze_run",
]

DEFAULT_RELATIVE_DEPTH = 0.05
"""Relative depth of :func:`point_squeezes` when neither the call nor the scene gives one."""


def _timed(call: Callable[[], object]) -> tuple[object, float]:
    start = time.perf_counter()
    value = call()
    return value, time.perf_counter() - start


# --------------------------------------------------------------------------- point contacts


@dataclass(frozen=True)
class PointSqueezes:
    """The unit stable and pure squeezes at the scene's two contacts, and the scene's squeeze
    at a depth (Sec. 3-4).

    Attributes
    ----------
    setup : GraspSetup
    stable, pure : Squeeze
        Unit squeezes (forces per unit depth, N/m).
    depth : float
        rho, m, of the scene's squeeze type at the requested depth.
    boundary_displacement : dict
        "stable"/"pure" -> displacement (b, 2) of the outer boundary at ``depth``, m.
    reduced_condition : float
        Condition number of the reduced compliance.
    """

    setup: GraspSetup
    stable: Squeeze
    pure: Squeeze
    depth: float
    boundary_displacement: Mapping[SqueezeKind, np.ndarray]
    reduced_condition: float

    @property
    def chosen(self) -> Squeeze:
        """The squeeze of the scene's ``squeeze.type``."""
        return self.stable if self.setup.scene.squeeze.type == SqueezeKind.STABLE else self.pure

    def to_json(self) -> dict:
        """The ``plan`` JSON (keys in the README)."""
        setup, rho = self.setup, self.depth
        mesh = setup.solid.mesh
        i, j = setup.contacts
        return {
            "contacts": [i, j],
            "contact_points": mesh.nodes[[i, j]].tolist(),
            SqueezeKind.STABLE: _unit_json(self.stable),
            SqueezeKind.PURE: _unit_json(self.pure),
            "rigid_rotation": self.stable.rigid_rotation,
            "squeeze_type": self.chosen.kind,
            "depth": rho,
            "relative_depth": self.chosen.relative_depth(rho),
            "rigid_rotation_at_depth": {
                SqueezeKind.STABLE: rho * self.stable.rigid_rotation,
                SqueezeKind.PURE: rho * self.pure.rigid_rotation,
            },
            "boundary_displacement": {k: v.tolist()
                                      for k, v in self.boundary_displacement.items()},
            "force_closure": force_closure(
                mesh.nodes[i], mesh.normal_at(i), mesh.nodes[j], mesh.normal_at(j),
                setup.scene.mu
            ),
            "mu": setup.scene.mu,
            "diagnostics": {**setup.solid.diagnostics(),
                            "reduced_condition": self.reduced_condition},
        }


def _unit_json(sq: Squeeze) -> dict:
    """JSON block of a unit squeeze."""
    return {
        "displacement": sq.displacement.tolist(),
        "forces": sq.forces.tolist(),
        "energy_per_unit_depth2": sq.energy_per_unit_depth2,
        "stiffness": sq.stiffness,
        "rigid_rotation": sq.rigid_rotation,
        "inward": sq.inward,
        "relative_depth_per_unit_depth": sq.relative_depth(1.0),
    }


def _requested_depth(requests, sq: Squeeze) -> float:
    """Depth rho (m) from the first (depth, relative depth) pair that gives one, else
    :data:`DEFAULT_RELATIVE_DEPTH`.
    """
    for depth, rel in requests:
        if depth is not None:
            require_relative_depth(sq.relative_depth(depth), depth)
            return depth
        if rel is not None:
            require_relative_depth(rel)
            return sq.depth_for_relative(rel)
    return sq.depth_for_relative(DEFAULT_RELATIVE_DEPTH)


def point_squeezes(setup: GraspSetup, *, depth: float | None = None,
                   relative_depth: float | None = None) -> PointSqueezes:
    """Both unit squeezes at the scene's contacts and the scene's squeeze at a depth: ``depth``
    (m) or ``relative_depth``, else the scene's, else :data:`DEFAULT_RELATIVE_DEPTH`.
    """
    obj, contacts = setup.solid, list(setup.contacts)
    red = reduced_stiffness(obj, contacts)
    stable = plan_squeeze(obj, contacts, kind=SqueezeKind.STABLE, red=red)
    pure = plan_squeeze(obj, contacts, kind=SqueezeKind.PURE, red=red)
    sq = setup.scene.squeeze
    chosen = stable if sq.type == SqueezeKind.STABLE else pure
    rho = _requested_depth(((depth, relative_depth), (sq.depth, sq.relative_depth)), chosen)
    disp = {k: boundary_displacement(obj, red, rho * s.displacement)
            for k, s in ((SqueezeKind.STABLE, stable), (SqueezeKind.PURE, pure))}
    return PointSqueezes(setup, stable, pure, rho, disp, red.condition)


# --------------------------------------------------------------------------- event squeezes


@dataclass(frozen=True)
class SqueezeRun:
    """An event-driven squeeze of a scene and how long it took.

    Attributes
    ----------
    setup : GraspSetup
    result : EventSqueeze
    timing : dict
        "precompute_s" (factorisation and boundary compliance), "squeeze_s", s.
    """

    setup: GraspSetup
    result: EventSqueeze
    timing: Mapping[str, float]

    def to_json(self) -> dict:
        """The ``squeeze`` JSON: the scene's name, the result (docs/events.md), the contact
        points, the mesh size and the timing.
        """
        mesh = self.setup.solid.mesh
        return {
            "scene": self.setup.scene.name,
            **self.result.to_json(),
            "contact_points": mesh.nodes[list(self.result.contacts)].tolist(),
            "mesh": {"nodes": mesh.n, "boundary": len(mesh.boundary)},
            "timing": dict(self.timing),
        }


def squeeze_run(setup: GraspSetup, *, reference: bool = False, **overrides) -> SqueezeRun:
    """Precompute (unless ``reference``) and squeeze; ``overrides`` as
    :meth:`GraspSetup.event_squeeze`.
    """
    _, t_pre = _timed(lambda: None if reference else setup.precompute())
    result, t_run = _timed(lambda: setup.event_squeeze(reference=reference, **overrides))
    return SqueezeRun(setup, result, {"precompute_s": t_pre, "squeeze_s": t_run})


@dataclass(frozen=True)
class ModelComparison:
    """The scene's squeeze under every material model.

    Attributes
    ----------
    setup : GraspSetup
    results : dict
        Material model -> EventSqueeze.
    seconds : dict
        Material model -> wall-clock time of its squeeze, s.
    """

    setup: GraspSetup
    results: Mapping[MaterialModel, EventSqueeze]
    seconds: Mapping[MaterialModel, float]

    def rows(self) -> dict:
        """Material model -> forces, energy, contact half-widths, strains and stress (with their
        measures), events, time.
        """
        return {m: _model_row(res, self.seconds[m]) for m, res in self.results.items()}

    def to_json(self) -> dict:
        """``models`` (one row each) and ``relative_difference`` from linear.

        Strains are compared like for like: ``max_principal_strain`` holds every field's
        largest principal strain in every measure, and its differences are taken measure by
        measure (``common_strain_measure`` is the one the text shows). A model's own measure
        (``max_strain``) is never compared with another model's.
        """
        rows = self.rows()
        base = rows[MaterialModel.LINEAR]

        def rel(value: float, ref: float) -> float:
            return (value - ref) / abs(ref) if ref else float("nan")

        differences = {
            m: {"force": {f: rel(r["force"][f], base["force"][f]) for f in r["force"]},
                "energy": rel(r["energy"], base["energy"]),
                "max_principal_strain": {k: rel(v, base["max_principal_strain"][k])
                                         for k, v in r["max_principal_strain"].items()},
                "contact_half_width": {f: rel(r["contact_half_width"][f],
                                              base["contact_half_width"][f])
                                       for f in r["contact_half_width"]},
                "seconds_ratio": r["seconds"] / max(base["seconds"], 1e-12)}
            for m, r in rows.items() if m != MaterialModel.LINEAR}
        return {"scene": self.setup.scene.name, "compare_models": True,
                "common_strain_measure": str(COMMON_STRAIN_MEASURE), "models": rows,
                "relative_difference": differences}


def _model_row(res: EventSqueeze, seconds: float) -> dict:
    segments = {f: [s.node for s in seg] for f, seg in res.segments.items()}
    widths = {}
    for f, seg in res.segments.items():
        thetas = [s.theta for s in seg]
        widths[f] = 0.5 * res.tip_radius[f] * (max(thetas) - min(thetas)) if thetas else 0.0
    h = res.health
    return {
        "termination": res.termination,
        "depth": res.depth,
        "relative_depth": res.relative_depth,
        "force": {f: res.finger_force[f][1] for f in res.segments},
        "energy": res.energy,
        "contact_half_width": widths,
        "contact_nodes": {f: len(nodes) for f, nodes in segments.items()},
        "max_strain": h.max_strain,
        "strain_measure": str(h.strain_measure),
        "max_principal_strain": {str(m): v for m, v in h.max_principal_strain.items()},
        "max_von_mises": h.max_von_mises,
        "stress_measure": str(h.stress_measure),
        "event_counts": res.event_counts,
        "work_minus_energy": res.diagnostics["work_minus_energy"],
        "dissipation": sum(res.dissipation.values()),
        "nonlinear": res.diagnostics.get("nonlinear"),
        "seconds": seconds,
    }


def compare_models(setup: GraspSetup, *, on_model: Callable[[str], None] | None = None,
                   **overrides) -> ModelComparison:
    """The scene's squeeze under every material model (``on_model`` is called with each model
    before its squeeze); ``overrides`` as :meth:`GraspSetup.event_squeeze`.
    """
    setup.precompute()
    results, seconds = {}, {}
    for model in MaterialModel.values():
        if on_model is not None:
            on_model(model)
        results[model], seconds[model] = _timed(
            lambda: setup.event_squeeze(material_model=model, **overrides))
    return ModelComparison(setup, results, seconds)


# --------------------------------------------------------------------------- resistance


@dataclass(frozen=True)
class ResistanceStudy:
    """The optimal resistance of F1 and F2 to the scene's adversary (Sec. 6).

    Attributes
    ----------
    setup : GraspSetup
    resistance : Resistance or FrictionalResistance
        Fixed contacts (Sec. 6.1-6.2) or Algorithm 2 under friction (Sec. 6.3).
    timing : dict
        Phase -> wall-clock seconds.
    grasp : ResistanceGrasp or None
        The fixed-contact problem (point and segment contacts).
    comparison : dict or None
        Against a resistance along a given direction (Table 4).
    sweep : ResistanceSweep or None
        W*_F over push directions.
    squeeze : EventSqueeze or None
        The squeeze Algorithm 2 starts from (friction).
    """

    setup: GraspSetup
    resistance: Resistance | FrictionalResistance
    timing: Mapping[str, float]
    grasp: ResistanceGrasp | None = None
    comparison: Mapping[str, Any] | None = None
    sweep: ResistanceSweep | None = None
    squeeze: EventSqueeze | None = None

    def to_json(self) -> dict:
        """The ``resist`` JSON (docs/resistance.md)."""
        res, obj = self.resistance, self.setup.solid
        out = {"scene": self.setup.scene.name, **res.to_json(),
               "contact_points": obj.mesh.nodes[res.contacts].tolist()}
        if self.squeeze is not None:
            sq = self.squeeze
            out["squeeze"] = {"termination": sq.termination, "depth": sq.depth,
                              "event_counts": sq.event_counts, "work": dict(sq.work)}
            out["timing"] = dict(self.timing)
            return out
        if self.comparison is not None:
            out["comparison"] = self.comparison
        if self.sweep is not None:
            out["sweep"] = self.sweep.to_json()
        out["timing"] = dict(self.timing)
        out["diagnostics"] = {**out["diagnostics"], **obj.diagnostics()}
        return out


def resistance_study(
    setup: GraspSetup,
    *,
    mode: SqueezeKind | None = None,
    contacts: ContactKind | None = None,
    directions: int | None = None,
    half_width: float | None = None,
    compare_direction: Sequence[float] | None = None,
) -> ResistanceStudy:
    """The resistance to the scene's adversary; arguments override ``adversary.mode``,
    ``.contacts``, ``.segment_half_width`` and ``.compare_direction``, and ``directions`` adds
    a sweep over push directions (fixed contacts).
    """
    adv = setup.scene.adversary
    _ = setup.adversary_node  # the scene has an adversary, off F1's and F2's nodes
    mode = mode or adv.mode
    contacts = contacts or adv.contacts
    if contacts != ContactKind.FRICTION and directions is not None and directions < 1:
        raise InvalidInputError(f"directions must be >= 1, got {directions}")
    _, t_pre = _timed(setup.precompute)
    if contacts == ContactKind.FRICTION:
        squeeze, t_squeeze = _timed(setup.event_squeeze)
        res, t_res = _timed(lambda: setup.frictional_resistance(squeeze, mode=mode))
        timing = {"precompute_s": t_pre, "squeeze_s": t_squeeze, "resistance_s": t_res}
        return ResistanceStudy(setup, res, timing, squeeze=squeeze)
    half_width = adv.segment_half_width if half_width is None else half_width
    start = time.perf_counter()
    grasp = setup.resistance_grasp(contacts, half_width=half_width)
    res = optimal_resistance(grasp, adv.a, mode=mode)
    timing = {"precompute_s": t_pre, "resistance_s": time.perf_counter() - start}
    direction = compare_direction or adv.compare_direction
    comparison = None
    if direction is not None and res.success:
        comparison = compare_resistances(res, resistance_along(grasp, adv.a, direction, mode))
    sweep = None
    if directions:
        sweep, timing["sweep_s"] = _timed(lambda: sweep_directions(grasp, mode, directions))
    return ResistanceStudy(setup, res, timing, grasp=grasp, comparison=comparison, sweep=sweep)


# --------------------------------------------------------------------------- rings and maps


def _strain_limit(setup: GraspSetup) -> float | None:
    """epsilon* of the scene, None without the strain_limit effect."""
    scene = setup.scene
    return scene.strain_limit.epsilon if scene.has(Effect.STRAIN_LIMIT) else None


@dataclass(frozen=True)
class RingPlacement:
    """A ring grasp at the scene's placement, tested at a requested depth (Sec. 7).

    Attributes
    ----------
    grasp : RingGrasp
    depth : float
        The requested depth rho, m.
    """

    grasp: RingGrasp
    depth: float

    def to_json(self) -> dict:
        """The ring model's name and :meth:`RingGrasp.to_json` at the requested depth."""
        return {"model": ObjectModel.RING, **self.grasp.to_json(self.depth)}


def ring_placement(setup: GraspSetup, *, depth: float | None = None,
                   relative_depth: float | None = None) -> RingPlacement:
    """The ring grasp at the scene's contacts: its maximum depth and limit, tested at ``depth``
    (m) or ``relative_depth``, else the scene's.
    """
    if depth is None and relative_depth is None:
        depth, relative_depth = setup.scene.squeeze.depth, setup.scene.squeeze.relative_depth
    if depth is None and relative_depth is None:
        raise SceneError(
            "give squeeze.depth or squeeze.relative_depth (or --depth/--relative-depth)"
        )
    scene = setup.scene
    grasp = ring_grasp(setup.ring, setup.contacts, scene.mu, epsilon=_strain_limit(setup),
                       kind=scene.squeeze.type)
    if depth is not None:
        require_relative_depth(grasp.relative_depth(depth), depth)
        rho = depth
    else:
        require_relative_depth(relative_depth)
        rho = grasp.depth_for_relative(relative_depth)
    return RingPlacement(grasp, rho)


@dataclass(frozen=True)
class GraspMapStudy:
    """Every placement pair of the scene's object: a solid's point-contact grasp map or a
    ring's feasibility map (Sec. 7).

    Attributes
    ----------
    setup : GraspSetup
    map : GraspMap or RingGraspMap
    """

    setup: GraspSetup
    map: GraspMap | RingGraspMap

    def to_json(self, *, best: int = 10, pairs: bool = False) -> dict:
        """The ``graspmap`` JSON: ``best`` placements of a ring map, or a solid map with
        (``pairs``) or without its full matrices.
        """
        if isinstance(self.map, RingGraspMap):
            return {"model": ObjectModel.RING, **self.map.to_json(best=best)}
        return {
            **self.map.to_json(pairs=pairs),
            "model": ObjectModel.SOLID,
            "note": "point-contact stiffness is mesh dependent: compare placements on one mesh",
        }


def grasp_map_study(setup: GraspSetup, *, relative_depth: float | None = None) -> GraspMapStudy:
    """The map of every placement: a ring's at ``relative_depth`` (default the scene's), or a
    solid's at the scene's mu.
    """
    scene = setup.scene
    if setup.is_ring:
        requested = scene.squeeze.relative_depth if relative_depth is None else relative_depth
        return GraspMapStudy(setup, ring_grasp_map(
            setup.ring, scene.mu, epsilon=_strain_limit(setup), kind=scene.squeeze.type,
            requested_relative_depth=requested))
    return GraspMapStudy(setup, grasp_map(setup.solid, scene.mu))
