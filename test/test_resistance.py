# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Optimal resistance at fixed contacts (Sec. 6.1-6.2) against independent routes.

The closed forms are checked against a generic constrained minimiser (SLSQP) of the work
written straight from the reduced stiffness C, with the constraints written from the node
positions (stable) or from col(AC) (pure), never from the forms under test.
"""

import dataclasses
import json

import numpy as np
import pytest
from scipy.optimize import minimize

from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, mesh_from_triangles
from squeeze_grasp_ros.mechanics.elastic.reduced import displacement_field
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.resistance.forms import expansion_matrix, pure_form
from squeeze_grasp_ros.mechanics.resistance.optimal import (
    ResistanceGrasp,
    compare_resistances,
    contact_segments,
    evaluate_resistance,
    optimal_resistance,
    resistance_along,
    resistance_grasp,
    sweep_directions,
)
from squeeze_grasp_ros.mechanics.vocabulary import Finger

SCENES = "config/scenes"


@pytest.fixture(scope="module")
def blob():
    outline = shapes.fourier_blob(0.05, cos=[0.02, 0.06, 0.0], sin=[0.03, 0.0, 0.02])
    mesh = generate_mesh(outline, outline.area / 160, min_angle=28.0)
    return ElasticObject(mesh, Material(5e4, 0.3, 0.0254)).precompute()


@pytest.fixture(scope="module")
def square():
    """0.1 m square on a structured 21 x 21 grid: bottom-edge nodes every 5 mm."""
    g = np.linspace(-0.05, 0.05, 21)
    X, Y = np.meshgrid(g, g)
    k = np.arange(21 * 21).reshape(21, 21)
    a, b, c, d = k[:-1, :-1].ravel(), k[:-1, 1:].ravel(), k[1:, 1:].ravel(), k[1:, :-1].ravel()
    tris = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    mesh = mesh_from_triangles(np.column_stack([X.ravel(), Y.ravel()]), tris)
    return ElasticObject(mesh, Material(5e4, 0.3, 0.0254)).precompute()


def cross2(u, v):
    """z-component of planar cross products over the last axis."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def random_placement(obj, rng, segment=False):
    """Three boundary contacts at least a sixth of the boundary apart (segments if asked)."""
    b = obj.mesh.boundary
    nb = len(b)
    start = rng.integers(nb)
    gaps = rng.integers(nb // 6, nb // 3, size=2)
    pos = (start + np.concatenate([[0], np.cumsum(gaps)])) % nb
    nodes = b[pos]
    if segment:
        sets = contact_segments(obj.mesh, nodes, half_width=float(rng.uniform(0.002, 0.012)))
    else:
        sets = [[n] for n in nodes]
    return dict(zip(tuple(Finger), sets))


def reference_work(grasp, x, a):
    """W_F = 1/2 (d1, d2, 0) . C (d1, d2, a), expanded node by node (eq. 53 / 94)."""
    P = expansion_matrix(grasp.counts)
    full = P @ np.concatenate([x, a])
    moving = P @ np.concatenate([x, [0.0, 0.0]])
    return 0.5 * moving @ grasp.red.C @ full


def stable_constraints(grasp, a):
    """Sum delta = 0 and sum p x delta = 0 over all contact nodes, from the node positions."""
    P = expansion_matrix(grasp.counts)
    p = grasp.obj.mesh.nodes[grasp.red.contacts]
    rows = np.vstack(
        [np.tile(np.eye(2), len(p)), np.column_stack([-p[:, 1], p[:, 0]]).reshape(1, -1)]
    )
    M = rows @ P
    return M[:, :4], -M[:, 4:] @ a


def pure_constraints(grasp, a):
    """Delta in col(A C): orthogonal to the left null space of A C (no use of E)."""
    P = expansion_matrix(grasp.counts)
    AC = grasp.red.A @ grasp.red.C
    U, s, _ = np.linalg.svd(AC)
    N = U[:, np.count_nonzero(s > 1e-9 * s[0]) :]
    M = N.T @ P
    return M[:, :4], -M[:, 4:] @ a


def numerical_optimum(grasp, a, constraints):
    """SLSQP on the dimensionless problem; returns (d1, d2) in m and W_F in J."""
    L = grasp.obj.scale
    M, rhs = constraints(grasp, a)
    scale = grasp.obj.material.force_scale * L * L

    def fun(y):
        return reference_work(grasp, y * L, a) / scale

    res = minimize(
        fun,
        np.zeros(4),
        method="SLSQP",
        tol=1e-14,
        options={"maxiter": 500},
        constraints=[{"type": "eq", "fun": lambda y: (M @ (y * L) - rhs) / L}],
    )
    assert res.success, res.message
    return res.x * L, res.fun * scale


@pytest.mark.parametrize(
    "mode,constraints", [("stable", stable_constraints), ("pure", pure_constraints)]
)
@pytest.mark.parametrize("segment", [False, True])
@pytest.mark.parametrize("seed", range(4))
def test_closed_form_equals_numerical_minimiser(blob, mode, constraints, segment, seed):
    rng = np.random.default_rng(seed)
    grasp = resistance_grasp(blob, random_placement(blob, rng, segment))
    a = rng.normal(size=2) * 0.004
    res = optimal_resistance(grasp, a, mode=mode)
    assert res.success, res.reason
    x_num, w_num = numerical_optimum(grasp, a, constraints)
    assert res.work["total"] == pytest.approx(w_num, rel=1e-6, abs=1e-9 * abs(res.energy))
    x = np.concatenate([res.d1, res.d2])
    assert np.allclose(x, x_num, atol=1e-5 * np.linalg.norm(x))
    assert reference_work(grasp, x, a) == pytest.approx(res.work["total"], rel=1e-10)


@pytest.mark.parametrize("seed", range(4))
def test_stable_constraints_and_equilibrium(blob, seed):
    rng = np.random.default_rng(10 + seed)
    grasp = resistance_grasp(blob, random_placement(blob, rng))
    a = rng.normal(size=2) * 0.003
    res = optimal_resistance(grasp, a, mode="stable")
    p = blob.mesh.nodes[res.contacts]
    delta = np.array([res.d1, res.d2, a])
    assert np.allclose(delta.sum(axis=0), 0, atol=1e-15)  # eq. (54)
    assert abs(np.sum(cross2(p, delta))) < 1e-12 * np.linalg.norm(a) * blob.scale  # eq. (55)
    f = np.array([res.forces[k] for k in tuple(Finger)])
    fmax = np.abs(f).max()
    assert np.allclose(f.sum(axis=0), 0, atol=1e-10 * fmax)
    assert abs(np.sum(cross2(p, f))) < 1e-10 * fmax * blob.scale
    assert res.energy == pytest.approx(res.work["total"] + res.work["A"], rel=1e-12)


@pytest.mark.parametrize("segment", [False, True])
def test_pure_resistance_has_no_rigid_component(blob, segment):
    rng = np.random.default_rng(3)
    grasp = resistance_grasp(blob, random_placement(blob, rng, segment))
    a = np.array([0.002, -0.003])
    res = optimal_resistance(grasp, a, mode="pure")
    delta = expansion_matrix(grasp.counts) @ np.concatenate([res.d1, res.d2, a])
    field = displacement_field(blob, grasp.red, delta).reshape(-1) / blob.scale
    rigid = blob.rigid.T @ field
    assert np.linalg.norm(rigid) < 1e-9 * np.linalg.norm(field)
    assert abs(res.rigid_rotation) < 1e-12
    stable = optimal_resistance(grasp, a, mode="stable")
    assert (
        stable.work["total"] <= res.work["total"] * (1 + 1e-12) or abs(stable.rigid_rotation) > 0
    )


def test_scaling_with_push_and_material(blob):
    rng = np.random.default_rng(7)
    segments = random_placement(blob, rng)
    grasp = resistance_grasp(blob, segments)
    stiffer = ElasticObject(blob.mesh, Material(2e9, 0.3, 0.003)).precompute()
    grasp2 = resistance_grasp(stiffer, segments)
    eh_ratio = 2e9 * 0.003 / (5e4 * 0.0254)
    a = np.array([-0.003, 0.001])
    for mode in ("stable", "pure"):
        base = optimal_resistance(grasp, a, mode=mode)
        for s in (0.1, 3.0):
            scaled = optimal_resistance(grasp, s * a, mode=mode)
            assert scaled.work["total"] == pytest.approx(s * s * base.work["total"], rel=1e-10)
            assert np.allclose(scaled.psi()[0], base.psi()[0], atol=1e-12)
            assert np.allclose(scaled.d2, s * base.d2, rtol=1e-10, atol=1e-15)
        other = optimal_resistance(grasp2, a, mode=mode)
        assert other.work["total"] == pytest.approx(eh_ratio * base.work["total"], rel=1e-8)
        assert np.allclose(other.d1, base.d1, rtol=1e-8, atol=1e-14)


def edge_placement(square, offset):
    """F1, F2 on the bottom edge of the square with A at node ``offset`` from their midpoint."""
    b = square.mesh.boundary
    p = square.mesh.nodes[b]
    bottom = np.flatnonzero(np.abs(p[:, 1] + 0.05) < 1e-12)
    bottom = bottom[np.argsort(p[bottom, 0])]
    i, j = bottom[3], bottom[17]
    mid = np.flatnonzero(np.all(np.isclose(p[bottom], 0.5 * (p[i] + p[j]), atol=1e-12), axis=1))
    assert len(mid) == 1, "the test mesh must have a node at the midpoint"
    k = bottom[mid[0] + offset]
    return {"F1": [b[i]], "F2": [b[j]], "A": [b[k]]}


def test_theorem11_null_space_at_midpoint_and_unique_optimum(square):
    grasp = resistance_grasp(square, edge_placement(square, 0))
    form = grasp.stable
    lam, vec = np.linalg.eigh(form.H)
    assert lam[0] < 1e-9 * lam[1]  # H singular at the midpoint
    assert abs(vec[:, 0] @ form.t) < 1e-6  # null(H) is normal to p_i - p_j
    assert form.b2 > 0.1 * lam[1]  # yet b2 = t^T H t > 0
    off = resistance_grasp(square, edge_placement(square, 2)).stable
    assert np.linalg.eigvalsh(off.H)[0] > 1e-3 * lam[1]
    res = optimal_resistance(grasp, [0.001, 0.002], mode="stable")
    x_num, w_num = numerical_optimum(grasp, np.array([0.001, 0.002]), stable_constraints)
    assert res.work["total"] == pytest.approx(w_num, rel=1e-6)
    assert np.allclose(np.concatenate([res.d1, res.d2]), x_num, atol=1e-5 * np.linalg.norm(x_num))


def test_optimum_is_continuous_as_pk_crosses_the_midpoint(square):
    """The optimum at the midpoint node agrees with the quadratic through its neighbours."""
    a = np.array([0.001, 0.002])
    offsets = np.array([-2, -1, 0, 1, 2])
    runs = [
        optimal_resistance(resistance_grasp(square, edge_placement(square, off)), a, mode="stable")
        for off in offsets
    ]
    values = np.array([[*r.d1, *r.d2, r.work["total"]] for r in runs])
    assert np.all(np.isfinite(values))
    side = offsets != 0
    for column in values.T:
        fit = np.polyval(np.polyfit(offsets[side], column[side], 2), 0.0)
        spread = np.ptp(column[side])
        assert abs(column[2] - fit) < 0.05 * spread + 1e-12 * abs(column).max()


def test_segments_make_H_definite_at_the_midpoint(square):
    point = edge_placement(square, 0)
    nodes = [point[f][0] for f in tuple(Finger)]
    sets = dict(zip(tuple(Finger), contact_segments(square.mesh, nodes)))
    H = resistance_grasp(square, sets).stable.H
    lam = np.linalg.eigvalsh(H)
    assert lam[0] > 1e-3 * lam[1]  # Proposition 12


def synthetic_grasp(blob, U):
    """A real grasp whose pure feasible set is replaced by the span of ``U`` (6 x k)."""
    grasp = resistance_grasp(blob, random_placement(blob, np.random.default_rng(1)))
    grasp.__dict__["pure"] = pure_form(grasp.G, U)
    return grasp


def minimise_over_span(grasp, U, a):
    """SLSQP over tau with U tau = (d1, d2, a); dependent constraint rows dropped."""
    L = grasp.obj.scale
    Uq, sv, _ = np.linalg.svd(U[4:])
    rows = Uq[:, sv > 1e-9].T

    def fun(tau):
        x = U @ tau
        return reference_work(grasp, x[:4] * L, x[4:] * L) / grasp.obj.material.force_scale / L**2

    res = minimize(
        fun,
        np.linalg.lstsq(U[4:], a / L, rcond=None)[0],
        method="SLSQP",
        tol=1e-14,
        constraints=[{"type": "eq", "fun": lambda tau: rows @ (U[4:] @ tau - a / L)}],
    )
    assert res.success
    return (U @ res.x)[:4] * L


@pytest.mark.parametrize("rank", [2, 1, 0])
def test_rank_cases_of_Q(blob, rank):
    rng = np.random.default_rng(rank)
    U = np.linalg.qr(rng.normal(size=(6, 3)))[0]
    v = np.array([1.0, 1.0]) / np.sqrt(2.0)
    if rank < 2:
        U[4:] = 0.0
        if rank == 1:
            U[4:, 0] = 0.5 * v
        U = np.linalg.qr(U)[0]
    grasp = synthetic_grasp(blob, U)
    assert grasp.pure.rank == rank
    inside = 0.004 * v
    outside = 0.004 * np.array([v[1], -v[0]])
    if rank >= 1:
        res = optimal_resistance(grasp, inside, mode="pure")
        assert res.success and res.reason == "optimal pure resistance"
        assert np.allclose(
            np.concatenate([res.d1, res.d2]),
            minimise_over_span(grasp, U, inside),
            atol=1e-6 * np.linalg.norm(res.d1) + 1e-12,
        )
    if rank < 2:
        res = optimal_resistance(grasp, outside, mode="pure")
        assert not res.success and res.reason.startswith("cannot be resisted")
        out = res.to_json()
        json.dumps(out, allow_nan=False)
        assert out["d1"] is None and out["work"]["total"] is None
        assert out["diagnostics"]["rank_Q"] == rank
        sweep = sweep_directions(grasp, "pure", 8)
        assert sweep.feasible.sum() == (2 if rank == 1 else 0)
        json.dumps(sweep.to_json(), allow_nan=False)


@pytest.mark.parametrize("mode", ["stable", "pure"])
def test_sweep_matches_single_directions(blob, mode):
    grasp = resistance_grasp(blob, random_placement(blob, np.random.default_rng(5)))
    sweep = sweep_directions(grasp, mode, 12)
    for k in (0, 5, 11):
        u = np.array([np.cos(sweep.angles[k]), np.sin(sweep.angles[k])])
        res = optimal_resistance(grasp, 0.002 * u, mode=mode)
        assert sweep.unit_work[k] == pytest.approx(res.unit_work, rel=1e-10)
        assert np.allclose(sweep.psi[k], np.concatenate(res.psi()), atol=1e-12)


@pytest.mark.parametrize("mode", ["stable", "pure"])
def test_a_push_and_its_opposite_cost_the_same_and_the_extremes_take_the_first(blob, mode):
    """W*_F of fixed contacts is even in a (a quadratic form of the push): over an even number
    of directions each one's opposite has the same unit work to round-off, so the easiest and
    the hardest are each reached twice; the sweep names the first of each pair (the smallest
    angle), not the one the machine's round-off favours (Fig. 9's hardest push printed 92 deg
    on one machine and 272 deg on another).
    """
    grasp = resistance_grasp(blob, random_placement(blob, np.random.default_rng(5)))
    sweep = sweep_directions(grasp, mode, 360)
    w = sweep.unit_work
    assert np.all(sweep.feasible == np.roll(sweep.feasible, 180))
    ok = sweep.feasible
    assert np.abs(w[ok] - np.roll(w, 180)[ok]).max() <= 1e-13 * np.nanmax(w)
    ext = sweep.extremes()
    for key, pick in (("min", np.nanmin), ("max", np.nanmax)):
        k = int(round(ext[key]["angle_deg"]))
        assert k < 180 and ext[key]["unit_work"] == pytest.approx(pick(w), rel=1e-12)
        flipped = dataclasses.replace(sweep, unit_work=np.roll(w, 180))  # the other round-off
        assert flipped.extremes()[key]["angle_deg"] == ext[key]["angle_deg"]


def test_user_given_resistance_against_the_optimum(blob):
    grasp = resistance_grasp(blob, random_placement(blob, np.random.default_rng(8)))
    a = np.array([0.0024, 0.0044])
    best = optimal_resistance(grasp, a, mode="stable")
    same = resistance_along(grasp, a, best.d1, "stable")
    assert np.allclose(same.d1, best.d1, atol=1e-12) and same.success
    other = resistance_along(grasp, a, [0.447, -0.894], "stable")
    assert other.success and abs(cross2(other.d1, np.array([0.447, -0.894]))) < 1e-15
    cmp = compare_resistances(best, other)
    assert cmp["excess_work"] > 0 and cmp["ratio"] > 1
    bad = evaluate_resistance(grasp, other.d1, other.d2 + 1e-4, a, "stable")
    assert not bad.success and "not a stable resistance" in bad.reason
    ok = evaluate_resistance(grasp, other.d1, other.d2, a, "stable")
    assert ok.success and ok.work["total"] == pytest.approx(other.work["total"])


def test_invalid_inputs(blob):
    b = blob.mesh.boundary
    with pytest.raises(InvalidInputError, match="disjoint"):
        resistance_grasp(blob, {"F1": [b[0], b[1]], "F2": [b[1]], "A": [b[9]]})
    with pytest.raises(InvalidInputError, match="keys"):
        resistance_grasp(blob, {"F1": [b[0]], "F2": [b[5]]})
    grasp = resistance_grasp(blob, {"F1": [b[0]], "F2": [b[12]], "A": [b[25]]})
    with pytest.raises(InvalidInputError, match="nonzero"):
        optimal_resistance(grasp, [0.0, 0.0])
    with pytest.raises(InvalidInputError, match="mode"):
        optimal_resistance(grasp, [0.001, 0.0], mode="rigid")
    assert isinstance(grasp, ResistanceGrasp)


def test_cli_resist_point_segment_and_sweep(tmp_path, capsys):
    plot = tmp_path / "fig9.png"
    assert (
        main(
            [
                "resist",
                f"{SCENES}/resist_fig9.yaml",
                "--json",
                "--directions",
                "36",
                "--plot",
                str(plot),
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    for key in ("success", "reason", "d1", "d2", "a", "work", "forces", "event_counts"):
        assert key in out
    assert out["success"] and set(out["work"]) >= {"F1", "F2", "total"}
    assert np.allclose(np.add(np.add(out["d1"], out["d2"]), out["a"]), 0, atol=1e-15)
    assert len(out["sweep"]["unit_work"]) == 36 and plot.stat().st_size > 0
    assert (
        main(
            [
                "resist",
                f"{SCENES}/resist_fig10.yaml",
                "--contacts",
                "segment",
                "--mode",
                "pure",
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["contact_model"] == "segment" and out["mode"] == "pure"
    assert all(len(out["segments"][f]) >= 2 for f in tuple(Finger))


@pytest.mark.parametrize("bad", [10**6, -1])
def test_a_node_index_outside_the_mesh_is_refused(square, bad):
    """An index past the mesh's nodes used to escape as IndexError."""
    b = [int(k) for k in square.mesh.boundary]
    with pytest.raises(InvalidInputError, match=r"contact nodes must be node indices in \[0, "):
        resistance_grasp(square, {"F1": [b[0]], "F2": [bad], "A": [b[5]]})


def test_a_direction_beyond_the_float_range_is_the_same_direction(blob):
    """``--compare-direction 1e308 1e308`` overflowed the normalisation (with a RuntimeWarning)
    and compared the resistance along [0, 0]: now it is the resistance along [1, 1], bit for
    bit, and the ordinary direction's answer is unchanged.
    """
    grasp = resistance_grasp(blob, random_placement(blob, np.random.default_rng(8)))
    a = np.array([0.0024, 0.0044])
    along = resistance_along(grasp, a, [1.0, 1.0], "stable")
    with np.errstate(all="raise"):
        huge = resistance_along(grasp, a, [1e308, 1e308], "stable")
    assert huge.success and huge.reason == along.reason
    assert np.array_equal(huge.d1, along.d1) and huge.work == along.work


def test_overlapping_segments_name_the_half_width_and_its_bound(capsys):
    """A ``--segment-half-width`` so wide that two fingers' segments meet was refused as
    "contact sets of F1, F2 and A must be disjoint" with three lists of up to 60 nodes, not
    naming the option or its bound: now one short line with the nearest contacts' distance
    along the boundary and the half width below which the segments stay apart.
    """
    words = ["resist", f"{SCENES}/resist_fig9.yaml", "--contacts", "segment",
             "--segment-half-width"]
    assert main([*words, "1e308"]) == 2
    message = capsys.readouterr().err.strip()
    assert message == (
        "squeeze-grasp resist: error: segment half width 1e+308 m makes the contact segments "
        "of F1 and F2 overlap; the nearest contacts, F2 and A, are 0.09472 m apart along the "
        "boundary, so the half width must be below 0.04736 m")
    assert main([*words, "0.0473", "--json"]) == 0
    capsys.readouterr()
