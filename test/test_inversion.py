# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A squeeze deep enough to turn an element inside out ends ``element_inverted``, located,
with the element named, never NaN and never a solver traceback; the CLI says so.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from foam_support import foam_square

from squeeze_grasp_ros.api import ElasticObject, event_squeeze, scene_file
from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic.hyperelastic import area_ratios, gradient_operator
from squeeze_grasp_ros.mechanics.squeeze.contact_model import INVERSION_AREA_RATIO, ContactModel
from squeeze_grasp_ros.mechanics.vocabulary import Termination


@pytest.fixture(scope="module")
def coarse_square():
    return foam_square(120)[1:]


def min_area_ratio(obj: ElasticObject, displacement: np.ndarray) -> float:
    """Smallest det F of the final field, computed from the mesh here, not by the stepper."""
    return float(area_ratios(gradient_operator(obj.mesh.nodes, obj.mesh.triangles),
                             displacement.reshape(-1)).min())


@pytest.mark.parametrize("model", ["linear", "corotational"])
def test_a_squeeze_through_an_element_ends_element_inverted_at_the_located_point(
        model, coarse_square):
    """Both laws without an energy barrier at det F = 0 stop where the smallest area ratio
    reaches the threshold (to the event tolerance), with finite forces; a squeeze to just
    short of that depth reaches its depth with every element intact.
    """
    obj, contacts = coarse_square
    res = event_squeeze(obj, contacts, 0.02, 0.4, material_model=model, relative_depth=0.9)
    assert res.termination == Termination.ELEMENT_INVERTED
    assert 0.3 < res.relative_depth < 0.9
    det = min_area_ratio(obj, res.displacement)
    assert INVERSION_AREA_RATIO - 1e-3 < det <= INVERSION_AREA_RATIO + 1e-9
    assert res.diagnostics["min_area_ratio"] == pytest.approx(det, abs=1e-9)
    assert 0 <= res.diagnostics["inverted_element"] < len(obj.mesh.triangles)
    assert all(np.isfinite(v).all() for v in res.finger_force.values())
    short = event_squeeze(obj, contacts, 0.02, 0.4, material_model=model,
                          relative_depth=res.relative_depth - 0.01)
    assert short.termination == Termination.DEPTH_REACHED
    assert min_area_ratio(obj, short.displacement) > INVERSION_AREA_RATIO


def test_shallow_squeezes_never_report_an_inversion(coarse_square):
    """At the paper's 12 % the smallest area ratio stays far above the threshold."""
    obj, contacts = coarse_square
    res = event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.12)
    assert res.termination == Termination.DEPTH_REACHED
    assert min_area_ratio(obj, res.displacement) > 0.5


def test_the_cli_reports_the_inversion_as_the_termination(tmp_path, capfd):
    """``squeeze --json`` names the termination and the element; exit 0 (an outcome, not an
    error), and the text route prints it too.
    """
    text = scene_file("foam_square").read_text().replace("nodes: 2000", "nodes: 120")
    path = tmp_path / "coarse.yaml"
    path.write_text(text)
    assert main(["squeeze", str(path), "--relative-depth", "0.9", "--json"]) == 0
    out = json.loads(capfd.readouterr().out)
    assert out["termination"] == "element_inverted"
    assert out["relative_depth"] < 0.9
    assert main(["squeeze", str(path), "--relative-depth", "0.9"]) == 0
    assert "element_inverted" in capfd.readouterr().out


def test_the_gradient_bound_never_understates_an_element_gradient(coarse_square):
    """The linear model's area check solves nothing: for random loads on random boundary
    nodes, every element's exact displacement gradient (one solve, here) is below the
    per-element bound, and the area ratio the model reports is the exact smallest one (with its
    element) or, when no element is near the threshold, a lower bound of it.
    """
    obj, _ = coarse_square
    model = ContactModel(obj, 0.4)
    boundary = model.boundary_nodes
    rng = np.random.default_rng(7)
    used_bound = 0
    for scale in (1e-3, 1e-2, 3e-2):
        for _ in range(10):
            nodes = np.sort(rng.choice(boundary, 4, replace=False))
            forces = scale * rng.normal(size=(4, 2))
            loads = np.zeros(2 * obj.mesh.n)
            loads[np.stack([2 * nodes, 2 * nodes + 1], 1).ravel()] = forces.ravel()
            H = (obj.gradient @ obj.pinv_apply(loads)).reshape(-1, 4)
            bound = obj.gradient_bounds(nodes) @ np.linalg.norm(forces, axis=1)
            assert np.all(np.sqrt((H * H).sum(axis=1)) <= bound * (1 + 1e-12) + 1e-15)
            sd = model.set_data(tuple(nodes.tolist()))
            delta = np.zeros((4, 2))
            reported, element = model.area_ratio(sd, delta, forces)
            exact, worst = model.field_area_ratio(model.full_displacement(sd, delta, forces))
            if element == -1:
                assert reported <= exact + 1e-12
                used_bound += 1
            else:
                assert (reported, element) == (pytest.approx(exact, abs=1e-10), worst)
    assert 0 < used_bound < 30
