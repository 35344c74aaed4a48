# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The shipped foam square re-meshed to a chosen size, for the material-model tests."""
from __future__ import annotations

import dataclasses

from squeeze_grasp_ros.api import ElasticObject, Material, load_scene, scene_file
from squeeze_grasp_ros.scene import Scene, build_mesh, finger_nodes


def foam_square(nodes: int) -> tuple[Scene, ElasticObject, tuple[int, int]]:
    """(scene, meshed object, F1/F2 contact nodes) of the foam square at about ``nodes``."""
    scene = load_scene(scene_file("foam_square"))
    scene = dataclasses.replace(scene, object=dataclasses.replace(
        scene.object, mesh=dataclasses.replace(scene.object.mesh, nodes=nodes)))
    mesh = build_mesh(scene)
    return scene, ElasticObject(mesh, Material(5e4, 0.3, 0.0254)), finger_nodes(scene, mesh)
