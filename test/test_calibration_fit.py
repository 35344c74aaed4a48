# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Linear and neo-Hookean fits of a uniaxial compression curve (calibrate --compression)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from squeeze_grasp_ros.cli import main
from squeeze_grasp_ros.mechanics.calibration.hyperelastic_fit import (
    CompressionCurve,
    MaterialFit,
    fit_compression,
    linear_validity,
    uniaxial_response,
)
from squeeze_grasp_ros.mechanics.elastic import hyperelastic
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

SIDES = (0.05, 0.04, 0.02)


def curve(strain, *, E=5e4, nu=0.3, lateral=True, noise=0.0, seed=0):
    P, l2 = uniaxial_response("neo_hookean", 1 - strain, E=E, nu=nu)
    force = -P * SIDES[1] * SIDES[2]
    force = force * (1 + noise * np.random.default_rng(seed).standard_normal(len(force)))
    return CompressionCurve(*SIDES, force, -strain * SIDES[0],
                            (l2 - 1) * SIDES[1] if lateral else None)


def test_uniaxial_neo_hookean_is_the_plane_stress_law_with_free_faces():
    """The scalar uniaxial response equals the element law's P11 at F = diag(l1, l2) with the
    lateral stretch that leaves the faces free (P22 = 0): an independent check of both.
    """
    l1 = np.array([0.95, 0.8, 0.7])
    P, l2 = uniaxial_response("neo_hookean", l1, E=5e4, nu=0.3)
    F = np.zeros((3, 2, 2))
    F[:, 0, 0], F[:, 1, 1] = l1, l2
    _, P_el, _ = hyperelastic.stress_and_tangent("neo_hookean", F, nu=0.3)
    assert np.allclose(P_el[:, 0, 0] * 5e4, P, rtol=1e-10)
    assert np.abs(P_el[:, 1, 1]).max() < 1e-10


def test_exact_data_give_back_the_law():
    fit = fit_compression(curve(np.linspace(0.01, 0.3, 10)), model="neo_hookean")
    assert fit.E == pytest.approx(5e4, rel=1e-8) and fit.nu == pytest.approx(0.3, rel=1e-8)
    assert fit.nu_fitted and fit.residual < 1e-10


def test_linear_is_right_at_small_strain_and_wrong_at_large():
    small = fit_compression(curve(np.linspace(0.001, 0.01, 6)), model="linear")
    assert small.E == pytest.approx(5e4, rel=0.01)
    data = curve(np.linspace(0.01, 0.3, 12), lateral=False)
    linear, neo = (fit_compression(data, model=m) for m in ("linear", "neo_hookean"))
    assert not linear.nu_fitted and linear.nu == 0.3
    assert neo.residual < 1e-9 < 0.01 < linear.residual


def test_noisy_data_fit_within_the_noise():
    fit = fit_compression(curve(np.linspace(0.01, 0.3, 40), noise=0.01), model="neo_hookean")
    assert fit.E == pytest.approx(5e4, rel=0.02) and 0.001 < fit.residual < 0.01


def test_the_linear_range_shrinks_with_the_tolerance():
    fit = MaterialFit(MaterialModel.NEO_HOOKEAN, 5e4, 0.3, 0.0, False)
    ranges = [linear_validity(fit, tolerance=t) for t in (0.01, 0.05, 0.2)]
    assert ranges == sorted(ranges) and 0.0 < ranges[0] < ranges[2]


def test_the_cli_route(tmp_path, capfd):
    data = curve(np.linspace(0.01, 0.25, 8))
    path = tmp_path / "curve.csv"
    path.write_text("force,dl,dw\n" + "".join(f"{f:.17g},{d:.17g},{w:.17g}\n" for f, d, w in
                                               zip(data.force, data.dl, data.dw)))
    args = ["calibrate", "--compression", str(path), "--sample-size", *map(str, SIDES)]
    assert main(args + ["--json"]) == 0
    out = json.loads(capfd.readouterr().out)["compression"]
    assert out["neo_hookean"]["E"] == pytest.approx(5e4, rel=1e-6)
    assert 0.03 < out["linear_within_5_percent_up_to_strain"] < 0.1
    assert main(args) == 0
    assert "within 5 % of the neo-Hookean fit" in capfd.readouterr().out
    assert main(["calibrate", "--compression", str(path)]) == 2
    assert "--sample-size" in capfd.readouterr().err
    path.write_text("force,dl\n1.0,0.001\n2.0,0.002\n")
    assert main(args) == 2
    assert "dl must be in" in capfd.readouterr().err


def test_an_unknown_model_and_mismatched_arrays_are_refused_by_name():
    """An unknown model used to escape as ValueError; arrays of two lengths were reported as
    too few points.
    """
    with pytest.raises(InvalidInputError, match="model must be linear or neo_hookean, got 'x'"):
        fit_compression(curve(np.linspace(0.01, 0.1, 5)), model="x")
    with pytest.raises(InvalidInputError, match=r"got shapes \(3,\) and \(2,\)"):
        CompressionCurve(*SIDES, np.ones(3), -0.001 * np.ones(2))


@pytest.mark.parametrize("option, cells, message", [
    ("--compression", ["--sample-size", "0.05", "0.04", "0.02", "--nu", "nan"],
     "nu must be finite, got nan"),
    ("--compression", ["--sample-size", "0.05", "0.04", "0.02", "--nu", "5"],
     "nu must be in (-1, 0.5], got 5"),
    ("--compression", ["--sample-size", "1e308", "1e308", "1e308"],
     "--sample-size L must be in [1e-06, 1000] m, got 1e+308"),
    ("--compression", ["--sample-size", "0.05", "1e-300", "0.02"],
     "--sample-size W must be in [1e-06, 1000] m, got 1e-300"),
    ("--cuboids", [], "cuboid.length must be in [1e-06, 1000] m, got 1e+308"),
])
def test_samples_and_ratios_out_of_range_are_refused_by_name(tmp_path, capfd, option, cells,
                                                              message):
    """``--nu nan`` and ``--sample-size 1e308 ...`` ended in scipy ValueError tracebacks (exit
    1), ``--nu 5`` was accepted, and a cuboid of 1e308 m sides reported a NaN Poisson's ratio:
    each is one line naming the field and its range, exit 2.
    """
    data = curve(np.linspace(0.01, 0.25, 8))
    path = tmp_path / "data.csv"
    if option == "--compression":
        path.write_text("force,dl\n" + "".join(f"{float(f)!r},{float(d)!r}\n" for f, d in
                                                zip(data.force, data.dl)))
    else:
        path.write_text("force,length,width,height,dl,dw\n1,1e308,1e308,1e308,-1,0.1\n"
                        "2,1e308,1e308,1e308,-2,0.2\n")
    assert main(["calibrate", option, str(path), *cells]) == 2
    out, err = capfd.readouterr()
    assert out == "" and err.strip().endswith(message) and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("model", ["linear", "neo_hookean"])
def test_a_compression_below_a_nanostrain_is_refused_by_name(model):
    """-dl / l = 1e-200: the linear curve fit raised scipy's "Residuals are not finite in the
    initial point" (a ValueError), the neo-Hookean one a NumericalError with a NaN residual, and
    a cuboid "fitted Poisson's ratio nan ... check the signs".
    """
    from squeeze_grasp_ros.mechanics.calibration.material_fit import Cuboid

    force = np.linspace(0.1, 1.0, 8)
    with pytest.raises(InvalidInputError, match=r"dl must be in \(-0.05, -5e-11\] m at every "
                                                 r"point \(the cuboid shortens, by at least "
                                                 r"1e-09 of its length\)"):
        fit_compression(CompressionCurve(0.05, 0.05, 0.02, force, -1e-202 * np.arange(1, 9)),
                        model=model, nu=0.3)
    with pytest.raises(InvalidInputError, match=r"cuboid.dl must be in \(-0.05, -5e-11\] m .* "
                                                r"got -1e-202"):
        Cuboid(1.0, 0.05, 0.05, 0.02, -1e-202, 0.0)
    # a nanostrain is measured and fitted
    fit = fit_compression(CompressionCurve(0.05, 0.05, 0.02, force, -5e-11 * np.arange(1, 9)),
                          model=model, nu=0.3)
    assert np.isfinite(fit.E) and fit.E > 0
