# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The neo-Hookean assembly's compiled kernel (numba, the ``fast`` extra) against the numpy
route, against its own derivatives and run uncompiled; and a neo-Hookean squeeze by either
route (events, forces).
"""
from __future__ import annotations

import numpy as np
import pytest
from foam_support import foam_square

from squeeze_grasp_ros.api import event_squeeze
from squeeze_grasp_ros.mechanics.elastic import hyperelastic as H
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE

numba = pytest.importorskip("numba", reason="the fast extra is not installed: "
                                            "pip install '.[fast]'")
from squeeze_grasp_ros.mechanics.elastic import hyperelastic_numba  # noqa: E402


@pytest.fixture(scope="module")
def patch():
    """An irregular mesh of a 0.1 x 0.06 m rectangle and a smooth field with strains of about
    10 % plus noise (every element upright).
    """
    mesh = generate_mesh(shapes.rectangle(0.1, 0.06), 3e-4, min_angle=25.0)
    rng = np.random.default_rng(3)
    X = mesh.nodes
    u = np.column_stack([0.004 * np.sin(60 * X[:, 1]),
                         -0.1 * X[:, 1] + 0.003 * np.cos(50 * X[:, 0])])
    u = u.reshape(-1) + 2e-6 * rng.standard_normal(2 * mesh.n)
    return mesh, u


def _both(mesh, u, *, tangent=True):
    plain = H.mesh_geometry(mesh.nodes, mesh.triangles)
    compiled = H.mesh_geometry(mesh.nodes, mesh.triangles, compiled=True)
    return [H.assemble("neo_hookean", mesh.nodes, mesh.triangles, u, nu=0.3, geometry=g,
                       tangent=tangent) for g in (plain, compiled)]


def test_the_compiled_assembly_is_the_numpy_one(patch):
    """Energy and forces equal to the numpy route's to round-off (measured 7e-16; only the
    order of the sums differs), the tangent equal bit for bit (the numpy route forms the
    kernel's closed form with the kernel's products) and symmetric bit for bit.
    """
    mesh, u = patch
    numpy_, compiled = _both(mesh, u)
    assert 0.05 < -H.determinants(numpy_.deformation).min() + 1.0 < 0.5  # a real deformation
    assert compiled.energy == pytest.approx(numpy_.energy, rel=1e-13)
    assert np.abs(compiled.force - numpy_.force).max() <= 1e-13 * np.abs(numpy_.force).max()
    K, K0 = compiled.tangent, numpy_.tangent
    assert np.array_equal(K.data, K0.data)
    assert (K - K.T).count_nonzero() == 0
    geometry = H.mesh_geometry(mesh.nodes, mesh.triangles, compiled=True)
    lean = H.assemble("neo_hookean", mesh.nodes, mesh.triangles, u, nu=0.3, geometry=geometry,
                      tangent=False)
    added = H.with_tangent("neo_hookean", lean, nu=0.3, geometry=geometry)
    assert np.array_equal(added.tangent.data, K.data) and np.array_equal(added.force,
                                                                          compiled.force)
    only = _both(mesh, u, tangent=False)[1]
    assert only.tangent is None and np.array_equal(only.force, compiled.force)


def test_the_compiled_tangent_is_the_derivative_of_its_forces(patch):
    """Central differences of the compiled route's energy and forces (an independent check of
    the closed-form element stiffness).
    """
    mesh, u = patch
    geometry = H.mesh_geometry(mesh.nodes, mesh.triangles, compiled=True)
    d = np.random.default_rng(5).standard_normal(2 * mesh.n)

    def at(x):
        return H.assemble("neo_hookean", mesh.nodes, mesh.triangles, x, nu=0.3,
                          geometry=geometry)

    a, h = at(u), 1e-7
    up, um = at(u + h * d), at(u - h * d)
    assert (up.energy - um.energy) / (2 * h) == pytest.approx(a.force @ d, rel=1e-6)
    fd = (up.force - um.force) / (2 * h)
    assert np.linalg.norm(fd - a.tangent @ d) < 1e-6 * np.linalg.norm(fd)


def test_the_kernel_uncompiled_gives_the_same_floats(patch):
    """``py_func`` (the same code run by the interpreter) on a few elements: bit for bit."""
    mesh, u = patch
    g = H.mesh_geometry(mesh.nodes, mesh.triangles)
    F = g.deformation(u)[:40]
    det = H.determinants(F)
    lam, mu = H._lame(0.3)
    l3 = H.thickness_stretch("neo_hookean", F, nu=0.3)
    args = (F, l3, np.log(det * l3), g.shape_gradients[:40], g.area[:40], g.dofs[:40],
            g.slots.reshape(-1, 36)[:40], lam, mu)
    out = []
    for kernel in (hyperelastic_numba.neo_hookean, hyperelastic_numba.neo_hookean.py_func):
        force, data = np.zeros(g.n2), np.zeros(len(g.indices))
        out.append((kernel(*args, force, data), force, data))
    assert out[0][0] == out[1][0]
    assert np.array_equal(out[0][1], out[1][1]) and np.array_equal(out[0][2], out[1][2])


def test_a_neo_hookean_squeeze_by_either_route(monkeypatch):
    """The foam square at 12 %, friction 0.05 (sliding) and 0.4, by the numpy route and by the
    compiled one (``SQUEEZE_GRASP_KERNEL=numba``, which assembles by the kernel): the same
    events (type, node, finger, mode, slip), depths to 1e-10 L (the event tolerance is
    1e-9 L), forces and energy to 1e-9.
    """
    _, obj, contacts = foam_square(500)
    calls = []
    kernel = hyperelastic_numba.neo_hookean
    monkeypatch.setattr(hyperelastic_numba, "neo_hookean",
                        lambda *a: calls.append(1) or kernel(*a))
    for mu in (0.05, 0.4):
        runs = {}
        for route in ("numpy", "numba"):
            monkeypatch.setenv(KERNEL_VARIABLE, route)
            runs[route] = event_squeeze(obj, contacts, 0.02, mu, material_model="neo_hookean",
                                        relative_depth=0.12)
            assert bool(calls) == (route == "numba")
        a, b = runs["numpy"], runs["numba"]

        def events(res):
            return [(e.type, e.node, e.finger, e.mode, e.slip) for e in res.events]

        assert len(a.events) >= 4 and events(a) == events(b) and a.termination == b.termination
        assert max(abs(x.depth - y.depth) for x, y in zip(a.events, b.events)) < 1e-10 * obj.scale
        for finger in ("F1", "F2"):
            assert b.finger_force[finger] == pytest.approx(a.finger_force[finger], rel=1e-9)
        assert b.energy == pytest.approx(a.energy, rel=1e-9)
        calls.clear()


def test_large_objects_assemble_compiled_unless_the_route_is_chosen(monkeypatch):
    """With SQUEEZE_GRASP_KERNEL unset and numba installed, objects of at least
    COMPILED_ASSEMBLY_NODES nodes assemble the neo-Hookean law compiled (there a squeeze saves
    more than numba's start-up), smaller ones by numpy; a route set in the variable wins either
    way; the squeeze's diagnostics name the assembly route, and the kernel runs only when they
    say numba.
    """
    from squeeze_grasp_ros.mechanics.squeeze import nonlinear_model as N

    monkeypatch.delenv(KERNEL_VARIABLE, raising=False)
    large = N.COMPILED_ASSEMBLY_NODES
    assert N.compiled_assembly(large) and not N.compiled_assembly(large - 1)
    monkeypatch.setenv(KERNEL_VARIABLE, "numpy")
    assert not N.compiled_assembly(10 * large)
    monkeypatch.setenv(KERNEL_VARIABLE, "numba")
    assert N.compiled_assembly(1)
    monkeypatch.delenv(KERNEL_VARIABLE)
    calls = []
    kernel = hyperelastic_numba.neo_hookean
    monkeypatch.setattr(hyperelastic_numba, "neo_hookean",
                        lambda *a: calls.append(1) or kernel(*a))
    _, obj, contacts = foam_square(300)
    for threshold, route in ((large, "numpy"), (obj.mesh.n, "numba")):
        monkeypatch.setattr(N, "COMPILED_ASSEMBLY_NODES", threshold)
        res = event_squeeze(obj, contacts, 0.02, 0.4, material_model="neo_hookean",
                            relative_depth=0.03)
        assert res.diagnostics["nonlinear"]["assembly"] == route
        assert bool(calls) == (route == "numba")
