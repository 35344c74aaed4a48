# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Finite-deformation material models: the laws (derivatives, frame indifference, patch test,
small-strain limit, inversion), an independent assembly with scikit-fem, and the event-driven
squeeze on corotational and neo-Hookean objects (agreement with linear as the depth vanishes,
rotated scenes, work = energy, scaling with E, nu near 0.5).
"""
from __future__ import annotations

import re

import numpy as np
import pytest
from foam_support import foam_square
from hypothesis import given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.api import (
    ElasticObject,
    Material,
    NumericalError,
    event_squeeze,
    scene_file,
)
from squeeze_grasp_ros.mechanics.elastic import hyperelastic as H
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.contact_response import ContactResponse
from squeeze_grasp_ros.mechanics.elastic.fem import stiffness_matrix
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, mesh_from_triangles
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

MODELS = ("linear", "corotational", "neo_hookean")
NONLINEAR = ("corotational", "neo_hookean")


def rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


@pytest.fixture(scope="module")
def patch():
    """An irregular mesh of a 0.1 x 0.06 m rectangle."""
    return generate_mesh(shapes.rectangle(0.1, 0.06), 2e-4, min_angle=25.0)


@pytest.mark.parametrize("model", MODELS)
def test_forces_and_tangent_are_the_derivatives(model, patch):
    rng = np.random.default_rng(7)
    u = 0.003 * rng.standard_normal(2 * patch.n)
    d = rng.standard_normal(2 * patch.n)
    a = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3)
    h = 1e-7
    up = H.assemble(model, patch.nodes, patch.triangles, u + h * d, nu=0.3)
    um = H.assemble(model, patch.nodes, patch.triangles, u - h * d, nu=0.3)
    assert (up.energy - um.energy) / (2 * h) == pytest.approx(a.force @ d, rel=1e-6)
    fd = (up.force - um.force) / (2 * h)
    assert np.linalg.norm(fd - a.tangent @ d) < 1e-6 * np.linalg.norm(fd)
    assert abs(a.tangent - a.tangent.T).max() < 1e-12 * abs(a.tangent).max()


@pytest.mark.parametrize("model", MODELS)
def test_a_forces_only_assembly_is_the_full_one_without_the_tangent(model, patch):
    u = 0.001 * np.random.default_rng(3).standard_normal(2 * patch.n)
    full = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3)
    lean = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3, tangent=False)
    assert lean.tangent is None and full.tangent is not None
    assert lean.energy == full.energy and np.array_equal(lean.force, full.force)


@pytest.mark.parametrize("model", MODELS)
def test_a_tangent_added_to_a_forces_only_assembly_is_the_full_one(model, patch):
    """``with_tangent`` (Newton's tangent of a state it assembled forces-only, reusing its
    deformation and thickness stretches): the floats of a full assembly; the neo-Hookean
    tangent (closed form, upper triangle mirrored) symmetric bit for bit.
    """
    u = 0.003 * np.random.default_rng(4).standard_normal(2 * patch.n)
    geometry = H.mesh_geometry(patch.nodes, patch.triangles)
    full = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3, geometry=geometry)
    lean = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3, geometry=geometry,
                      tangent=False)
    added = H.with_tangent(model, lean, nu=0.3, geometry=geometry)
    assert lean.tangent is None and added.energy == full.energy
    assert np.array_equal(added.force, full.force)
    assert np.array_equal(added.tangent.data, full.tangent.data)
    assert H.with_tangent(model, full, nu=0.3, geometry=geometry) is full
    if model == "neo_hookean":
        assert (full.tangent - full.tangent.T).count_nonzero() == 0


def test_a_thickness_newton_from_a_nearby_state_gives_the_same_law(patch):
    """Neo-Hookean stretches started from a nearby state's (Newton's trial from its iterate):
    the stretches, energy and forces of a start from 1 to round-off.
    """
    rng = np.random.default_rng(6)
    u = 0.003 * rng.standard_normal(2 * patch.n)
    near = u + 1e-6 * rng.standard_normal(2 * patch.n)
    X, tri = patch.nodes, patch.triangles
    start = H.assemble("neo_hookean", X, tri, near, nu=0.3, tangent=False).stretch
    cold = H.assemble("neo_hookean", X, tri, u, nu=0.3, tangent=False)
    warm = H.assemble("neo_hookean", X, tri, u, nu=0.3, tangent=False, stretch=start)
    assert not np.array_equal(start, cold.stretch)
    assert np.abs(warm.stretch - cold.stretch).max() <= 4e-16
    assert warm.energy == pytest.approx(cold.energy, rel=1e-14)
    assert np.abs(warm.force - cold.force).max() <= 1e-14 * np.abs(cold.force).max()


@pytest.mark.parametrize("model", NONLINEAR)
def test_the_contact_stiffness_against_direct_sparse_solves(model, patch):
    """S = K_cc - K_cf K_ff^-1 K_fc applied through the LDL^T of K_ff, and the interior
    responses, equal what SciPy's spsolve gives on the interior block, on a stressed state whose
    whole tangent is singular (the free object's translations); a multiple of a vector already
    applied costs no solve.
    """
    import scipy.sparse.linalg as spla

    from squeeze_grasp_ros.mechanics.elastic.interior import InteriorBlocks

    rng = np.random.default_rng(5)
    u = (patch.nodes @ np.array([[-0.08, 0.02], [0.03, 0.05]])).ravel()
    K = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3).tangent
    contacts = np.sort(rng.choice(patch.n, 6, replace=False))
    cd = np.stack([2 * contacts, 2 * contacts + 1], 1).ravel()
    free = np.setdiff1d(np.arange(2 * patch.n), cd)
    Kff, Kfc = K[free][:, free].tocsc(), K[free][:, cd].toarray()
    blocks = InteriorBlocks(K, free, cd)
    solves = []
    solve = blocks.factor(K)
    S = blocks.contact_stiffness(K, lambda r: solves.append(1) or solve(r))
    ref = K[cd][:, cd].toarray() - Kfc.T @ spla.spsolve(Kff, Kfc)
    dense = S.toarray()
    assert np.abs(dense - ref).max() < 1e-12 * np.abs(ref).max()
    assert np.linalg.eigvalsh(0.5 * (dense + dense.T))[0] < 1e-10 * np.abs(ref).max()
    d = rng.standard_normal(len(cd))
    x = spla.spsolve(Kff, Kfc @ d)
    assert np.abs(S.interior_response(d) - x).max() < 1e-12 * np.abs(x).max()
    before = len(solves)
    assert np.abs(S @ (-2.5 * d) + 2.5 * (ref @ d)).max() < 1e-11 * np.abs(ref @ d).max()
    assert len(solves) == before and S.knows(3 * d) and not S.knows(d + 1e-3)


def test_a_kept_state_keeps_its_own_stiffness_after_the_factorisation_moved_on(patch):
    """The factorisation of K_ff is shared by a response's states and by the contact sets of
    an object: a kept state's dF/d delta, applied after another state or set was factorised,
    refactors for its own state and equals that of a fresh response at its delta.
    """
    left, right = np.argsort(patch.nodes[:, 0])[:2], np.argsort(-patch.nodes[:, 0])[:2]

    def response():
        return ContactResponse(MaterialModel.NEO_HOOKEAN, patch.nodes / 0.1, patch.triangles,
                               np.r_[left, right], 0.3)

    near, far = np.zeros((4, 2)), np.zeros((4, 2))
    near[:2, 0], near[2:, 0], far[:2, 0], far[2:, 0] = 0.01, -0.01, 0.03, -0.03
    shared = response()
    first = shared.evaluate(near)
    shared.evaluate(far)
    v = np.random.default_rng(4).standard_normal(8)
    count = shared.stats["factorizations"]
    own = first.C @ v
    assert shared.stats["factorizations"] == count + 1
    reference = response().evaluate(near).C
    alone = reference @ v
    assert np.abs(own - alone).max() < 1e-9 * np.abs(alone).max()
    # the same across contact sets that share the object's factorisation
    other = ContactResponse(MaterialModel.NEO_HOOKEAN, patch.nodes / 0.1, patch.triangles,
                            np.r_[left, right[:1]], 0.3, factorization=shared.factorization)
    other.evaluate(far[:3])
    w = v[::-1].copy()
    assert np.abs(first.C @ w - reference @ w).max() < 1e-9 * np.abs(reference @ w).max()


@pytest.mark.parametrize("model", NONLINEAR)
def test_the_response_tangent_is_the_derivative_of_its_forces(model, patch):
    """dF/d delta of a contact set's equilibrium against central differences of F."""
    left = np.argsort(patch.nodes[:, 0])[:2]
    right = np.argsort(-patch.nodes[:, 0])[:2]
    contacts = np.r_[left, right]
    L = 0.1
    delta = np.zeros((4, 2))
    delta[:2, 0], delta[2:, 0] = 0.004 / L, -0.004 / L
    d = np.random.default_rng(2).standard_normal((4, 2)) * 1e-3

    def response():
        return ContactResponse(MaterialModel(model), patch.nodes / L, patch.triangles, contacts,
                               0.3)

    at = response().evaluate(delta)
    h = 1e-5
    plus, minus = response().evaluate(delta + h * d), response().evaluate(delta - h * d)
    fd = (plus.F - minus.F).reshape(-1) / (2 * h)
    assert np.linalg.norm(at.C @ d.reshape(-1) - fd) < 1e-6 * np.linalg.norm(fd)


def test_a_response_returns_to_a_kept_state_without_solving(patch):
    """Evaluating again at a delta solved shortly before restores that state (field, energy,
    tangent) without a Newton iteration or a factorisation; an older one is solved again.
    """
    from squeeze_grasp_ros.mechanics.elastic.contact_response import KEPT_STATES

    left, right = np.argsort(patch.nodes[:, 0])[:2], np.argsort(-patch.nodes[:, 0])[:2]
    response = ContactResponse(MaterialModel.NEO_HOOKEAN, patch.nodes / 0.1, patch.triangles,
                               np.r_[left, right], 0.3)
    deltas = [np.zeros((4, 2)) for _ in range(KEPT_STATES + 1)]
    for k, delta in enumerate(deltas):
        delta[:2, 0], delta[2:, 0] = 0.01 * (k + 1), -0.01 * (k + 1)
    first = [response.evaluate(d) for d in deltas]
    before = dict(response.stats)
    again = response.evaluate(deltas[1])
    assert again is first[1] and response.stats["factorizations"] == before["factorizations"]
    assert response.stats["look_ups"] == before["look_ups"] + 1
    assert response.state_energy() == first[1].energy
    assert np.array_equal(response.state_u(), first[1].u)
    assert response.at(deltas[2]) and np.array_equal(response.state_u(), first[2].u)
    oldest = response.evaluate(deltas[0])
    assert response.stats["evaluations"] == before["evaluations"] + 1
    assert abs(oldest.energy - first[0].energy) < 1e-12 * first[0].energy


def test_the_linear_law_is_the_cst_stiffness(patch):
    K = stiffness_matrix(patch, 0.3)
    u = np.random.default_rng(3).standard_normal(2 * patch.n) * 1e-3
    a = H.assemble("linear", patch.nodes, patch.triangles, u, nu=0.3)
    assert abs(a.tangent - K).max() < 1e-12 * abs(K).max()
    assert np.allclose(a.force, K @ u, rtol=0, atol=1e-12 * np.abs(K @ u).max())


@settings(max_examples=30, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2))
def test_frame_indifference_of_the_laws(angle, a, b, c):
    """W(QF) = W(F) and P(QF) = Q P(F) for the nonlinear laws; the linear law stores energy
    under a pure rotation, growing like angle^4 (its strain is 1 - cos(angle)).
    """
    F = np.array([[[1 + a, b], [c, 1 - 0.5 * a]]])
    Q = rotation(angle)[None]
    for model in NONLINEAR:
        W, P, _ = H.stress_and_tangent(model, F, nu=0.3)
        Wq, Pq, _ = H.stress_and_tangent(model, Q @ F, nu=0.3)
        assert Wq[0] == pytest.approx(W[0], rel=1e-9, abs=1e-14)
        assert np.allclose(Pq[0], Q[0] @ P[0], rtol=1e-9, atol=1e-12)
    W_rot, _, _ = H.stress_and_tangent("linear", Q, nu=0.3)
    eps = 1 - np.cos(angle)
    assert W_rot[0] == pytest.approx(eps * eps / (1 - 0.3), rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("F", [[[1.1, 0.0], [0.0, 1.0]], [[1.0, 0.2], [0.0, 1.0]],
                               [[0.9, 0.05], [-0.03, 1.04]]], ids=["stretch", "shear", "mixed"])
def test_patch_test(model, F, patch):
    """A homogeneous deformation on an irregular mesh: interior nodes in equilibrium, and the
    boundary reactions are the traction P N of the law over the boundary.
    """
    F = np.array(F)
    u = (patch.nodes @ (F - np.eye(2)).T).reshape(-1)
    a = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3)
    interior = np.setdiff1d(np.arange(patch.n), patch.boundary)
    f = a.force.reshape(-1, 2)
    assert np.abs(f[interior]).max() < 1e-12 * np.abs(f).max()
    _, P, _ = H.stress_and_tangent(model, F[None], nu=0.3)
    right = patch.nodes[:, 0] > 0.05 - 1e-12
    assert f[right].sum(axis=0) == pytest.approx(P[0] @ [1.0, 0.0] * 0.06, rel=1e-9, abs=1e-12)


def test_small_strain_limit_of_every_law():
    F = np.eye(2)[None] + 1e-6 * np.array([[[1.0, 0.4], [-0.2, -0.7]]])
    _, P_lin, A_lin = H.stress_and_tangent("linear", F, nu=0.3)
    for model in NONLINEAR:
        _, P, A = H.stress_and_tangent(model, F, nu=0.3)
        assert np.allclose(P, P_lin, rtol=1e-4, atol=1e-11)
        assert np.allclose(A, A_lin, atol=1e-5)


def test_an_inverted_element_is_an_error_not_nan(patch):
    u = np.zeros(2 * patch.n)
    k = patch.triangles[0]
    u[2 * k[0]:2 * k[0] + 2] = patch.nodes[k[1]] - patch.nodes[k[0]] + patch.nodes[k[2]] - \
        patch.nodes[k[0]]
    for model in MODELS:
        with pytest.raises(H.InvertedElementError) as info:
            H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3)
        assert isinstance(info.value, NumericalError) and "det_F" in info.value.residuals


def test_neo_hookean_refuses_nu_one_half():
    with pytest.raises(ValueError, match="nu must be < 0.5"):
        H.stress_and_tangent("neo_hookean", np.eye(2)[None], nu=0.5)


def _scikit_fem_state(patch, u: np.ndarray):
    """(skfem, its vector P1 basis on ``patch``, our DOF -> its DOF, ``u`` in its order), or a
    visible skip when scikit-fem is not installed.
    """
    skfem = pytest.importorskip(
        "skfem", reason="scikit-fem (the independent FEM cross-check) is not installed: "
                        "pip install scikit-fem")
    m = skfem.MeshTri(patch.nodes.T.copy(), patch.triangles.T.copy())
    basis = skfem.Basis(m, skfem.ElementVector(skfem.ElementTriP1()))
    # skfem orders vector DOFs node-wise (x1, y1, x2, ...) like ours for ElementVector(P1)
    nodal = basis.nodal_dofs
    ours_to_sk = np.empty(2 * patch.n, int)
    ours_to_sk[0::2], ours_to_sk[1::2] = nodal[0], nodal[1]
    w = np.empty(basis.N)
    w[ours_to_sk] = u
    return skfem, basis, ours_to_sk, w


def test_internal_forces_against_scikit_fem(patch):
    """The internal force of each law, assembled independently by scikit-fem's P1 basis from the
    law's stress P(F): the same vector.
    """
    u = 0.001 * np.random.default_rng(11).standard_normal(2 * patch.n)
    skfem, basis, ours_to_sk, w = _scikit_fem_state(patch, u)
    from skfem.helpers import ddot, grad

    for model in MODELS:
        @skfem.LinearForm
        def residual(v, p):
            Fq = np.eye(2)[:, :, None, None] + p["w"].grad
            flat = np.moveaxis(Fq, (0, 1), (-2, -1)).reshape(-1, 2, 2)
            _, P, _ = H.stress_and_tangent(model, flat, nu=0.3)
            Pq = np.moveaxis(P.reshape(Fq.shape[2:] + (2, 2)), (-2, -1), (0, 1))
            return ddot(Pq, grad(v))

        sk = residual.assemble(basis, w=basis.interpolate(w))[ours_to_sk]
        ours = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3).force
        assert np.allclose(ours, sk, rtol=1e-10, atol=1e-12 * np.abs(ours).max())


def test_tangent_against_scikit_fem(patch):
    """The tangent stiffness of each law, assembled independently by scikit-fem's P1 basis from
    the law's dP/dF: the same matrix (our assembly precomputes the pattern and the products of
    the shape-function gradients per mesh and scatters every element at once).
    """
    u = 0.002 * np.random.default_rng(5).standard_normal(2 * patch.n)
    skfem, basis, ours_to_sk, w = _scikit_fem_state(patch, u)
    from skfem.helpers import grad

    for model in MODELS:
        @skfem.BilinearForm
        def stiffness(du, v, p):
            Fq = np.eye(2)[:, :, None, None] + p["w"].grad
            flat = np.moveaxis(Fq, (0, 1), (-2, -1)).reshape(-1, 2, 2)
            _, _, A = H.stress_and_tangent(model, flat, nu=0.3)
            Aq = np.moveaxis(A.reshape(Fq.shape[2:] + (2, 2, 2, 2)), (-4, -3, -2, -1),
                             (0, 1, 2, 3))
            return np.einsum("ijkl...,kl...,ij...->...", Aq, grad(du), grad(v))

        sk = stiffness.assemble(basis, w=basis.interpolate(w))[ours_to_sk][:, ours_to_sk]
        ours = H.assemble(model, patch.nodes, patch.triangles, u, nu=0.3).tangent
        sym = 0.5 * (sk + sk.T)  # ours is symmetrised (the corotational dP/dF is not exactly)
        assert abs(ours - sym).max() <= 1e-12 * abs(sym).max(), model
        assert ours.nnz == sk.nnz


def test_assembly_against_an_element_by_element_loop(patch):
    """Forces, energy and tangent against the textbook loop over elements (B^T P and
    B^T A B per element, added into dense arrays): equal to round-off for every law.
    """
    rng = np.random.default_rng(9)
    u = 0.003 * rng.standard_normal(2 * patch.n)
    X, tri = patch.nodes, patch.triangles
    for model in MODELS:
        ours = H.assemble(model, X, tri, u, nu=0.3)
        F = H.deformation(X, tri, u)
        W, P, A = H.stress_and_tangent(model, F, nu=0.3)
        n2 = 2 * patch.n
        K, f, energy = np.zeros((n2, n2)), np.zeros(n2), 0.0
        for e, (a, b, c) in enumerate(tri):
            J = np.column_stack([X[b] - X[a], X[c] - X[a]])
            area = 0.5 * abs(np.linalg.det(J))
            g = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]) @ np.linalg.inv(J)
            B = np.zeros((4, 6))  # dF_ij / du_(node, k) = delta_ik g_node,j
            for node in range(3):
                for i in range(2):
                    B[2 * i:2 * i + 2, 2 * node + i] = g[node]
            dofs = np.array([[2 * k, 2 * k + 1] for k in (a, b, c)]).ravel()
            f[dofs] += area * B.T @ P[e].ravel()
            K[np.ix_(dofs, dofs)] += area * B.T @ A[e].reshape(4, 4) @ B
            energy += area * W[e]
        K = 0.5 * (K + K.T)
        assert ours.energy == pytest.approx(energy, rel=1e-13), model
        assert np.abs(ours.force - f).max() <= 1e-13 * np.abs(f).max(), model
        assert np.abs(ours.tangent.toarray() - K).max() <= 1e-13 * np.abs(K).max(), model


# --------------------------------------------------------------------------- the squeeze
@pytest.fixture(scope="module")
def square():
    return foam_square(500)


def squeeze(obj, contacts, model, **kw):
    return event_squeeze(obj, contacts, 0.02, 0.4, material_model=model, **kw)


def test_every_model_tends_to_linear_as_the_depth_vanishes(square):
    """Differences from linear are first order in the depth: at 0.01 % approach they are below
    0.1 %, and ten times less than at 0.1 %.
    """
    _, obj, contacts = square
    diffs = {}
    for rel in (1e-4, 1e-3):
        linear = squeeze(obj, contacts, "linear", relative_depth=rel)
        for model in NONLINEAR:
            res = squeeze(obj, contacts, model, relative_depth=rel)
            f, f0 = res.finger_force["F1"][1], linear.finger_force["F1"][1]
            diffs[model, rel] = abs(f - f0) / f0
            assert res.energy == pytest.approx(linear.energy, rel=3 * diffs[model, rel] + 1e-9)
    for model in NONLINEAR:
        assert diffs[model, 1e-4] < 1e-3
        assert 4 < diffs[model, 1e-3] / max(diffs[model, 1e-4], 1e-16) < 25


@pytest.mark.parametrize("model", MODELS)
def test_a_rotated_scene_gives_rotated_results(model, square):
    """The same squeeze with the whole object turned by 37 and 90 degrees: forces rotate,
    energy, depths and events are the same (the stable directions are planned in each frame).
    """
    _, obj, contacts = square
    base = squeeze(obj, contacts, model, relative_depth=0.03)
    for angle in (np.radians(37.0), np.pi / 2):
        Q = rotation(angle)
        turned = ElasticObject(mesh_from_triangles(obj.mesh.nodes @ Q.T, obj.mesh.triangles),
                               obj.material)
        res = squeeze(turned, contacts, model, relative_depth=0.03)
        assert res.energy == pytest.approx(base.energy, rel=1e-8)
        assert [(e.type, e.node) for e in res.events] == [(e.type, e.node) for e in base.events]
        for c, c0 in zip(res.state.contacts, base.state.contacts):
            assert np.allclose(c.force, Q @ c0.force, rtol=0, atol=1e-8 * abs(base.energy) /
                               0.001)


@pytest.mark.parametrize("model", NONLINEAR)
def test_finger_work_equals_the_strain_energy_when_nothing_slides(model, square):
    _, obj, contacts = square
    res = squeeze(obj, contacts, model, relative_depth=0.05)
    assert res.event_counts["C"] == 0
    work = sum(res.work.values())
    assert abs(work - res.energy) < 1e-6 * res.energy


@pytest.mark.parametrize("model", MODELS)
def test_finger_work_equals_strain_energy_plus_frictional_dissipation(model, square):
    """With slippery tips (mu = 0.05) contacts slide and friction dissipates: work = energy +
    dissipation to 1e-6 of the energy, the dissipation is positive, and halving the substep
    shrinks the balance's residual (the dissipation is integrated by the trapezoid rule).
    """
    _, obj, contacts = square
    residual = []
    for step in (1e-3, 5e-4):
        res = event_squeeze(obj, contacts, 0.02, 0.05, material_model=model,
                            relative_depth=0.12, step=step)
        counts = res.event_counts
        assert counts["C"] + counts["D"] > 0 or any(c.mode == "slip" for c in res.state.contacts)
        work, lost = sum(res.work.values()), sum(res.dissipation.values())
        assert lost > 0.0
        residual.append(abs(work - res.energy - lost) / res.energy)
        assert residual[-1] == pytest.approx(abs(res.diagnostics["energy_balance"]) / res.energy)
    assert residual[0] < 1e-6 and residual[1] < residual[0]


@pytest.mark.parametrize("model", NONLINEAR)
def test_adaptive_substeps_agree_with_the_step_grid(model, square):
    """A nonlinear model adapts its substeps between events; against the same squeeze on the
    fixed grid (12 %, mu = 0.4) it finds the same events (type, node, finger, mode) at the same
    depths to 4 event tolerances, the same forces and energy to 1e-8, work = energy to 1e-7,
    and needs at most 2/3 of the grid's evaluations.
    """
    from squeeze_grasp_ros.mechanics.squeeze.contact_model import SolveOptions

    _, obj, contacts = square
    adaptive = squeeze(obj, contacts, model, relative_depth=0.12)
    grid = squeeze(obj, contacts, model, relative_depth=0.12,
                   options=SolveOptions(adaptive_substeps=False))

    def events(res):
        return [(e.type, e.node, e.finger, e.mode, e.slip) for e in res.events]

    assert len(grid.events) >= 4 and events(adaptive) == events(grid)
    shift = max(abs(a.depth - b.depth) for a, b in zip(adaptive.events, grid.events))
    assert shift < 4e-9 * obj.scale
    F, F0 = np.array(adaptive.finger_force["F1"]), np.array(grid.finger_force["F1"])
    assert np.abs(F - F0).max() < 1e-8 * np.abs(F0).max()
    assert adaptive.energy == pytest.approx(grid.energy, rel=1e-8)
    assert abs(sum(adaptive.work.values()) - adaptive.energy) < 1e-7 * adaptive.energy
    cost = [res.diagnostics["nonlinear"]["evaluations"] for res in (adaptive, grid)]
    assert cost[0] < 2 / 3 * cost[1]
    assert adaptive.diagnostics["substeps"] < grid.diagnostics["substeps"]


@pytest.mark.parametrize("mu", [0.05, 0.4])
def test_event_location_skips_only_evaluations_whose_outcome_is_sure(mu, square, monkeypatch):
    """A nonlinear model's evaluations are dear, and event location skips those whose sign
    the exact values and slopes already known make sure. Against the same neo-Hookean squeeze
    with every location point evaluated (12 %, friction 0.05 and 0.4): the same events (type,
    node, finger, mode, slip), their depths to 1e-12 L and the forces and energy to 1e-12
    (measured: 4e-16 L, 5e-15; the event tolerance is 1e-9 L: a skipped evaluation is one
    kept state fewer, so a later Newton may start from another and stop elsewhere within its
    tolerance), with fewer location evaluations and nonlinear evaluations.
    """
    from squeeze_grasp_ros.mechanics.squeeze.nonlinear_model import NonlinearContactModel

    _, obj, contacts = square

    def run():
        return event_squeeze(obj, contacts, 0.02, mu, material_model="neo_hookean",
                             relative_depth=0.12)

    sure = run()
    monkeypatch.setattr(NonlinearContactModel, "dear_evaluations", property(lambda _: False))
    every = run()

    def events(res):
        return [(e.type, e.node, e.finger, e.mode, e.slip) for e in res.events]

    assert len(every.events) >= 4 and events(sure) == events(every)
    shift = max(abs(a.depth - b.depth) for a, b in zip(sure.events, every.events))
    assert shift < 1e-12 * obj.scale
    for finger in ("F1", "F2"):
        assert sure.finger_force[finger] == pytest.approx(every.finger_force[finger], rel=1e-12)
    assert sure.energy == pytest.approx(every.energy, rel=1e-12)
    assert sure.diagnostics["root_evaluations"] < every.diagnostics["root_evaluations"]
    cost = [res.diagnostics["nonlinear"]["evaluations"] for res in (sure, every)]
    assert cost[0] < cost[1]


def test_an_object_s_squeezes_share_its_set_up_and_keep_their_floats():
    """A planner or a sweep squeezes one object many times: its contact models share the mesh
    geometry (read-only) and the factor's pattern layout (ordering, held masks, block gathers)
    kept on the object. A neo-Hookean squeeze after another squeeze of the same object, at
    another placement, gives the floats of the same squeeze on a fresh copy of the object, bit
    for bit (the numeric factorisations stay per squeeze), and builds no geometry of its own.
    """
    from squeeze_grasp_ros.mechanics.elastic.interior import PatternLayout

    _, obj, contacts = foam_square(300)
    fresh = ElasticObject(obj.mesh, obj.material)
    nodes = obj.mesh.nodes
    turn = nodes.mean(axis=0) + (nodes[list(contacts)] - nodes.mean(axis=0)) @ rotation(
        np.pi / 2).T
    across = tuple(int(np.argmin(np.hypot(*(nodes - p).T))) for p in turn)

    def run(target, pair):
        res = squeeze(target, pair, "neo_hookean", relative_depth=0.06)
        return res.to_json() | {"diagnostics": None}

    first = run(obj, across)
    kept = obj._shared["mesh_geometry"]
    layout = obj._shared["pattern_layout"]
    assert len(kept) == 1 and isinstance(layout, PatternLayout)
    geometry = next(iter(kept.values()))
    assert not geometry.slots.flags.writeable and not geometry.gradient.data.flags.writeable
    again = run(obj, contacts)
    assert obj._shared["mesh_geometry"] == kept and next(iter(kept.values())) is geometry
    assert obj._shared["pattern_layout"] is layout and len(layout._orders) == 2
    assert again == run(fresh, contacts)
    assert first == run(ElasticObject(obj.mesh, obj.material), across)
    assert again["events"] and first["events"] != again["events"]


def test_forces_scale_with_e_for_a_very_soft_object(square):
    _, obj, contacts = square
    soft = ElasticObject(obj.mesh, Material(1e3, 0.3, 0.0254))
    stiff = squeeze(obj, contacts, "neo_hookean", relative_depth=0.03)
    res = squeeze(soft, contacts, "neo_hookean", relative_depth=0.03)
    assert res.finger_force["F1"][1] == pytest.approx(stiff.finger_force["F1"][1] * 1e3 / 5e4,
                                                      rel=1e-7)


def test_nearly_incompressible_plane_stress_does_not_lock(square):
    """Plane stress leaves the thickness free, so nu -> 0.5 is benign for P1 triangles: the force
    changes smoothly (no locking jump) from nu = 0.45 to 0.499.
    """
    _, obj, contacts = square
    forces = []
    for nu in (0.45, 0.49, 0.499):
        o = ElasticObject(obj.mesh, Material(5e4, nu, 0.0254))
        forces.append(squeeze(o, contacts, "neo_hookean", relative_depth=0.03)
                      .finger_force["F1"][1])
    assert abs(forces[2] - forces[1]) < abs(forces[1] - forces[0])
    assert forces[2] / forces[0] < 1.2


def test_the_model_comes_from_the_scene_and_the_cli_compares(tmp_path, capfd):
    import json

    import yaml

    from squeeze_grasp_ros.cli import main

    data = yaml.safe_load(open(scene_file("foam_square")))
    data["object"]["mesh"]["nodes"] = 400
    data["object"]["material"]["model"] = "corotational"
    path = tmp_path / "square.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["squeeze", str(path), "--relative-depth", "0.02", "--json"]) == 0
    one = json.loads(capfd.readouterr().out)
    assert one["diagnostics"]["nonlinear"]["material_model"] == "corotational"
    assert main(["squeeze", str(path), "--relative-depth", "0.02", "--compare-models",
                 "--json"]) == 0
    both = json.loads(capfd.readouterr().out)
    assert set(both["models"]) == set(MODELS)
    assert both["models"]["corotational"]["force"]["F1"] == one["finger_force"]["F1"]["end"]
    d = both["relative_difference"]["neo_hookean"]["force"]["F1"]
    rows = both["models"]
    assert d == pytest.approx(rows["neo_hookean"]["force"]["F1"] / rows["linear"]["force"]["F1"]
                              - 1)
    data["object"]["material"]["model"] = "rubber"
    path.write_text(yaml.safe_dump(data))
    assert main(["squeeze", str(path)]) == 2
    assert "object.material.model" in capfd.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize("model", NONLINEAR)
def test_a_thirty_percent_squeeze_converges(model, square):
    """30 % relative depth (log strains near 0.5) ends at the depth, with finite results that
    bracket the physics: the corotational square is softer than the linear one, the
    neo-Hookean one stiffer. Finger work = strain energy + frictional dissipation within 1e-6:
    two of the corotational square's contacts arrive sliding (their A events decide slip), and
    friction takes 1.1e-6 of the energy, which is the whole of work minus energy.
    """
    _, obj, contacts = square
    linear = squeeze(obj, contacts, "linear", relative_depth=0.30)
    res = squeeze(obj, contacts, model, relative_depth=0.30, step=5e-4)
    assert res.termination == "depth_reached" and np.isfinite(res.energy)
    ratio = res.finger_force["F1"][1] / linear.finger_force["F1"][1]
    assert (ratio < 1.0) if model == "corotational" else (ratio > 1.0)
    work, lost = sum(res.work.values()), sum(res.dissipation.values())
    assert abs(work - res.energy - lost) < 1e-6 * res.energy
    sliding = any(c.mode == "slip" for c in res.state.contacts)
    assert (lost > 1e-7 * res.energy) == sliding


def test_frictional_resistance_runs_on_the_scene_s_material_model(tmp_path, capfd):
    """Algorithm 2 (resist --contacts friction) uses the scene's model: on the 500-node Fig. 10
    scene the neo-Hookean forces differ from the linear ones, by a few percent, with the same
    outcome.
    """
    import json

    import yaml

    from squeeze_grasp_ros.cli import main

    out = {}
    for model in ("linear", "neo_hookean"):
        data = yaml.safe_load(open(scene_file("resist_fig10")))
        data["object"]["material"]["model"] = model
        data["object"]["mesh"] = {"nodes": 500, "min_angle": 30}
        path = tmp_path / f"{model}.yaml"
        path.write_text(yaml.safe_dump(data))
        assert main(["resist", str(path), "--contacts", "friction", "--json"]) == 0
        out[model] = json.loads(capfd.readouterr().out)
    lin, nh = out["linear"], out["neo_hookean"]
    assert (lin["success"], lin["reason"]) == (nh["success"], nh["reason"])
    for finger in ("F1", "F2", "A"):
        a, b = lin["force_along"][finger]["end"], nh["force_along"][finger]["end"]
        assert a != b and abs(b / a - 1) < 0.05


# --------------------------------------------------------------------------- mesh refinement
def structured_square(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit square, n x n cells, each cut into two triangles along alternating diagonals."""
    x = np.linspace(0.0, 1.0, n + 1)
    nodes = np.column_stack([np.tile(x, n + 1), np.repeat(x, n + 1)])
    triangles = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            triangles += [[a, b, d], [a, d, c]] if (i + j) % 2 == 0 else [[a, b, c], [b, d, c]]
    return nodes, np.array(triangles)


def plate_force(model: str, n: int) -> float:
    """Force of rigid sticking plates compressing the unit square by 10 % (bottom edge held,
    top edge moved down by 0.1), dimensionless (/ E h L).
    """
    nodes, triangles = structured_square(n)
    bottom = np.flatnonzero(np.isclose(nodes[:, 1], 0.0))
    top = np.flatnonzero(np.isclose(nodes[:, 1], 1.0))
    response = ContactResponse(MaterialModel(model), nodes, triangles,
                               np.concatenate([bottom, top]), 0.3)
    delta = np.zeros((len(bottom) + len(top), 2))
    delta[len(bottom):, 1] = -0.1
    out = response.evaluate(delta)
    assert out.residual < 1e-9
    return float(-out.F[len(bottom):, 1].sum())


@pytest.mark.parametrize("model", MODELS)
def test_the_force_converges_under_mesh_refinement_with_its_order_fitted(model):
    """Uniform refinement 8 -> 16 -> 32 cells per side: the force decreases monotonically
    (P1 triangles are too stiff) and the fitted order log2(d1 / d2) is that of the
    clamped-corner singularity, about 1.3 for every law (smooth problems give 2); the nonlinear
    laws converge like the linear one.
    """
    forces = np.array([plate_force(model, n) for n in (8, 16, 32)])
    d1, d2 = forces[0] - forces[1], forces[1] - forces[2]
    assert d1 > d2 > 0
    order = np.log2(d1 / d2)
    print(f"{model}: forces {forces}, fitted order {order:.3f}")
    assert 1.15 < order < 1.6
    linear = np.array([plate_force("linear", n) for n in (8, 16, 32)])
    assert abs(order - np.log2((linear[0] - linear[1]) / (linear[1] - linear[2]))) < 0.15


def test_the_squeeze_force_agrees_on_finer_meshes():
    """The foam square's neo-Hookean F1 force at 4 % on meshes of about 800 and 1,600 nodes
    agrees within 0.5 % (contact segments are quantised by the boundary node spacing, so the
    sequence is not monotone and has no clean order; the plate problem above has one).
    """
    forces = []
    for nodes in (800, 1600):
        _, obj, contacts = foam_square(nodes)
        res = squeeze(obj, contacts, "neo_hookean", relative_depth=0.04)
        forces.append(res.finger_force["F1"][1])
    assert forces[1] == pytest.approx(forces[0], rel=5e-3)


def _stated(path: str, pattern: str) -> list[float]:
    """The numbers ``pattern`` captures in the docs page ``path`` (whitespace normalised,
    thousands separators dropped).
    """
    from doc_transcripts import REPO

    text = " ".join((REPO / path).read_text().split())
    found = re.search(pattern, text)
    assert found, f"{path} no longer states {pattern!r}"
    return [float(x.replace(",", "")) for x in found.groups()]


def test_the_docs_neo_hookean_counts_are_the_shipped_square_s():
    """docs/events.md and docs/materials.md state what the 12 % neo-Hookean squeeze of the
    shipped foam square costs in evaluations, look-ups, substeps, root evaluations,
    factorisations and Newton iterations, with CHOLMOD, with QDLDL and on the fixed step
    grid. Those are the diagnostics of the squeeze itself.
    """
    from squeeze_grasp_ros.api import finger_nodes, load_scene, scene_file, scene_solid
    from squeeze_grasp_ros.mechanics.elastic.interior import factorizer
    from squeeze_grasp_ros.mechanics.squeeze.contact_model import SolveOptions

    scene = load_scene(scene_file("foam_square"))
    obj = scene_solid(scene)
    contacts = finger_nodes(scene, obj.mesh)

    def counts(method, **kw):
        with factorizer(method):
            diag = squeeze(obj, contacts, "neo_hookean", relative_depth=0.12, **kw).diagnostics
        return diag, diag["nonlinear"]

    diag, nl = counts("cholmod")
    qdiag, qnl = counts("qdldl")
    gdiag, gnl = counts("cholmod", options=SolveOptions(adaptive_substeps=False))
    nodes, evaluations, look_ups, substeps, roots, q_requests, q_low, q_high, g_evaluations, \
        g_substeps, g_low = _stated(
            "docs/events.md",
            r"neo-Hookean, ([\d,]+) nodes\) that is (\d+) evaluations and (\d+) look-ups in "
            r"(\d+) substeps and (\d+) root evaluations with CHOLMOD \((\d+) requests with "
            r"QDLDL too, split (\d+) and \d+ on one\s+machine and (\d+) and \d+ on another "
            r"with AVX-512: .*?\); on the fixed grid "
            r"\(`SolveOptions\(adaptive_substeps=False\)`\) it is "
            r"(\d+) evaluations in (\d+) substeps \((\d+) with AVX-512")
    assert obj.mesh.n == nodes
    assert (nl["evaluations"], nl["look_ups"], diag["substeps"], diag["root_evaluations"]) == (
        evaluations, look_ups, substeps, roots)
    assert qnl["evaluations"] + qnl["look_ups"] == q_requests  # the split is round-off's
    assert q_low <= qnl["evaluations"] <= q_high
    assert g_low <= gnl["evaluations"] <= g_evaluations and gdiag["substeps"] == g_substeps
    stated = _stated(
        "docs/materials.md",
        r"squeeze takes (\d+) substeps, (\d+) root evaluations, (\d+) evaluations \(plus (\d+) "
        r"look-ups\), ([\d.]+) Newton iterations per evaluation and (\d+) factorisations \((\d+) "
        r"sets bordered, below; CHOLMOD; with QDLDL (\d+) evaluations and (\d+) look-ups, "
        r"(\d+) and (\d+) on a machine with AVX-512")
    assert stated[:7] == [diag["substeps"], diag["root_evaluations"], nl["evaluations"],
                          nl["look_ups"], round(nl["newton_iterations"] / nl["evaluations"], 1),
                          nl["factorizations"], nl["bordered"]]
    assert (qnl["evaluations"], qnl["look_ups"]) in (tuple(stated[7:9]), tuple(stated[9:]))
    high, low = _stated("docs/materials.md",
                        r"then, (\d+) evaluations now \((\d+) on a machine with AVX-512\)")
    assert low <= gnl["evaluations"] <= high
