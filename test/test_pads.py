# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Flat pads with rounded edges (a gripper's jaws) in the event squeeze: the face's geometry
against a brute-force distance, closed-form uniform compression of a block under wide pads in
every material model, the bound theorem with Poisson expansion, the physical invariants at the
end of slipping squeezes, symmetry, and the two limits (a pad no wider than its rounded edges
is that circle; a circle of growing radius tends to the pad).
"""
from __future__ import annotations

import functools

import numpy as np
import pytest
from contact_support import check_state
from hypothesis import given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.fingertips import place_fingertip
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry, TipShape, unit
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

E, THICKNESS = 5e4, 0.01
W, H = 0.06, 0.03  # the block: W between the pads, H along them
WIDE_PAD = TipShape.pad(width=0.05, edge_radius=0.003)  # covers a whole H side
DEPTH = 0.002


@functools.lru_cache(maxsize=None)
def block(nu: float) -> tuple[ElasticObject, tuple[int, int]]:
    """The W x H block and the boundary nodes in the middle of its two H sides."""
    outline = shapes.rectangle(W, H)
    obj = ElasticObject(generate_mesh(outline, target_max_area(outline, 400)),
                        Material(E, nu, THICKNESS)).precompute()
    return obj, _nearest(obj, ([-W / 2, 0.0], [W / 2, 0.0]))


@functools.lru_cache(maxsize=None)
def disk() -> tuple[ElasticObject, tuple[int, int]]:
    outline = shapes.disk(0.03)
    obj = ElasticObject(generate_mesh(outline, target_max_area(outline, 600)),
                        Material(E, 0.3, THICKNESS)).precompute()
    return obj, _nearest(obj, ([-0.03, 0.0], [0.03, 0.0]))


def _nearest(obj: ElasticObject, points) -> tuple[int, int]:
    b = obj.mesh.boundary
    return tuple(int(b[np.argmin(np.linalg.norm(obj.mesh.nodes[b] - p, axis=1))])
                 for p in points)


def finger_force(sq, finger: str = "F1") -> np.ndarray:
    return sum(n.force for n in sq.segments[finger])


# --- geometry ---------------------------------------------------------------------------------

@settings(max_examples=60, deadline=None)
@given(width=st.floats(0.004, 0.05), edge=st.floats(0.0005, 0.002),
       facing=st.floats(-np.pi, np.pi), x=st.floats(-0.04, 0.04), y=st.floats(-0.04, 0.04))
def test_pad_gap_is_the_distance_to_its_face(width, edge, facing, x, y):
    """The closed-form gap is the brute-force distance to the pad (a dense union of disks).

    For points in front of the face, the face point at the coordinate found for the point has
    zero gap, and the point lies on the normal there at the gap's distance.
    """
    pad = TipShape.pad(width=max(width, 2 * edge), edge_radius=edge)
    tips = TipGeometry.of([pad], [facing])
    # the full stadium: the flat segment of half-width a swept by a disk of radius r_e
    a, r = pad.half_flat, pad.radius
    t0 = np.array([-np.sin(facing), np.cos(facing)])
    seg = np.linspace(-a, a, 1001)[:, None] * t0
    ring = r * unit(np.linspace(0, 2 * np.pi, 721, endpoint=False))
    point = np.array([x, y])
    brute = np.min(np.linalg.norm(point - seg[:, None] - ring[None], axis=2))
    gap = tips.gaps(point[None], np.zeros((1, 2)))[0, 0]
    if gap > 1e-4:  # outside: the brute-force distance to the boundary curve
        assert gap == pytest.approx(brute, abs=2e-6)
    if gap > 1e-6 and point @ unit(facing) > 0:
        q = tips.coordinate(point, 0)
        on = tips.offset(np.array([q]))[0]
        assert abs(tips.gaps(on[None], np.zeros((1, 2)))[0, 0]) < 1e-12
        nu = tips.normal_angle(np.array([q]))[0]
        assert np.allclose(on + gap * unit(nu), point, atol=1e-12)


def test_face_coordinate_kinematics():
    """|dx/dq| = r_e on the whole face; the normal turns only on the rounded edges."""
    pad = TipShape.pad(width=0.02, edge_radius=0.002)
    tips = TipGeometry.of([pad], [0.3])
    h = pad.half_flat / pad.radius
    q = 0.3 + np.linspace(-h - 1.0, h + 1.0, 2001)
    x = tips.offset(q, np.zeros(len(q), int))
    speed = np.linalg.norm(np.diff(x, axis=0), axis=1) / np.diff(q)
    assert np.allclose(speed, pad.radius, rtol=1e-6)
    kappa = tips.curvature(q, np.zeros(len(q), int))
    flat = np.abs(q - 0.3) < h
    assert np.all(kappa[flat] == 0) and np.all(kappa[np.abs(q - 0.3) > h] == 1)
    nu = tips.normal_angle(q, np.zeros(len(q), int))
    assert np.allclose(nu[flat], 0.3)


def test_a_circle_is_the_pad_without_a_flat():
    """The circle's formulas, bit for bit, from the pad's code with a = 0."""
    r, q = 0.004, np.linspace(-3, 3, 50)
    circle = TipGeometry.of([TipShape.circle(r)], [0.7])
    narrow = TipGeometry.of([TipShape.pad(width=2 * r, edge_radius=r)], [0.7])
    idx = np.zeros(len(q), int)
    assert np.array_equal(circle.offset(q, idx), r * unit(q))
    assert np.array_equal(narrow.offset(q, idx), circle.offset(q, idx))
    assert np.array_equal(circle.normal_angle(q, idx), q)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"width": 0.003, "edge_radius": 0.002}, "tip.width"),
    ({"width": 0.01, "edge_radius": 0.0}, "tip.edge_radius"),
    ({"width": float("nan"), "edge_radius": 0.001}, "tip.width"),
])
def test_invalid_pads_name_the_field(kwargs, field):
    with pytest.raises(InvalidInputError, match=field):
        TipShape.pad(**kwargs)


def test_pad_placed_on_a_flat_side_touches_every_node_under_it():
    obj, (left, _) = block(0.3)
    tip = place_fingertip(obj.mesh, "F1", left, WIDE_PAD)
    side = obj.mesh.boundary[np.abs(obj.mesh.nodes[obj.mesh.boundary, 0] + W / 2) < 1e-12]
    assert {tip.node, *(k for k, _ in tip.touching)} == set(side.tolist())
    assert tip.facing == pytest.approx(0.0, abs=1e-12)  # facing +x, into the block


# --- closed forms -----------------------------------------------------------------------------

def uniaxial_force(model: MaterialModel, stretch: float) -> float:
    """Force (N) on a side of the nu = 0 block compressed to ``stretch`` between frictional
    wide pads: with nu = 0 there is no lateral expansion, so the uniaxial state is exact, needs
    no friction, and the linear FEM reproduces it (the patch test).

    Linear and corotational (no rotation): E (1 - lambda) H h. Neo-Hookean with lambda_Lame = 0
    (nu = 0): the lateral and thickness stretches stay 1 and P_xx = mu (lambda - 1/lambda),
    mu = E / 2.
    """
    if model == MaterialModel.NEO_HOOKEAN:
        return 0.5 * E * (1.0 / stretch - stretch) * H * THICKNESS
    return E * (1.0 - stretch) * H * THICKNESS


@pytest.mark.parametrize("model", list(MaterialModel))
def test_wide_pads_compress_a_block_uniformly(model):
    obj, ends = block(0.0)
    sq = event_squeeze(obj, ends, WIDE_PAD, 0.2, depth=DEPTH, material_model=model)
    assert sq.termination == "depth_reached"
    # depth is the length of the stacked finger translation: each jaw moves DEPTH / sqrt 2
    jaws = sq.state.fingers
    closing = float(np.linalg.norm(jaws[1].translation - jaws[0].translation))
    assert closing == pytest.approx(np.sqrt(2) * DEPTH, rel=1e-12)
    expected = uniaxial_force(model, 1.0 - closing / W)
    force = finger_force(sq)
    assert force[0] == pytest.approx(expected, rel=1e-8)
    assert abs(force[1]) < 1e-9 * expected
    side = obj.mesh.boundary[np.abs(obj.mesh.nodes[obj.mesh.boundary, 0] + W / 2) < 1e-12]
    seg = sq.segments["F1"]
    assert {n.node for n in seg} == set(side.tolist())  # the whole side from the start
    assert all(n.mode == "stick" and abs(n.tangential_force) < 1e-9 * expected for n in seg)
    assert sum(sq.event_counts.values()) == 0


@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_pads_bound_the_stiffness_of_a_poisson_block():
    """A Poisson block (nu = 0.3) under sticking pads.

    The bonded faces restrain the lateral expansion, so the force lies between the free
    uniaxial one (E) and the laterally rigid one (E / (1 - nu^2)) (minimum potential energy
    over nested displacement sets); frictionless faces would give the lower bound, and sliding
    at small mu lies between them and the sticking pads.
    """
    nu = 0.3
    obj, ends = block(nu)
    lower = E * np.sqrt(2) * DEPTH / W * H * THICKNESS
    stuck = finger_force(event_squeeze(obj, ends, WIDE_PAD, 1.0, depth=DEPTH))[0]
    sliding = finger_force(event_squeeze(obj, ends, WIDE_PAD, 0.05, depth=DEPTH))[0]
    assert lower < sliding < stuck < lower / (1 - nu * nu)


# --- events and invariants ---------------------------------------------------------------------

@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_slipping_pads_keep_the_invariants():
    """Low friction on the Poisson block: nodes near the pad's corners slip outwards (C,
    possibly sticking again, D); the end state is in equilibrium, on the face, inside the cones.
    """
    obj, ends = block(0.3)
    sq = event_squeeze(obj, ends, WIDE_PAD, 0.05, depth=DEPTH)
    assert sq.event_counts["C"] >= 1
    slipping = [n for n in sq.segments["F1"] if n.mode == "slip"]
    for n in slipping:  # a slipping node on the left pad moves away from the middle
        assert np.sign(obj.mesh.nodes[n.node, 1]) == -np.sign(n.tangential_force) or \
            abs(obj.mesh.nodes[n.node, 1]) < 1e-12
    check_state(ContactModel(obj, 0.05), sq.state)


@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_pads_wrap_a_disk_with_new_contacts():
    """A pad flattens a disk: contacts spread over the flat (events A), the normal of every
    node on the flat is the pad's facing, and the invariants hold.
    """
    obj, ends = disk()
    pad = TipShape.pad(width=0.02, edge_radius=0.004)
    sq = event_squeeze(obj, ends, pad, 0.5, depth=0.004)
    assert sq.event_counts["A"] >= 4
    facing = {f.name: f.facing for f in sq.state.fingers}
    flat = {f.name: f.flat for f in sq.state.fingers}
    for c in sq.state.contacts:
        if abs(c.theta - facing[c.finger]) * 0.004 < flat[c.finger]:
            assert c.normal_angle == pytest.approx(facing[c.finger], abs=1e-12)
    check_state(ContactModel(obj, 0.5), sq.state)


@pytest.mark.usefixtures("kernel")  # both fixed-set routes
def test_pad_squeeze_of_a_symmetric_object_is_symmetric():
    """A structured mesh symmetric about both axes: the two jaws' forces mirror each other and
    each jaw's nodal forces mirror about the closing line.
    """
    from test_events import symmetric_square

    obj, ends = symmetric_square(12)
    pad = TipShape.pad(width=0.06, edge_radius=0.004)
    sq = event_squeeze(obj, ends, pad, 0.3, depth=0.006)
    f1, f2 = finger_force(sq, "F1"), finger_force(sq, "F2")
    assert np.allclose(f1, -f2, atol=1e-9 * abs(f1[0]))
    assert abs(f1[1]) < 1e-9 * abs(f1[0])
    nodes = obj.mesh.nodes
    by_y = {round(float(nodes[n.node, 1]), 9): n for n in sq.segments["F1"]}
    for y, n in by_y.items():
        m = by_y[round(-y, 9) + 0.0]
        assert n.normal_force == pytest.approx(m.normal_force, rel=1e-8)
        assert n.tangential_force == pytest.approx(-m.tangential_force, abs=1e-8 * abs(f1[0]))


# --- limits -----------------------------------------------------------------------------------

def test_pad_of_vanishing_flat_is_the_circle():
    obj, ends = disk()
    r = 0.004
    circle = event_squeeze(obj, ends, r, 0.5, depth=0.004)
    same = event_squeeze(obj, ends, TipShape.pad(width=2 * r, edge_radius=r), 0.5, depth=0.004)
    # to round-off, not bit for bit: the pad's flat of zero length and the circle reach the
    # gaps by other operation orders (one host gave 5e-15 relative on the y force)
    np.testing.assert_allclose(finger_force(same), finger_force(circle), rtol=1e-12,
                               atol=1e-12 * np.linalg.norm(finger_force(circle)))
    assert same.event_counts == circle.event_counts
    for eps in (1e-6, 1e-7):
        near = event_squeeze(obj, ends, TipShape.pad(width=2 * r + eps, edge_radius=r), 0.5,
                             depth=0.004)
        assert near.event_counts == circle.event_counts
        # the force moves by O(eps / r) of itself
        gap = np.linalg.norm(finger_force(near) - finger_force(circle))
        assert gap < 10 * eps / r * np.linalg.norm(finger_force(circle))


def test_pad_of_vanishing_width_is_the_point_finger():
    """A pad narrower than the mesh's node spacing touches one node all the way: the squeeze is
    the paper's stable squeeze at point contacts (Sec. 3-4, :func:`plan_squeeze`, an
    independent solve), forces linear in depth; wider pads gather contacts and force.
    """
    from squeeze_grasp_ros.mechanics.squeeze.stable_pure import plan_squeeze

    obj, ends = disk()
    depth = 0.003
    point = plan_squeeze(obj, list(ends)).forces.reshape(2, 2)[0] * depth
    forces = []
    for width in (0.02, 0.01, 0.002, 0.0005):
        sq = event_squeeze(obj, ends, TipShape.pad(width=width, edge_radius=width / 4), 0.5,
                           depth=depth)
        forces.append(finger_force(sq)[0])
        if width <= 0.002:
            assert len(sq.segments["F1"]) == 1 and sum(sq.event_counts.values()) == 0
            assert np.allclose(finger_force(sq), point, rtol=1e-10, atol=1e-12 * point[0])
    assert forces[0] > forces[1] > forces[2] == pytest.approx(point[0], rel=1e-10)


def test_circles_of_growing_radius_tend_to_the_pad():
    """Circles of radius R facing the block's sides: the face deviates from the flat by
    ~ H^2 / (8 R) over the side, so the force error falls like 1/R.
    """
    obj, ends = block(0.3)
    pad = finger_force(event_squeeze(obj, ends, WIDE_PAD, 0.5, depth=DEPTH))[0]
    facing = {"F1": 0.0, "F2": np.pi}
    errors = [abs(finger_force(event_squeeze(obj, ends, TipShape.circle(R), 0.5, depth=DEPTH,
                                             facing=facing))[0] - pad)
              for R in (10.0, 100.0, 1000.0)]
    assert errors[2] < 1e-4 * pad
    assert errors[0] / errors[1] == pytest.approx(10, rel=0.05)
    assert errors[1] / errors[2] == pytest.approx(10, rel=0.05)


# --- scenes -----------------------------------------------------------------------------------

def block_scene(**finger):
    """The nu = 0 block as a scene, both fingers given ``finger`` (tip or tip_radius)."""
    from squeeze_grasp_ros.scene import parse_scene

    return parse_scene({
        "object": {"shape": {"type": "rectangle", "width": W, "height": H},
                   "material": {"E": E, "nu": 0.0, "thickness": THICKNESS}},
        "fingers": {"F1": {**finger, "placement": {"point": [-W / 2, 0.0]}},
                    "F2": {**finger, "placement": {"point": [W / 2, 0.0]}}},
        "squeeze": {"depth": DEPTH}, "friction": {"mu": 0.2}, "effects": ["friction"],
    })


def test_scene_pad_tips_drive_the_same_squeeze_as_the_mechanics():
    from squeeze_grasp_ros.scene import GraspSetup

    scene = block_scene(tip={"shape": "pad", "width": 0.05, "edge_radius": 0.003})
    assert scene.fingers["F1"].tip_radius == 0.003  # filled: the radius that touches
    setup = GraspSetup.build(scene)
    via_scene = setup.event_squeeze()
    direct = event_squeeze(setup.solid, setup.contacts, WIDE_PAD, 0.2, depth=DEPTH)
    assert np.array_equal(finger_force(via_scene), finger_force(direct))
    # the nu = 0 closed form again, through the scene's own mesh
    closing = np.sqrt(2) * DEPTH
    assert finger_force(via_scene)[0] == pytest.approx(E * closing / W * H * THICKNESS, rel=1e-8)
    assert via_scene.to_json()["tips"]["F1"] == {"shape": "pad", "width": 0.05,
                                                 "edge_radius": 0.003}


def test_scene_circle_tip_is_tip_radius():
    from squeeze_grasp_ros.scene import GraspSetup

    scene = block_scene(tip={"shape": "circle", "radius": 0.01})
    assert scene.fingers["F2"].tip_radius == 0.01
    a = GraspSetup.build(scene).event_squeeze()
    b = GraspSetup.build(block_scene(tip_radius=0.01)).event_squeeze()
    assert np.array_equal(finger_force(a), finger_force(b))
    assert a.to_json()["tips"]["F1"] == {"shape": "circle", "radius": 0.01}


@pytest.mark.parametrize(("finger", "message"), [
    ({"tip": {"shape": "pad", "width": 0.05}}, r"fingers\.F1\.tip\.edge_radius is required"),
    ({"tip": {"shape": "pad", "width": 0.004, "edge_radius": 0.003}},
     r"fingers\.F1\.tip\.width must be >= 2 fingers\.F1\.tip\.edge_radius"),
    ({"tip": {"shape": "circle", "radius": 0.01, "width": 0.02}},
     r"fingers\.F1\.tip\.width does not apply to shape: circle"),
    ({"tip": {"shape": "circle", "radius": 0.01}, "tip_radius": 0.02},
     r"fingers\.F1: give tip or tip_radius, not both"),
    ({"tip": {"shape": "square", "radius": 0.01}}, r"fingers\.F1\.tip\.shape"),
    ({"tip": {"shape": "pad", "width": -0.05, "edge_radius": 0.003}},
     r"fingers\.F1\.tip\.width"),
])
def test_bad_tips_name_the_field(finger, message):
    from squeeze_grasp_ros.scene import SceneError

    with pytest.raises(SceneError, match=message):
        block_scene(**finger)


def test_the_squeeze_verb_says_it_takes_flat_pads(capsys):
    """``squeeze`` runs pad scenes (``sponge_gripper.yaml``); its help must not say rounded
    fingertips only.
    """
    from squeeze_grasp_ros.cli import main

    with pytest.raises(SystemExit):
        main(["squeeze", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "rounded fingertips or flat pads" in text


def test_two_pads_touching_the_same_nodes_are_refused_by_name():
    """Two 60 mm pads placed 28 mm apart on one side of the foam square both touch that side's
    nodes 109-114: one node cannot be held by two fingers. Before, the squeeze failed deep in
    the stable squeeze's plan with "Z^T A Z is not positive definite: contact nodes coincide
    or the compliance is corrupt" (a random campaign of squeezes met it three times).
    """
    from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid

    obj = scene_solid(load_scene(scene_file("foam_square")))
    pad = TipShape.pad(width=0.06, edge_radius=0.0075)
    with pytest.raises(InvalidInputError, match=r"fingers F1 and F2 both touch boundary "
                                                r"node\(s\) \[109, 110, 111, 112, 113, 114\]"):
        event_squeeze(obj, (116, 107), pad, 0.2, kind="stable", relative_depth=0.05)
    narrow = TipShape.pad(width=0.01, edge_radius=0.001)  # apart: squeezed (it slips at once)
    assert event_squeeze(obj, (116, 107), narrow, 0.2, kind="pure", relative_depth=0.05)
