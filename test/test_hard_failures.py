# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Solves that cannot succeed end in bounded work: the nonlinear response's load sub-stepping,
its line search on a tangent of its own, and the Newton on the sliding angles over an
equilibrium solve each stop once going on cannot help, and a hard squeeze that has no
equilibrium ahead fails with its depth after a bounded number of force assemblies.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from contact_support import check_state
from hypothesis import assume, event, given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.api import load_scene, scene_file, scene_solid
from squeeze_grasp_ros.mechanics.elastic import contact_response as cr
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
from squeeze_grasp_ros.mechanics.errors import InfeasibleError, InvalidInputError, NumericalError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    NEWTON_BACKTRACKS,
    Configuration,
    ContactModel,
    LinearResponse,
    SolveFailure,
    attempt_fixed_set,
)
from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze
from squeeze_grasp_ros.mechanics.squeeze.nonlinear_model import STALL_HALVINGS
from squeeze_grasp_ros.mechanics.squeeze.stepper import solving
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry, TipShape
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel
from squeeze_grasp_ros.scene import GraspSetup


@pytest.fixture(scope="module")
def response_and_target():
    """A neo-Hookean response of a 0.1 x 0.06 m rectangle held at two nodes each side, and a
    2 % squeeze of it (contact displacements / L).
    """
    mesh = generate_mesh(shapes.rectangle(0.1, 0.06), 4e-4, min_angle=25.0)
    left, right = np.argsort(mesh.nodes[:, 0])[:2], np.argsort(-mesh.nodes[:, 0])[:2]
    target = np.zeros((4, 2))
    target[:2, 0], target[2:, 0] = 0.01, -0.01

    def fresh():
        return cr.ContactResponse(MaterialModel.NEO_HOOKEAN, mesh.nodes / 0.1, mesh.triangles,
                                  np.r_[left, right], 0.3)
    return fresh, target


def _reach_limited(response, target: np.ndarray, limit: float) -> list[bool]:
    """Make ``response``'s Newton fail whenever its goal is more than ``limit`` of the whole
    load (from its state to ``target``) beyond the last contact displacement it reached; the
    outcome of every call, in order.
    """
    real, outcomes = response._newton, []
    reached = [response._delta.copy()]
    reach = limit * np.abs(target - reached[0]).max() * (1 + 1e-12)

    def newton(u, delta):
        if np.abs(delta - reached[-1]).max() > reach:
            outcomes.append(False)
            return cr.ResponseFailure("beyond the test's reach", 1.0)
        out = real(u, delta)
        outcomes.append(not isinstance(out, cr.ResponseFailure))
        reached.append(delta.copy())
        return out
    response._newton = newton
    return outcomes


@pytest.mark.parametrize("limit, halvings, succeeds", [
    (1.0, 0, True), (0.3, 2, True), (0.04, 5, True),
    # 1/64 of the load a substep would need 64 substeps after 6 failures: more than MAX_SUBSTEPS
    (1 / 60, 6, False), (1e-9, 6, False)])
def test_load_sub_stepping_stops_once_the_rest_of_the_load_is_out_of_reach(
        response_and_target, limit, halvings, succeeds):
    """The increment halves at each failed Newton and never grows again, and a call has at most
    MAX_SUBSTEPS Newton solves: once those left cannot add up to the rest of the load, the
    evaluation fails with its last Newton failure. Before, it halved on to 1e-6 of the load (20
    failures) or marched 1/128 of the load until the solves ran out (64 solves), each failure a
    Newton that had used its iterations.
    """
    fresh, target = response_and_target
    response = fresh()
    outcomes = _reach_limited(response, target, limit)
    out = response.evaluate(target)
    assert outcomes.count(False) == halvings == response.stats["substeps"]
    assert len(outcomes) <= cr.MAX_SUBSTEPS
    if succeeds:
        assert isinstance(out, cr.Evaluation)
        assert outcomes.count(True) == 2 ** halvings
        whole = fresh().evaluate(target)  # the same equilibrium as one step
        assert np.abs(out.F - whole.F).max() <= 1e-8 * np.abs(whole.F).max()
    else:
        assert isinstance(out, cr.ResponseFailure) and out.reason == "beyond the test's reach"
        assert not any(outcomes)


def _sliding_problem():
    """A two-node contact set, one node sliding, whose sliding angle is off its solution: the
    Newton on the sliding angles must take a step (response, configuration, centres,
    directions, initial angles, friction angle).
    """
    C = np.array([[3.0, 0.2, -1.0, 0.0], [0.2, 2.0, 0.0, -0.5],
                  [-1.0, 0.0, 3.0, 0.1], [0.0, -0.5, 0.1, 2.5]])
    tip = TipGeometry(np.array([0.1, 0.1]), np.zeros(2), np.array([0.0, np.pi]))
    centers = np.array([[-0.2, 0.0], [0.2, 0.0]])
    theta = np.array([0.0, np.pi])
    p0 = centers + tip.offset(theta) + np.array([[-0.01, 0.003], [0.012, -0.002]])
    cfg = Configuration(p0, np.array([True, False]), np.array([0, 1]), tip)
    return LinearResponse(C), cfg, centers, np.array([[1.0, 0.0], [-1.0, 0.0]]), \
        theta + np.array([0.0, 0.3]), float(np.arctan(0.5))


class _Counted:
    """A response that answers at the initial angles and, elsewhere, ``elsewhere(F, C)``;
    ``stall_halvings`` as a nonlinear model's response declares it (None: not declared).
    """

    def __init__(self, linear, start_delta, elsewhere, stall_halvings):
        self.linear, self.start, self.elsewhere, self.calls = linear, start_delta, elsewhere, 0
        if stall_halvings is not None:
            self.stall_halvings = stall_halvings

    def __call__(self, delta):
        self.calls += 1
        F, C = self.linear(delta)
        return (F, C) if np.array_equal(delta, self.start) else self.elsewhere(F, C)


@pytest.mark.parametrize("declared", [STALL_HALVINGS, None])
@pytest.mark.parametrize("trial", ["fails", "no_lower"])
def test_the_sliding_newton_over_equilibrium_solves_stops_after_its_stall_halvings(
        declared, trial):
    """Every trial step of the Newton on the sliding angles costs one response evaluation,
    for the nonlinear models an equilibrium solve of the whole object. A response that declares
    ``stall_halvings`` ends the solve after that many halvings of a step: with the failure of
    the last trial when every trial failed, or as a stall when the trials were solved but none
    lowered the cone residual. Without it (the linear model: a trial is a matrix product) the
    line search keeps its 30 halvings.
    """
    linear, cfg, centers, dirs, theta0, phi = _sliding_problem()
    start = centers + cfg.tip.offset(theta0) - cfg.p0
    failure = SolveFailure("the test's equilibrium cannot be found", 1.0)
    # off the start, a force across the sliding node's cone edge, 1,000 times the start's: no
    # trial angle near the start lowers the cone residual
    edge = cfg.tip.normal_angle(theta0)[1] - cfg.slip[1] * phi
    across = 1e3 * np.abs(linear(start)[0]).max() * np.array([-np.sin(edge), np.cos(edge)])
    elsewhere = {"fails": lambda F, C: failure,
                 "no_lower": lambda F, C: (np.array([F[0], across]), C)}[trial]
    response = _Counted(linear, start, elsewhere, declared)
    out = attempt_fixed_set(response, cfg, centers, dirs, theta0, phi)
    if declared is None:  # the linear model's line search: to 30 halvings or a 1e-14 rad step
        assert response.calls > 1 + 1 + STALL_HALVINGS
        assert response.calls >= 1 + NEWTON_BACKTRACKS or trial == "fails"
        return
    assert isinstance(out, SolveFailure)
    assert response.calls == 1 + 1 + declared  # the start, then trials at 2^0 ... 2^-declared
    if trial == "fails":
        assert out is failure
    else:
        assert out.reason.startswith(f"Newton on the sliding angles stalled: {declared} halvings")


@pytest.mark.slow
def test_a_squeeze_with_no_equilibrium_ahead_fails_in_bounded_work(monkeypatch):
    """The corotational blob squeezed from node 57 against node 4 at mu = 1.5 with 12 mm tips
    (found by a random campaign of hard squeezes): beyond 17 % of the depth its contact set has
    no equilibrium the solver can reach. The squeeze fails with its depth and reason, in 20,980
    force assemblies (2026-11-29); before these bounds it spent 145,221 (about two minutes).
    """
    assemblies = [0]
    real = cr.ContactResponse._assemble

    def counted(self, *args, **kwargs):
        assemblies[0] += 1
        return real(self, *args, **kwargs)
    monkeypatch.setattr(cr.ContactResponse, "_assemble", counted)
    obj = scene_solid(load_scene(scene_file("nonconvex_blob")))
    with pytest.raises(NumericalError, match=r"^at depth 0\.0207\d* m \(relative depth 0\.\d+\): "
                       r"the fixed-set solve failed after 12 substep halvings"):
        event_squeeze(obj, (57, 4), 0.012047076053241505, 1.5, kind="stable",
                      relative_depth=0.25, material_model="corotational")
    assert assemblies[0] < 30_000


def test_a_line_search_on_the_state_s_own_tangent_gives_up_after_its_halvings(
        response_and_target, monkeypatch):
    """A Newton step of a tangent factorised in this solve that lowers the residual only below
    2^-FRESH_BACKTRACKS of itself is stalling at a minimum of the residual norm that is no
    equilibrium: the solve fails after FRESH_BACKTRACKS trial assemblies (before: BACKTRACKS,
    30), and a step of a factorisation held from another state keeps all BACKTRACKS before the
    tangent is refactored.
    """
    fresh, target = response_and_target
    response = fresh()
    trials = []
    real = cr.ContactResponse._assemble

    def no_descent(self, u, **known):  # every trial's residual 1,000 times the start's
        asm = real(self, u, **known)
        if "stretch" not in known:
            return asm
        trials.append(asm)
        return dataclasses.replace(asm, force=1e3 * asm.force)
    monkeypatch.setattr(cr.ContactResponse, "_assemble", no_descent)
    out = response._newton(response.state_u(), 0.25 * target)
    assert isinstance(out, cr.ResponseFailure)
    assert out.reason == "interior line search found no descent"
    assert len(trials) == cr.FRESH_BACKTRACKS < cr.BACKTRACKS


SHAPES = ("foam_square", "disk", "ellipse", "convex_blob", "nonconvex_blob", "resist_fig9")


@pytest.fixture(scope="module")
def shipped_solids():
    return {name: scene_solid(load_scene(scene_file(name))) for name in SHAPES}


@settings(max_examples=40, deadline=None, derandomize=True)
@given(data=st.data())
def test_random_hard_squeezes_end_in_a_checked_state_or_a_named_error(shipped_solids, data):
    """A sample of the random campaign that found the squeezes above: six shipped shapes, a
    boundary node and one within three of the farthest from it, mu up to 1.5, tips from 0.5 %
    to 30 % of the object or pads, both squeeze kinds, every model (the nonlinear ones to
    12 %). Each squeeze ends in a state the mechanics allows (zero force at the start; for the
    linear model equilibrium, forces in their cones and no node inside a tip, from an
    independent full solve; work at least the stored energy) or in a named refusal or solver
    error: never another exception, never NaN.
    """
    obj = shipped_solids[data.draw(st.sampled_from(SHAPES), label="shape")]
    boundary = obj.mesh.boundary
    k = data.draw(st.integers(0, len(boundary) - 1), label="F1")
    far = int(np.argmax(np.hypot(*(obj.mesh.nodes[boundary] - obj.mesh.nodes[boundary[k]]).T)))
    i, j = int(boundary[k]), int(boundary[(far + data.draw(st.integers(-3, 3), label="F2 off "
                                                                 "the farthest")) % len(boundary)])
    assume(i != j)
    mu = data.draw(st.sampled_from([0.0, 0.05, 0.2, 0.5, 0.9, 1.5]), label="mu")
    size = data.draw(st.sampled_from([0.005, 0.02, 0.1, 0.3]), label="tip size") * obj.mesh.size
    tip = TipShape.pad(width=2 * size, edge_radius=0.25 * size) if data.draw(
        st.booleans(), label="pad") else size
    model = data.draw(st.sampled_from(["linear"] * 4 + ["corotational", "neo_hookean"]),
                      label="model")
    depth = data.draw(st.sampled_from([0.01, 0.05, 0.12] + ([0.25] if model == "linear" else [])),
                      label="relative depth")
    kind = data.draw(st.sampled_from(["stable", "pure"]), label="kind")
    try:
        res = event_squeeze(obj, (i, j), tip, mu, kind=kind, relative_depth=depth,
                            material_model=model)
    except (InvalidInputError, InfeasibleError, NumericalError) as exc:
        assert str(exc)
        event(type(exc).__name__)
        return
    event(f"{model} {res.termination.value}{' at depth 0' if res.relative_depth == 0 else ''}")
    assert max(abs(forces[0]) for forces in res.finger_force.values()) < 1e-9
    assert np.isfinite(res.energy) and all(np.isfinite(w) for w in res.work.values())
    assert res.diagnostics["work_minus_energy"] >= -1e-6 * res.energy - 1e-15
    loaded = max((np.abs(c.force).max() for c in res.state.contacts), default=0.0)
    if model == "linear" and loaded > 1e-9:
        check_state(ContactModel(obj, mu), res.state)


def test_a_failed_equilibrium_names_its_residual_interior_not_cone(shipped_solids):
    """A nonlinear response that finds no equilibrium reports the residual of that equilibrium
    (the interior forces, relative to the contact forces), and says so: "residuals: interior".
    Before, every fixed-set failure labelled its residual "cone", the sliding Newton's.
    """
    from squeeze_grasp_ros.mechanics.squeeze.nonlinear_model import contact_model

    obj = shipped_solids["foam_square"]
    b = obj.mesh.boundary
    model = contact_model("neo_hookean", obj, 0.5)
    response = model.response(model.set_data((int(b[0]), int(b[len(b) // 2]))))
    squashed = np.array([[0.6, 0.0], [-0.6, 0.0]])  # each node pushed through the other
    out = response(squashed)
    assert isinstance(out, SolveFailure) and out.inverted and out.measure == "interior"
    assert "(residuals: interior " in str(out.error())
    assert SolveFailure("a cone that cannot close", 0.5).error().residuals == {"cone": 0.5}


class _Stop(Exception):
    """The cancellation of the checkpoint test."""


@pytest.mark.parametrize("model", [MaterialModel.LINEAR, MaterialModel.COROTATIONAL])
def test_a_cancellation_stops_a_squeeze_within_one_fixed_set_solve(model, monkeypatch):
    """The checkpoint (the planner's cancellation) runs before every fixed-set solve and every
    equilibrium solve of a nonlinear one, not only before every substep: a substep's halvings
    can take many solves (the blob squeeze above spent up to 5.9 s of CPU between two
    substeps, the neo-Hookean foam square of docs/reliability.md 12 s; 0.8 s at most now).
    Every solve follows a checkpoint call, and none follows the call that raises.
    """
    log: list[str] = []
    real, evaluate = solving.attempt_fixed_set, cr.ContactResponse.evaluate

    def solve(*args, **kwargs):
        log.append("solve")
        return real(*args, **kwargs)

    def equilibrium(self, delta):
        log.append("equilibrium")
        return evaluate(self, delta)
    monkeypatch.setattr(solving, "attempt_fixed_set", solve)
    monkeypatch.setattr(cr.ContactResponse, "evaluate", equilibrium)

    def checkpoint():
        log.append("check")
        if log.count("solve") >= 25:
            raise _Stop
    setup = GraspSetup.build(load_scene(scene_file("foam_square_low_friction")))
    with pytest.raises(_Stop):
        setup.event_squeeze(material_model=model, checkpoint=checkpoint)
    assert log.count("solve") == 25 and log[-1] == "check"
    assert all(log[k - 1] == "check" for k, entry in enumerate(log) if entry == "solve")
    # a nonlinear solve's equilibrium solves (the trials of its Newton) each follow one too
    equilibria = [k for k, entry in enumerate(log) if entry == "equilibrium"]
    assert (len(equilibria) > 25) == (model != MaterialModel.LINEAR)
    assert all(log[k - 1] == "check" for k in equilibria)
