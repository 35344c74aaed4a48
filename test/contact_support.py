# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Physical invariants of a contact state, checked from the full FEM displacement field (any
tip shape: circles and pads alike).
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactState, tip_geometry


def forces_and_field(model: ContactModel, state: ContactState):
    """Contact forces (m, 2), N, and the full displacement field (n, 2), m, of ``state``."""
    L, fu = model.length, model.force_unit
    sd = model.set_data(tuple(c.node for c in state.contacts))
    delta = np.array([c.displacement for c in state.contacts]) / L
    F = np.array([c.force for c in state.contacts]) / fu
    return F * fu, model.full_displacement(sd, delta, F).reshape(-1, 2) * L


def check_state(model: ContactModel, state: ContactState, tol: float = 1e-9) -> None:
    """Equilibrium, friction cones and no penetration, from the full displacement field."""
    obj = model.obj
    mesh = obj.mesh
    F, u = forces_and_field(model, state)
    scale = np.abs(F).max()
    nodes = np.array([c.node for c in state.contacts])
    # equilibrium of the external forces and of the full FEM problem K u = f
    assert np.abs(F.sum(axis=0)).max() < 1e-10 * scale
    p = mesh.nodes[nodes]
    assert abs(np.sum(p[:, 0] * F[:, 1] - p[:, 1] * F[:, 0])) < 1e-10 * scale * obj.scale
    f_full = np.zeros(2 * mesh.n)
    f_full[np.stack([2 * nodes, 2 * nodes + 1], 1).ravel()] = F.ravel()
    K = obj.stiffness * obj.material.force_scale
    assert np.abs(K @ u.ravel() - f_full).max() < 1e-8 * scale
    # contact nodes lie on their tip's face at their coordinate; forces inside / on the cone
    tips = tip_geometry(state.fingers)
    index = {f.name: k for k, f in enumerate(state.fingers)}
    mu = model.mu
    for c, f in zip(state.contacts, F):
        k = index[c.finger]
        x = mesh.nodes[c.node] + u[c.node]
        on_face = state.fingers[k].center + tips.offset(np.array([c.theta]), np.array([k]))[0]
        assert np.linalg.norm(x - on_face) < 1e-12
        assert abs(c.normal_angle - tips.normal_angle(np.array([c.theta]), np.array([k]))[0]) \
            < 1e-12
        fn, ft = c.normal_force(), c.tangential_force()
        assert np.allclose(f, c.force)
        assert fn > -1e-6 * scale
        if c.mode == "stick":
            assert abs(ft) <= mu * fn + 1e-6 * scale
        else:
            assert abs(mu * fn - abs(ft)) < 1e-9 * scale
            assert ft * c.slip <= 1e-9 * scale  # friction opposes the slip
    # no non-contact boundary node inside a fingertip beyond the tolerance
    free = np.setdiff1d(mesh.boundary, nodes)
    centers = np.array([f.center for f in state.fingers])
    gaps = tips.gaps(mesh.nodes[free] + u[free], centers)
    assert gaps.min() > -10 * tol * obj.scale
