# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Reported strains and stresses are finite or refused by name: a grasp-health number that is
not finite names the quantity and its measure (not an unlabelled list), and the von Mises stress
neither overflows to NaN nor underflows to 0 when the stresses themselves are representable.
"""
from __future__ import annotations

import numpy as np
import pytest

from squeeze_grasp_ros.api import (
    ElasticObject,
    InvalidInputError,
    Material,
    build_mesh,
    event_squeeze,
    finger_nodes,
    load_scene,
    scene_file,
)
from squeeze_grasp_ros.mechanics.squeeze import events


@pytest.fixture(scope="module")
def foam():
    scene = load_scene(scene_file("foam_square"))
    mesh = build_mesh(scene)
    return mesh, finger_nodes(scene, mesh)


@pytest.mark.parametrize("model, stress", [("linear", "small-strain"),
                                           ("corotational", "Cauchy")])
def test_a_non_finite_health_number_is_named_with_its_measure(foam, monkeypatch, model, stress):
    mesh, contacts = foam
    monkeypatch.setattr(events, "von_mises", lambda s: np.full(len(s), np.inf))
    obj = ElasticObject(mesh, Material(E=5e4, nu=0.3, thickness=0.01))
    with pytest.raises(InvalidInputError) as info:
        event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.02, material_model=model)
    assert str(info.value) == (f"grasp health: max von Mises stress ({stress} stress, Pa) must "
                               "be finite, got inf")
