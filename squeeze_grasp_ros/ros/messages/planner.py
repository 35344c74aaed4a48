# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner's responses and feedback: objects, squeezes, grasp maps, resistance, rings."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, TypeVar

import numpy as np

from squeeze_grasp_interfaces.action import EventSqueeze as EventSqueezeAction
from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.msg import (
    ContactNode,
    EventSqueezeData,
    GraspCandidate,
    GraspMapData,
    ObjectModel,
)
from squeeze_grasp_interfaces.srv import LoadObject, PlanResistance, PlanSqueeze, RingGraspTest
from squeeze_grasp_ros.control.force_watch import squeeze_forces
from squeeze_grasp_ros.mechanics import vocabulary
from squeeze_grasp_ros.mechanics.resistance.frictional import FrictionalResistance
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap
from squeeze_grasp_ros.mechanics.vocabulary import Finger
from squeeze_grasp_ros.planning import (
    ErrorCode,
    LoadedObject,
    ResistancePlan,
    RingTest,
    SqueezePlan,
)
from squeeze_grasp_ros.ros.messages.common import (
    bool_list,
    failure,
    float64_array,
    int32_array,
    success,
    vector3,
)
from squeeze_grasp_ros.ros.messages.contacts import (
    contact_event_msg,
    contact_node_msg,
    contact_state_msg,
)

Response = TypeVar("Response")


# --------------------------------------------------------------------------- objects


def object_model(loaded: LoadedObject) -> ObjectModel:
    """The mesh and material of a loaded solid as an ``ObjectModel`` (m, Pa)."""
    obj = loaded.solid()
    mesh, material = obj.mesh, obj.material
    return ObjectModel(
        object_id=loaded.object_id,
        node_xy=float64_array(mesh.nodes),
        triangles=int32_array(mesh.triangles),
        boundary=int32_array(mesh.boundary),
        youngs_modulus=material.E,
        poisson_ratio=material.nu,
        thickness=material.thickness,
    )


def load_object_response(
    loaded: LoadedObject, cached: bool, return_model: bool
) -> LoadObject.Response:
    """The ``LoadObject`` response of a loaded (or cache-hit) object.

    ``precompute_time`` is 0 for a cache hit; ``model_data`` is filled for solids when asked.
    """
    solid = loaded.model == vocabulary.ObjectModel.SOLID
    model = object_model(loaded) if return_model and solid else ObjectModel()
    return success(
        LoadObject.Response,
        object_id=loaded.object_id,
        object_digest=loaded.digest,
        model=loaded.model,
        num_nodes=loaded.num_nodes,
        num_boundary_nodes=len(loaded.boundary),
        finger_nodes=int32_array(loaded.finger_nodes),
        mu=loaded.scene.mu,
        precompute_time=0.0 if cached else loaded.precompute_time,
        model_data=model,
    )


# --------------------------------------------------------------------------- squeezes and maps


def plan_squeeze_response(plan: SqueezePlan) -> PlanSqueeze.Response:
    """The ``PlanSqueeze`` response of a planned squeeze.

    Displacements (m) and forces (N) are the unit squeeze's times ``plan.scale`` (the requested
    depth rho, or 1 for a unit squeeze); the rigid rotation (rad) likewise. Energy per depth^2
    (J/m^2) and stiffness (N/m) do not depend on the depth.
    """
    sq, rho = plan.squeeze, plan.scale
    return success(
        PlanSqueeze.Response,
        displacement=float64_array(rho * sq.displacement),
        forces=float64_array(rho * sq.forces),
        energy_per_unit_depth2=sq.energy_per_unit_depth2,
        stiffness=sq.stiffness,
        rigid_rotation=rho * sq.rigid_rotation,
        inward=sq.inward,
        force_closure=plan.force_closure,
        relative_depth=sq.relative_depth(rho),
        boundary_displacement=float64_array(plan.boundary_displacement),
    )


def grasp_candidates(placements: Sequence[tuple[Sequence[int], float]]) -> list[GraspCandidate]:
    """``GraspCandidate`` messages of (contact nodes, quality) pairs."""
    return [
        GraspCandidate(contacts=int32_array(nodes), quality=float(quality))
        for nodes, quality in placements
    ]


def grasp_map_data(
    gmap: GraspMap, object_id: str, best_count: int, full_matrices: bool, *, digest: str = ""
) -> GraspMapData:
    """A solid's grasp map as ``GraspMapData`` (``digest``: the object's ``object_digest``).

    ``best`` holds the ``best_count`` stiffest feasible placements (quality = stiffness, N/m);
    the b x b matrices (row-major, boundary order) only with ``full_matrices``.
    """
    summary = gmap.to_json()
    low, high = summary["stiffness_range"]
    data = GraspMapData(
        object_id=object_id,
        object_digest=digest,
        mu=gmap.mu,
        boundary=int32_array(gmap.boundary),
        pairs=summary["pairs"],
        inward_pairs=summary["inward_pairs"],
        force_closure_pairs=summary["force_closure_pairs"],
        feasible_pairs=summary["feasible_pairs"],
        stiffness_min=low,
        stiffness_max=high,
        best=grasp_candidates([((i, j), k) for i, j, k in gmap.best(best_count)]),
    )
    if full_matrices:
        data.stiffness = float64_array(gmap.stiffness)
        data.inward = bool_list(gmap.inward)
        data.force_closure = bool_list(gmap.force_closure)
    return data


def grasp_map_feedback(
    stage: str, index: int, count: int, num_nodes: int
) -> GraspMapAction.Feedback:
    """Feedback of the GraspMap action when stage ``index`` of ``count`` starts."""
    return GraspMapAction.Feedback(
        stage=stage, stage_index=index, stage_count=count, num_nodes=num_nodes
    )


# --------------------------------------------------------------------------- resistance


def plan_resistance_response(plan: ResistancePlan) -> PlanResistance.Response:
    """The ``PlanResistance`` response of an optimal resistance (and its sweep).

    A fixed-contact resistance that does not exist (e.g. a pure resistance to an adversary
    translation outside col(Q)) is a NOT_FEASIBLE failure with the mechanics' reason; a
    frictional one during which F1 or F2 slips is NOT_FEASIBLE with the fields filled.
    """
    res = plan.resistance
    if isinstance(res, FrictionalResistance):
        return frictional_resistance_response(res)
    if not res.success:
        return failure(PlanResistance.Response, ErrorCode.NOT_FEASIBLE, res.reason)
    nodes = []
    forces = iter(res.node_forces)
    for finger in tuple(Finger):
        nodes += [
            ContactNode(
                finger=finger,
                node=int(n),
                polar_angle=0.0,
                mode=ContactNode.STICK,
                force=vector3(next(forces)),
            )
            for n in res.segments[finger]
        ]
    sweep = {}
    if plan.sweep is not None:
        sweep = {
            "sweep_angles": float64_array(plan.sweep.angles),
            "sweep_unit_work": float64_array(plan.sweep.unit_work),
        }
    return success(
        PlanResistance.Response,
        **resistance_fields(res.d1, res.d2, res.work, res.forces),
        unit_work=res.unit_work,
        energy=res.energy,
        rigid_rotation=res.rigid_rotation,
        nodes=nodes,
        travelled=float(np.linalg.norm(res.a)),
        **sweep,
    )


def frictional_resistance_response(res: FrictionalResistance) -> PlanResistance.Response:
    """The ``PlanResistance`` response of Algorithm 2: totals, final state and events.

    Energy and rigid rotation are NaN (not defined along the frictional path); forces are the
    fingers' resultants at the end.
    """
    code = ErrorCode.OK if res.success else ErrorCode.NOT_FEASIBLE
    return PlanResistance.Response(
        success=res.success,
        error_code=int(code),
        message="" if res.success else res.reason,
        **resistance_fields(res.d1, res.d2, res.work, {f: v[1] for f, v in res.forces.items()}),
        unit_work=res.work["total"] / float(res.a @ res.a),
        energy=math.nan,
        rigid_rotation=math.nan,
        travelled=res.travelled,
        nodes=[contact_node_msg(c) for f in tuple(Finger) for c in res.state.segment(f)],
        events=[contact_event_msg(e) for e in res.events],
    )


def resistance_fields(d1: np.ndarray, d2: np.ndarray, work: dict, forces: dict) -> dict[str, Any]:
    """Translations (m), works (J) and resultant forces (N) of a resistance as response fields."""
    return {
        "d1": vector3(d1),
        "d2": vector3(d2),
        "work_f1": work[Finger.F1],
        "work_f2": work[Finger.F2],
        "work_a": work[Finger.A],
        "work_total": work["total"],
        "force_f1": vector3(forces[Finger.F1]),
        "force_f2": vector3(forces[Finger.F2]),
        "force_a": vector3(forces[Finger.A]),
    }


# --------------------------------------------------------------------------- rings


def ring_grasp_test_response(test: RingTest, best_count: int) -> RingGraspTest.Response:
    """The ``RingGraspTest`` response of a ring grasp test (and its all-pairs map).

    Forces (N) and the largest fibre strain are those at the requested depth; ``best`` ranks
    placements by their largest feasible relative depth (the quality).
    """
    grasp, depth = test.grasp, test.depth
    fields: dict[str, Any] = {}
    if test.map is not None:
        gmap = test.map
        ok = gmap.succeeds(gmap.requested_relative_depth or 0.0)
        fields = {
            "pairs": len(gmap.pairs),
            "feasible_pairs": int(ok.sum()),
            "best": grasp_candidates(
                [(b["contacts"], b["max_relative_depth"]) for b in gmap.best(best_count)]
            ),
        }
    return success(
        RingGraspTest.Response,
        contacts=int32_array(grasp.contacts),
        max_depth=grasp.max_depth,
        max_relative_depth=grasp.max_relative_depth,
        limit=grasp.limit.value,
        feasible=test.feasible,
        depth=depth,
        stiffness=grasp.stiffness,
        forces=float64_array(grasp.forces_at(depth)),
        max_strain=grasp.max_strain_at(depth),
        **fields,
    )


def event_squeeze_data(result: EventSqueeze, object_id: str, *,
                       digest: str = "") -> EventSqueezeData:
    """An event-driven squeeze's outcome as ``EventSqueezeData`` (``digest``: the object's
    ``object_digest``).

    Finger forces are the final forces along each finger's motion direction (N), the work is
    each finger's work on the object (J), the health numbers those of the final configuration,
    with the measures of its strain and stress.
    """
    health = result.health
    curve = squeeze_forces(result)
    return EventSqueezeData(
        object_id=object_id,
        object_digest=digest,
        termination=result.termination,
        squeeze_type=result.kind,
        contacts=int32_array(result.contacts),
        target_depth=result.target_depth,
        depth=result.depth,
        relative_depth=result.relative_depth,
        mu=result.mu,
        direction_f1=vector3(result.directions[Finger.F1]),
        direction_f2=vector3(result.directions[Finger.F2]),
        events=[contact_event_msg(e) for e in result.events],
        final_state=contact_state_msg(result.state),
        energy=result.energy,
        work_f1=result.work[Finger.F1],
        work_f2=result.work[Finger.F2],
        force_f1=result.finger_force[Finger.F1][1],
        force_f2=result.finger_force[Finger.F2][1],
        material_model=str(result.material_model),
        max_strain=health.max_strain,
        strain_measure=str(health.strain_measure),
        max_von_mises=health.max_von_mises,
        stress_measure=str(health.stress_measure),
        max_displacement=health.max_displacement,
        curve_depths=float64_array(curve.depths if curve else []),
        curve_force_f1=float64_array(curve.forces[Finger.F1] if curve else []),
        curve_force_f2=float64_array(curve.forces[Finger.F2] if curve else []),
    )


def event_squeeze_feedback(fraction: float) -> EventSqueezeAction.Feedback:
    """Feedback of the EventSqueeze action: the completed fraction of the target depth."""
    return EventSqueezeAction.Feedback(fraction=float(fraction))
