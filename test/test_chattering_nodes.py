# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Nodes the chattering bound freezes stay physical: a frozen node that sticks still slides when
its force reaches its friction cone, and the nodes of a finger that can only start to slide
together are decided together. Each case below is a squeeze of a random campaign (or a shipped
scene) that ended with a sticking node outside its cone, or failed, before.
"""
from __future__ import annotations

import numpy as np
import pytest
from contact_support import check_state

from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
from squeeze_grasp_ros.mechanics.errors import NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import ContactModel
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.stepper import modes
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipShape
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel
from squeeze_grasp_ros.scene.setup import GraspSetup

PAD = 0.01999757519470627
"""Pad width of the disk cases (m): a fifth of the disk's size."""


def _pad(width: float) -> TipShape:
    return TipShape.pad(width=width, edge_radius=0.125 * width)


# (scene, contact nodes, mu, tip, kind): linear squeezes to 25 % whose end state had a sticking
# node outside its cone (|f_t| over mu f_n by 0.2 % and 1.8 % of the largest force component)
OUTSIDE_BEFORE = [
    ("resist_fig9", (49, 19), 0.05, 0.01124860113132606, "stable"),
    ("disk", (1, 52), 0.2, "pad", "pure"),
]


@pytest.mark.parametrize("scene, nodes, mu, tip, kind", OUTSIDE_BEFORE)
def test_a_frozen_node_never_sticks_outside_its_cone(kernel, scene, nodes, mu, tip, kind):
    obj = scene_solid(load_scene(scene_file(scene)))
    res = event_squeeze(obj, nodes, _pad(PAD) if tip == "pad" else tip, mu, kind=kind,
                        relative_depth=0.25)
    assert res.chatter, "the case no longer exercises the chattering bound"
    assert res.termination == "depth_reached"
    check_state(ContactModel(obj, mu), res.state)  # equilibrium, cones, no penetration


def test_a_finger_whose_nodes_start_to_slide_together_is_decided_jointly(kernel, monkeypatch):
    """The disk between 20 mm pads at mu = 0.05: four contacts of F1 must all start to slide one
    way at once. Node by node each one alone is inconsistent; without the joint search after it
    the squeeze failed at 16 mm ("Newton on the sliding angles did not converge").
    """
    obj = scene_solid(load_scene(scene_file("disk")))

    def squeeze():
        return event_squeeze(obj, (16, 66), _pad(PAD), 0.05, kind="stable",
                             relative_depth=0.25)

    res = squeeze()
    assert res.termination == "depth_reached" and res.relative_depth == pytest.approx(0.25)
    check_state(ContactModel(obj, 0.05), res.state)
    monkeypatch.setattr(modes, "MAX_SEARCHED_NODES", modes.MAX_JOINT_NODES)
    with pytest.raises(NumericalError, match="fixed-set solve failed"):
        squeeze()


@pytest.mark.parametrize("model", [MaterialModel.COROTATIONAL, MaterialModel.NEO_HOOKEAN])
def test_the_low_friction_foam_square_ends_inside_every_cone(model):
    """The shipped scene at mu = 0.05 chatters under the nonlinear models; the corotational
    squeeze ended with node 113 sticking at |f_t| = 1.44 mu f_n.
    """
    setup = GraspSetup.build(load_scene(scene_file("foam_square_low_friction"))).precompute()
    mu = setup.scene.friction.mu
    res = setup.event_squeeze(material_model=model)
    assert res.termination == "depth_reached"
    assert res.chatter, "the scene no longer exercises the chattering bound"
    scale = max(np.abs(c.force).max() for c in res.state.contacts)
    tolerance = 1e-6 * scale  # the nonlinear equilibrium is solved to about 1e-8 of the forces
    for c in res.state.contacts:
        fn, ft = c.normal_force(), c.tangential_force()
        assert fn > 0.0
        if c.mode == "stick":
            assert abs(ft) <= mu * fn + tolerance, (c.node, ft, mu * fn)
        else:
            assert abs(abs(ft) - mu * fn) <= tolerance and ft * c.slip <= tolerance
