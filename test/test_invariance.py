# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Physical invariances of the event-driven squeeze, as properties over random inputs.

Through the public API (:mod:`squeeze_grasp_ros.api`) on a small nonconvex object (about 240
nodes, so every squeeze takes well under a second): a rigid motion of the object with its
finger placements, a mirror image, a mirror-symmetric object squeezed symmetrically, the
scaling of forces with E, the thickness and the size, at the ends of the material's ranges, and
a perturbation of one part in a billion of an input.
Each compares events (type, node, finger, mode), event depths, forces, energy and the
displacement field with a reference squeeze, and asserts every returned float is finite.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from functools import cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.api import (
    ElasticObject,
    Material,
    Mesh,
    event_squeeze,
    generate_mesh,
    polygon,
)
from squeeze_grasp_ros.mechanics.elastic.material import E_RANGE, THICKNESS_RANGE
from squeeze_grasp_ros.mechanics.elastic.mesh import mesh_from_triangles

MODELS = ("linear", "corotational", "neo_hookean")
OUTLINE = [[0, 0], [0.04, 0], [0.045, 0.03], [0.01, 0.035], [0, 0.03]]
"""A skewed pentagon (m): no symmetry that could hide a frame-dependent term."""
TIP, MU, RELATIVE_DEPTH = 0.02, 0.4, 0.15
RTOL = {"linear": 1e-9, "corotational": 1e-7, "neo_hookean": 1e-7}
"""Relative tolerance of forces and energy between frames: round-off for the linear model, the
finite-deformation Newton's accuracy (RESPONSE_ACCURACY, 1e-8 of the force) for the others,
whose adaptive substeps take another path in another frame (seen: energy 2.4e-8, an event's
depth 1.3e-8 of the size, the displacement field 1.1e-7 of its largest)."""
FOAM = Material(E=1e5, nu=0.3, thickness=0.01)


def nonfinite_fields(value, path: str = "result") -> list[str]:
    """Paths of every non-finite float in a result (dataclasses, mappings, sequences, arrays)."""
    if isinstance(value, (float, np.floating)):
        return [] if math.isfinite(value) else [path]
    if isinstance(value, np.ndarray):
        return [] if value.dtype.kind != "f" or np.all(np.isfinite(value)) else [path]
    if isinstance(value, (str, bytes, enum.Enum, int, type(None))):
        return []
    if dataclasses.is_dataclass(value):
        return [p for f in dataclasses.fields(value)
                for p in nonfinite_fields(getattr(value, f.name), f"{path}.{f.name}")]
    if hasattr(value, "items"):
        return [p for k, v in value.items() for p in nonfinite_fields(v, f"{path}[{k!r}]")]
    if isinstance(value, (list, tuple)):
        return [p for k, v in enumerate(value) for p in nonfinite_fields(v, f"{path}[{k}]")]
    return []


@cache
def pentagon() -> tuple[Mesh, tuple[int, int]]:
    """The object's mesh and the boundary nodes nearest (0, 0.012) and (0.0425, 0.017)."""
    mesh = generate_mesh(polygon(OUTLINE), 5e-6)
    b = mesh.boundary

    def nearest(point):
        return int(b[np.argmin(np.hypot(*(mesh.nodes[b] - point).T))])

    return mesh, (nearest([0.0, 0.012]), nearest([0.0425, 0.017]))


def squeeze(mesh: Mesh, contacts, model: str, material: Material = FOAM, scale: float = 1.0,
            mu: float = MU, **kw):
    result = event_squeeze(ElasticObject(mesh, material), contacts, TIP * scale, mu,
                           relative_depth=RELATIVE_DEPTH, material_model=model, **kw)
    assert not nonfinite_fields(result), nonfinite_fields(result)
    return result


@cache
def reference(model: str):
    mesh, contacts = pentagon()
    return squeeze(mesh, contacts, model)


def events(result) -> list[tuple]:
    return [(e.type, e.node, e.finger, e.mode) for e in result.events]


def assert_same_squeeze(result, base, *, size: float, depth_scale: float = 1.0,
                        force_scale: float = 1.0) -> None:
    """Same termination and events; forces and energy within the model's :data:`RTOL` after
    scaling, depths within 10 RTOL of the size.
    """
    rtol = RTOL[base.material_model]
    assert result.termination == base.termination
    assert events(result) == events(base)
    depths = np.array([e.depth for e in result.events])
    assert np.abs(depths - depth_scale * np.array([e.depth for e in base.events])).max(
        initial=0.0) <= 10 * rtol * size
    for finger, (start, end) in base.finger_force.items():
        assert result.finger_force[finger][1] == pytest.approx(force_scale * end, rel=rtol)
    assert result.energy == pytest.approx(force_scale * depth_scale * base.energy, rel=rtol)


def rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


@pytest.mark.parametrize("model", MODELS)
@settings(max_examples=3, deadline=None)
@given(angle=st.floats(-math.pi, math.pi),
       shift=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)))
def test_a_rigid_motion_of_object_and_placements_gives_the_same_squeeze(model, angle, shift):
    """Turn and move the object (up to 20 times its size) with its finger placements: the same
    events at the same depths, the same forces and energy, the displacement field turned.
    """
    mesh, contacts = pentagon()
    base = reference(model)
    Q = rotation(angle)
    moved = Mesh(mesh.nodes @ Q.T + np.array(shift), mesh.triangles, mesh.boundary,
                 mesh.inner_boundaries, mesh.normals @ Q.T)
    res = squeeze(moved, contacts, model)
    assert_same_squeeze(res, base, size=mesh.size)
    u, u0 = res.displacement, base.displacement @ Q.T
    assert np.abs(u - u0).max() <= 10 * RTOL[model] * np.abs(u0).max()


@pytest.mark.parametrize("model", MODELS)
@settings(max_examples=2, deadline=None)
@given(axis=st.floats(0.0, math.pi))
def test_a_mirror_image_gives_the_mirrored_squeeze(model, axis):
    """Reflect the object about a line at angle ``axis``: the squeeze is the mirror image (the
    same events by node, finger and mode; the same forces and energy).
    """
    mesh, contacts = pentagon()
    base = reference(model)
    Q = rotation(axis)
    S = Q @ np.diag([1.0, -1.0]) @ Q.T
    mirrored = mesh_from_triangles(mesh.nodes @ S.T, mesh.triangles)
    res = squeeze(mirrored, contacts, model)
    assert_same_squeeze(res, base, size=mesh.size)
    u, u0 = res.displacement, base.displacement @ S.T
    assert np.abs(u - u0).max() <= 10 * RTOL[model] * np.abs(u0).max()


@cache
def symmetric_object() -> tuple[Mesh, np.ndarray]:
    """A mesh symmetric about x = 0 (its half x >= 0 meshed and mirrored) and the node map of
    the mirror.
    """
    half = generate_mesh(polygon([[0, -0.02], [0.025, -0.02], [0.03, 0.0], [0.02, 0.02],
                                  [0, 0.025]]), 5e-6)
    nodes = half.nodes.copy()
    on_axis = np.abs(nodes[:, 0]) < 1e-12
    nodes[on_axis, 0] = 0.0
    off = np.flatnonzero(~on_axis)
    image = np.arange(len(nodes))
    image[off] = len(nodes) + np.arange(len(off))
    mesh = mesh_from_triangles(np.vstack([nodes, nodes[off] * [-1.0, 1.0]]),
                               np.vstack([half.triangles, image[half.triangles][:, ::-1]]))
    mirror = np.empty(mesh.n, int)
    mirror[: len(nodes)] = image
    mirror[image] = np.arange(len(nodes))
    assert np.array_equal(mesh.nodes[mirror] * [-1.0, 1.0], mesh.nodes)
    return mesh, mirror


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("kind", ["stable", "pure"])
def test_a_symmetric_object_squeezed_symmetrically_stays_symmetric(model, kind):
    """Fingers at mirror nodes of a mirror-symmetric object: equal finger forces, each event of
    F1 at the mirror node of one of F2 at the same depth, and a mirror-symmetric displacement.
    """
    mesh, mirror = symmetric_object()
    b = mesh.boundary
    right = int(b[np.argmin(np.hypot(*(mesh.nodes[b] - [0.03, 0.0]).T))])
    res = squeeze(mesh, (int(mirror[right]), right), model, kind=kind)
    assert res.termination == "depth_reached" and res.events
    f1, f2 = res.finger_force["F1"][1], res.finger_force["F2"][1]
    assert f1 == pytest.approx(f2, rel=1e-9)
    left = sorted((str(e.type), int(mirror[e.node]), e.mode, e.depth) for e in res.events
                  if e.finger == "F1")
    right_events = sorted((str(e.type), e.node, e.mode, e.depth) for e in res.events
                          if e.finger == "F2")
    assert [e[:3] for e in left] == [e[:3] for e in right_events]
    assert np.allclose([e[3] for e in left], [e[3] for e in right_events], rtol=0,
                       atol=1e-9 * mesh.size)
    u = res.displacement
    assert np.abs(u[mirror] * [-1.0, 1.0] - u).max() <= 1e-9 * np.abs(u).max()


@settings(max_examples=6, deadline=None)
@given(model=st.sampled_from(MODELS),
       log_E=st.floats(math.log10(E_RANGE[0]), math.log10(E_RANGE[1])),
       log_h=st.floats(math.log10(THICKNESS_RANGE[0]), math.log10(THICKNESS_RANGE[1])),
       log_size=st.floats(-4.0, 4.0))
def test_forces_scale_with_E_thickness_and_size_across_the_material_ranges(model, log_E,
                                                                           log_h, log_size):
    """Plane stress with the same shape and relative depth: depths scale with the size k,
    forces with E h k and the energy with E h k^2, at every E and thickness a Material takes
    (the same events; every returned float finite).
    """
    mesh, contacts = pentagon()
    E, h, k = 10.0**log_E, 10.0**log_h, 10.0**log_size
    scaled = Mesh(mesh.nodes * k, mesh.triangles, mesh.boundary, mesh.inner_boundaries,
                  mesh.normals)
    res = squeeze(scaled, contacts, model, Material(E, FOAM.nu, h), scale=k)
    ratio = (E * h) / (FOAM.E * FOAM.thickness)
    assert_same_squeeze(res, reference(model), size=k * mesh.size, depth_scale=k,
                        force_scale=ratio * k)


@settings(max_examples=4, deadline=None)
@given(model=st.sampled_from(MODELS), which=st.sampled_from(["mu", "tip", "E", "nodes"]),
       sign=st.sampled_from([-1.0, 1.0]), seed=st.integers(0, 2**16))
def test_a_perturbation_of_one_part_in_a_billion_moves_the_squeeze_continuously(model, which,
                                                                                sign, seed):
    """mu, the tip radius, E or every node moved by 1e-9 (relative, or of the size): the same
    events, depths within 1e-6 of the size and forces within 1e-6 (seen: 1.8e-8 and 4e-9).
    """
    mesh, contacts = pentagon()
    base = reference(model)
    eps = sign * 1e-9
    if which == "nodes":
        noise = np.random.default_rng(seed).standard_normal(mesh.nodes.shape)
        mesh = Mesh(mesh.nodes + eps * mesh.size * noise, mesh.triangles, mesh.boundary,
                    mesh.inner_boundaries, mesh.normals)
    res = squeeze(mesh, contacts, model,
                  material=Material(FOAM.E * (1 + eps), FOAM.nu, FOAM.thickness)
                  if which == "E" else FOAM,
                  scale=1 + eps if which == "tip" else 1.0,
                  mu=MU * (1 + eps) if which == "mu" else MU)
    assert res.termination == base.termination
    assert events(res) == events(base)
    assert np.allclose([e.depth for e in res.events], [e.depth for e in base.events], rtol=0,
                       atol=1e-6 * mesh.size)
    for finger, (_, end) in base.finger_force.items():
        assert res.finger_force[finger][1] == pytest.approx(end, rel=1e-6)
