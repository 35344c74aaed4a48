# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp calibrate``: E, nu from cuboid compressions (App. B), linear and neo-Hookean
fits of a compression curve, and mu from a slope.
"""
from __future__ import annotations

import argparse

import numpy as np

from squeeze_grasp_ros.commands.csv_io import read_columns
from squeeze_grasp_ros.mechanics.calibration.hyperelastic_fit import (
    CompressionCurve,
    fit_compression,
    linear_validity,
)
from squeeze_grasp_ros.mechanics.calibration.material_fit import (
    SIDE_RANGE,
    Cuboid,
    calibrate_elasticity,
    friction_from_angle,
    friction_from_trials,
    require_side,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel, StrainMeasure

CUBOID_COLUMNS = ("force", "length", "width", "height", "dl", "dw")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """--cuboids CSV, --slope-angle DEG | --slope-trials CSV."""
    parser.add_argument("--cuboids", metavar="CUBOIDS.csv",
                        help="compression measurements, columns force,length,width,height,dl,dw"
                             "[,dh] (N, m; dl < 0 when shortened, dw, dh > 0 when bulging)")
    parser.add_argument("--compression", metavar="CURVE.csv",
                        help="a uniaxial compression curve of one cuboid, columns force,dl[,dw] "
                             "(N, m; dl < 0): fits the linear and the neo-Hookean law and says "
                             "up to which strain linear suffices; needs --sample-size")
    parser.add_argument("--sample-size", type=float, nargs=3, metavar=("L", "W", "H"),
                        help="the compressed cuboid's sides, m: loaded length, width, height "
                             f"(each in [{SIDE_RANGE[0]:g}, {SIDE_RANGE[1]:g}])")
    parser.add_argument("--nu", type=float, default=0.3,
                        help="Poisson's ratio used when the curve has no dw column, in "
                             "(-1, 0.5] (default 0.3)")
    slope = parser.add_mutually_exclusive_group()
    slope.add_argument("--slope-angle", type=float, metavar="DEG",
                       help="critical slope angle alpha0, degrees: mu = tan(alpha0)")
    slope.add_argument("--slope-trials", metavar="TRIALS.csv",
                       help="slope trials, columns angle_deg,slid (slid: 1/0 or true/false)")


def _truth(cell: str) -> bool:
    value = cell.strip().lower()
    if value not in ("1", "0", "true", "false", "yes", "no"):
        raise InvalidInputError(f"slid must be 1/0, true/false or yes/no, got {cell!r}")
    return value in ("1", "true", "yes")


def _compression(args: argparse.Namespace) -> dict:
    """Linear and neo-Hookean fits of one compression curve, and linear's validity range."""
    if not args.sample_size:
        raise InvalidInputError("--compression needs --sample-size L W H (m)")
    for letter, side in zip("LWH", args.sample_size):
        require_side(f"--sample-size {letter}", side)
    rows = read_columns(args.compression, ("force", "dl"), ("dw",))
    try:
        force = [float(r["force"]) for r in rows]
        dl = [float(r["dl"]) for r in rows]
        dw = [float(r["dw"]) for r in rows] if all(r.get("dw") for r in rows) else None
    except ValueError as exc:
        raise InvalidInputError(f"{args.compression}: {exc}") from None
    curve = CompressionCurve(*args.sample_size, np.array(force), np.array(dl),
                             None if dw is None else np.array(dw))
    linear = fit_compression(curve, model=MaterialModel.LINEAR, nu=args.nu)
    neo = fit_compression(curve, model=MaterialModel.NEO_HOOKEAN, nu=args.nu)
    return {"points": len(force), "max_strain": float(curve.strain.max()),
            "strain_measure": str(StrainMeasure.BIOT),
            MaterialModel.LINEAR: linear.to_json(), MaterialModel.NEO_HOOKEAN: neo.to_json(),
            "linear_within_5_percent_up_to_strain": linear_validity(neo)}


def run(args: argparse.Namespace) -> dict:
    """The calibrated values."""
    if not (args.cuboids or args.compression or args.slope_angle is not None
            or args.slope_trials):
        raise InvalidInputError("give --cuboids, --compression and/or --slope-angle / "
                                "--slope-trials")
    out: dict = {}
    if args.cuboids:
        rows = read_columns(args.cuboids, CUBOID_COLUMNS, ("dh",))
        try:
            cuboids = [Cuboid(*(float(r[c]) for c in CUBOID_COLUMNS),
                              float(r["dh"]) if r.get("dh") else None) for r in rows]
        except ValueError as exc:
            raise InvalidInputError(f"{args.cuboids}: {exc}") from None
        out["elasticity"] = calibrate_elasticity(cuboids).to_json()
    if args.compression:
        out["compression"] = _compression(args)
    if args.slope_angle is not None:
        out["friction"] = friction_from_angle(np.radians(args.slope_angle)).to_json()
    if args.slope_trials:
        rows = read_columns(args.slope_trials, ("angle_deg", "slid"))
        try:
            trials = [(np.radians(float(r["angle_deg"])), _truth(r["slid"])) for r in rows]
        except ValueError as exc:
            raise InvalidInputError(f"{args.slope_trials}: {exc}") from None
        out["friction"] = friction_from_trials(trials).to_json()
    return out


def summary(result: dict) -> str:
    """Human-readable calibration."""
    lines = []
    el = result.get("elasticity")
    if el:
        lines.append(f"E = {el['E']:.5g} Pa, nu = {el['nu']:.4g} from {len(el['per_cuboid'])} "
                     f"cuboid(s) (relative rms residuals {el['E_residual']:.2g}, "
                     f"{el['nu_residual']:.2g})")
    cp = result.get("compression")
    if cp:
        measure = StrainMeasure(cp["strain_measure"]).label
        for name in (MaterialModel.LINEAR, MaterialModel.NEO_HOOKEAN):
            fit = cp[name]
            lines.append(f"{name}: E = {fit['E']:.5g} Pa, nu = {fit['nu']:.4g}"
                         f"{'' if fit['nu_fitted'] else ' (given)'}, relative rms residual "
                         f"{fit['residual']:.3g} over {cp['points']} points up to compressive "
                         f"{measure} strain {cp['max_strain']:.3g}")
        lines.append("linear elasticity (same E, nu) stays within 5 % of the neo-Hookean fit up "
                     f"to {100 * cp['linear_within_5_percent_up_to_strain']:.1f} % compressive "
                     f"{measure} strain (-dl / l): beyond that, use material.model: neo_hookean")
    fr = result.get("friction")
    if fr:
        lo, hi = fr["bracket_deg"]
        lines.append(f"mu = {fr['mu']:.4g} (alpha0 = {fr['alpha0_deg']:.4g} deg"
                     + (f", bracket {lo:.4g}-{hi:.4g} deg" if hi > lo else "") + ")")
    return "\n".join(lines)
