# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""App. C similarity matching and App. B calibration: exact recovery of known transforms and
materials, the special case c3 = c4 = 0, an FEM round trip, and the match/calibrate verbs.
"""
from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from squeeze_grasp_ros import cli
from squeeze_grasp_ros.mechanics.calibration.matching import match_similarity
from squeeze_grasp_ros.mechanics.calibration.material_fit import (
    Cuboid,
    bisect_slope,
    calibrate_elasticity,
    friction_from_angle,
    friction_from_trials,
)
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh
from squeeze_grasp_ros.mechanics.errors import InvalidInputError

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"


def similarity(points, s, theta, t):
    c, si = np.cos(theta), np.sin(theta)
    return s * points @ np.array([[c, -si], [si, c]]).T + t


@pytest.mark.parametrize("seed", range(5))
def test_match_recovers_a_random_similarity_exactly(seed):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(rng.integers(3, 40), 2)) * 0.05
    s, theta, t = rng.uniform(0.3, 3.0), rng.uniform(-np.pi, np.pi), rng.normal(size=2)
    # measured Q is P seen in another frame: P = s R Q + t
    Q = similarity(P - t, 1 / s, -theta, np.zeros(2))
    m = match_similarity(P, Q)
    assert m.scale == pytest.approx(s, rel=1e-12)
    assert np.angle(np.exp(1j * (m.rotation - theta))) == pytest.approx(0, abs=1e-12)
    assert m.translation == pytest.approx(t, abs=1e-12)
    assert m.mean_error < 1e-12


def test_match_special_case_of_centred_measured_points():
    rng = np.random.default_rng(7)
    Q = rng.normal(size=(12, 2))
    Q -= Q.mean(axis=0)  # c3 = c4 = 0
    P = similarity(Q, 1.7, 0.4, np.array([0.2, -0.1]))
    m = match_similarity(P, Q)
    c1, c2 = P.mean(axis=0)
    c5, c6 = np.mean(P[:, 0] * Q[:, 0]), np.mean(P[:, 0] * Q[:, 1])
    c7, c8 = np.mean(P[:, 1] * Q[:, 0]), np.mean(P[:, 1] * Q[:, 1])
    c9c10 = np.mean(Q[:, 0] ** 2 + Q[:, 1] ** 2)
    assert m.translation == pytest.approx([c1, c2], abs=1e-13)
    assert m.scale == pytest.approx(np.hypot(c7 - c6, c5 + c8) / c9c10, rel=1e-13)
    assert m.rotation == pytest.approx(np.arctan2(c7 - c6, c5 + c8), abs=1e-13)
    assert (m.scale, m.rotation) == pytest.approx((1.7, 0.4), rel=1e-12)


def test_match_is_the_least_squares_optimum_with_noise():
    rng = np.random.default_rng(3)
    P = rng.normal(size=(30, 2))
    Q = similarity(P, 0.8, 1.1, np.array([1.0, 2.0])) + 0.01 * rng.normal(size=P.shape)
    m = match_similarity(P, Q)
    best = np.sum(m.errors ** 2)
    for _ in range(50):  # any perturbed transform is worse
        d = 1e-3 * rng.normal(size=4)
        trial = similarity(Q, m.scale + d[0], m.rotation + d[1], m.translation + d[2:])
        assert np.sum((P - trial) ** 2) >= best
    with pytest.raises(InvalidInputError, match="coincide"):
        match_similarity(P[:3], np.ones((3, 2)))
    with pytest.raises(InvalidInputError, match="same n"):
        match_similarity(P[:3], P[:4])


def test_calibration_round_trips_known_material():
    E, nu = 5e4, 0.3
    cuboids = [Cuboid.simulate(E, nu, f, l, w, h)
               for f, l, w, h in ((2.0, 0.1, 0.03, 0.0254), (1.5, 0.05, 0.04, 0.0254),
                                  (3.0, 0.08, 0.05, 0.03))]
    fit = calibrate_elasticity(cuboids)
    assert fit.E == pytest.approx(E, rel=1e-12) and fit.nu == pytest.approx(nu, rel=1e-12)
    assert fit.E_residual < 1e-12 and fit.nu_residual < 1e-12
    assert friction_from_angle(np.arctan(0.4)).mu == pytest.approx(0.4, rel=1e-14)
    trials = bisect_slope(lambda a: np.tan(a) > 0.4, tol=1e-9)
    fr = friction_from_trials(trials)
    assert fr.mu_range[0] <= 0.4 <= fr.mu_range[1]
    assert fr.mu == pytest.approx(0.4, abs=1e-8)
    with pytest.raises(InvalidInputError, match="inconsistent"):
        friction_from_trials([(0.5, False), (0.3, True)])


def test_calibration_recovers_the_fem_material_of_a_compressed_cuboid():
    """A plane-stress FEM cuboid under uniform end traction, measured like App. B."""
    E, nu, h = 7e4, 0.35, 0.02
    l, w, f = 0.08, 0.04, 1.5
    obj = ElasticObject(generate_mesh(shapes.rectangle(l, w), 2e-5), Material(E, nu, h))
    x = obj.mesh.nodes
    loads = np.zeros_like(x)
    for side, sign in ((x[:, 0].max(), -1.0), (x[:, 0].min(), 1.0)):
        end = np.flatnonzero(np.isclose(x[:, 0], side))
        end = end[np.argsort(x[end, 1])]
        share = np.zeros(len(end))
        seg = np.diff(x[end, 1])
        share[:-1] += seg / 2
        share[1:] += seg / 2
        loads[end, 0] = sign * f * share / w  # consistent nodal loads of a uniform traction
    u = obj.pinv_apply(loads.ravel() / (E * h * obj.scale)).reshape(-1, 2) * obj.scale
    def span(axis):
        hi, lo = np.isclose(x[:, axis], x[:, axis].max()), np.isclose(x[:, axis], x[:, axis].min())
        return u[hi, axis].mean() - u[lo, axis].mean()
    fit = calibrate_elasticity([Cuboid(f, l, w, h, span(0), span(1))])
    assert fit.E == pytest.approx(E, rel=1e-8) and fit.nu == pytest.approx(nu, rel=1e-8)


def run_cli(args, capsys) -> dict:
    assert cli.main(args) == 0
    return json.loads(capsys.readouterr().out)


def test_match_and_calibrate_verbs(tmp_path, capsys):
    sim = tmp_path / "sim.csv"
    out = run_cli(["squeeze", str(SCENES / "foam_square.yaml"), "--relative-depth", "0.04",
                   "--save-boundary", str(sim), "--json"], capsys)
    assert out["boundary_csv"] == str(sim)
    P = np.loadtxt(sim, delimiter=",", skiprows=1)
    Q = similarity(P, 1 / 1.25, -0.3, np.array([0.02, -0.01]))
    meas = tmp_path / "measured.csv"
    np.savetxt(meas, Q, delimiter=",", header="# scanner points", comments="")
    png = tmp_path / "match.png"
    m = run_cli(["match", str(sim), str(meas), "--json", "--plot", str(png)], capsys)
    back = similarity(Q, m["scale"], m["rotation"], np.array(m["translation"]))
    assert np.abs(back - P).max() < 1e-9 and m["mean_error"] < 1e-9
    assert png.stat().st_size > 5_000
    cub = tmp_path / "cuboids.csv"
    c = Cuboid.simulate(5e4, 0.3, 2.0, 0.1, 0.03, 0.0254)
    cub.write_text("force,length,width,height,dl,dw,dh\n"
                   f"{c.force},{c.length},{c.width},{c.height},{c.dl!r},{c.dw!r},{c.dh!r}\n")
    trials = tmp_path / "trials.csv"
    trials.write_text("angle_deg,slid\n15,0\n25,1\n20,0\n22.5,1\n")
    cal = run_cli(["calibrate", "--cuboids", str(cub), "--slope-trials", str(trials), "--json"],
                  capsys)
    assert cal["elasticity"]["E"] == pytest.approx(5e4, rel=1e-9)
    assert cal["elasticity"]["nu"] == pytest.approx(0.3, rel=1e-9)
    assert cal["friction"]["mu"] == pytest.approx(np.tan(np.radians(21.25)))
    assert cli.main(["calibrate"]) == 2
    bad = tmp_path / "bad.csv"
    bad.write_text("force,length\n1,2\n")
    assert cli.main(["calibrate", "--cuboids", str(bad)]) == 2
    assert "columns" in capsys.readouterr().err


@pytest.mark.parametrize("simulated, measured, message", [
    # coincident simulated points were matched with scale 0 and every error 0 (exit 0)
    ([[0, 0], [0, 0], [0, 0]], [[0, 0], [1, 0], [0, 1]], "the simulated points coincide"),
    ([[1e-300, 0], [0, 1e-300], [-1e-300, 0]], [[0, 0], [1, 0], [0, 1]],
     "the simulated points coincide"),
    # 1e308 m overflowed the moments: scale inf, a NaN mean error, RuntimeWarnings (exit 0)
    ([[1e308, 1e308], [-1e308, 1e308], [0, -1e308]], [[0, 0], [1, 0], [0, 1]],
     "simulated points must lie within 1e+06 m of the origin (coordinates in m), got a "
     "coordinate of 1e+308"),
    # here the overflow was reported as "the measured points coincide"
    ([[0, 0], [1, 0], [0, 1]], [[1e308, 1e308], [-1e308, 1e308], [0, -1e308]],
     "measured points must lie within 1e+06 m"),
])
def test_degenerate_or_overflowing_point_sets_are_refused(tmp_path, capfd, simulated,
                                                          measured, message):
    paths = []
    for name, points in (("sim", simulated), ("meas", measured)):
        paths.append(tmp_path / f"{name}.csv")
        paths[-1].write_text("x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in points))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert cli.main(["match", *map(str, paths)]) == 2
    out, err = capfd.readouterr()
    assert out == "" and message in err and len(err.strip().splitlines()) == 1, err
