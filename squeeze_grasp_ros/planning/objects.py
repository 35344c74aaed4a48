# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Limits of the planner (PlannerLimits), scene sources and the object cache (a bounded LRU of
loaded objects).
"""

from __future__ import annotations

import hashlib
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from squeeze_grasp_ros.inputs import InputError, confine, load_yaml, read_text
from squeeze_grasp_ros.mechanics.elastic.compliance import ROUTES, ElasticObject
from squeeze_grasp_ros.mechanics.ring.model import RingModel
from squeeze_grasp_ros.mechanics.squeeze.graspmap import GraspMap, grasp_map
from squeeze_grasp_ros.mechanics.vocabulary import ContactKind, ObjectModel, ShapeType
from squeeze_grasp_ros.planning.budget import check_load
from squeeze_grasp_ros.planning.errors import ErrorCode, PlannerError, invalid
from squeeze_grasp_ros.planning.object_ids import (
    check_digest,
    check_object_id,
    replaced,
    shown,
    taken,
)
from squeeze_grasp_ros.scene import Scene, build_outline, parse_scene, requested_nodes
from squeeze_grasp_ros.scene.setup import RING_STAGES, SOLID_STAGES, GraspSetup

CONTACT_MODELS: tuple[str, ...] = ContactKind.values()
MAX_BEST_COUNT = 100_000
"""Most placements one grasp map may return as candidates."""
MAX_PATH_CHARS = 4096
"""Longest ``scene_path`` (PATH_MAX on Linux): messages quote the path when they refuse it."""

Progress = Callable[[str, int, int, int], None]
"""Called as ``progress(stage, index, count, num_nodes)`` when a stage starts (the stages of
:data:`SOLID_STAGES`, :data:`RING_STAGES`); may raise :class:`Cancelled` to stop the
computation."""


# --------------------------------------------------------------------------- limits and objects


@dataclass(frozen=True)
class PlannerLimits:
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
    max_bytes : int or None
        Most memory a load may need (the cache's bound): a mesh whose dense blocks would need
        more is refused before its factorisation (:mod:`.budget`); None = no bound.
    """

    max_nodes: int = 60_000
    max_spectral_nodes: int = 3_000
    max_ring_elements: int = 1_000
    default_route: str = "factorized"
    best_count: int = 10
    min_step: float = 1e-5
    max_bytes: int | None = None


class GraspMapCache:
    """Grasp maps of one loaded object by friction coefficient, the newest ``size`` kept.

    The map is of point contacts (Sec. 4: stiffness, inwardness and force closure of node
    pairs), so the solid and mu are its whole key: a gripper's pads, opening or the request's
    yaw range enter only the ranking made from it. Thread-safe; two workers asking for a missing
    map at once may both compute it (the same map), none waits for the other.

    Attributes
    ----------
    hits, misses : int
        Requests served from the cache, and computed.
    """

    def __init__(self, size: int = 4) -> None:
        self.size = size
        self.maps: OrderedDict[float, GraspMap] = OrderedDict()
        self.lock = threading.Lock()
        self.hits = self.misses = 0

    def get(self, mu: float, compute: Callable[[], GraspMap]) -> GraspMap:
        """The map at ``mu``: cached, else ``compute()`` and kept."""
        with self.lock:
            if mu in self.maps:
                self.hits += 1
                self.maps.move_to_end(mu)
                return self.maps[mu]
            self.misses += 1
        gmap = compute()
        with self.lock:
            self.maps[mu] = gmap
            while len(self.maps) > self.size:
                self.maps.popitem(last=False)
        return gmap


@dataclass(frozen=True)
class LoadedObject:
    """An object with its precomputed mechanics, as the planner caches it.

    Attributes
    ----------
    object_id : str
    setup : GraspSetup
        The scene made mechanics: the scene (fingers, friction, limits, squeeze defaults), the
        precomputed body (factorisation and boundary compliance of a solid, or the ring's
        compliance) and the fingers' initial contact nodes.
    digest : str
        SHA-256 of the scene text and the solver route: same digest, same object.
    precompute_time : float
        Wall time of meshing and precompute, s.
    maps : GraspMapCache
        The grasp maps computed for this object (:meth:`grasp_map`); a reload builds a new
        object, so they go with the old one.
    """

    object_id: str
    setup: GraspSetup
    digest: str
    precompute_time: float
    maps: GraspMapCache = field(default_factory=lambda: GraspMapCache(), compare=False,
                                repr=False)

    def grasp_map(self, mu: float) -> GraspMap:
        """The all-pairs grasp map of the solid at friction ``mu``, computed once per mu."""
        return self.maps.get(float(mu), lambda: grasp_map(self.solid(), float(mu)))

    @property
    def scene(self) -> Scene:
        """The validated scene the object came from."""
        return self.setup.scene

    @property
    def body(self) -> ElasticObject | RingModel:
        """The precomputed solid or ring model."""
        return self.setup.body

    @property
    def finger_nodes(self) -> tuple[int, int]:
        """Initial contact nodes of F1, F2 from the scene's placements."""
        return self.setup.contacts

    @property
    def model(self) -> ObjectModel:
        """Body model: solid (FEM mesh) or ring (curved beam)."""
        return self.setup.model

    @property
    def num_nodes(self) -> int:
        """Mesh nodes (solid) or ring nodes."""
        return self.setup.num_nodes

    @property
    def boundary(self) -> np.ndarray:
        """Nodes a finger can touch: the outer boundary loop (solid) or every ring node."""
        return self.setup.boundary

    def solid(self) -> ElasticObject:
        """The FEM object; a ring raises INVALID_ARGUMENT naming the service to use."""
        if self.setup.is_ring:
            raise invalid(
                f"object {self.object_id!r} is a ring model (Sec. 7): use the "
                "ring_grasp_test service"
            )
        return self.setup.solid

    def ring(self) -> RingModel:
        """The ring model; a solid raises INVALID_ARGUMENT."""
        if not self.setup.is_ring:
            raise invalid(
                f"object {self.object_id!r} is a solid (object.model: solid), not a ring"
            )
        return self.setup.ring


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
    if len(scene_path) > MAX_PATH_CHARS:
        raise invalid(f"scene_path has {len(scene_path)} characters, more than {MAX_PATH_CHARS}")
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
        if roots is not None and shape["type"] == ShapeType.FILE:
            confine(shape["path"], roots, what="object.shape.path")
    except InputError as exc:
        raise invalid(str(exc)) from None
    return SceneSource(scene, text)


def check_size(count: int | None, limit: int, what: str) -> None:
    """Refuse a model with more than ``limit`` nodes (INVALID_ARGUMENT, oversized).

    A count of 16 digits or more is given to 3 significant digits: ``mesh.max_area: 1e-308``
    asks for an integer of 306 digits, which the message quoted whole.

    >>> check_size(10**306 * 8, 60000, "factorized mesh")
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.planning.errors.PlannerError: oversized factorized mesh: 8e+306 nodes, \
more than the planner's limit of 60000 (parameter); coarsen object.mesh or object.ring
    """
    if count is not None and count > limit:
        shown_count = f"{count:.3g}" if count >= 10**15 else f"{count}"
        raise invalid(
            f"oversized {what}: {shown_count} nodes, more than the planner's limit of "
            f"{limit} (parameter); coarsen object.mesh or object.ring"
        )


def node_limit(route: str, limits: PlannerLimits) -> int:
    """Most mesh nodes of a solid on solver ``route``."""
    return limits.max_nodes if route == "factorized" else limits.max_spectral_nodes


def check_requested(scene: Scene, route: str, limits: PlannerLimits) -> None:
    """Refuse, before anything is built, a scene that asks for more nodes than the planner's
    limits (INVALID_ARGUMENT, oversized) or whose outline is invalid (e.g. self-intersecting).
    """
    if scene.object.model == ObjectModel.RING:
        check_size(requested_nodes(scene), limits.max_ring_elements, "ring model")
    else:
        build_outline(scene.object.shape)
        check_size(requested_nodes(scene), node_limit(route, limits), f"{route} mesh")


def solver_route(route: str, limits: PlannerLimits) -> str:
    """The request's solver route, or the node's default when empty."""
    route = route or limits.default_route
    if route not in ROUTES:
        raise invalid(f"solver_route must be one of {list(ROUTES)} or empty, got {shown(route)}")
    return route


def no_progress(stage: str, index: int, count: int, num_nodes: int) -> None:
    """A :data:`Progress` that ignores every stage."""


@dataclass(frozen=True)
class ObjectKey:
    """Where and how a scene's object is built.

    Attributes
    ----------
    object_id : str
        The request's id, else the scene's name, else ``object-<digest prefix>``
        (:func:`~.object_ids.check_object_id`).
    route : str
        Solver route (the node's default when the request leaves it empty).
    digest : str
        SHA-256 of the route and the scene text: same digest, same object.
    """

    object_id: str
    route: str
    digest: str


def object_key(source: SceneSource, object_id: str, route: str,
               limits: PlannerLimits) -> ObjectKey:
    """The :class:`ObjectKey` of a load request."""
    route = solver_route(route, limits)
    digest = hashlib.sha256(f"{route}\0{source.text}".encode()).hexdigest()
    if object_id:
        object_id = check_object_id(object_id)
    elif source.scene.name:
        object_id = check_object_id(source.scene.name, "the scene's name (the default object_id)")
    return ObjectKey(object_id or f"object-{digest[:12]}", route, digest)


def load_object(
    source: SceneSource, key: ObjectKey, limits: PlannerLimits, progress: Progress = no_progress
) -> LoadedObject:
    """Build and precompute the object of a scene, stage by stage.

    Parameters
    ----------
    source : SceneSource
        The scene (see :func:`read_scene`).
    key : ObjectKey
        Id, solver route (rings ignore it) and digest (see :func:`object_key`).
    limits : PlannerLimits
    progress : Progress
        Called with :data:`SOLID_STAGES` or :data:`RING_STAGES` as they start.

    Raises
    ------
    PlannerError
        INVALID_ARGUMENT for an oversized or invalid model, CANCELLED from ``progress``.
    """
    scene = source.scene
    start = time.perf_counter()
    check_requested(scene, key.route, limits)
    if scene.object.model == ObjectModel.RING:
        progress(RING_STAGES[0], 0, len(RING_STAGES), 0)
        setup = GraspSetup.build(scene)
    else:
        progress(SOLID_STAGES[0], 0, len(SOLID_STAGES), 0)
        setup = GraspSetup.build(scene, route=key.route, max_nodes=node_limit(key.route, limits))
        mesh = setup.solid.mesh
        check_load(boundary_nodes=len(mesh.boundary), nodes=mesh.n, route=key.route,
                   max_bytes=limits.max_bytes)
    setup.precompute(progress)
    _ = setup.contacts  # the placements are checked at load, not at the first request
    return LoadedObject(key.object_id, setup, key.digest, time.perf_counter() - start)


def resident_bytes(value: object) -> int:
    """Bytes of the arrays an object holds: numpy arrays, scipy sparse matrices and SuperLU
    factors reached through dataclass fields, instance and cached-property dicts, and
    containers, each counted once. Python object overhead is not counted (it is small next to
    a mesh's compliance and factorisation).

    A SuperLU object also keeps the sparse L and U it built once they were read (scipy caches
    them; as large as the factorisation): the factorized solver holds them in an attribute so
    that they are counted (before, a 20,000-node object was counted at 111 MiB and held 205
    MiB; now 188 MiB counted against 208 MiB of RSS).
    """
    seen: set[int] = set()
    stack, total = [value], 0
    while stack:
        item = stack.pop()
        if id(item) in seen or item is None or isinstance(item, (str, bytes, int, float, bool)):
            continue
        seen.add(id(item))
        if isinstance(item, np.ndarray):
            total += item.nbytes
        elif sp.issparse(item):
            total += sum(getattr(item, a).nbytes for a in ("data", "indices", "indptr", "row",
                                                           "col") if hasattr(item, a))
        elif type(item).__name__ == "SuperLU":
            total += 12 * item.nnz + 8 * 2 * item.shape[0]
        elif isinstance(item, dict):
            stack.extend(item.values())
        elif isinstance(item, (list, tuple, set, frozenset)):
            stack.extend(item)
        elif hasattr(item, "__dict__") or hasattr(item, "__slots__"):
            stack.extend(getattr(item, "__dict__", {}).values())
            stack.extend(getattr(item, s) for s in getattr(item, "__slots__", ())
                         if hasattr(item, s))
    return total


class ObjectCache:
    """Loaded objects by id, least recently used evicted first; safe to share between threads.

    Parameters
    ----------
    capacity : int
        Most objects kept (>= 1).
    max_bytes : int, optional
        Most bytes of arrays (:func:`resident_bytes`) kept; least recently used objects are
        evicted until the cache fits, and an object larger than this alone is refused.
    """

    def __init__(self, capacity: int, max_bytes: int | None = None) -> None:
        if capacity < 1:
            raise ValueError(f"cache capacity must be >= 1, got {capacity}")
        if max_bytes is not None and max_bytes < 1:
            raise ValueError(f"cache max_bytes must be >= 1, got {max_bytes}")
        self.capacity = capacity
        self.max_bytes = max_bytes
        self._objects: OrderedDict[str, LoadedObject] = OrderedDict()
        self._bytes: dict[str, int] = {}
        self._lock = threading.Lock()

    @property
    def bytes(self) -> int:
        """Bytes of arrays held by the cached objects, counted now."""
        with self._lock:
            self._recount()
            return sum(self._bytes.values())

    def _recount(self) -> None:
        """Count again what each cached object holds: its caches (load gradients, gradient
        operators) fill as requests use it, after it was counted on entry (lock held).
        """
        for object_id, held in self._objects.items():
            self._bytes[object_id] = resident_bytes(held.body)

    def get(self, object_id: str, digest: str = "") -> LoadedObject:
        """The object loaded under ``object_id`` (now the most recently used).

        Parameters
        ----------
        object_id : str
        digest : str
            The ``object_digest`` the client's load returned, or "" (not checked).

        Raises
        ------
        PlannerError
            UNKNOWN_OBJECT when no object or, with ``digest``, another object is loaded under
            ``object_id`` (:mod:`.object_ids`). The message does not list the loaded ids: they
            belong to other clients.
        """
        check_digest(digest)
        with self._lock:
            loaded = self._objects.get(object_id)
            if loaded is None:
                raise PlannerError(
                    ErrorCode.UNKNOWN_OBJECT,
                    f"unknown object_id {shown(object_id)}: load it first with "
                    "load_object (objects are evicted when the cache is full)",
                )
            if digest and loaded.digest != digest:
                raise replaced(object_id, loaded.digest, digest)
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

    def check_free(self, object_id: str, digest: str) -> None:
        """Refuse a load of ``digest`` under ``object_id`` while it holds another object.

        Raises
        ------
        PlannerError
            INVALID_ARGUMENT naming the id and the digest it holds (:mod:`.object_ids`).
        """
        with self._lock:
            held = self._objects.get(object_id)
        if held is not None and held.digest != digest:
            raise taken(object_id, held.digest)

    def put(self, loaded: LoadedObject, replace: bool = False) -> list[str]:
        """Store ``loaded``; return the evicted ids.

        Raises
        ------
        PlannerError
            INVALID_ARGUMENT if the object alone needs more than ``max_bytes``, or if another
            object is loaded under its id and not ``replace`` (:mod:`.object_ids`).
        """
        size = resident_bytes(loaded.body)
        if self.max_bytes is not None and size > self.max_bytes:
            raise PlannerError(
                ErrorCode.INVALID_ARGUMENT,
                f"object {loaded.object_id!r} needs {size / 2**20:.0f} MiB, more than the "
                f"cache allows ({self.max_bytes / 2**20:.0f} MiB, planner parameter "
                "cache_max_megabytes); use a coarser mesh",
            )
        with self._lock:
            held = self._objects.get(loaded.object_id)
            if held is not None and held.digest != loaded.digest and not replace:
                raise taken(loaded.object_id, held.digest)
            self._objects[loaded.object_id] = loaded
            self._bytes[loaded.object_id] = size
            self._objects.move_to_end(loaded.object_id)
            self._recount()
            evicted = []
            while len(self._objects) > self.capacity or (
                    self.max_bytes is not None and len(self._objects) > 1
                    and sum(self._bytes.values()) > self.max_bytes):
                old, _ = self._objects.popitem(last=False)
                del self._bytes[old]
                evicted.append(old)
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
    limits: PlannerLimits,
    progress: Progress = no_progress,
    replace: bool = False,
) -> tuple[LoadedObject, bool]:
    """The cached object of the same id, scene and route, or a freshly loaded and cached one.

    A load under an id that holds another object is refused unless ``replace``
    (:mod:`.object_ids`), after the request's size checks and before any other work.

    Returns
    -------
    (LoadedObject, bool)
        The object and whether it came from the cache.
    """
    key = object_key(source, object_id, route, limits)
    cached = cache.find(key.object_id, key.digest)
    if cached is not None:
        return cached, True
    check_requested(source.scene, key.route, limits)
    if not replace:
        cache.check_free(key.object_id, key.digest)
    loaded = load_object(source, key, limits, progress)
    cache.put(loaded, replace)
    return loaded, False
