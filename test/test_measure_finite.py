# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Reported strains and stresses are finite or refused by name: a grasp-health number that is
not finite names the quantity and its measure (not an unlabelled list), the von Mises stress
neither overflows to NaN nor underflows to 0 when the stresses themselves are representable,
and a strain a command prints names its measure.
"""
from __future__ import annotations

import dataclasses
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from squeeze_grasp_ros.api import (
    ElasticObject,
    InvalidInputError,
    Material,
    TerminationLimits,
    build_mesh,
    event_squeeze,
    finger_nodes,
    load_scene,
    scene_file,
)
from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.elastic.material import E_RANGE
from squeeze_grasp_ros.mechanics.elastic.stress_measures import von_mises
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


@pytest.mark.parametrize("scale", [1e200, 1e-200])
def test_von_mises_of_representable_stresses_neither_overflows_nor_underflows(scale):
    stress = np.array([[[1.0, 0.3], [0.3, -0.5]], [[0.0, 1.0], [1.0, 0.0]]])
    with np.errstate(all="raise"):
        assert von_mises(scale * stress) / scale == pytest.approx(von_mises(stress), rel=1e-15)


def test_the_linear_von_mises_stress_scales_with_e_through_the_api(foam):
    """Linear elasticity: the deformation does not depend on E and the stress is E times it,
    so max von Mises / E is one number over the whole range a Material takes (E_RANGE). Before
    that range, 0.0 Pa at E = 1e-300 and NaN at 1e300 (squares beyond the float range); both
    are refused now, by name.
    """
    mesh, contacts = foam
    for E in (1e-300, 1e300):
        with pytest.raises(InvalidInputError,
                           match=r"material\.E must be in \[0\.001, 1e\+13\] Pa"):
            Material(E=E, nu=0.3, thickness=0.01)
    per_e = []
    for E in (5e4, *E_RANGE):
        obj = ElasticObject(mesh, Material(E=E, nu=0.3, thickness=0.01))
        with np.errstate(over="ignore", under="ignore"):
            health = event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.02).health
        per_e.append(health.max_von_mises / E)
    assert per_e[1:] == pytest.approx([per_e[0]] * 2, rel=1e-9)


def test_every_strain_calibrate_prints_names_its_measure(capsys):
    """``calibrate --compression``: the fits' strain range is the compressive Biot strain -dl/l
    (before: 'over 15 points up to strain 0.3', no measure).
    """
    examples = Path(__file__).resolve().parents[1] / "config" / "examples"
    assert main(["calibrate", "--compression", str(examples / "foam_compression.csv"),
                 "--sample-size", "0.05", "0.05", "0.02"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 3
    for line in lines:
        assert re.search(r"strain [0-9]", line) is None or "Biot strain" in line, line
    assert all(line.endswith("up to compressive Biot strain 0.3") for line in lines[:2]), lines


@pytest.mark.parametrize("value", [float("inf"), float("nan"), 0.0])
def test_a_non_finite_strain_limit_or_weight_is_refused_as_such(value):
    """Before: 'strain_limit.epsilon must be > 0, got inf' (inf is > 0: the rule not stated)."""
    with pytest.raises(InvalidInputError, match=r"^strain_limit.epsilon \(in the material "
                       r"model's strain measure\) must be finite and > 0, got "):
        TerminationLimits(strain=value)
    with pytest.raises(InvalidInputError, match="^pickup.weight must be finite and > 0 N, got "):
        TerminationLimits(weight=value)


def test_the_model_comparison_prints_no_nan_at_depth_zero(tmp_path, capsys):
    """A squeeze to depth 0 (zero contact forces) has no contact width under linear: its
    relative difference is undefined and said so (before: 'F1 half-width +nan %').
    """
    source = Path(__file__).resolve().parents[1] / "config" / "scenes" / "foam_square.yaml"
    scene = tmp_path / "depth0.yaml"
    scene.write_text(source.read_text().replace("relative_depth: 0.12", "relative_depth: 0.0"))
    assert main(["squeeze", str(scene), "--compare-models"]) == 0
    out = capsys.readouterr().out
    assert "nan" not in out.lower() and "inf " not in out, out
    assert out.count("F1 half-width undefined (linear 0)") == 2, out


def test_a_degenerate_element_is_refused_by_name_not_a_singular_factor(foam):
    """An interior node moved onto the midpoint of its element's opposite edge (zero area):
    before, numpy divide-by-zero warnings, NaN strain matrices and scipy's RuntimeError
    'Factor is exactly singular' from the squeeze.
    """
    mesh, contacts = foam
    interior = np.setdiff1d(np.arange(len(mesh.nodes)), mesh.boundary)[5]
    k = int(np.flatnonzero(np.any(mesh.triangles == interior, axis=1))[0])
    a, b = (n for n in mesh.triangles[k] if n != interior)
    nodes = mesh.nodes.copy()
    nodes[interior] = 0.5 * (nodes[a] + nodes[b])
    obj = ElasticObject(dataclasses.replace(mesh, nodes=nodes),
                        Material(E=5e4, nu=0.3, thickness=0.01))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidInputError, match=rf"^mesh element {k} \(nodes .*\) has area "
                           r"0 m\^2: elements must be counter-clockwise with a positive area"):
            event_squeeze(obj, contacts, 0.02, 0.4, relative_depth=0.02)
