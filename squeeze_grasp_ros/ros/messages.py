# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Conversion between mechanics results and ROS messages: the one place where both meet.

Every function is pure: it builds and returns a new message (or numpy arrays) and never keeps
state, except the ``fill_*`` functions of the lockstep loop, which refill a node's own
per-tick message in place (rclpy serialises a message when it is published, so a publisher can
reuse one object; building a fresh ``PoseStamped`` costs about 15 times as much).

Units are SI; positions, displacements, forces and directions are in the object frame
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
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, PoseStamped, Vector3, WrenchStamped
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Header
from visualization_msgs.msg import Marker, MarkerArray

from squeeze_grasp_interfaces.action import EventSqueeze as EventSqueezeAction
from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.action import GraspMap as GraspMapAction
from squeeze_grasp_interfaces.msg import (
    Alarm,
    ContactEvent,
    ContactEventArray,
    ContactNode,
    ContactState,
    EventSqueezeData,
    ExecutorStatus,
    GraspCandidate,
    GraspMapData,
    MonitorStatus,
    ObjectModel,
    SimState,
    TactileArray,
    Tick,
)
from squeeze_grasp_interfaces.srv import LoadObject, PlanResistance, PlanSqueeze, RingGraspTest

from squeeze_grasp_ros.control.motion import Command, GraspGoal, GraspProgram, Observation
from squeeze_grasp_ros.control.tracker import (
    PredictedEvent,
    TrackedAlarm,
    TrackedEvent,
    TrackerOutput,
)
from squeeze_grasp_ros.mechanics.squeeze import contact_state
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap

from squeeze_grasp_ros.mechanics.resistance.frictional import FrictionalResistance
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.planning import (
    ErrorCode,
    LoadedObject,
    ResistancePlan,
    RingTest,
    SqueezePlan,
)
from squeeze_grasp_ros.sim.world import WorldView
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, Finger

Response = TypeVar("Response")

CONTACT_MODES: dict[str, int] = {"stick": ContactNode.STICK, "slip": ContactNode.SLIP}
"""Mechanics contact mode -> ``ContactNode.mode`` (= ``ContactState.modes``) constant."""


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
    model = object_model(loaded) if return_model and loaded.model == "solid" else ObjectModel()
    return success(
        LoadObject.Response,
        object_id=loaded.object_id,
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
    gmap: GraspMap, object_id: str, best_count: int, full_matrices: bool
) -> GraspMapData:
    """A solid's grasp map as ``GraspMapData``.

    ``best`` holds the ``best_count`` stiffest feasible placements (quality = stiffness, N/m);
    the b x b matrices (row-major, boundary order) only with ``full_matrices``.
    """
    summary = gmap.to_json()
    low, high = summary["stiffness_range"]
    data = GraspMapData(
        object_id=object_id,
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
        "work_a": work["A"],
        "work_total": work["total"],
        "force_f1": vector3(forces[Finger.F1]),
        "force_f2": vector3(forces[Finger.F2]),
        "force_a": vector3(forces["A"]),
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
        limit=grasp.limit,
        feasible=test.feasible,
        depth=depth,
        stiffness=grasp.stiffness,
        forces=float64_array(grasp.forces_at(depth)),
        max_strain=grasp.max_strain_at(depth),
        **fields,
    )


# --------------------------------------------------------------------------- contact state


def contact_node_msg(node: contact_state.ContactNode) -> ContactNode:
    """A contact node of the stepper as ``ContactNode`` (polar angle rad, force N)."""
    return ContactNode(
        finger=node.finger,
        node=int(node.node),
        polar_angle=float(node.theta),
        mode=CONTACT_MODES[node.mode],
        force=vector3(node.force),
    )


def contact_state_msg(
    state: contact_state.ContactState, header: Header | None = None
) -> ContactState:
    """The contact set of a stepper state as ``ContactState`` (depth rho in m)."""
    contacts = state.contacts
    return contact_arrays_msg(
        [c.finger for c in contacts],
        [int(c.node) for c in contacts],
        [float(c.theta) for c in contacts],
        [CONTACT_MODES[c.mode] for c in contacts],
        [float(c.force[0]) for c in contacts],
        [float(c.force[1]) for c in contacts],
        float(state.depth),
        float(state.relative_depth),
        header,
    )


def contact_arrays_msg(
    fingers: list[str],
    nodes: list[int],
    angles: list[float],
    modes: list[int],
    forces_x: list[float],
    forces_y: list[float],
    depth: float,
    relative_depth: float,
    header: Header | None = None,
) -> ContactState:
    """``ContactState`` of parallel per-contact lists (angles rad, forces N, depth m)."""
    return ContactState(
        header=header or Header(),
        fingers=fingers,
        nodes=array.array("i", nodes),
        polar_angles=array.array("d", angles),
        modes=array.array("B", modes),
        forces_x=array.array("d", forces_x),
        forces_y=array.array("d", forces_y),
        depth=depth,
        relative_depth=relative_depth,
    )


def contact_records(msg: ContactState) -> list[dict]:
    """The contacts of a ``ContactState`` as JSON-able dicts (node, finger, mode, force N)."""
    return [
        {
            "node": int(n),
            "finger": f,
            "mode": ContactMode.STICK if m == ContactState.STICK else ContactMode.SLIP,
            "polar_angle": float(a),
            "force": [float(x), float(y)],
        }
        for f, n, a, m, x, y in zip(
            msg.fingers, msg.nodes, msg.polar_angles, msg.modes, msg.forces_x, msg.forces_y
        )
    ]


def contact_event_msg(event: contact_state.Event, header: Header | None = None) -> ContactEvent:
    """A located event (types A-D of Sec. 5.3) as ``ContactEvent`` (depth rho in m)."""
    return ContactEvent(
        header=header or Header(),
        type=event.type,
        node=int(event.node),
        finger=event.finger,
        depth=float(event.depth),
        relative_depth=float(event.relative_depth),
    )


def event_squeeze_data(result: EventSqueeze, object_id: str) -> EventSqueezeData:
    """An event-driven squeeze's outcome as ``EventSqueezeData``.

    Finger forces are the final forces along each finger's motion direction (N), the work is
    each finger's work on the object (J), the health numbers those of the final configuration.
    """
    health = result.health
    return EventSqueezeData(
        object_id=object_id,
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
        max_strain=health.max_strain,
        max_von_mises=health.max_von_mises,
        max_displacement=health.max_displacement,
    )


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


def _check_taxels(finger: str, *arrays: Sequence[float]) -> None:
    """Raise ValueError unless the tactile arrays of ``finger`` have one entry per taxel."""
    sizes = {len(a) for a in arrays}
    if len(sizes) != 1:
        raise ValueError(f"tactile arrays of {finger} differ in length: {sorted(sizes)}")


def tactile_array_msg(readings: TactileReadings, header: Header | None = None) -> TactileArray:
    """``TactileArray`` of a fingertip's readings; the three arrays must have one entry per taxel.

    Raises
    ------
    ValueError
        If the arrays differ in length.
    """
    _check_taxels(readings.finger, readings.angles, readings.normal, readings.tangential)
    return TactileArray(
        header=header or Header(),
        finger=readings.finger,
        taxel_angles=float64_array(readings.angles),
        normal_forces=float64_array(readings.normal),
        tangential_forces=float64_array(readings.tangential),
    )


def fill_tactile(
    msg: TactileArray, normal: np.ndarray, tangential: np.ndarray, ns: int
) -> TactileArray:
    """Refill a :func:`tactile_array_msg` in place with new taxel forces, N, and stamp (the
    taxel angles stay).

    Raises
    ------
    ValueError
        If the force arrays do not have one entry per taxel.
    """
    _check_taxels(msg.finger, msg.taxel_angles, normal, tangential)
    set_stamp(msg.header.stamp, ns)
    msg.normal_forces = float64_array(normal)
    msg.tangential_forces = float64_array(tangential)
    return msg


def tactile_readings(msg: TactileArray) -> TactileReadings:
    """The readings of a ``TactileArray`` as numpy arrays (inverse of
    :func:`tactile_array_msg`).
    """
    return TactileReadings(
        msg.finger,
        np.asarray(msg.taxel_angles, dtype=float),
        np.asarray(msg.normal_forces, dtype=float),
        np.asarray(msg.tangential_forces, dtype=float),
    )


# --------------------------------------------------------------------------- pipeline: time


def stamp(ns: int) -> Time:
    """A ``builtin_interfaces/Time`` of ``ns`` nanoseconds (sim or wall time)."""
    return Time(sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))


def stamp_ns(time: Time) -> int:
    """Nanoseconds of a ``builtin_interfaces/Time`` (inverse of :func:`stamp`)."""
    return int(time.sec) * 1_000_000_000 + int(time.nanosec)


def header(ns: int, frame_id: str = "") -> Header:
    """A ``Header`` stamped ``ns`` nanoseconds in ``frame_id``."""
    return Header(stamp=stamp(ns), frame_id=frame_id)


def clock_msg(ns: int) -> Clock:
    """The ``/clock`` message of sim time ``ns``."""
    return Clock(clock=stamp(ns))


def set_stamp(time: Time, ns: int) -> None:
    """Set a ``builtin_interfaces/Time`` to ``ns`` nanoseconds in place."""
    time.sec, time.nanosec = divmod(int(ns), 1_000_000_000)


# --------------------------------------------------------------------------- pipeline: devices


def pose_msg(position: Sequence[float] | np.ndarray, ns: int, frame_id: str) -> PoseStamped:
    """A fingertip centre (x, y), m, as ``PoseStamped`` (z = 0, identity orientation)."""
    msg = PoseStamped(header=header(ns, frame_id))
    msg.pose.position.x = float(position[0])
    msg.pose.position.y = float(position[1])
    msg.pose.orientation.w = 1.0
    return msg


def fill_pose(msg: PoseStamped, position: Sequence[float] | np.ndarray, ns: int) -> PoseStamped:
    """Refill a :func:`pose_msg` in place with a new position (x, y), m, and stamp; returns it."""
    set_stamp(msg.header.stamp, ns)
    point = msg.pose.position
    point.x, point.y = float(position[0]), float(position[1])
    return msg


def pose_position(msg: PoseStamped) -> np.ndarray:
    """The planar position (x, y), m, of a ``PoseStamped``."""
    return np.array([msg.pose.position.x, msg.pose.position.y])


def pose_in_base(values: Sequence[float], frame_id: str) -> PoseStamped:
    """``PoseStamped`` of [x, y, z, qx, qy, qz, qw] (m, unit quaternion) in ``frame_id``."""
    msg = PoseStamped(header=Header(frame_id=frame_id))
    p, q = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z, q.x, q.y, q.z, q.w = (float(v) for v in values)
    return msg


def wrench_msg(force: np.ndarray, torque: np.ndarray, ns: int, frame_id: str) -> WrenchStamped:
    """``WrenchStamped`` of a force (3,), N, and torque (3,), N m, in ``frame_id``."""
    msg = WrenchStamped(header=header(ns, frame_id))
    w = msg.wrench
    w.force.x, w.force.y, w.force.z = (float(v) for v in force)
    w.torque.x, w.torque.y, w.torque.z = (float(v) for v in torque)
    return msg


def fill_wrench(
    msg: WrenchStamped, force: np.ndarray, torque: np.ndarray, ns: int
) -> WrenchStamped:
    """Refill a :func:`wrench_msg` in place with a new force, N, torque, N m, and stamp."""
    set_stamp(msg.header.stamp, ns)
    f, t = msg.wrench.force, msg.wrench.torque
    f.x, f.y, f.z = (float(v) for v in force)
    t.x, t.y, t.z = (float(v) for v in torque)
    return msg


def wrench_force(msg: WrenchStamped) -> np.ndarray:
    """The force (3,), N, of a ``WrenchStamped``."""
    f = msg.wrench.force
    return np.array([f.x, f.y, f.z])


def tick_msg(index: int, ns: int, readings: Sequence[str]) -> Tick:
    """The end-of-tick message of lockstep tick ``index`` at sim time ``ns`` (readings as
    "<device>/<stream>").
    """
    return Tick(header=header(ns), index=int(index), readings=list(readings))


# --------------------------------------------------------------------------- pipeline: ground trut


def sim_state_msg(
    state: contact_state.ContactState,
    fingers: Sequence[str],
    termination: str | None,
    ns: int,
    frame_id: str,
) -> SimState:
    """Ground truth of the simulated world as ``SimState`` (fingers without a tip: zeros)."""
    present = {f.name: f for f in state.fingers}
    positions, forces, work = [], [], []
    for name in fingers:
        f = present.get(name)
        positions.append(Point(x=float(f.center[0]), y=float(f.center[1])) if f else Point())
        forces.append(vector3(state.finger_force(name)))
        work.append(f.work if f else 0.0)
    stamp_header = header(ns, frame_id)
    return SimState(
        header=stamp_header,
        fingers=list(fingers),
        positions=positions,
        forces=forces,
        work=float64_array(work),
        contacts=contact_state_msg(state, stamp_header),
        termination=termination or "",
    )


def sim_events_msg(
    events: Sequence[contact_state.Event],
    termination: str,
    state: contact_state.ContactState,
    ns: int,
) -> ContactEventArray:
    """The ground-truth events of one tick as ``ContactEventArray``; ``termination`` (e.g.
    "finger_slip", or "") is set at the tick the world ends, with the depth it ended at.
    """
    head = header(ns)
    return ContactEventArray(
        header=head,
        events=[contact_event_msg(e, head) for e in events],
        termination=termination,
        depth=float(state.depth) if termination else 0.0,
    )


def event_record(msg: ContactEvent) -> dict:
    """A ``ContactEvent`` as a JSON-able dict (stamp in ns)."""
    return {
        "stamp_ns": stamp_ns(msg.header.stamp),
        "type": msg.type,
        "node": int(msg.node),
        "finger": msg.finger,
        "depth": float(msg.depth),
        "relative_depth": float(msg.relative_depth),
    }


MARKER_COLOURS: dict[str, tuple[float, float, float]] = {
    "outline": (0.2, 0.4, 0.9),
    "tip": (0.5, 0.5, 0.5),
    "stick": (0.1, 0.75, 0.2),
    "slip": (0.9, 0.2, 0.1),
    "force": (0.95, 0.7, 0.1),
}
"""RGB of the visualisation markers (contacts: sticking green, sliding red)."""


def _marker(
    ns: int,
    frame_id: str,
    namespace: str,
    ident: int,
    kind: int,
    colour: str,
    points: np.ndarray,
    width: float,
) -> Marker:
    r, g, b = MARKER_COLOURS[colour]
    m = Marker(header=header(ns, frame_id), ns=namespace, id=ident, type=kind, action=Marker.ADD)
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = width
    m.color.r, m.color.g, m.color.b, m.color.a = r, g, b, 1.0
    m.points = [Point(x=float(x), y=float(y)) for x, y in points]
    return m


def world_markers(
    view: WorldView, ns: int, frame_id: str, force_scale: float = 0.002
) -> MarkerArray:
    """``MarkerArray`` of the deformed outline, fingertip circles, contact nodes (sticking green,
    sliding red) and contact force arrows (``force_scale`` m per N), object frame.
    """
    markers = [
        _marker(
            ns,
            frame_id,
            "outline",
            0,
            Marker.LINE_STRIP,
            "outline",
            np.vstack([view.outline, view.outline[:1]]),
            0.0005,
        )
    ]
    circle = np.linspace(0.0, 2.0 * np.pi, 49)
    for k, (_, centre, radius) in enumerate(view.tips):
        pts = centre + radius * np.stack([np.cos(circle), np.sin(circle)], axis=1)
        markers.append(
            _marker(ns, frame_id, "fingertips", k, Marker.LINE_STRIP, "tip", pts, 0.0005)
        )
    for k, (_, point, mode, force) in enumerate(view.contacts):
        markers.append(
            _marker(ns, frame_id, "contacts", k, Marker.SPHERE, mode, np.zeros((0, 2)), 0.002)
        )
        markers[-1].pose.position.x, markers[-1].pose.position.y = float(point[0]), float(point[1])
        arrow = np.array([point - force_scale * np.asarray(force), point])
        markers.append(_marker(ns, frame_id, "forces", k, Marker.ARROW, "force", arrow, 0.0005))
    clear = Marker(header=header(ns, frame_id), action=Marker.DELETEALL)
    return MarkerArray(markers=[clear] + markers)


# --------------------------------------------------------------------------- pipeline: monitor


def _point(xy: np.ndarray) -> Point:
    return Point(x=float(xy[0]), y=float(xy[1]))


def tracked_event_msg(event: TrackedEvent, ns: int) -> ContactEvent:
    """A monitor event as ``ContactEvent`` (node -1: taxel patches are not mesh nodes)."""
    return ContactEvent(
        header=header(ns),
        type=event.type,
        node=-1,
        finger=event.finger,
        depth=float(event.depth),
        relative_depth=float(event.relative_depth),
    )


def tracked_events_msg(out: TrackerOutput) -> ContactEventArray:
    """The events of one monitor tick as one ``ContactEventArray``."""
    return ContactEventArray(
        header=header(out.stamp_ns),
        events=[tracked_event_msg(e, out.stamp_ns) for e in out.events],
    )


def alarm_msg(alarm: TrackedAlarm, ns: int) -> Alarm:
    """A monitor alarm as ``Alarm``."""
    return Alarm(
        header=header(ns),
        type=alarm.type,
        finger=alarm.finger,
        value=float(alarm.value),
        message=alarm.message,
    )


def patches_state_msg(out: TrackerOutput, frame_id: str) -> ContactState:
    """The monitor's reconstructed contact patches as ``ContactState`` (node = -1, polar angle
    = the patch's mean taxel angle, force = the patch force on the object, N).
    """
    patches = out.patches
    trig = [(math.cos(p.angle), math.sin(p.angle)) for p in patches]
    return contact_arrays_msg(
        [p.finger for p in patches],
        [-1] * len(patches),
        [p.angle for p in patches],
        [CONTACT_MODES[p.mode] for p in patches],
        [p.normal * c - p.tangential * s for p, (c, s) in zip(patches, trig)],
        [p.normal * s + p.tangential * c for p, (c, s) in zip(patches, trig)],
        out.depth,
        out.relative_depth,
        header(out.stamp_ns, frame_id),
    )


def monitor_status_msg(out: TrackerOutput, frame_id: str) -> MonitorStatus:
    """The monitor's per-tick ``MonitorStatus`` (fingers without a pose report the origin)."""
    zero = np.zeros(2)
    return MonitorStatus(
        header=header(out.stamp_ns, frame_id),
        fingers=list(out.fingers),
        positions=[_point(out.positions.get(f, zero)) for f in out.fingers],
        forces=[vector3(out.forces[f]) for f in out.fingers],
        normals=[vector3(out.normals[f]) for f in out.fingers],
        sensor_age=float64_array([min(out.ages[f], 1e300) for f in out.fingers]),
        depth=out.depth,
        relative_depth=out.relative_depth,
        events=[tracked_event_msg(e, out.stamp_ns) for e in out.events],
        alarms=[alarm_msg(a, out.stamp_ns) for a in out.alarms],
    )


def prediction_msg(
    events: Sequence[ContactEvent], termination: str, depth: float
) -> ContactEventArray:
    """The planner's predicted events as ``ContactEventArray``."""
    return ContactEventArray(events=list(events), termination=termination, depth=float(depth))


def predicted_events(msg: ContactEventArray) -> list[PredictedEvent]:
    """The A-D events of a prediction for the tracker."""
    return [PredictedEvent(e.type, e.finger, float(e.depth)) for e in msg.events]


# --------------------------------------------------------------------------- pipeline: executor


def observation(msg: MonitorStatus) -> Observation:
    """The executor's :class:`Observation` of a ``MonitorStatus``."""
    fingers = list(msg.fingers)
    return Observation(
        stamp_ns(msg.header.stamp),
        {f: np.array([p.x, p.y]) for f, p in zip(fingers, msg.positions)},
        {f: np.array([v.x, v.y]) for f, v in zip(fingers, msg.forces)},
        {f: np.array([v.x, v.y]) for f, v in zip(fingers, msg.normals)},
        tuple((a.type, a.finger) for a in msg.alarms),
        tuple(e.type for e in msg.events),
        float(msg.depth),
    )


def _planar(vectors: Sequence[Vector3]) -> np.ndarray:
    return np.array([[v.x, v.y] for v in vectors], float).reshape(-1, 2)


def grasp_goal(msg: ExecuteGrasp.Goal) -> GraspGoal:
    """The :class:`GraspGoal` of an ``ExecuteGrasp`` goal (shapes are checked by
    :func:`..control.motion.goal_problem`).
    """
    fingers = tuple(msg.fingers)
    waypoints = _planar(msg.resist_waypoints)
    k = len(msg.resist_travel)
    shaped = (
        waypoints.reshape(k, len(fingers), 2)
        if k and len(waypoints) == k * len(fingers)
        else waypoints.reshape(1, -1, 2)
    )
    return GraspGoal(
        fingers,
        _planar(msg.directions),
        float(msg.depth),
        float(msg.relative_per_depth),
        msg.on_slip_alarm or "hold",
        _planar(msg.pure_directions) if msg.pure_directions else None,
        msg.adversary if msg.resist else "",
        np.array([msg.adversary_translation.x, msg.adversary_translation.y]),
        np.asarray(msg.resist_travel, float),
        shaped,
    )


def grasp_goal_msg(goal: GraspGoal) -> ExecuteGrasp.Goal:
    """The ``ExecuteGrasp`` goal of a :class:`GraspGoal`."""
    msg = ExecuteGrasp.Goal(
        fingers=list(goal.fingers),
        directions=[vector3(d) for d in goal.directions],
        depth=float(goal.depth),
        relative_per_depth=float(goal.relative_per_depth),
        on_slip_alarm=goal.on_slip_alarm,
        resist=goal.resist,
        adversary=goal.adversary,
        adversary_translation=vector3(goal.adversary_translation),
        resist_travel=float64_array(goal.resist_travel),
        resist_waypoints=[vector3(w) for w in goal.resist_waypoints.reshape(-1, 2)],
    )
    if goal.pure_directions is not None:
        msg.pure_directions = [vector3(d) for d in goal.pure_directions]
    return msg


def grasp_feedback(
    state: str,
    obs: Observation,
    fingers: Sequence[str],
    events: Sequence[ContactEvent],
    relative_per_depth: float,
) -> ExecuteGrasp.Feedback:
    """``ExecuteGrasp`` feedback: measured depth and forces, events since the last feedback."""
    return ExecuteGrasp.Feedback(
        state=state,
        depth=obs.depth,
        relative_depth=obs.depth * relative_per_depth,
        fingers=list(fingers),
        forces=[vector3(obs.forces.get(f, np.zeros(2))) for f in fingers],
        latest_events=list(events),
    )


def grasp_result(
    program: GraspProgram,
    command: Command,
    obs: Observation | None,
    events: Sequence[ContactEvent],
    duration: float,
    success_terminations: Sequence[str],
) -> ExecuteGrasp.Result:
    """``ExecuteGrasp`` result of a finished :class:`GraspProgram` (measured numbers)."""
    fingers = list(program.fingers)
    forces = obs.forces if obs is not None else {}
    return ExecuteGrasp.Result(
        success=command.termination in success_terminations,
        termination=command.termination,
        message=command.message,
        depth=obs.depth if obs is not None else 0.0,
        relative_depth=(obs.depth if obs is not None else 0.0) * program.goal.relative_per_depth,
        ticks=program.ticks,
        duration=float(duration),
        hold_ticks=program.hold_ticks,
        redirected=program.redirected,
        fingers=fingers,
        forces=[vector3(forces.get(f, np.zeros(2))) for f in fingers],
        work=float64_array([program.work[f] for f in fingers]),
        events=list(events),
    )


def invalid_goal_result(message: str) -> ExecuteGrasp.Result:
    """The result of a goal that cannot be executed."""
    return ExecuteGrasp.Result(
        success=False, termination=ExecuteGrasp.Result.INVALID_GOAL, message=message
    )


def executor_status_msg(state: str, depth: float, message: str, ns: int) -> ExecutorStatus:
    """``ExecutorStatus`` of the executor (depth: commanded or measured, m)."""
    return ExecutorStatus(header=header(ns), state=state, depth=float(depth), message=message)
