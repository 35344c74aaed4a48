# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Hard cases that must stay finite and accurate (or fail with a clear message).

Each case asserts finite results, equilibrium residuals below a stated tolerance, and
agreement with a reference or an exact scaling law.
"""

import warnings

import numpy as np
import pytest

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import (
    Mesh,
    generate_mesh,
    mesh_from_triangles,
    target_max_area,
)
from squeeze_grasp_ros.mechanics.elastic.reduced import displacement_field, reduced_stiffness
from squeeze_grasp_ros.mechanics.errors import ConditioningWarning, InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.graspmap import grasp_map
from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze

EQUILIBRIUM_TOL = 1e-9
KIDNEY = [[0.06, 0.0], [0.045, 0.04], [0.0, 0.05], [-0.045, 0.04], [-0.06, 0.0],
          [-0.04, -0.035], [0.0, -0.012], [0.04, -0.035]]
"""Control points (m) of a non-convex outline, a kidney whose lower side bulges inward."""
"""Force/torque residual relative to the largest contact force (and object size for torque)."""


def blob(nodes: int = 400, size: float = 0.05) -> Mesh:
    outline = shapes.fourier_blob(size, cos=[0.0, 0.12, 0.04], sin=[0.05, 0.0, 0.02])
    return generate_mesh(outline, outline.area / nodes * 0.8)


def check_squeeze(obj: ElasticObject, contacts) -> None:
    """Finite outputs, equilibrium, and agreement with the spectral-free identities."""
    red = reduced_stiffness(obj, contacts)
    sq = plan_squeeze(obj, contacts, kind="stable", red=red)
    pure = plan_squeeze(obj, contacts, kind="pure", red=red)
    for s in (sq, pure):
        assert np.all(np.isfinite(s.forces)) and np.isfinite(s.energy_per_unit_depth2)
        F = s.forces.reshape(-1, 2)
        p = obj.mesh.nodes[list(contacts)]
        fmax = np.abs(F).max()
        assert np.abs(F.sum(axis=0)).max() <= EQUILIBRIUM_TOL * fmax
        torque = np.sum(p[:, 0] * F[:, 1] - p[:, 1] * F[:, 0])
        assert abs(torque) <= EQUILIBRIUM_TOL * fmax * obj.scale
    assert np.isclose(
        sq.displacement @ pure.displacement, pure.stiffness / sq.stiffness, rtol=1e-8
    )
    assert obj.diagnostics()["rigid_mode_residual"] < 1e-12


@pytest.mark.parametrize("nu", [0.499, 0.5, -0.9, -0.99])
def test_extreme_poisson_ratios(nu):
    mesh = blob()
    obj = ElasticObject(mesh, Material(1e5, nu, 0.01))
    c = [mesh.boundary[2], mesh.boundary[len(mesh.boundary) // 2]]
    check_squeeze(obj, c)
    ref = ElasticObject(mesh, Material(1e5, nu, 0.01), "spectral")
    a, b = obj.compliance_block(c), ref.compliance_block(c)
    assert np.abs(a - b).max() <= 1e-9 * np.abs(b).max()


def test_poisson_ratio_outside_range_is_a_clear_error():
    with pytest.raises(InvalidInputError, match=r"nu must be in \(-1, 0.5\]"):
        Material(1e5, 0.5000001, 0.01)


@pytest.mark.parametrize("field, value, named", [
    ("E", 1e-320, r"material.E must be in \[0.001, 1e\+13\] Pa, got 1e-320"),
    ("E", 1e16, r"material.E must be in \[0.001, 1e\+13\] Pa, got 1e\+16"),
    ("thickness", 1e-320, r"material.thickness must be in \[1e-09, 1000\] m, got 1e-320"),
    ("thickness", 1e-12, r"material.thickness must be in \[1e-09, 1000\] m, got 1e-12"),
])
def test_material_magnitudes_beyond_the_scene_ranges_are_refused_by_field(field, value, named):
    """A Material takes the scene's ranges. Before, E = 1e-320 Pa (or E h = 1e-322 N/m) made
    an event-driven squeeze return NaN work and dissipation with no error, and E h = 1e310 N/m
    ended in "reduced stiffness must be finite" naming no material field.
    """
    with pytest.raises(InvalidInputError, match=named):
        Material(**{"E": 1e5, "nu": 0.3, "thickness": 0.01, field: value})


@pytest.mark.parametrize("model, nu", [("linear", -0.95), ("corotational", -0.95),
                                       ("neo_hookean", 0.49995), ("neo_hookean", -0.5)])
def test_an_event_squeeze_refuses_a_poisson_ratio_its_model_cannot_represent(model, nu):
    """The API applies POISSON_RANGES as a scene does. Before, event_squeeze took any nu in
    (-1, 0.5): the neo-Hookean model at nu = -0.9 ran 24 s and ended contact_lost with a finger
    force of -0.007 N, and -0.5 did not finish in 300 s.
    """
    from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze

    mesh = blob(300)
    obj = ElasticObject(mesh, Material(1e5, nu, 0.01))
    contacts = (int(mesh.boundary[2]), int(mesh.boundary[len(mesh.boundary) // 2]))
    with pytest.raises(InvalidInputError, match=rf"material.nu must be in \[.*\] for the "
                                                rf"{model} model, got {nu:g}"):
        event_squeeze(obj, contacts, 0.01, 0.4, relative_depth=0.05, material_model=model)


def test_E_from_foam_to_steel_scales_exactly():
    mesh = blob()
    c = [mesh.boundary[5], mesh.boundary[30]]
    base = plan_squeeze(ElasticObject(mesh, Material(1e3, 0.3, 0.01)), c)
    for E in np.logspace(3, np.log10(2e11), 6):
        obj = ElasticObject(mesh, Material(E, 0.3, 0.01))
        check_squeeze(obj, c)
        sq = plan_squeeze(obj, c)
        assert np.allclose(sq.displacement, base.displacement, atol=1e-13)
        assert np.allclose(sq.forces, base.forces * E / 1e3, rtol=1e-9)
        # the internal (dimensionless) stiffness, hence its conditioning, does not depend on E
        assert (obj.stiffness != ElasticObject(mesh, Material(1e3, 0.3, 0.01)).stiffness).nnz == 0


@pytest.mark.parametrize("size", [1e-3, 10.0])
def test_object_size_from_a_millimetre_to_ten_metres(size):
    ref = blob(size=0.05)
    scaled = Mesh(
        ref.nodes * (size / 0.05), ref.triangles, ref.boundary, ref.inner_boundaries, ref.normals
    )
    c = [ref.boundary[4], ref.boundary[27]]
    mat = Material(2e9, 0.3, 0.003)
    o_ref, o = ElasticObject(ref, mat), ElasticObject(scaled, mat)
    check_squeeze(o, c)
    s_ref, s = plan_squeeze(o_ref, c), plan_squeeze(o, c)
    # 2-D CST stiffness is scale-free: forces per unit depth do not change with size, so at a
    # fixed relative depth (depth ~ size) forces scale with size and energies with size^2
    k = size / 0.05
    assert np.allclose(s.forces, s_ref.forces, rtol=1e-9)
    rel = 0.1
    assert np.isclose(
        s.depth_for_relative(rel) ** 2 * s.energy_per_unit_depth2,
        k**2 * s_ref.depth_for_relative(rel) ** 2 * s_ref.energy_per_unit_depth2,
        rtol=1e-9,
    )
    assert np.isclose(s.rigid_rotation, s_ref.rigid_rotation / k, rtol=1e-9)
    field = displacement_field(o, reduced_stiffness(o, c), 1e-3 * size * s.displacement)
    assert np.all(np.isfinite(field))
    # a freshly meshed object of that size (not a scaled copy) is fine too
    outline = shapes.disk(size)
    mesh = generate_mesh(outline, outline.area / 300)
    check_squeeze(
        ElasticObject(mesh, mat), [mesh.boundary[0], mesh.boundary[len(mesh.boundary) // 2]]
    )


def test_very_small_element_angles_warn_or_stay_accurate():
    """A sliver mesh (angles ~0.5 degrees) still gives equilibrium and matches the spectral
    route.
    """
    x = np.linspace(0, 1, 41)
    y = np.array([0.0, 0.0002, 0.0004])
    X, Y = np.meshgrid(x, y)
    nodes = np.column_stack([X.ravel(), Y.ravel()])
    tris = []
    nx = len(x)
    for j in range(len(y) - 1):
        for i in range(nx - 1):
            a, b, c, d = j * nx + i, j * nx + i + 1, (j + 1) * nx + i, (j + 1) * nx + i + 1
            tris += [[a, b, d], [a, d, c]]
    mesh = mesh_from_triangles(nodes, np.array(tris))
    assert mesh.min_angle_deg() < 1.0
    mat = Material(1e6, 0.3, 0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConditioningWarning)
        obj = ElasticObject(mesh, mat)
        left, right = np.argmin(nodes[:, 0] + nodes[:, 1]), np.argmax(nodes[:, 0] - nodes[:, 1])
        check_squeeze(obj, [left, right])
        ref = ElasticObject(mesh, mat, "spectral")
        a, b = obj.compliance_block([left, right]), ref.compliance_block([left, right])
    cond = obj.diagnostics()["condition_estimate"]
    print(
        f"sliver mesh: condition estimate {cond:.3g}, route difference "
        f"{np.abs(a - b).max() / np.abs(b).max():.3g}"
    )
    # both routes lose digits in proportion to the conditioning, no more
    assert np.abs(a - b).max() <= 10 * cond * np.finfo(float).eps * np.abs(b).max()


def test_two_adjacent_contact_nodes():
    mesh = blob()
    c = [mesh.boundary[10], mesh.boundary[11]]
    obj = ElasticObject(mesh, Material(5e4, 0.3, 0.0254))
    check_squeeze(obj, c)
    assert reduced_stiffness(obj, c).condition < 1e6


@pytest.mark.parametrize("mu", [0.0, 1e-9, 50.0, 1e9])
def test_friction_extremes_in_the_grasp_map(mu):
    mesh = blob(300)
    gm = grasp_map(ElasticObject(mesh, Material(5e4, 0.3, 0.0254)), mu)
    iu = np.triu_indices(len(mesh.boundary), 1)
    assert np.all(np.isfinite(gm.stiffness[iu])) and np.all(gm.stiffness[iu] > 0)
    if mu >= 50:
        # wide cones: every inward placement with no sharp corner between is force closure
        assert gm.force_closure[iu].mean() > 0.9
    if mu == 0.0:
        # only exactly antipodal normals could close; a smooth blob has (almost) none
        assert gm.force_closure[iu].mean() < 0.01


def test_nonconvex_object_and_inward_check():
    outline = shapes.spline(KIDNEY)
    mesh = generate_mesh(outline, outline.area / 600)
    obj = ElasticObject(mesh, Material(5e4, 0.3, 0.0254))
    b = mesh.boundary
    top = b[np.argmax(mesh.nodes[b, 1])]
    dent = b[np.argmin(np.abs(mesh.nodes[b, 0]) + 10 * (mesh.nodes[b, 1] > 0))]
    check_squeeze(obj, [top, dent])
    gm = grasp_map(obj, 0.5)
    assert 0 < gm.feasible.sum() < gm.feasible.size


@pytest.mark.slow
def test_mesh_with_fifty_thousand_nodes():
    outline = shapes.ellipse(0.1, 0.06)
    mesh = generate_mesh(outline, target_max_area(outline, 52000))
    assert mesh.n >= 50000
    obj = ElasticObject(mesh, Material(5e4, 0.3, 0.0254)).precompute()
    c = [mesh.boundary[0], mesh.boundary[len(mesh.boundary) // 2]]
    check_squeeze(obj, c)
    red = reduced_stiffness(obj, c)
    sq = plan_squeeze(obj, c, red=red)
    field = displacement_field(obj, red, 1e-3 * sq.displacement)
    assert np.all(np.isfinite(field))
    assert obj.diagnostics()["last_solve_relative_residual"] < 1e-10


# --------------------------------------------------------------------------- event-driven squeeze
def foam(nodes: int = 800, size: float = 0.1, E: float = 5e4, h: float = 0.0254):
    """Square of side ``size`` (m), fingertips r = size / 5 at the side midpoints."""
    from squeeze_grasp_ros.bench.events import foam_square

    obj, contacts = foam_square(nodes)
    k = size / 0.1
    mesh = obj.mesh
    scaled = Mesh(
        mesh.nodes * k, mesh.triangles, mesh.boundary, mesh.inner_boundaries, mesh.normals
    )
    return ElasticObject(scaled, Material(E, 0.3, h)), contacts


def squeeze(obj, contacts, mu=0.05, **kw):
    from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze

    if "depth" not in kw:
        kw.setdefault("relative_depth", 0.12)
    return event_squeeze(obj, contacts, 0.2 * obj.scale, mu, **kw)


def check_event_result(res, obj) -> None:
    """Finite forces, total force equilibrium (the fingers balance), consistent energy."""
    F = np.array([c.force for c in res.state.contacts])
    assert np.all(np.isfinite(F)) and np.isfinite(res.energy)
    assert np.abs(F.sum(axis=0)).max() <= 1e-8 * np.abs(F).max()
    assert sum(res.work.values()) >= res.energy * (1 - 1e-6)


@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_event_squeeze_E_from_foam_to_steel_changes_forces_only():
    obj, contacts = foam()
    base = squeeze(obj, contacts)
    for E in (1e3, 2e11):
        o, _ = foam(E=E)
        res = squeeze(o, contacts)
        check_event_result(res, o)
        assert [(e.type, e.node) for e in res.events] == [(e.type, e.node) for e in base.events]
        assert np.allclose(
            [e.depth for e in res.events], [e.depth for e in base.events], atol=1e-9 * obj.scale
        )
        assert res.energy == pytest.approx(base.energy * E / 5e4, rel=1e-6)


@pytest.mark.parametrize("size", [1e-3, 10.0])
def test_event_squeeze_object_size_scales_depths_and_forces(size):
    obj, contacts = foam()
    base = squeeze(obj, contacts)
    o, _ = foam(size=size)
    res = squeeze(o, contacts)
    check_event_result(res, o)
    k = size / 0.1
    assert [(e.type, e.node) for e in res.events] == [(e.type, e.node) for e in base.events]
    assert np.allclose(
        [e.depth for e in res.events], [k * e.depth for e in base.events], atol=1e-8 * o.scale
    )
    assert res.finger_force["F1"][1] == pytest.approx(k * base.finger_force["F1"][1], rel=1e-6)
    assert res.energy == pytest.approx(k * k * base.energy, rel=1e-6)


@pytest.mark.parametrize("mu", [1e-6, 1e3])
@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_event_squeeze_friction_extremes(mu):
    """A squeeze line exactly along both normals (structured symmetric mesh) needs no friction
    at first; as the segments grow, a nearly frictionless tip lets nodes slide.
    """
    from test_events import symmetric_square

    obj, contacts = symmetric_square()
    res = squeeze(obj, contacts, mu=mu)
    assert res.termination == "depth_reached"
    check_event_result(res, obj)
    modes = {c.mode for c in res.state.contacts}
    if mu > 1:
        assert modes == {"stick"}
        assert sum(res.work.values()) == pytest.approx(res.energy, rel=1e-6)
    else:
        assert "slip" in modes


@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_frictionless_single_node_contacts_are_a_clear_error():
    """With mu = 0 and one node per finger the object can slide along the tips: the problem is
    indeterminate, and the engine says so instead of returning garbage.
    """
    from test_events import symmetric_square

    obj, contacts = symmetric_square()
    with pytest.raises(InvalidInputError, match="use mu > 0|can be solved"):
        squeeze(obj, contacts, mu=0.0)


def test_event_squeeze_from_a_nanometre_depth():
    obj, contacts = foam()
    tiny = squeeze(obj, contacts, depth=1e-9 * obj.scale)
    check_event_result(tiny, obj)
    assert tiny.termination == "depth_reached" and not tiny.events
    plan = plan_squeeze(obj, list(contacts))
    # before any new contact, the rounded-tip squeeze is the point-contact squeeze
    rho = 1e-9 * obj.scale
    assert tiny.energy == pytest.approx(rho**2 * plan.energy_per_unit_depth2, rel=1e-6)


@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_event_squeeze_on_a_nonconvex_object():
    outline = shapes.spline(KIDNEY)
    obj = ElasticObject(
        generate_mesh(outline, target_max_area(outline, 1200)), Material(5e4, 0.3, 0.0254)
    )
    b = obj.mesh.boundary
    p = obj.mesh.nodes[b]
    contacts = (int(b[np.argmin(p[:, 0])]), int(b[np.argmax(p[:, 0])]))
    res = squeeze(obj, contacts, mu=0.5, relative_depth=0.05)
    check_event_result(res, obj)
    assert res.event_counts["A"] > 0


@pytest.mark.parametrize("ratio", [1e-3, 1e-1])
def test_thin_and_thick_rings_stay_accurate(ratio):
    from squeeze_grasp_ros.mechanics.ring.model import (
        circle_diametral_response,
        ring_diameter_changes,
    )

    R, E, w = 0.04, 2e9, 0.01
    P = 1e-4 * R / abs(ring_diameter_changes(R, E, w, ratio * R, 1.0)[0])  # small displacement
    exact = np.array(ring_diameter_changes(R, E, w, ratio * R, P))
    fe = np.array(circle_diametral_response(256, R, E, w, ratio * R, P)[:2])
    assert np.all(np.isfinite(fe))
    assert np.abs(fe / exact - 1).max() < 1e-3


def test_degraded_conditioning_warns_instead_of_crashing():
    x = np.linspace(0, 1, 21)
    y = np.array([0.0, 1e-6])
    X, Y = np.meshgrid(x, y)
    nodes = np.column_stack([X.ravel(), Y.ravel()])
    nx = len(x)
    tris = [[i, i + 1, nx + i + 1] for i in range(nx - 1)] + [
        [i, nx + i + 1, nx + i] for i in range(nx - 1)
    ]
    mesh = mesh_from_triangles(nodes, np.array(tris))
    obj = ElasticObject(mesh, Material(1e6, 0.3, 0.01))
    with pytest.warns(ConditioningWarning, match="condition estimate"):
        cond = obj.diagnostics()["condition_estimate"]
    assert np.isfinite(cond) and cond > 1e12
