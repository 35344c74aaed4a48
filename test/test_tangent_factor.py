# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The two factorisers of the interior tangent (CHOLMOD's supernodal LL^T, QDLDL's LDL^T):
solves against SciPy's, the LDL^T fallback for a tangent that is not positive definite, the
fill counts on an analytic case, and one squeeze under each with the same events and forces.

The CHOLMOD tests need cvxopt (``pip install '.[cholmod]'``, in the test extra) and skip with
that line without it.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from foam_support import foam_square

from squeeze_grasp_ros.api import (
    event_squeeze,
    event_squeeze_scene,
    load_scene,
    scene_file,
    scene_solid,
)
from squeeze_grasp_ros.extras import installed
from squeeze_grasp_ros.mechanics.elastic import hyperelastic as H
from squeeze_grasp_ros.mechanics.elastic import interior
from squeeze_grasp_ros.mechanics.elastic.interior import TangentFactor, factorizer
from squeeze_grasp_ros.mechanics.vocabulary import EventType, Factorizer

CHOLMOD = pytest.param(
    Factorizer.CHOLMOD,
    marks=pytest.mark.skipif(not installed("cvxopt"),
                             reason="cvxopt not installed: pip install '.[cholmod]'"))
METHODS = (CHOLMOD, Factorizer.QDLDL)


def held_block(K: sp.spmatrix, held: np.ndarray) -> tuple[sp.csc_matrix, np.ndarray]:
    """K_ff of the DOFs not ``held``, and those DOFs."""
    free = np.setdiff1d(np.arange(K.shape[0]), held)
    return sp.csc_matrix(K)[free][:, free], free


@pytest.fixture(scope="module")
def stressed():
    """The neo-Hookean tangent of a compressed and sheared foam square (about 500 nodes) and
    six held nodes.
    """
    _, obj, _ = foam_square(500)
    X = obj.mesh.nodes / 0.1
    u = (X @ np.array([[-0.08, 0.02], [0.03, 0.05]])).ravel()
    K = H.assemble("neo_hookean", X, obj.mesh.triangles, u, nu=0.3).tangent
    nodes = np.random.default_rng(5).choice(len(X), 6, replace=False)
    held = np.sort(np.r_[2 * nodes, 2 * nodes + 1])
    return K, held


@pytest.mark.parametrize("method", METHODS)
def test_a_factoriser_solves_the_interior_block_as_scipy_does(method, stressed):
    """The solve is K_ff^-1 b on the free DOFs and 0 on the held ones, to 1e-12 of SciPy's spsolve;
    refactoring another tangent of the same mesh in place gives that tangent's solution.
    """
    K, held = stressed
    factor = TangentFactor(method)
    rng = np.random.default_rng(1)
    for scale in (1.0, 2.5):
        Kf, free = held_block(scale * K, held)
        factor.factor(scale * K.tocsr(), tuple(held.tolist()))
        b = np.zeros(K.shape[0])
        b[free] = rng.standard_normal(len(free))
        x = factor.solve(b)
        ref = spla.spsolve(Kf, b[free])
        assert np.abs(x[free] - ref).max() < 1e-12 * np.abs(ref).max()
        assert not x[held].any()
    assert factor.fallbacks == 0 and factor.method == method


@pytest.mark.parametrize("method", METHODS)
def test_a_set_grown_by_nodes_solves_with_the_smaller_set_s_factor_bordered(method, stressed):
    """A contact set that holds one or two nodes more than the factorisation held solves with
    it, bordered, without a factorisation of its own: K_ff^-1 b of its own free DOFs to 1e-12 of
    SciPy's spsolve, zero on every held DOF; the bordering is built once per factorisation, and
    a set that adds more than MAX_BORDERED_DOFS, or lacks a held DOF, is not served.
    """
    K, held = stressed
    K = K.tocsr()
    factor = TangentFactor(method)
    factor.factor(K, tuple(held.tolist()))
    rng = np.random.default_rng(3)
    spare = np.setdiff1d(np.arange(K.shape[0] // 2), held // 2)
    for added in (1, 2):
        nodes = rng.choice(spare, added, replace=False)
        grown = np.sort(np.r_[held, 2 * nodes, 2 * nodes + 1])
        free = np.setdiff1d(np.arange(K.shape[0]), grown)
        blocks = interior.InteriorBlocks(K, free, grown, factor)
        assert blocks.serves and blocks.factored is K
        r = rng.standard_normal(len(free))
        ref = spla.spsolve(held_block(K, grown)[0], r)
        for _ in range(2):
            assert np.abs(blocks.solve(r) - ref).max() < 1e-12 * np.abs(ref).max()
        assert factor.bordered == added and factor.generation == 1
    too_many = np.r_[held, 2 * spare[:3], 2 * spare[:3] + 1]
    lacking = held[2:]
    for cdofs in (np.sort(too_many), lacking):
        blocks = interior.InteriorBlocks(K, np.setdiff1d(np.arange(K.shape[0]), cdofs), cdofs,
                                         factor)
        assert not blocks.serves and blocks.solve is None and blocks.owner is None


def test_a_bordered_state_keeps_its_bits_when_the_factorisation_moves_on(stressed):
    """The S of a state that took a subset's factorisation bordered: after the shared
    factorisation moved to another tangent its solve refactors its tangent with the subset's
    DOFs (bordered again: the same bits), and after it came back to that tangent and those DOFs
    by another way it takes it without a factorisation.
    """
    K, held = stressed
    K = K.tocsr()
    factor = TangentFactor(Factorizer.QDLDL)
    factor.factor(K, tuple(held.tolist()))
    node = np.setdiff1d(np.arange(K.shape[0] // 2), held // 2)[7]
    grown = np.sort(np.r_[held, 2 * node, 2 * node + 1])
    blocks = interior.InteriorBlocks(K, np.setdiff1d(np.arange(K.shape[0]), grown), grown,
                                     factor)
    calls = []

    def refactor(owner, held_dofs=None):
        calls.append(held_dofs)
        return blocks.factor(K, owner, held_dofs)

    S = blocks.owned_stiffness(K, refactor)
    assert calls == [] and blocks.owner is S.owner
    r = np.random.default_rng(4).standard_normal(len(blocks.free))
    first = S.solve(r)
    factor.factor(2.0 * K, tuple(grown.tolist()))
    assert blocks.owner is not S.owner
    assert np.array_equal(S.solve(r), first) and calls == [tuple(held.tolist())]
    factor.factor(K, tuple(held.tolist()))
    assert np.array_equal(S.solve(r), first) and len(calls) == 1


def test_a_squeeze_bordering_the_factor_gives_the_events_and_forces_of_its_own_factors(
        monkeypatch):
    """The neo-Hookean foam square (about 400 nodes) at 12 %: each contact set a node joins
    (Event A) solves with the previous set's factorisation bordered, one factorisation fewer
    each, and
    gives the same events, depths to 1e-9 of the squeeze depth and forces to 1e-9 as with a
    factorisation of every set (MAX_BORDERED_DOFS = 0).
    """
    _, obj, contacts = foam_square(400)
    runs = {}
    for limit in (0, interior.MAX_BORDERED_DOFS):
        monkeypatch.setattr(interior, "MAX_BORDERED_DOFS", limit)
        runs[limit] = event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.12,
                                    material_model="neo_hookean")
    own, bordered = runs[0], runs[interior.MAX_BORDERED_DOFS]
    a, b = own.diagnostics["nonlinear"], bordered.diagnostics["nonlinear"]
    joined = sum(e.type == EventType.A for e in bordered.events)
    assert a["bordered"] == 0 and joined >= 2 and b["bordered"] == joined
    assert b["factorizations"] == a["factorizations"] - b["bordered"]
    assert [(e.type, e.node, e.finger, e.mode) for e in own.events] == \
        [(e.type, e.node, e.finger, e.mode) for e in bordered.events]
    depths = np.array([[e.depth, f.depth] for e, f in zip(own.events, bordered.events)])
    assert np.abs(depths[:, 0] - depths[:, 1]).max() < 1e-9 * own.depth
    for finger in ("F1", "F2"):
        assert bordered.finger_force[finger][1] == pytest.approx(own.finger_force[finger][1],
                                                                 rel=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_a_tangent_that_is_not_positive_definite_is_factorised_by_ldlt(method):
    """K_ff with eigenvalues 3 and -1 (pivots 1 and -3: nonzero): the Cholesky factorisation
    refuses it, LDL^T takes it (one fallback counted), and the solve is exact.
    """
    K = sp.csr_matrix(np.array([[1.0, 2.0, 0.5], [2.0, 1.0, 0.0], [0.5, 0.0, 4.0]]))
    factor = TangentFactor(method)
    factor.factor(K, (2,))
    x = factor.solve(np.array([1.0, 0.0, 0.0]))
    assert np.allclose(x, [-1 / 3, 2 / 3, 0.0], rtol=0, atol=1e-15)
    assert factor.fallbacks == (method == Factorizer.CHOLMOD)


@pytest.mark.parametrize("method", METHODS)
def test_fill_of_a_tridiagonal_matrix(method):
    """A path graph has an elimination order without fill: LDL^T stores exactly its 2n - 1
    entries and 4(n - 1) + 1 multiply-adds; a supernodal factor may store zeros inside its
    supernodes but never fewer entries.
    """
    n = 40
    K = sp.diags([-np.ones(n - 1), 2.5 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    fill = TangentFactor(method).fill(K, (0,))
    if method == Factorizer.QDLDL:
        assert (fill.nnz, fill.flops) == (2 * n - 1, 4 * (n - 1) + 1)
    else:
        assert fill.nnz >= 2 * n - 1 and fill.flops >= 4 * (n - 1) + 1


def test_both_orders_fill_a_mesh_alike(stressed):
    """Both factorisers order by approximate minimum degree: on a 500-node mesh their factors
    are within a factor 1.5 of each other and many times the tangent's lower triangle.
    """
    pytest.importorskip("cvxopt", reason="pip install '.[cholmod]'")
    K, held = stressed
    held = tuple(held.tolist())
    a, b = (TangentFactor(m).fill(K.tocsr(), held) for m in Factorizer)
    assert 1 / 1.5 < a.nnz / b.nnz < 1.5
    assert min(a.nnz, b.nnz) > 2 * sp.tril(K).nnz


def test_a_squeeze_gives_the_same_events_and_forces_under_either_factoriser():
    """The neo-Hookean foam square (about 400 nodes) at 12 % under each factoriser: the same
    events; depths and forces agree to the contact model's accuracy (the factorisations differ
    in rounding only; Newton stops at a relative residual of 1e-10, so a different rounding
    can end an evaluation one iteration earlier or later).
    """
    pytest.importorskip("cvxopt", reason="pip install '.[cholmod]'")
    _, obj, contacts = foam_square(400)
    runs = {}
    for method in Factorizer:
        with factorizer(method):
            runs[method] = event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.12,
                                         material_model="neo_hookean")
    a, b = runs[Factorizer.CHOLMOD], runs[Factorizer.QDLDL]
    assert a.diagnostics["nonlinear"]["factorizer"] == "cholmod"
    assert b.diagnostics["nonlinear"]["factorizer"] == "qdldl"
    assert len(a.events) >= 4
    assert [(e.type, e.node, e.finger, e.mode) for e in a.events] == \
        [(e.type, e.node, e.finger, e.mode) for e in b.events]
    depths = np.array([[e.depth, f.depth] for e, f in zip(a.events, b.events)])
    assert np.abs(depths[:, 0] - depths[:, 1]).max() < 1e-9 * a.depth
    for finger in ("F1", "F2"):
        assert a.finger_force[finger][1] == pytest.approx(b.finger_force[finger][1], rel=1e-9)
    assert a.energy == pytest.approx(b.energy, rel=1e-9)


def test_the_cholmod_factoriser_without_cvxopt_names_the_install_line(monkeypatch):
    monkeypatch.setattr(interior, "installed", lambda module: False)
    with pytest.raises(ImportError, match=r"pip install '\.\[cholmod\]'"):
        with factorizer("cholmod"):
            pass
    assert interior.default_factorizer() == Factorizer.QDLDL


def test_the_nested_dissection_order_keeps_a_node_s_dofs_together(stressed):
    """METIS's order of the tangent's DOFs is a permutation in which x and y of each node
    follow each other, and it is the same on every call (METIS's seed is fixed).
    """
    pytest.importorskip("pymetis", reason="pip install '.[cholmod]'")
    K, _ = stressed
    order = interior.nested_dissection(K)
    assert sorted(order.tolist()) == list(range(K.shape[0]))
    assert np.array_equal(order[1::2], order[0::2] + 1) and not (order[0::2] % 2).any()
    assert np.array_equal(order, interior.nested_dissection(K))


@pytest.mark.parametrize("scene_name", ["ellipse", "resist_fig10"])
@pytest.mark.parametrize("model", ["corotational", "neo_hookean"])
def test_an_object_sliding_rigidly_at_depth_zero_logs_the_same_events_under_either_factoriser(
        scene_name, model):
    """The ellipse and the Fig. 10 object at mu = 0.05 slide along a finger from the first
    contact on: there the slide hypothesis leaves the normal-force rate an exact zero, computed
    as round-off of about 1e-15 whose sign differs between the factorisers. The mode decision's
    noise floor makes both choose the same modes, so both log the same events (and as the
    linear model does).
    """
    pytest.importorskip("cvxopt", reason="pip install '.[cholmod]'")
    scene = load_scene(scene_file(scene_name))
    scene = dataclasses.replace(scene, friction=dataclasses.replace(scene.friction, mu=0.05))
    obj = scene_solid(scene)

    def events(**kw):
        res = event_squeeze_scene(scene, obj, **kw)
        return res.termination, [(e.type, e.node, e.finger, e.mode, e.depth) for e in res.events]

    runs = {}
    for method in Factorizer:
        with factorizer(method):
            runs[method] = events(material_model=model)
    assert runs[Factorizer.CHOLMOD] == runs[Factorizer.QDLDL]
    linear = events(material_model="linear")
    assert [e[:4] for e in runs[Factorizer.QDLDL][1]] == [e[:4] for e in linear[1]]


@pytest.mark.parametrize("method", METHODS)
def test_one_ordering_and_symbolic_analysis_serve_every_contact_set(method):
    """A neo-Hookean squeeze that adds contacts (each a new contact set, new held DOFs) orders
    and analyses the interior tangent once; every other factorisation is numeric only.
    """
    _, obj, contacts = foam_square(400)
    with factorizer(method):
        res = event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.12,
                            material_model="neo_hookean")
    nl = res.diagnostics["nonlinear"]
    assert sum(e.type == EventType.A for e in res.events) >= 2
    assert nl["factorizations"] > 5 * len(res.events)
    assert nl["analyses"] == 1


@pytest.mark.parametrize("method", METHODS)
def test_factorisations_solves_and_evaluations_run_blas_on_one_thread(method, monkeypatch):
    """With a caller's BLAS at two threads, the factorisation, its solves and a nonlinear
    evaluation's assemblies see one thread, and the caller's two come back after each.
    """
    threadpoolctl = pytest.importorskip("threadpoolctl")
    from squeeze_grasp_ros.mechanics.elastic import contact_response

    seen = []

    def blas_threads() -> set:
        return {info["num_threads"] for info in threadpoolctl.threadpool_info()
                if info["user_api"] == "blas" and "cvxopt" not in info["filepath"]}

    def recording(function):
        def call(*args, **kwargs):
            seen.append((function.__name__, blas_threads()))
            return function(*args, **kwargs)
        call.__name__ = function.__name__
        return call

    chosen = TangentFactor._cholmod if method == Factorizer.CHOLMOD else TangentFactor._qdldl
    monkeypatch.setattr(TangentFactor, chosen.__name__, recording(chosen))
    monkeypatch.setattr(contact_response, "assemble", recording(contact_response.assemble))
    _, obj, contacts = foam_square(300)
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        assert blas_threads() == {2}
        with factorizer(method):
            res = event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.03,
                                material_model="neo_hookean")
        assert blas_threads() == {2}
    assert res.termination == "depth_reached"
    assert {name for name, _ in seen} == {chosen.__name__, "assemble"}
    assert all(threads == {1} for _, threads in seen)


def test_nested_one_thread_blocks_give_the_callers_threads_back_once():
    """An inner block's end keeps BLAS at one thread for the outer one; the outermost end
    gives the caller's two threads back.
    """
    threadpoolctl = pytest.importorskip("threadpoolctl")
    from squeeze_grasp_ros.threads import one_blas_thread

    def blas_threads() -> set:
        return {info["num_threads"] for info in threadpoolctl.threadpool_info()
                if info["user_api"] == "blas" and "cvxopt" not in info["filepath"]}

    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        with one_blas_thread():
            with one_blas_thread():
                assert blas_threads() == {1}
            assert blas_threads() == {1}
        assert blas_threads() == {2}
