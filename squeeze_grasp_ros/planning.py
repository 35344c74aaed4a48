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

from __future__ import annotations

import dataclasses
import hashlib
import math
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import IntEnum
from pathlib import Path

import numpy as np

from squeeze_grasp_ros.inputs import InputError, confine, load_yaml, read_text
from squeeze_grasp_ros.mechanics.elastic.compliance import ROUTES, ElasticObject
from squeeze_grasp_ros.mechanics.errors import (
    InfeasibleError,
    InternalError,
    InvalidInputError,
    NumericalError,
    SqueezeGraspError,
)
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap, grasp_map
from squeeze_grasp_ros.mechanics.elastic.reduced import boundary_displacement, reduced_stiffness
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    Resistance,
    ResistanceSweep,
    contact_segments,
    optimal_resistance,
    resistance_grasp,
    sweep_directions,
)
from squeeze_grasp_ros.mechanics.resistance.frictional import (
    FrictionalResistance,
    add_adversary,
    frictional_resistance,
)
from squeeze_grasp_ros.mechanics.ring.grasp_map import RingGraspMap, ring_grasp_map
from squeeze_grasp_ros.mechanics.ring.model import RingModel
from squeeze_grasp_ros.mechanics.ring.squeeze import RingGrasp, ring_grasp
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import Squeeze, force_closure, plan_squeeze
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.scene import (
    Scene,
    build_mesh,
    build_outline,
    build_ring,
    finger_nodes,
    parse_scene,
    scene_material,
)
from squeeze_grasp_ros.scene_events import event_squeeze_scene, scene_contact_model
from squeeze_grasp_ros.mechanics.vocabulary import Finger, SqueezeKind

CONTACT_MODELS: tuple[str, ...] = ("point", "segment", "friction")
MAX_DIRECTIONS = 100_000
"""Most push directions one resistance sweep may ask for."""
MAX_BEST_COUNT = 100_000
"""Most placements one grasp map may return as candidates."""
SOLID_STAGES: tuple[str, ...] = ("mesh", "stiffness", "factorisation", "boundary compliance")
RING_STAGES: tuple[str, ...] = ("ring model", "compliance")

Progress = Callable[[str, int, int, int], None]
"""Called as ``progress(stage, index, count, num_nodes)`` when a stage starts; may raise
:class:`Cancelled` to stop the computation."""


class ErrorCode(IntEnum):
    """Error codes of every planner response (the constants of the .srv/.action files)."""

    OK = 0
    INVALID_ARGUMENT = 1
    UNKNOWN_OBJECT = 2
    NOT_FEASIBLE = 3
    INTERNAL_ERROR = 4
    CANCELLED = 5
    BUSY = 6
    NUMERICAL_FAILURE = 7


class PlannerError(Exception):
    """A request the planner refuses; ``code`` says why in one word, the message in full."""

    def __init__(self, code: ErrorCode, message: str) -> None:
        super().__init__(message)
        self.code = code


class Cancelled(PlannerError):
    """The client cancelled the goal, or the node is shutting down."""

    def __init__(self, message: str = "cancelled") -> None:
        super().__init__(ErrorCode.CANCELLED, message)


def invalid(message: str) -> PlannerError:
    """A :class:`PlannerError` with code INVALID_ARGUMENT."""
    return PlannerError(ErrorCode.INVALID_ARGUMENT, message)


ERROR_CODES: dict[type[SqueezeGraspError], ErrorCode] = {
    InvalidInputError: ErrorCode.INVALID_ARGUMENT,
    InfeasibleError: ErrorCode.NOT_FEASIBLE,
    NumericalError: ErrorCode.NUMERICAL_FAILURE,
    InternalError: ErrorCode.INTERNAL_ERROR,
}
"""The service error code of each error kind."""


def classify(exc: Exception) -> tuple[ErrorCode, str]:
    """The error code and message of a failed request.

    Parameters
    ----------
    exc : Exception
        What the computation raised.

    Returns
    -------
    (ErrorCode, str)
        :class:`PlannerError` keeps its code; the error kinds of
        :mod:`squeeze_grasp_ros.mechanics.errors` map to INVALID_ARGUMENT, NOT_FEASIBLE,
        NUMERICAL_FAILURE and INTERNAL_ERROR; anything else is INTERNAL_ERROR too (a bug: its
        type is named in the message).
    """
    if isinstance(exc, PlannerError):
        return exc.code, str(exc)
    for kind, code in ERROR_CODES.items():
        if isinstance(exc, kind):
            return code, str(exc)
    return ErrorCode.INTERNAL_ERROR, f"internal error ({type(exc).__name__}): {exc}"


# --------------------------------------------------------------------------- limits and objects


@dataclass(frozen=True)
class Limits:
    """What the node accepts (its parameters).

    Attributes
    ----------
    max_nodes : int
        Largest solid mesh, nodes; larger scenes are refused before and after meshing.
    max_spectral_nodes : int
        Largest mesh for the dense spectral route (O(n^3) time, O(n^2) memory).
    max_ring_elements : int
        Largest ring model, elements (its compliance is dense).
    default_route : str
        Solver route used when a request leaves it empty.
    best_count : int
        Placements a grasp map returns when a request asks for 0.
    min_step : float
        Smallest event-squeeze substep relative to the object size.
    """

    max_nodes: int = 60_000
    max_spectral_nodes: int = 3_000
    max_ring_elements: int = 1_000
    default_route: str = "factorized"
    best_count: int = 10
    min_step: float = 1e-5


@dataclass(frozen=True)
class LoadedObject:
    """An object with its precomputed mechanics, as the planner caches it.

    Attributes
    ----------
    object_id : str
    scene : Scene
        The validated scene it came from (fingers, friction, limits, squeeze defaults).
    body : ElasticObject or RingModel
        Precomputed: factorisation and boundary compliance (solid) or compliance (ring).
    finger_nodes : (int, int)
        Initial contact nodes of F1, F2 from the scene's placements.
    digest : str
        SHA-256 of the scene text and the solver route: same digest, same object.
    precompute_time : float
        Wall time of meshing and precompute, s.
    """

    object_id: str
    scene: Scene
    body: ElasticObject | RingModel
    finger_nodes: tuple[int, int]
    digest: str
    precompute_time: float

    @property
    def model(self) -> str:
        """Body model: "solid" (FEM mesh) or "ring" (curved beam)."""
        return "ring" if isinstance(self.body, RingModel) else "solid"

    @property
    def num_nodes(self) -> int:
        """Mesh nodes (solid) or ring nodes."""
        return int(self.body.n) if self.model == "ring" else int(self.body.mesh.n)

    @property
    def boundary(self) -> np.ndarray:
        """Nodes a finger can touch: the outer boundary loop (solid) or every ring node."""
        return self.body.boundary if self.model == "ring" else self.body.mesh.boundary

    def solid(self) -> ElasticObject:
        """The FEM object; a ring raises INVALID_ARGUMENT naming the service to use."""
        if not isinstance(self.body, ElasticObject):
            raise invalid(
                f"object {self.object_id!r} is a ring model (Sec. 7): use the "
                "ring_grasp_test service"
            )
        return self.body

    def ring(self) -> RingModel:
        """The ring model; a solid raises INVALID_ARGUMENT."""
        if not isinstance(self.body, RingModel):
            raise invalid(
                f"object {self.object_id!r} is a solid (object.model: solid), not a ring"
            )
        return self.body


@dataclass(frozen=True)
class SceneSource:
    """A validated scene with the text it came from.

    Attributes
    ----------
    scene : Scene
    text : str
        The YAML text (the file's content for a path).
    """

    scene: Scene
    text: str


def read_scene(
    scene_yaml: str, scene_path: str, roots: Sequence[str | Path] | None = None
) -> SceneSource:
    """Parse the scene of a request: exactly one of YAML text and a file path.

    Parameters
    ----------
    scene_yaml, scene_path : str
        The request's fields; exactly one is non-empty.
    roots : sequence of path-like, optional
        Folders that ``scene_path`` and an outline file named by the scene must lie in (after
        following symlinks and ``..``); None allows any path.

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT for neither or both, paths outside ``roots``, unreadable or oversized
        files, YAML aliases, bad YAML or a bad scene (the message names the field and never
        quotes a file's contents).
    """
    if bool(scene_yaml) == bool(scene_path):
        raise invalid("give exactly one of scene_yaml and scene_path")
    try:
        if scene_path:
            path = (
                confine(scene_path, roots, what="scene_path")
                if roots is not None
                else Path(scene_path)
            )
            text = read_text(path, what="scene_path")
            data, base_dir = load_yaml(text, what="scene_path"), path.parent
        else:
            text = scene_yaml
            data, base_dir = load_yaml(scene_yaml, what="scene_yaml"), None
        scene = parse_scene(data, base_dir=base_dir)
        shape = scene.object.shape
        if roots is not None and shape["type"] == "file":
            confine(shape["path"], roots, what="object.shape.path")
    except InputError as exc:
        raise invalid(str(exc)) from None
    return SceneSource(scene, text)


def requested_nodes(scene: Scene) -> int | None:
    """Nodes the scene asks for before anything is built; None for the mesher's default size.

    A ring asks for ``object.ring.elements``; a solid for ``object.mesh.nodes``, or about
    0.8 * area / max_area for ``object.mesh.max_area`` (the inverse of
    :func:`~.mechanics.mesh.target_max_area`).
    """
    obj = scene.object
    if obj.model == "ring":
        return obj.ring.elements
    if obj.mesh.nodes is not None:
        return obj.mesh.nodes
    if obj.mesh.max_area is None:
        return None
    area = build_outline(obj.shape).area
    return math.ceil(0.8 * area / min(obj.mesh.max_area, 0.25 * area))


def check_size(count: int | None, limit: int, what: str) -> None:
    """Refuse a model with more than ``limit`` nodes (INVALID_ARGUMENT, oversized)."""
    if count is not None and count > limit:
        raise invalid(
            f"oversized {what}: {count} nodes, more than the planner's limit of "
            f"{limit} (parameter); coarsen object.mesh or object.ring"
        )


def solver_route(route: str, limits: Limits) -> str:
    """The request's solver route, or the node's default when empty."""
    route = route or limits.default_route
    if route not in ROUTES:
        raise invalid(f"solver_route must be one of {list(ROUTES)} or empty, got {route!r}")
    return route


def no_progress(stage: str, index: int, count: int, num_nodes: int) -> None:
    """A :data:`Progress` that ignores every stage."""


@dataclass(frozen=True)
class ObjectKey:
    """Where and how a scene's object is built.

    Attributes
    ----------
    object_id : str
        The request's id, else the scene's name, else ``object-<digest prefix>``.
    route : str
        Solver route (the node's default when the request leaves it empty).
    digest : str
        SHA-256 of the route and the scene text: same digest, same object.
    """

    object_id: str
    route: str
    digest: str


def object_key(source: SceneSource, object_id: str, route: str, limits: Limits) -> ObjectKey:
    """The :class:`ObjectKey` of a load request."""
    route = solver_route(route, limits)
    digest = hashlib.sha256(f"{route}\0{source.text}".encode()).hexdigest()
    return ObjectKey(object_id or source.scene.name or f"object-{digest[:12]}", route, digest)


def load_object(
    source: SceneSource, key: ObjectKey, limits: Limits, progress: Progress = no_progress
) -> LoadedObject:
    """Build and precompute the object of a scene, stage by stage.

    Parameters
    ----------
    source : SceneSource
        The scene (see :func:`read_scene`).
    key : ObjectKey
        Id, solver route (rings ignore it) and digest (see :func:`object_key`).
    limits : Limits
    progress : Progress
        Called with :data:`SOLID_STAGES` or :data:`RING_STAGES` as they start.

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT for an oversized or invalid model, CANCELLED from ``progress``.
    """
    scene = source.scene
    start = time.perf_counter()
    if scene.object.model == "ring":
        check_size(requested_nodes(scene), limits.max_ring_elements, "ring model")
        progress(RING_STAGES[0], 0, len(RING_STAGES), 0)
        body = build_ring(scene)
        progress(RING_STAGES[1], 1, len(RING_STAGES), body.n)
        body.precompute()
        nodes = finger_nodes(scene, body)
    else:
        limit = limits.max_nodes if key.route == "factorized" else limits.max_spectral_nodes
        check_size(requested_nodes(scene), limit, f"{key.route} mesh")
        progress(SOLID_STAGES[0], 0, len(SOLID_STAGES), 0)
        mesh = build_mesh(scene)
        check_size(mesh.n, limit, f"{key.route} mesh")
        body = ElasticObject(mesh, scene_material(scene), key.route)
        progress(SOLID_STAGES[1], 1, len(SOLID_STAGES), mesh.n)
        _ = body.stiffness
        progress(SOLID_STAGES[2], 2, len(SOLID_STAGES), mesh.n)
        _ = body.solver
        progress(SOLID_STAGES[3], 3, len(SOLID_STAGES), mesh.n)
        body.precompute()
        nodes = finger_nodes(scene, mesh)
    return LoadedObject(key.object_id, scene, body, nodes, key.digest, time.perf_counter() - start)


class ObjectCache:
    """Loaded objects by id, least recently used evicted first; safe to share between threads.

    Parameters
    ----------
    capacity : int
        Most objects kept (>= 1).
    """

    def __init__(self, capacity: int) -> None:
        if capacity < 1:
            raise ValueError(f"cache capacity must be >= 1, got {capacity}")
        self.capacity = capacity
        self._objects: OrderedDict[str, LoadedObject] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, object_id: str) -> LoadedObject:
        """The object loaded under ``object_id`` (now the most recently used).

        Raises
        ------
        PlannerError
            UNKNOWN_OBJECT. The message does not list the loaded ids: they belong to other
            clients.
        """
        with self._lock:
            loaded = self._objects.get(object_id)
            if loaded is None:
                raise PlannerError(
                    ErrorCode.UNKNOWN_OBJECT,
                    f"unknown object_id {object_id!r}: load it first with "
                    "load_object (objects are evicted when the cache is full)",
                )
            self._objects.move_to_end(object_id)
            return loaded

    def find(self, object_id: str, digest: str) -> LoadedObject | None:
        """The object under ``object_id`` if it was built from the same scene and route."""
        with self._lock:
            loaded = self._objects.get(object_id)
            if loaded is None or loaded.digest != digest:
                return None
            self._objects.move_to_end(object_id)
            return loaded

    def put(self, loaded: LoadedObject) -> list[str]:
        """Store ``loaded`` (replacing an object of the same id); return the evicted ids."""
        with self._lock:
            self._objects[loaded.object_id] = loaded
            self._objects.move_to_end(loaded.object_id)
            evicted = []
            while len(self._objects) > self.capacity:
                evicted.append(self._objects.popitem(last=False)[0])
            return evicted

    def ids(self) -> list[str]:
        """Loaded ids, least recently used first."""
        with self._lock:
            return list(self._objects)


def load_cached(
    cache: ObjectCache,
    source: SceneSource,
    object_id: str,
    route: str,
    limits: Limits,
    progress: Progress = no_progress,
) -> tuple[LoadedObject, bool]:
    """The cached object of the same id, scene and route, or a freshly loaded and cached one.

    Returns
    -------
    (LoadedObject, bool)
        The object and whether it came from the cache.
    """
    key = object_key(source, object_id, route, limits)
    cached = cache.find(key.object_id, key.digest)
    if cached is not None:
        return cached, True
    loaded = load_object(source, key, limits, progress)
    cache.put(loaded)
    return loaded, False


# --------------------------------------------------------------------------- request checks


def check_number(name: str, value: float, low: float = -math.inf, high: float = math.inf) -> float:
    """``value`` if finite and in [low, high], else INVALID_ARGUMENT naming ``name``."""
    if not math.isfinite(value):
        raise invalid(f"{name} must be finite, got {value}")
    if not low <= value <= high:
        bounds = f">= {low}" if high == math.inf else f"in [{low}, {high}]"
        raise invalid(f"{name} must be {bounds}, got {value}")
    return float(value)


def check_step(step: float, limits: Limits) -> float:
    """An event-squeeze substep no smaller than the node's ``min_step``."""
    if step < limits.min_step:
        raise invalid(
            f"step {step} is below the planner's min_step {limits.min_step} "
            "(parameter): the squeeze would take too long"
        )
    return step


def best_count(requested: int, limits: Limits) -> int:
    """Placements a map returns: ``requested`` in [1, MAX_BEST_COUNT], or the default for 0."""
    return int(check_number("best_count", requested, 0, MAX_BEST_COUNT)) or limits.best_count


def choice(name: str, value: str, allowed: Sequence[str], default: str | None = None) -> str:
    """``value`` (or ``default`` when empty and given) if it is one of ``allowed``."""
    if not value and default is not None:
        return default
    if value not in allowed:
        raise invalid(f"{name} must be one of {list(allowed)}, got {value!r}")
    return value


def contact_nodes(
    loaded: LoadedObject,
    contacts: Sequence[int],
    count: int | None = None,
    default: Sequence[int] | None = None,
) -> np.ndarray:
    """Validated contact nodes: distinct nodes of the outer boundary (every node of a ring).

    Parameters
    ----------
    loaded : LoadedObject
    contacts : sequence of int
        Requested nodes; empty means ``default``.
    count : int, optional
        Exact number of nodes required (at least 2 when None).
    default : sequence of int, optional
        Nodes used for an empty request (none: an empty request is refused).
    """
    if len(contacts) == 0 and default is not None:
        contacts = default
    nodes = np.asarray(list(contacts), dtype=np.int64).reshape(-1)
    if count is not None and len(nodes) != count:
        raise invalid(f"contacts needs exactly {count} nodes, got {len(nodes)}")
    if len(nodes) < 2:
        raise invalid(f"contacts needs at least 2 nodes, got {len(nodes)}")
    if len(np.unique(nodes)) != len(nodes):
        raise invalid(f"contacts must be distinct nodes, got {nodes.tolist()}")
    off = nodes[~np.isin(nodes, loaded.boundary)]
    if len(off):
        raise invalid(
            f"contact node {int(off[0])} is not on the outer boundary of object "
            f"{loaded.object_id!r} ({len(loaded.boundary)} boundary nodes; "
            "LoadObject with return_model lists them)"
        )
    return nodes


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
    obj = loaded.solid()
    kind = choice("squeeze_type", kind, SqueezeKind.values())
    scale = check_number("depth", depth, 0.0) or 1.0
    nodes = contact_nodes(loaded, contacts, default=loaded.finger_nodes)
    red = reduced_stiffness(obj, nodes)
    sq = plan_squeeze(obj, nodes, kind=kind, red=red)
    relative = sq.relative_depth(scale)
    if depth and len(nodes) == 2 and not relative < 1.0:
        raise invalid(
            f"depth {depth:.6g} m is a relative depth of {relative:.6g}: it must be "
            "below 1 (at 1 the fingers would meet)"
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
    """All-pairs grasp map of a solid (:func:`~.mechanics.graspmap.grasp_map`); mu >= 0."""
    return grasp_map(loaded.solid(), check_number("mu", mu, 0.0))


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
    limits: Limits,
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
    contact_model : {"point", "segment", "friction"}
    half_width : float
        Segment half width, m (>= 0; 0 = the node and its two neighbours).
    directions : int
        Push directions to sweep (0 = none; fixed contacts only).
    tip_radius : float
        Friction: A's fingertip radius, m (0 = the scene's adversary tip radius).
    limits : Limits
        Friction: the scene's squeeze step must be >= ``limits.min_step``.
    """
    obj = loaded.solid()
    mode = choice("mode", mode, SqueezeKind.values())
    contact_model = choice("contact_model", contact_model, CONTACT_MODELS)
    x, y, z = (check_number(f"a.{k}", v) for k, v in zip("xyz", a))
    if z != 0.0:
        raise invalid(f"a.z must be 0 (planar objects), got {z}")
    width = check_number("segment_half_width", half_width, 0.0)
    count = int(check_number("directions", directions, 0, MAX_DIRECTIONS))
    nodes = contact_nodes(loaded, contacts, count=3)
    if contact_model == "friction":
        if count:
            raise invalid("directions: the sweep needs point or segment contacts")
        return ResistancePlan(
            friction_resistance(loaded, nodes, (x, y), mode, tip_radius, limits), None
        )
    if contact_model == "point":
        sets = [[int(n)] for n in nodes]
    else:
        sets = contact_segments(obj.mesh, nodes.tolist(), width or None)
    grasp = resistance_grasp(obj, dict(zip(tuple(Finger), sets)))
    sweep = sweep_directions(grasp, mode, count) if count else None
    return ResistancePlan(optimal_resistance(grasp, (x, y), mode=mode), sweep)


def friction_resistance(
    loaded: LoadedObject,
    nodes: np.ndarray,
    a: tuple[float, float],
    mode: str,
    tip_radius: float,
    limits: Limits,
) -> FrictionalResistance:
    """Algorithm 2 after the scene's event-driven squeeze at F1, F2 (Sec. 6.3)."""
    scene = loaded.scene
    radius = check_number("adversary_tip_radius", tip_radius, 0.0)
    radius = radius or (scene.adversary.tip_radius if scene.adversary is not None else 0.0)
    if not radius > 0:
        raise invalid(
            "adversary_tip_radius must be > 0 m for friction contacts (the scene "
            "gives no adversary tip radius)"
        )
    check_step(scene.squeeze.step, limits)
    obj = loaded.solid()
    i, j, k = (int(n) for n in nodes)
    squeeze = event_squeeze_scene(scene, obj, (i, j))
    model = scene_contact_model(scene, obj)
    state = add_adversary(squeeze.state, model, squeeze.displacement, k, radius)
    return frictional_resistance(
        model,
        state,
        a,
        mode=mode,
        step=squeeze.step,
        event_tol=squeeze.event_tol,
        contacts=[i, j, k],
    )


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
    kind = choice("squeeze_type", kind, SqueezeKind.values())
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
    limits: Limits,
    progress: Callable[[float], None] | None = None,
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
    limits : Limits
    progress : callable, optional
        Called with the completed fraction; may raise :class:`Cancelled`.
    """
    obj = loaded.solid()
    scene = loaded.scene
    kind = choice("squeeze_type", kind, SqueezeKind.values(), scene.squeeze.type)
    depth = check_number("depth", depth, 0.0)
    relative_depth = check_number("relative_depth", relative_depth, 0.0, 1.0)
    if depth and relative_depth:
        raise invalid("give at most one of depth and relative_depth (0 = the scene's)")
    step = check_step(check_number("step", step, 0.0) or scene.squeeze.step, limits)
    event_tol = check_number("event_tol", event_tol, 0.0) or scene.squeeze.event_tol
    nodes = contact_nodes(loaded, contacts, count=2, default=loaded.finger_nodes)
    scene = dataclasses.replace(scene, squeeze=dataclasses.replace(scene.squeeze, type=kind))
    return event_squeeze_scene(
        scene,
        obj,
        (int(nodes[0]), int(nodes[1])),
        depth=depth or None,
        relative_depth=relative_depth or None,
        step=step,
        event_tol=event_tol,
        progress=progress,
    )
