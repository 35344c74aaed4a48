# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Conversion between mechanics results and ROS messages: the one place where both meet.

Every function is pure: it builds and returns a new message (or numpy arrays) and never keeps
state. Units are SI; positions, displacements, forces and directions are in the object frame
(x right, y up, the scene's coordinates), planar vectors travel as ``geometry_msgs/Vector3``
with z = 0. Arrays are flattened row-major: a list of contact displacements (m, 2) becomes
``[x0, y0, x1, y1, ...]`` and a b x b matrix its rows one after the other.

Large arrays are handed to the messages as ``array.array`` so the generated setters copy a
buffer instead of iterating over numpy scalars.
"""
from __future__ import annotations

import array
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
from geometry_msgs.msg import Vector3
from std_msgs.msg import Header

from squeeze_grasp_interfaces.action import EventSqueeze as EventSqueezeAction
from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.msg import (ContactEvent, ContactNode, ContactState,
                                          EventSqueezeData, GraspCandidate, GraspMapData,
                                          ObjectModel, TactileArray)
from squeeze_grasp_interfaces.srv import LoadObject, PlanResistance, PlanSqueeze, RingGraspTest

from .mechanics import contact_state
from .mechanics.graspmap import GraspMap
from .mechanics.resistance import FINGERS
from .mechanics.resistance_friction import FrictionalResistance
from .mechanics.squeeze_events import EventSqueeze
from .planning import (ErrorCode, LoadedObject, ResistancePlan, RingTest, SqueezePlan)

Response = TypeVar("Response")

CONTACT_MODES: dict[str, int] = {"stick": ContactNode.STICK, "slip": ContactNode.SLIP}
"""Mechanics contact mode -> ``ContactNode.mode`` constant."""


# --------------------------------------------------------------------------- building blocks


def float64_array(values: Any) -> array.array:
    """``values`` flattened (row-major) into an ``array('d')`` for a float64[] field."""
    out = array.array("d")
    out.frombytes(np.ascontiguousarray(values, dtype=np.float64).tobytes())
    return out


def int32_array(values: Any) -> array.array:
    """``values`` flattened (row-major) into an ``array('i')`` for an int32[] field."""
    out = array.array("i")
    out.frombytes(np.ascontiguousarray(values, dtype=np.int32).tobytes())
    return out


def bool_list(values: Any) -> list[bool]:
    """``values`` flattened (row-major) into the list of bools a bool[] field takes."""
    return np.asarray(values, dtype=bool).reshape(-1).tolist()


def vector3(xy: Sequence[float] | np.ndarray) -> Vector3:
    """A planar vector (x, y) as a ``Vector3`` with z = 0 (same unit)."""
    return Vector3(x=float(xy[0]), y=float(xy[1]), z=0.0)


def success(response_type: type[Response], **fields: Any) -> Response:
    """A response (or action result) with success, error_code OK and ``fields``."""
    return response_type(success=True, error_code=ErrorCode.OK, message="", **fields)


def failure(response_type: type[Response], code: ErrorCode, message: str) -> Response:
    """A response (or action result) with success false, ``code`` and the reason."""
    return response_type(success=False, error_code=int(code), message=message)


# --------------------------------------------------------------------------- objects


def object_model(loaded: LoadedObject) -> ObjectModel:
    """The mesh and material of a loaded solid as an ``ObjectModel`` (m, Pa)."""
    obj = loaded.solid()
    mesh, material = obj.mesh, obj.material
    return ObjectModel(object_id=loaded.object_id, node_xy=float64_array(mesh.nodes),
                       triangles=int32_array(mesh.triangles), boundary=int32_array(mesh.boundary),
                       youngs_modulus=material.E, poisson_ratio=material.nu,
                       thickness=material.thickness)


def load_object_response(loaded: LoadedObject, cached: bool,
                         return_model: bool) -> LoadObject.Response:
    """The ``LoadObject`` response of a loaded (or cache-hit) object.

    ``precompute_time`` is 0 for a cache hit; ``model_data`` is filled for solids when asked.
    """
    model = object_model(loaded) if return_model and loaded.model == "solid" else ObjectModel()
    return success(LoadObject.Response, object_id=loaded.object_id, model=loaded.model,
                   num_nodes=loaded.num_nodes, num_boundary_nodes=len(loaded.boundary),
                   finger_nodes=int32_array(loaded.finger_nodes), mu=loaded.scene.mu,
                   precompute_time=0.0 if cached else loaded.precompute_time,
                   model_data=model)


# --------------------------------------------------------------------------- squeezes and maps


def plan_squeeze_response(plan: SqueezePlan) -> PlanSqueeze.Response:
    """The ``PlanSqueeze`` response of a planned squeeze.

    Displacements (m) and forces (N) are the unit squeeze's times ``plan.scale`` (the requested
    depth rho, or 1 for a unit squeeze); the rigid rotation (rad) likewise. Energy per depth^2
    (J/m^2) and stiffness (N/m) do not depend on the depth.
    """
    sq, rho = plan.squeeze, plan.scale
    return success(PlanSqueeze.Response,
                   displacement=float64_array(rho * sq.displacement),
                   forces=float64_array(rho * sq.forces),
                   energy_per_unit_depth2=sq.energy_per_unit_depth2, stiffness=sq.stiffness,
                   rigid_rotation=rho * sq.rigid_rotation, inward=sq.inward,
                   force_closure=plan.force_closure, relative_depth=sq.relative_depth(rho),
                   boundary_displacement=float64_array(plan.boundary_displacement))


def grasp_candidates(placements: Sequence[tuple[Sequence[int], float]]) -> list[GraspCandidate]:
    """``GraspCandidate`` messages of (contact nodes, quality) pairs."""
    return [GraspCandidate(contacts=int32_array(nodes), quality=float(quality))
            for nodes, quality in placements]


def grasp_map_data(gmap: GraspMap, object_id: str, best_count: int,
                   full_matrices: bool) -> GraspMapData:
    """A solid's grasp map as ``GraspMapData``.

    ``best`` holds the ``best_count`` stiffest feasible placements (quality = stiffness, N/m);
    the b x b matrices (row-major, boundary order) only with ``full_matrices``.
    """
    summary = gmap.to_json()
    low, high = summary["stiffness_range"]
    data = GraspMapData(
        object_id=object_id, mu=gmap.mu, boundary=int32_array(gmap.boundary),
        pairs=summary["pairs"], inward_pairs=summary["inward_pairs"],
        force_closure_pairs=summary["force_closure_pairs"],
        feasible_pairs=summary["feasible_pairs"], stiffness_min=low, stiffness_max=high,
        best=grasp_candidates([((i, j), k) for i, j, k in gmap.best(best_count)]))
    if full_matrices:
        data.stiffness = float64_array(gmap.stiffness)
        data.inward = bool_list(gmap.inward)
        data.force_closure = bool_list(gmap.force_closure)
    return data


def grasp_map_feedback(stage: str, index: int, count: int,
                       num_nodes: int) -> GraspMapAction.Feedback:
    """Feedback of the GraspMap action when stage ``index`` of ``count`` starts."""
    return GraspMapAction.Feedback(stage=stage, stage_index=index, stage_count=count,
                                   num_nodes=num_nodes)


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
    for finger in FINGERS:
        nodes += [ContactNode(finger=finger, node=int(n), polar_angle=0.0, mode=ContactNode.STICK,
                              force=vector3(next(forces))) for n in res.segments[finger]]
    sweep = {}
    if plan.sweep is not None:
        sweep = {"sweep_angles": float64_array(plan.sweep.angles),
                 "sweep_unit_work": float64_array(plan.sweep.unit_work)}
    return success(PlanResistance.Response,
                   **resistance_fields(res.d1, res.d2, res.work, res.forces),
                   unit_work=res.unit_work, energy=res.energy, rigid_rotation=res.rigid_rotation,
                   nodes=nodes, travelled=float(np.linalg.norm(res.a)), **sweep)


def frictional_resistance_response(res: FrictionalResistance) -> PlanResistance.Response:
    """The ``PlanResistance`` response of Algorithm 2: totals, final state and events.

    Energy and rigid rotation are NaN (not defined along the frictional path); forces are the
    fingers' resultants at the end.
    """
    code = ErrorCode.OK if res.success else ErrorCode.NOT_FEASIBLE
    return PlanResistance.Response(
        success=res.success, error_code=int(code), message="" if res.success else res.reason,
        **resistance_fields(res.d1, res.d2, res.work, {f: v[1] for f, v in res.forces.items()}),
        unit_work=res.work["total"] / float(res.a @ res.a), energy=math.nan,
        rigid_rotation=math.nan, travelled=res.travelled,
        nodes=[contact_node_msg(c) for f in FINGERS for c in res.state.segment(f)],
        events=[contact_event_msg(e) for e in res.events])


def resistance_fields(d1: np.ndarray, d2: np.ndarray, work: dict,
                      forces: dict) -> dict[str, Any]:
    """Translations (m), works (J) and resultant forces (N) of a resistance as response fields."""
    return {"d1": vector3(d1), "d2": vector3(d2), "work_f1": work["F1"], "work_f2": work["F2"],
            "work_a": work["A"], "work_total": work["total"], "force_f1": vector3(forces["F1"]),
            "force_f2": vector3(forces["F2"]), "force_a": vector3(forces["A"])}


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
        fields = {"pairs": len(gmap.pairs), "feasible_pairs": int(ok.sum()),
                  "best": grasp_candidates([(b["contacts"], b["max_relative_depth"])
                                            for b in gmap.best(best_count)])}
    return success(RingGraspTest.Response, contacts=int32_array(grasp.contacts),
                   max_depth=grasp.max_depth, max_relative_depth=grasp.max_relative_depth,
                   limit=grasp.limit, feasible=test.feasible, depth=depth,
                   stiffness=grasp.stiffness, forces=float64_array(grasp.forces_at(depth)),
                   max_strain=grasp.max_strain_at(depth), **fields)


# --------------------------------------------------------------------------- contact state


def contact_node_msg(node: contact_state.ContactNode) -> ContactNode:
    """A contact node of the stepper as ``ContactNode`` (polar angle rad, force N)."""
    return ContactNode(finger=node.finger, node=int(node.node), polar_angle=float(node.theta),
                       mode=CONTACT_MODES[node.mode], force=vector3(node.force))


def contact_state_msg(state: contact_state.ContactState,
                      header: Header | None = None) -> ContactState:
    """The contact set of a stepper state as ``ContactState`` (depth rho in m)."""
    return ContactState(header=header or Header(),
                        nodes=[contact_node_msg(c) for c in state.contacts],
                        depth=float(state.depth), relative_depth=float(state.relative_depth))


def contact_event_msg(event: contact_state.Event, header: Header | None = None) -> ContactEvent:
    """A located event (types A-D of Sec. 5.3) as ``ContactEvent`` (depth rho in m)."""
    return ContactEvent(header=header or Header(), type=event.type, node=int(event.node),
                        finger=event.finger, depth=float(event.depth),
                        relative_depth=float(event.relative_depth))


def event_squeeze_data(result: EventSqueeze, object_id: str) -> EventSqueezeData:
    """An event-driven squeeze's outcome as ``EventSqueezeData``.

    Finger forces are the final forces along each finger's motion direction (N), the work is
    each finger's work on the object (J), the health numbers those of the final configuration.
    """
    health = result.health
    return EventSqueezeData(
        object_id=object_id, termination=result.termination, squeeze_type=result.kind,
        contacts=int32_array(result.contacts), target_depth=result.target_depth,
        depth=result.depth, relative_depth=result.relative_depth, mu=result.mu,
        direction_f1=vector3(result.directions["F1"]),
        direction_f2=vector3(result.directions["F2"]),
        events=[contact_event_msg(e) for e in result.events],
        final_state=contact_state_msg(result.state), energy=result.energy,
        work_f1=result.work["F1"], work_f2=result.work["F2"],
        force_f1=result.finger_force["F1"][1], force_f2=result.finger_force["F2"][1],
        max_strain=health.max_strain, max_von_mises=health.max_von_mises,
        max_displacement=health.max_displacement)


def event_squeeze_feedback(fraction: float) -> EventSqueezeAction.Feedback:
    """Feedback of the EventSqueeze action: the completed fraction of the target depth."""
    return EventSqueezeAction.Feedback(fraction=float(fraction))


# --------------------------------------------------------------------------- tactile arrays


@dataclass(frozen=True)
class TactileReadings:
    """One fingertip's tactile array as numpy arrays.

    Attributes
    ----------
    finger : str
        "F1", "F2" or "A".
    angles : (k,) ndarray
        Polar angle of each taxel on the fingertip, rad (see :mod:`.mechanics.fingertips`).
    normal : (k,) ndarray
        Normal force per taxel, N (> 0 pressing).
    tangential : (k,) ndarray
        Tangential force per taxel, N, positive counter-clockwise.
    """

    finger: str
    angles: np.ndarray
    normal: np.ndarray
    tangential: np.ndarray


def tactile_array_msg(readings: TactileReadings, header: Header | None = None) -> TactileArray:
    """``TactileArray`` of a fingertip's readings; the three arrays must have one entry per taxel.

    Raises
    ------
    ValueError
        If the arrays differ in length.
    """
    sizes = {len(readings.angles), len(readings.normal), len(readings.tangential)}
    if len(sizes) != 1:
        raise ValueError(f"tactile arrays of {readings.finger} differ in length: {sorted(sizes)}")
    return TactileArray(header=header or Header(), finger=readings.finger,
                        taxel_angles=float64_array(readings.angles),
                        normal_forces=float64_array(readings.normal),
                        tangential_forces=float64_array(readings.tangential))


def tactile_readings(msg: TactileArray) -> TactileReadings:
    """The readings of a ``TactileArray`` as numpy arrays (inverse of :func:`tactile_array_msg`)."""
    return TactileReadings(msg.finger, np.asarray(msg.taxel_angles, dtype=float),
                           np.asarray(msg.normal_forces, dtype=float),
                           np.asarray(msg.tangential_forces, dtype=float))
