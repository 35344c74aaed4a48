# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Strain and stress measures: closed forms on one element (uniaxial stretch, simple shear,
rigid rotation, the neo-Hookean and corotational plane-stress Cauchy stresses derived by hand),
the reference numbers of an independent neo-Hookean solver on the foam square at 12 %, the
strain limit in each model's measure, and reports that name their measures.
"""
from __future__ import annotations

import json

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic.hyperelastic import deformation
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.strain_measures import (
    largest_pair_entry,
    max_principal_strain,
    max_principal_strains,
    principal_strains,
)
from squeeze_grasp_ros.mechanics.elastic.stress_measures import element_stresses, von_mises
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel, StrainMeasure, StressMeasure
from squeeze_grasp_ros.scene import event_squeeze_scene

E, NU = 5e4, 0.3
X = np.array([[0.0, 0.0], [0.02, 0.0], [0.005, 0.015]])
"""One irregular element, m."""
TRI = np.array([[0, 1, 2]])


def element_F(F: np.ndarray) -> np.ndarray:
    """F of the one element under the homogeneous deformation x = F X, through its nodes."""
    u = X @ np.asarray(F, float).T - X
    return deformation(X, TRI, u.reshape(-1))


def rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def principal(F: np.ndarray, measure: StrainMeasure) -> np.ndarray:
    return principal_strains(element_F(F), measure)[0]


# --------------------------------------------------------------------- strains, closed forms
@given(st.floats(0.3, 2.5))
@settings(max_examples=40, deadline=None)
def test_uniaxial_stretch_in_every_measure(stretch):
    """F = diag(l, 1): small = Biot = l - 1, log = ln l, Green-Lagrange = (l^2 - 1) / 2; the
    other principal strain is 0 in every measure.
    """
    expected = {StrainMeasure.SMALL: stretch - 1, StrainMeasure.BIOT: stretch - 1,
                StrainMeasure.LOG: np.log(stretch),
                StrainMeasure.GREEN_LAGRANGE: (stretch**2 - 1) / 2}
    for measure, value in expected.items():
        eps = principal(np.diag([stretch, 1.0]), measure)
        assert sorted(eps) == pytest.approx(sorted([value, 0.0]), abs=1e-12)


@given(st.floats(-1.5, 1.5))
@settings(max_examples=40, deadline=None)
def test_simple_shear_in_every_measure(gamma):
    """F = [[1, g], [0, 1]]: stretches sqrt(1 + g^2/4) +- g/2; small strain +-g/2, Biot
    l - 1, log +-asinh(g/2), Green-Lagrange (l^2 - 1) / 2.
    """
    root = np.sqrt(1 + gamma**2 / 4)
    stretches = np.array([root + abs(gamma) / 2, root - abs(gamma) / 2])
    F = np.array([[1.0, gamma], [0.0, 1.0]])
    expected = {StrainMeasure.SMALL: [abs(gamma) / 2, -abs(gamma) / 2],
                StrainMeasure.BIOT: stretches - 1,
                StrainMeasure.LOG: [np.arcsinh(abs(gamma) / 2), -np.arcsinh(abs(gamma) / 2)],
                StrainMeasure.GREEN_LAGRANGE: (stretches**2 - 1) / 2}
    for measure, value in expected.items():
        assert principal(F, measure) == pytest.approx(value, abs=1e-12)


@given(st.floats(-3.0, 3.0), st.floats(0.5, 1.6), st.floats(0.5, 1.6))
@settings(max_examples=40, deadline=None)
def test_only_the_small_strain_sees_a_rotation(angle, a, b):
    """R diag(a, b) has the stretches of diag(a, b) in the Biot, log and Green-Lagrange
    measures; a rigid rotation has a small strain of cos(angle) - 1 in both directions.
    """
    for measure in (StrainMeasure.BIOT, StrainMeasure.LOG, StrainMeasure.GREEN_LAGRANGE):
        assert principal(rotation(angle) @ np.diag([a, b]), measure) == pytest.approx(
            principal(np.diag([a, b]), measure), abs=1e-12)
    assert principal(rotation(angle), StrainMeasure.SMALL) == pytest.approx(
        [np.cos(angle) - 1] * 2, abs=1e-12)


def test_small_strains_keep_their_digits():
    """At a 1e-10 stretch every measure equals the displacement gradient to 1e-12 relative: no
    cancellation in lambda - 1 or ln lambda (sqrt of F^T F - 1 would keep 6 digits).
    """
    F = np.diag([1.0 + 1e-10, 1.0 - 3e-11])[None]
    h = np.diag(F[0]) - 1.0
    for measure in StrainMeasure:
        assert principal_strains(F, measure)[0] == pytest.approx(h, rel=1e-12)


def test_the_largest_strains_of_a_field_are_its_elements_eigenvalues():
    """A field of 500 random gradients: the Green-Lagrange principal strains are the
    eigenvalues of (F^T F - I) / 2 (numpy's eigvalsh), and the largest strain of each measure
    is the largest |eigenvalue| mapped to the measure over the elements.
    """
    rng = np.random.default_rng(7)
    F = np.eye(2) + 0.3 * rng.standard_normal((500, 2, 2))
    F[:, 0, 0] = np.abs(F[:, 0, 0]) + 0.5  # keep det F > 0
    F[:, 1, 1] = np.abs(F[:, 1, 1]) + 0.5
    e = np.linalg.eigvalsh(0.5 * (np.swapaxes(F, 1, 2) @ F - np.eye(2)))[:, ::-1]
    np.testing.assert_allclose(principal_strains(F, StrainMeasure.GREEN_LAGRANGE), e,
                               rtol=1e-12, atol=1e-14)
    stretch = np.sqrt(1 + 2 * e)
    small = np.linalg.eigvalsh(0.5 * (F + np.swapaxes(F, 1, 2)) - np.eye(2))
    expected = {StrainMeasure.GREEN_LAGRANGE: e, StrainMeasure.BIOT: stretch - 1,
                StrainMeasure.LOG: np.log(stretch), StrainMeasure.SMALL: small}
    largest = max_principal_strains(F)
    for measure, eps in expected.items():
        assert largest[measure] == pytest.approx(float(np.abs(eps).max()), rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(*[st.sampled_from([-2.0, -1.0, -0.0, 0.0, 1.0, 2.0, np.nan])] * 3),
                min_size=1, max_size=12))
def test_the_largest_entry_is_the_first_element_with_the_largest_strain(rows):
    """Ties, signed zeros and NaN: (value, element) is max(|eps_1|, |eps_2|) of the first
    element where that is largest, a NaN winning as in argmax, also of a pair that is two
    columns of a wider array (the componentwise criterion's normal strains).
    """
    eps = np.array(rows, float)
    for pair in (eps[:, :2], eps[:, 1:]):
        per_element = [max(abs(a), abs(b)) if a == a and b == b else np.nan for a, b in pair]
        k = next((i for i, v in enumerate(per_element) if v != v), None)
        if k is None:
            k = int(np.argmax(per_element))
        value, element = largest_pair_entry(pair)
        assert element == k
        assert value == per_element[k] or (value != value and per_element[k] != per_element[k])


def test_the_field_maxima_are_each_measure_s_largest_element():
    """:func:`max_principal_strains` is the value :func:`max_principal_strain` finds per
    measure, to the bit (a field with an element folded to a line: log -inf).
    """
    rng = np.random.default_rng(3)
    F = np.eye(2) + 0.2 * rng.standard_normal((300, 2, 2))
    F[7] = [[1.0, 0.0], [0.0, 0.0]]
    largest = max_principal_strains(F)
    assert list(largest) == list(StrainMeasure)
    for measure in StrainMeasure:
        assert largest[measure] == max_principal_strain(F, measure)[0]
    assert largest[StrainMeasure.LOG] == np.inf


def test_an_unknown_measure_names_the_valid_ones():
    with pytest.raises(ValueError, match="strain measure must be one of"):
        principal_strains(np.eye(2)[None], "engineering")


# --------------------------------------------------------------------- stresses, closed forms
def neo_hookean_cauchy(F: np.ndarray, E: float, nu: float) -> np.ndarray:
    """By hand: the compressible neo-Hookean Cauchy stress sigma = mu / J (b - I) + lambda ln J /
    J I of F3 = diag(F, l3), with l3 the root of sigma33 = mu (l3^2 - 1) + lambda ln(J) = 0.
    """
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    J2 = np.linalg.det(F)
    l3 = brentq(lambda s: mu * (s * s - 1) + lam * np.log(J2 * s), 0.1, 10.0, xtol=1e-15)
    J = J2 * l3
    return mu / J * (F @ F.T - np.eye(2)) + lam * np.log(J) / J * np.eye(2)


@given(st.floats(-3.0, 3.0), st.floats(0.6, 1.5), st.floats(0.6, 1.5), st.floats(-0.5, 0.5),
       st.floats(0.0, 0.45))
@settings(max_examples=40, deadline=None)
def test_neo_hookean_cauchy_stress_is_the_closed_form(angle, a, b, shear, nu):
    F = rotation(angle) @ np.array([[a, shear], [0.0, b]])
    sigma, measure = element_stresses("neo_hookean", element_F(F), E=E, nu=nu)
    assert measure == StressMeasure.CAUCHY
    assert sigma[0] == pytest.approx(neo_hookean_cauchy(F, E, nu), abs=1e-9 * E)


@given(st.floats(-3.0, 3.0), st.floats(0.6, 1.5), st.floats(0.0, 0.49))
@settings(max_examples=40, deadline=None)
def test_corotational_uniaxial_cauchy_stress_is_the_closed_form(angle, stretch, nu):
    """Uniaxial Biot stress: F = R diag(l, l2) with l2 = 1 - nu (l - 1) leaves the lateral
    stress free; the thickness stretch is l2 too, so sigma = R diag(E (l - 1) / l2^2, 0) R^T.
    """
    lateral = 1 - nu * (stretch - 1)
    F = rotation(angle) @ np.diag([stretch, lateral])
    sigma, measure = element_stresses("corotational", element_F(F), E=E, nu=nu)
    expected = rotation(angle) @ np.diag([E * (stretch - 1) / lateral**2, 0.0]) @ rotation(angle).T
    assert measure == StressMeasure.CAUCHY
    assert sigma[0] == pytest.approx(expected, abs=1e-9 * E)
    assert von_mises(sigma)[0] == pytest.approx(E * abs(stretch - 1) / lateral**2, rel=1e-9,
                                                abs=1e-9 * E)


def test_the_linear_stress_is_c_eps():
    """The linear model's stress is the plane-stress D times the engineering strain of F."""
    H = np.array([[0.03, -0.02], [0.05, -0.04]])
    sigma, measure = element_stresses("linear", element_F(np.eye(2) + H), E=E, nu=NU)
    s = Material(E, NU, 0.01).elasticity_matrix() @ [H[0, 0], H[1, 1], H[0, 1] + H[1, 0]]
    assert measure == StressMeasure.SMALL_STRAIN
    assert sigma[0] == pytest.approx(np.array([[s[0], s[2]], [s[2], s[1]]]), rel=1e-12)


def test_von_mises_of_uniaxial_equibiaxial_and_shear_stress():
    stresses = np.array([np.diag([-7.0, 0.0]), np.diag([4.0, 4.0]), [[0.0, 2.0], [2.0, 0.0]]])
    assert von_mises(stresses) == pytest.approx([7.0, 4.0, 2 * np.sqrt(3)], rel=1e-14)


def test_every_model_names_its_own_measures():
    assert [(m.strain_measure, m.stress_measure) for m in MaterialModel] == [
        (StrainMeasure.SMALL, StressMeasure.SMALL_STRAIN),
        (StrainMeasure.BIOT, StressMeasure.CAUCHY), (StrainMeasure.LOG, StressMeasure.CAUCHY)]


# --------------------------------------------------------------------- the foam square at 12 %
@pytest.fixture(scope="module")
def foam_square_12():
    """The shipped foam square (2,054 nodes) squeezed to 12 %, linear and neo-Hookean."""
    scene = load_scene(scene_file("foam_square"))
    obj = scene_solid(scene).precompute()
    return obj, {m: event_squeeze_scene(scene, obj, material_model=m)
                 for m in (MaterialModel.LINEAR, MaterialModel.NEO_HOOKEAN)}


def independent_max_strains(obj, displacement) -> dict[str, float]:
    """Largest |principal strain| per measure from numpy's eigenvalues of sym(F) - I and F^T F."""
    p = obj.mesh.nodes[obj.mesh.triangles]
    d = displacement[obj.mesh.triangles]
    dX = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=2)
    dx = dX + np.stack([d[:, 1] - d[:, 0], d[:, 2] - d[:, 0]], axis=2)
    F = dx @ np.linalg.inv(dX)
    small = np.linalg.eigvalsh(0.5 * (F + np.swapaxes(F, 1, 2)) - np.eye(2))
    stretch = np.sqrt(np.linalg.eigvalsh(np.swapaxes(F, 1, 2) @ F))
    return {"small": np.abs(small).max(), "biot": np.abs(stretch - 1).max(),
            "log": np.abs(np.log(stretch)).max(),
            "green_lagrange": np.abs((stretch**2 - 1) / 2).max()}


def test_like_for_like_the_neo_hookean_peak_strain_is_lower(foam_square_12):
    """Reference (an independent neo-Hookean solver on the same mesh): the neo-Hookean peak
    strain is below linear's by 7.8 % (small), 8.2 % (nominal, Biot) and 9.4 % (log); the old
    report's 'max strain +3.87 %' compared its log strain with linear's small strain.
    """
    obj, res = foam_square_12
    lin, neo = (res[m].health for m in (MaterialModel.LINEAR, MaterialModel.NEO_HOOKEAN))
    for r in res.values():
        assert r.health.max_principal_strain == pytest.approx(
            independent_max_strains(obj, r.displacement), rel=1e-10)
    d = {m: neo.max_principal_strain[m] / lin.max_principal_strain[m] - 1 for m in StrainMeasure}
    assert (d["small"], d["biot"], d["log"]) == pytest.approx((-0.078, -0.082, -0.094), abs=5e-4)
    assert (lin.strain_measure, neo.strain_measure) == (StrainMeasure.SMALL, StrainMeasure.LOG)
    assert lin.max_strain == pytest.approx(lin.max_principal_strain["small"], rel=1e-12)
    assert neo.max_strain == pytest.approx(neo.max_principal_strain["log"], rel=1e-12)
    assert neo.max_strain / lin.max_strain - 1 == pytest.approx(0.0387, abs=5e-5)


def test_the_neo_hookean_stress_is_its_cauchy_stress(foam_square_12):
    """Reference: 13,217 Pa from the neo-Hookean Cauchy stress, where the old report gave the
    small-strain linear stress of the same field, 11,907 Pa (11 % low).
    """
    obj, res = foam_square_12
    neo = res[MaterialModel.NEO_HOOKEAN]
    assert neo.health.stress_measure == StressMeasure.CAUCHY
    assert neo.health.max_von_mises == pytest.approx(13217, abs=0.5)
    F = deformation(obj.mesh.nodes, obj.mesh.triangles, neo.displacement)
    small, _ = element_stresses("linear", F, E=obj.material.E, nu=obj.material.nu)
    assert von_mises(small).max() == pytest.approx(11907, abs=0.5)
    k = neo.health.max_von_mises_element
    by_hand = neo_hookean_cauchy(F[k], obj.material.E, obj.material.nu)
    assert von_mises(by_hand[None])[0] == pytest.approx(neo.health.max_von_mises, rel=1e-9)


# --------------------------------------------------------------------- the strain limit
@pytest.mark.parametrize("model", ["corotational", "neo_hookean"])
def test_the_strain_limit_is_on_the_model_s_own_measure(model):
    """A nonlinear squeeze stops where its own measure reaches epsilon*: the Biot or log strain
    of the final field (numpy's eigenvalues) is epsilon*, the other measures are not.
    """
    scene = load_scene(scene_file("foam_square_strain_limit"))
    obj = scene_solid(scene)
    res = event_squeeze_scene(scene, obj, material_model=model)
    eps = scene.strain_limit.epsilon
    assert res.termination == "strain_limit"
    own = MaterialModel(model).strain_measure
    strains = independent_max_strains(obj, res.displacement)
    assert strains[own] == pytest.approx(eps, rel=1e-6)
    assert all(abs(strains[m] / eps - 1) > 1e-3 for m in strains if m != own)
    out = res.to_json()
    assert out["strain_limit"] == {"epsilon": eps, "measure": own, "criterion": "principal"}
    assert out["health"]["strain_measure"] == own and out["material_model"] == model


# --------------------------------------------------------------------- reports
def test_squeeze_reports_name_their_measures(tmp_path, capfd):
    """JSON and text of a neo-Hookean strain-limited squeeze name the log strain and the Cauchy
    stress; --compare-models compares strains measure by measure and says which it shows.
    """
    data = yaml.safe_load(open(scene_file("foam_square_strain_limit")))
    data["object"]["mesh"]["nodes"] = 400
    data["object"]["material"]["model"] = "neo_hookean"
    path = tmp_path / "square.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["squeeze", str(path), "--json"]) == 0
    h = json.loads(capfd.readouterr().out)["health"]
    assert (h["strain_measure"], h["stress_measure"]) == ("log", "cauchy")
    assert set(h["max_principal_strain"]) == set(StrainMeasure.values())
    assert main(["squeeze", str(path)]) == 0
    text = capfd.readouterr().out
    assert "strain limit 0.1 on the log strain (principal)" in text
    assert "(log strain, principal, element" in text and "Pa (Cauchy stress)" in text
    assert main(["squeeze", str(path), "--relative-depth", "0.02", "--compare-models",
                 "--json"]) == 0
    out = json.loads(capfd.readouterr().out)
    rows, diff = out["models"], out["relative_difference"]
    assert out["common_strain_measure"] == "biot"
    assert {m: r["strain_measure"] for m, r in rows.items()} == {
        "linear": "small", "corotational": "biot", "neo_hookean": "log"}
    for model, d in diff.items():
        assert "max_strain" not in d
        for measure, value in d["max_principal_strain"].items():
            assert value == pytest.approx(rows[model]["max_principal_strain"][measure]
                                          / rows["linear"]["max_principal_strain"][measure] - 1)
    assert main(["squeeze", str(path), "--relative-depth", "0.02", "--compare-models"]) == 0
    text = capfd.readouterr().out
    assert "like for like" in text and "max Biot strain" in text


def test_a_symmetric_squeeze_names_the_first_of_its_mirror_twins():
    """The foam square squeezed symmetrically displaces two mirror nodes equally to round-off
    (1e-16 relative), which np.argmax would choose between by the machine's arithmetic: the
    grasp health names the first of them, and the largest strain's element is the first within
    the tie of the largest.
    """
    scene = load_scene(scene_file("foam_square"))
    result = event_squeeze_scene(scene, scene_solid(scene))
    norms = np.hypot(*result.displacement.T)
    twins = np.flatnonzero(norms >= norms.max() * (1 - 1e-12))
    assert len(twins) == 2 and np.ptp(norms[twins]) <= 1e-15 * norms.max()
    assert result.health.max_displacement_node == twins[0]
    assert result.health.max_displacement == pytest.approx(norms.max(), rel=1e-15)
    pair = np.array([[3.0, -1.0], [2.0, 3.0 * (1 + 1e-15)], [3.0, 0.0]])
    assert largest_pair_entry(pair) == (3.0 * (1 + 1e-15), 0)
