# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A squeeze's start (placed tips, finger motion, initial state) is kept by the object: a squeeze
from a kept start is the squeeze from a fresh one bit for bit, the start is shared read-only,
and what differs (tips, kind, directions, origins) is not taken for it.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from squeeze_grasp_ros.api import load_scene, scene_file
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze import events
from squeeze_grasp_ros.mechanics.squeeze.fingertips import place_fingertip
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipShape
from squeeze_grasp_ros.scene import GraspSetup


def foam(nodes: int = 300) -> GraspSetup:
    scene = load_scene(scene_file("foam_square"))
    obj = dataclasses.replace(scene.object, mesh=dataclasses.replace(scene.object.mesh,
                                                                     nodes=nodes))
    return GraspSetup.build(dataclasses.replace(scene, object=obj)).precompute()


def fingerprint(res) -> str:
    """Every number of a result that the start decides or the squeeze computes, as text."""
    data = res.to_json()
    data.pop("diagnostics")
    return repr(data) + repr(res.displacement.tobytes())


@pytest.mark.parametrize("mu", [0.05, 0.4])
def test_a_kept_start_gives_the_fresh_squeeze_bit_for_bit(mu):
    kept, new = foam(), foam()

    def squeeze(setup):
        return events.event_squeeze(setup.solid, setup.contacts, 0.02, mu, relative_depth=0.1)

    first = squeeze(kept)
    again = squeeze(kept)  # from the kept start
    fresh = squeeze(new)  # a new object: a new start
    assert len(kept.solid._shared["squeeze_starts"]) == 1
    assert fingerprint(first) == fingerprint(again) == fingerprint(fresh)


def test_the_kept_start_is_read_only_and_results_own_their_directions():
    setup = foam()
    res = setup.event_squeeze(relative_depth=0.05)
    (_, (tips, motion, state)), = setup.solid._shared["squeeze_starts"].values()
    for array in ([t.center for t in tips] + list(motion.directions.values())
                  + [c.force for c in state.contacts] + [f.center for f in state.fingers]):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0
    res.directions["F1"][0] = 0.0  # the result's copy: the kept motion is untouched
    assert motion.directions["F1"][0] != 0.0


def test_different_tips_kinds_and_directions_are_different_starts():
    setup = foam()
    obj, nodes = setup.solid, setup.contacts
    starts = obj._shared.setdefault("squeeze_starts", {})
    events.event_squeeze(obj, nodes, 0.02, 0.4, relative_depth=0.02)
    events.event_squeeze(obj, nodes, 0.01, 0.4, relative_depth=0.02)
    events.event_squeeze(obj, nodes, TipShape.circle(0.01), 0.4, relative_depth=0.02)
    events.event_squeeze(obj, nodes, 0.02, 0.4, kind="pure", relative_depth=0.02)
    assert len(starts) == 4  # the circle of 0.01 m given as a shape is its own key
    directed = events.event_squeeze(obj, nodes, 0.02, 0.4, relative_depth=0.02,
                                    directions={"F1": (1.0, 0.0), "F2": (-1.0, 0.0)})
    assert len(starts) == 4 and directed.kind == "custom"  # given directions: not kept
    origin = np.array([-0.09, 0.0])  # an array origin is read into the key as numbers
    events.event_squeeze(obj, nodes, {"F1": 0.02, "F2": 0.02}, 0.4, relative_depth=0.02,
                         facing={"F1": 0.0}, origins={"F1": origin})
    assert len(starts) == 5


def test_a_start_that_fails_is_not_kept_and_fails_again():
    setup = foam()
    obj = setup.solid
    b = obj.mesh.boundary
    pad = TipShape.pad(width=0.04, edge_radius=0.005)
    for _ in range(2):  # two wide pads on neighbouring nodes touch the same node
        with pytest.raises(InvalidInputError, match="both touch boundary node"):
            events.event_squeeze(obj, (int(b[0]), int(b[1])), pad, 0.4, relative_depth=0.02)
    assert not obj._shared.get("squeeze_starts")


def test_an_origin_that_is_no_key_fails_as_the_tip_placement_does():
    """The key is not built before the placement checks its inputs: a bad tip is named first,
    as the placement names it, and an origin that is not numbers fails as it fails there.
    """
    setup = foam()
    obj, nodes = setup.solid, setup.contacts
    with pytest.raises(InvalidInputError, match="tip_radius must be > 0"):
        events.event_squeeze(obj, nodes, -0.02, 0.4, relative_depth=0.02, facing={"F1": 0.0},
                             origins={"F1": "not a point"})
    with pytest.raises(ValueError) as direct:
        place_fingertip(obj.mesh, "F1", nodes[0], 0.02, 0.0, "not a point")
    with pytest.raises(ValueError) as squeezed:
        events.event_squeeze(obj, nodes, 0.02, 0.4, relative_depth=0.02, facing={"F1": 0.0},
                             origins={"F1": "not a point"})
    assert str(squeezed.value) == str(direct.value)
    assert not obj._shared.get("squeeze_starts")
