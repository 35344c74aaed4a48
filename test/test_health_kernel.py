# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The linear model's grasp-health field pass on its two routes (numpy, and the numba kernel of
the ``fast`` extra): the same floats and elements on random and real displacement fields, both
strain criteria, stresses near overflow and underflow, ties and NaN; the nonlinear models stay
on the numpy route.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from squeeze_grasp_ros.api import load_scene, scene_file
from squeeze_grasp_ros.mechanics.elastic.strain_measures import max_principal_strains
from squeeze_grasp_ros.mechanics.elastic.stress_measures import element_stresses, von_mises
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze import events
from squeeze_grasp_ros.mechanics.squeeze.contact_model import TerminationLimits
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import KERNEL_VARIABLE, Kernel
from squeeze_grasp_ros.mechanics.squeeze.nonlinear_model import contact_model
from squeeze_grasp_ros.mechanics.ties import first_max
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel, StrainCriterion
from squeeze_grasp_ros.scene import GraspSetup

pytest.importorskip("numba", reason="the fast extra is not installed: pip install '.[fast]'")


@pytest.fixture(scope="module")
def foam():
    """The shipped foam square at about 400 nodes, precomputed."""
    scene = load_scene(scene_file("foam_square"))
    obj = dataclasses.replace(scene.object, mesh=dataclasses.replace(scene.object.mesh,
                                                                     nodes=400))
    return GraspSetup.build(dataclasses.replace(scene, object=obj)).precompute()


def numpy_fields(model, u_hat):
    """The numpy route's (strain, element, von Mises, element, principal strains by measure);
    extreme fields overflow there as they do in the kernel, quietly.
    """
    with np.errstate(all="ignore"):
        strain, element = model.field_strain(u_hat)
        F = model.field_deformation(u_hat)
        material = model.obj.material
        vm = von_mises(element_stresses(MaterialModel.LINEAR, F, E=material.E,
                                        nu=material.nu)[0])
        k = first_max(vm)
        return strain, element, float(vm[k]), k, max_principal_strains(F)


def bits(fields) -> str:
    """The fields as text: equal when the floats are equal bit for bit (NaN equals NaN)."""
    strain, element, vm, k_vm, measures = fields
    return repr((float(strain).hex(), element, float(vm).hex(), k_vm,
                 {str(m): float(v).hex() for m, v in measures.items()}))


def compiled_fields(model, u_hat, monkeypatch):
    monkeypatch.setenv(KERNEL_VARIABLE, Kernel.NUMBA.value)
    return events._compiled_fields(model, u_hat)


def linear_model(setup, criterion=StrainCriterion.PRINCIPAL):
    return contact_model(MaterialModel.LINEAR, setup.solid, 0.4,
                         TerminationLimits(criterion=criterion), False, 4)


@pytest.mark.parametrize("criterion", list(StrainCriterion))
def test_random_fields_give_the_numpy_routes_floats(foam, criterion, monkeypatch):
    model = linear_model(foam, criterion)
    rng = np.random.default_rng(7)
    n2 = 2 * foam.solid.mesh.n
    for scale in (1e-9, 1e-3, 0.05, 0.3, 1e140, 1e-160):  # near over- and underflow of vm^2
        for _ in range(3):
            u = scale * rng.standard_normal(n2)
            assert bits(compiled_fields(model, u, monkeypatch)) == bits(numpy_fields(model, u))


def test_a_real_squeeze_reports_the_same_health_on_both_routes(foam, monkeypatch):
    runs = {}
    for route in Kernel:
        monkeypatch.setenv(KERNEL_VARIABLE, route.value)
        runs[route] = foam.event_squeeze(relative_depth=0.1)
    a, b = runs[Kernel.NUMPY].health, runs[Kernel.NUMBA].health
    assert a == b
    assert a.max_strain > 0.01 and a.max_von_mises > 0.0


def test_mirror_twins_report_the_first_element(foam, monkeypatch):
    """A field that is the same on every element ties everywhere: the first element wins."""
    model = linear_model(foam)
    nodes = foam.solid.mesh.nodes / model.length
    u = (0.01 * nodes).reshape(-1)  # a uniform stretch: every element the same to round-off
    strain, element, vm, k_vm, _ = compiled_fields(model, u, monkeypatch)
    assert (element, k_vm) == (0, 0)
    assert (strain, element, vm, k_vm) == numpy_fields(model, u)[:4]


def test_a_nan_field_fails_by_name_on_both_routes(foam, monkeypatch):
    model = linear_model(foam)
    u = np.zeros(2 * foam.solid.mesh.n)
    u[7] = np.nan
    fields = compiled_fields(model, u, monkeypatch)
    assert np.isnan(fields[0]) and np.isnan(fields[2])
    assert all(np.isnan(v) for v in fields[4].values())
    assert bits(fields) == bits(numpy_fields(model, u))


def test_a_nan_health_raises_the_same_error_on_both_routes(foam, monkeypatch):
    setup = foam
    res = setup.event_squeeze(relative_depth=0.05)
    model = linear_model(setup)
    state = res.state
    loads = events._contact_loads(model, state)
    broken = (loads[0], loads[1], np.full_like(loads[2], np.nan))
    messages = []
    for route in Kernel:
        monkeypatch.setenv(KERNEL_VARIABLE, route.value)
        with pytest.raises(InvalidInputError) as error:
            events._health(model, state, broken, None)
        messages.append(str(error.value))
    assert messages[0] == messages[1]
    assert messages[0].startswith("grasp health: max strain (small strain) must be finite")


@pytest.mark.parametrize("model", [MaterialModel.COROTATIONAL, MaterialModel.NEO_HOOKEAN])
def test_the_nonlinear_models_keep_the_numpy_route(foam, model, monkeypatch):
    nonlinear = contact_model(model, foam.solid, 0.4, TerminationLimits(), False, 4)
    assert compiled_fields(nonlinear, np.zeros(2 * foam.solid.mesh.n), monkeypatch) is None
