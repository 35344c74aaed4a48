# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Paper theorems (Sec. 3-4) as properties over random meshes and contact sets.

The null-space C is checked against an independent route: the paper's spectral A (dense
eigendecomposition) with M of eq. (27) inverted directly.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject, node_dofs
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
from squeeze_grasp_ros.mechanics.elastic.reduced import (
    displacement_field,
    reduced_stiffness,
    rotation_angle,
)
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze, two_contact_direction

SETTINGS = settings(
    max_examples=12,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@st.composite
def objects(draw):
    """A random star-shaped blob, coarse mesh, random material, both solver routes."""
    c = [draw(st.floats(-0.15, 0.15)) for _ in range(3)]
    s = [draw(st.floats(-0.15, 0.15)) for _ in range(3)]
    outline = shapes.fourier_blob(draw(st.floats(0.01, 1.0)), cos=c, sin=s)
    mesh = generate_mesh(outline, outline.area / draw(st.integers(80, 250)), min_angle=28.0)
    mat = Material(
        draw(st.floats(1e3, 1e9)), draw(st.floats(-0.5, 0.49)), draw(st.floats(1e-3, 0.1))
    )
    return ElasticObject(mesh, mat), ElasticObject(mesh, mat, "spectral")


@st.composite
def object_and_contacts(draw):
    obj, ref = draw(objects())
    b = len(obj.mesh.boundary)
    m = draw(st.integers(2, 4))
    pos = draw(st.lists(st.integers(0, b - 1), min_size=m, max_size=m, unique=True))
    return obj, ref, obj.mesh.boundary[pos]


def saddle_inverse(A, B):
    """The paper's route: invert M = [[A, B], [B^T, 0]] directly (eqs. 27, 29)."""
    m2 = len(A)
    M = np.block([[A, B], [B.T, np.zeros((3, 3))]])
    Minv = np.linalg.inv(M)
    return Minv[:m2, :m2], Minv[:m2, m2:], Minv[m2:, m2:]


@SETTINGS
@given(object_and_contacts())
def test_theorem7_against_spectral_saddle_inverse(case):
    obj, ref, contacts = case
    red = reduced_stiffness(obj, contacts)
    red_ref = reduced_stiffness(ref, contacts)
    C_ref, E_ref, H_ref = saddle_inverse(red_ref.A, red_ref.B)
    scale = np.abs(C_ref).max()
    assert np.abs(red.C - C_ref).max() <= 1e-7 * scale
    assert np.abs(red.E - E_ref).max() <= 1e-7 * max(np.abs(E_ref).max(), 1.0)
    assert np.abs(red.H - H_ref).max() <= 1e-7 * np.abs(H_ref).max()  # eq. (29), H block
    assert np.allclose(red.H, red.H.T, atol=1e-12 * np.abs(H_ref).max())
    # (i) C symmetric PSD with null(C) = col(B)
    assert np.allclose(red.C, red.C.T, atol=1e-12 * scale)
    eig = np.linalg.eigvalsh(red.C)
    assert eig.min() >= -1e-9 * eig.max()
    assert np.abs(red.C @ red.B).max() <= 1e-9 * scale
    assert np.sum(eig > 1e-9 * eig.max()) == 2 * red.m - 3
    # (ii) AC has rank 2m-3 with the single eigenvalue 1
    lam = np.sort(np.abs(np.linalg.eigvals(red.A @ red.C)))
    assert np.allclose(lam[3:], 1.0, atol=1e-7) and np.allclose(lam[:3], 0.0, atol=1e-7)
    # eq. (30): M M^-1 = I
    assert np.allclose(red.A @ red.C + red.B @ red.E.T, np.eye(2 * red.m), atol=1e-8)
    assert np.allclose(red.B.T @ red.E, np.eye(3), atol=1e-8)


@SETTINGS
@given(object_and_contacts())
def test_theorem5_saddle_matrix_nonsingular_and_lemma4(case):
    obj, _, contacts = case
    red = reduced_stiffness(obj, contacts)
    M = np.block([[red.A, red.B], [red.B.T, np.zeros((3, 3))]])
    s = np.linalg.svd(M, compute_uv=False)
    assert s.min() > 1e-10 * s.max()
    Q, _ = np.linalg.qr(red.B, mode="complete")
    Z = Q[:, 3:]
    assert np.linalg.eigvalsh(Z.T @ red.A @ Z).min() > 0


@SETTINGS
@given(object_and_contacts(), st.integers(0, 2**31 - 1))
def test_theorem8_pure_part_has_no_rigid_component(case, seed):
    obj, _, contacts = case
    red = reduced_stiffness(obj, contacts)
    delta = np.random.default_rng(seed).normal(size=2 * red.m) * 1e-3 * obj.scale
    field = displacement_field(obj, red, delta).ravel()
    pure = displacement_field(obj, red, red.pure_part(delta)).ravel()
    R = obj.rigid
    psi = field - R @ (R.T @ field)  # eq. (17)
    assert np.abs(R.T @ pure).max() <= 1e-9 * np.abs(field).max()
    assert np.allclose(pure, psi, atol=1e-9 * np.abs(field).max())
    # the field honours the prescribed contact displacements (eq. 22)
    assert np.allclose(field[node_dofs(contacts)], delta, atol=1e-10 * obj.scale)


@SETTINGS
@given(object_and_contacts())
def test_equilibrium_of_contact_forces(case):
    obj, _, contacts = case
    red = reduced_stiffness(obj, contacts)
    rng = np.random.default_rng(len(contacts))
    F = red.forces(rng.normal(size=2 * red.m)).reshape(-1, 2)
    p = obj.mesh.nodes[contacts]
    scale = np.abs(F).max()
    assert np.abs(F.sum(axis=0)).max() <= 1e-9 * scale
    torque = np.sum(p[:, 0] * F[:, 1] - p[:, 1] * F[:, 0])
    assert abs(torque) <= 1e-9 * scale * obj.scale


@SETTINGS
@given(objects(), st.integers(0, 10**6))
def test_theorem10_and_stable_pure_identities(pair, seed):
    obj, _ = pair
    b = obj.mesh.boundary
    rng = np.random.default_rng(seed)
    i, j = b[rng.choice(len(b), 2, replace=False)]
    red = reduced_stiffness(obj, [i, j])
    u = two_contact_direction(obj.mesh.nodes[i], obj.mesh.nodes[j])
    uAu = u @ red.A @ u
    assert np.allclose(red.C, np.outer(u, u) / uAu, atol=1e-9 * np.abs(red.C).max())
    stable = plan_squeeze(obj, [i, j], kind="stable", red=red)
    pure = plan_squeeze(obj, [i, j], kind="pure", red=red)
    sign = np.sign(stable.displacement @ u)
    Au = red.A @ u
    assert np.allclose(stable.forces, sign * u / uAu, rtol=1e-9, atol=1e-12 / uAu)
    assert np.allclose(pure.displacement, sign * Au / np.linalg.norm(Au), atol=1e-9)
    assert np.allclose(pure.forces, sign * u / np.linalg.norm(Au), atol=1e-9 / uAu)
    ratio = np.linalg.norm(pure.forces) / np.linalg.norm(stable.forces)
    assert np.isclose(stable.displacement @ pure.displacement, ratio, rtol=1e-9)
    assert ratio <= 1 + 1e-12
    assert abs(pure.rigid_rotation) <= 1e-9 * max(abs(stable.rigid_rotation), 1.0 / obj.scale)
    # Theorem 9: the stable squeeze maximises the strain energy among unit displacements
    trial = rng.normal(size=(50, 4))
    trial /= np.linalg.norm(trial, axis=1, keepdims=True)
    energies = 0.5 * np.einsum("ki,ij,kj->k", trial, red.C, trial)
    assert energies.max() <= stable.energy_per_unit_depth2 * (1 + 1e-12)


def test_stable_squeeze_of_three_contacts_is_top_eigenvector():
    outline = shapes.ellipse(0.06, 0.04)
    obj = ElasticObject(generate_mesh(outline, outline.area / 300), Material(1e5, 0.3, 0.01))
    b = obj.mesh.boundary
    contacts = b[[0, len(b) // 3, 2 * len(b) // 3]]
    red = reduced_stiffness(obj, contacts)
    sq = plan_squeeze(obj, contacts, kind="stable", red=red)
    lam, U = np.linalg.eigh(red.C)
    assert np.isclose(abs(U[:, -1] @ sq.displacement), 1.0)
    assert np.isclose(sq.energy_per_unit_depth2, 0.5 * lam[-1])
    assert sq.inward


def test_rotation_angle_of_pure_rotation():
    outline = shapes.disk(0.05)
    obj = ElasticObject(generate_mesh(outline, outline.area / 200), Material(1e5, 0.3, 0.01))
    c = obj.mesh.nodes - obj.mesh.nodes.mean(axis=0)
    theta = 1e-3
    field = theta * np.column_stack([-c[:, 1], c[:, 0]]).ravel()
    g = obj.rigid.T @ field
    assert np.isclose(rotation_angle(obj, g), theta, rtol=1e-12)


@pytest.mark.parametrize("m", [1])
def test_single_contact_is_rejected(m):
    outline = shapes.disk(0.05)
    obj = ElasticObject(generate_mesh(outline, outline.area / 100), Material(1e5, 0.3, 0.01))
    with pytest.raises(ValueError, match="at least 2"):
        reduced_stiffness(obj, obj.mesh.boundary[:m])
