# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Material fits to a measured uniaxial compression curve: linear and neo-Hookean.

A cuboid with sides l (loaded), w, h is compressed by a force f; the side l shortens by |dl|
and, if measured, w widens by dw. The lateral faces are free, so the stress is uniaxial:

- linear: f = E w h (-dl / l) and dw / w = nu (-dl / l);
- compressible neo-Hookean W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2 (the law of
  :mod:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic`): with the stretch l1 = 1 + dl / l
  and the lateral stretch l2 from mu (l2^2 - 1) + lambda ln(l1 l2^2) = 0 (free faces), the
  nominal stress is P = mu (l1 - 1/l1) + lambda ln(l1 l2^2) / l1 and f = P w h.

Both laws are fitted by least squares (scipy) to the forces and, when measured, the lateral
changes; E and nu are reported for both, with the relative rms residual of each, and the
strain up to which the linear fit stays within a tolerance of the neo-Hookean one.

>>> import numpy as np
>>> strain = np.linspace(0.01, 0.3, 12)
>>> P, lateral = uniaxial_response("neo_hookean", 1 - strain, E=5e4, nu=0.3)
>>> curve = CompressionCurve(0.05, 0.05, 0.02, -P * 0.05 * 0.02, -strain * 0.05,
...                          (lateral - 1) * 0.05)
>>> fit = fit_compression(curve, model="neo_hookean")
>>> print(f"{fit.E:.1f} Pa, nu = {fit.nu:.4f}", bool(fit.residual < 1e-9))
50000.0 Pa, nu = 0.3000 True
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from squeeze_grasp_ros.mechanics.calibration.material_fit import (
    MIN_STRAIN,
    require_side,
    shortened_by,
)
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError, require_finite
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

__all__ = ["CompressionCurve", "MaterialFit", "fit_compression", "linear_validity",
           "uniaxial_response"]


@dataclass(frozen=True)
class CompressionCurve:
    """A measured uniaxial compression of a cuboid.

    Attributes
    ----------
    length, width, height : float
        Undeformed sides l (loaded), w, h, m (in
        :data:`~squeeze_grasp_ros.mechanics.calibration.material_fit.SIDE_RANGE`).
    force : (k,) ndarray
        Compressive force magnitudes, N (> 0).
    dl : (k,) ndarray
        Changes of l, m (< 0, above -l).
    dw : (k,) ndarray or None
        Changes of w, m (lateral bulging), if measured.
    """

    length: float
    width: float
    height: float
    force: np.ndarray
    dl: np.ndarray
    dw: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in ("length", "width", "height"):
            require_side(name, getattr(self, name))
        force, dl = np.asarray(self.force, float), np.asarray(self.dl, float)
        if force.shape != dl.shape or force.ndim != 1 or len(force) < 2:
            raise InvalidInputError("a compression curve needs at least 2 (force, dl) points, "
                                    f"force and dl of one length: got shapes {force.shape} "
                                    f"and {dl.shape}")
        if not np.all(np.isfinite(force)) or not np.all(force > 0):
            raise InvalidInputError("force must be > 0 N (compression) at every point")
        if not shortened_by(dl, self.length):
            raise InvalidInputError(f"dl must be in (-{self.length:g}, "
                                    f"{-MIN_STRAIN * self.length:.3g}] m at every point (the "
                                    f"cuboid shortens, by at least {MIN_STRAIN:g} of its length)")
        if self.dw is not None and (np.shape(self.dw) != dl.shape
                                    or not np.all(np.isfinite(self.dw))):
            raise InvalidInputError("dw must have one finite value per point")

    @property
    def strain(self) -> np.ndarray:
        """Compressive engineering (Biot, nominal) strain -dl / l at each point."""
        return -np.asarray(self.dl, float) / self.length


@dataclass(frozen=True)
class MaterialFit:
    """A law fitted to a compression curve.

    Attributes
    ----------
    model : MaterialModel
        ``linear`` or ``neo_hookean``.
    E : float
        Young's modulus, Pa (the small-strain modulus of the law).
    nu : float
        Poisson's ratio (fitted when lateral changes were measured, else the given one).
    residual : float
        Relative rms residual: rms of (predicted - measured) force over the largest force, and
        of the lateral changes over the largest one when measured.
    nu_fitted : bool
        True if nu was fitted.
    """

    model: MaterialModel
    E: float
    nu: float
    residual: float
    nu_fitted: bool

    def to_json(self) -> dict:
        """JSON-able dict."""
        return {"model": str(self.model), "E": self.E, "nu": self.nu, "residual": self.residual,
                "nu_fitted": self.nu_fitted}


def _lateral_stretch(l1: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """l2 with mu (l2^2 - 1) + lam ln(l1 l2^2) = 0 (free lateral faces), by Newton."""
    l2 = np.ones_like(l1)
    for _ in range(60):
        g = mu * (l2 * l2 - 1.0) + lam * np.log(l1 * l2 * l2)
        step = g / (2.0 * mu * l2 + 2.0 * lam / l2)
        l2 = np.maximum(l2 - step, 0.5 * l2)
        if np.max(np.abs(step)) < 1e-15:
            return l2
    raise NumericalError("the lateral stretch of the uniaxial neo-Hookean state did not "
                         "converge", residuals={"step": float(np.max(np.abs(step)))})


def uniaxial_response(model: MaterialModel | str, stretch: np.ndarray, *, E: float,
                      nu: float) -> tuple[np.ndarray, np.ndarray]:
    """(nominal stress P, Pa, lateral stretch) of uniaxial stress at axial ``stretch``."""
    l1 = np.asarray(stretch, float)
    if MaterialModel(model) == MaterialModel.LINEAR:
        return E * (l1 - 1.0), 1.0 - nu * (l1 - 1.0)
    if not -1.0 < nu < 0.5:
        raise InvalidInputError(f"nu must be in (-1, 0.5) for the neo_hookean law, got {nu}")
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    l2 = _lateral_stretch(l1, lam, mu)
    return mu * (l1 - 1.0 / l1) + lam * np.log(l1 * l2 * l2) / l1, l2


def fit_compression(curve: CompressionCurve, *, model: MaterialModel | str,
                    nu: float = 0.3) -> MaterialFit:
    """Least-squares fit of ``model`` to ``curve``; nu is fitted when ``curve.dw`` is given,
    else held at ``nu``.

    Parameters
    ----------
    curve : CompressionCurve
        The measured compression.
    model : MaterialModel or str
        ``linear`` or ``neo_hookean``.
    nu : float
        Poisson's ratio, dimensionless, in (-1, 0.5] (below 0.5 for ``neo_hookean``): held
        when ``curve.dw`` is None, else the fit's starting value.

    Raises
    ------
    InvalidInputError
        For a ``model`` other than ``linear`` or ``neo_hookean``, or a ``nu`` the law cannot
        take (not finite or outside (-1, 0.5]).
    """
    if model not in MaterialModel.values():
        raise InvalidInputError(f"model must be linear or neo_hookean, got {model!r}")
    model = MaterialModel(model)
    require_finite("nu", nu)
    if not -1.0 < nu <= 0.5:
        raise InvalidInputError(f"nu must be in (-1, 0.5], got {nu:g}")
    if model == MaterialModel.COROTATIONAL:
        raise InvalidInputError("calibrate fits linear and neo_hookean laws (the corotational "
                                "law's uniaxial response is the linear one)")
    force = np.asarray(curve.force, float)
    area = curve.width * curve.height
    l1 = 1.0 + np.asarray(curve.dl, float) / curve.length
    lateral = None if curve.dw is None else np.asarray(curve.dw, float) / curve.width
    E0 = float(np.sum(force * curve.strain) / np.sum(curve.strain ** 2)) / area
    fit_nu = lateral is not None

    def unpack(x: np.ndarray) -> tuple[float, float]:
        E = E0 * np.exp(x[0])
        return E, (0.499 * np.tanh(x[1]) if fit_nu else nu)

    def residuals(x: np.ndarray) -> np.ndarray:
        E, v = unpack(x)
        P, l2 = uniaxial_response(model, l1, E=E, nu=v)
        r = (-P * area - force) / force.max()
        if lateral is not None:
            r = np.concatenate([r, (l2 - 1.0 - lateral) / max(np.abs(lateral).max(), 1e-300)])
        return r

    x0 = np.array([0.0, np.arctanh(min(max(nu, -0.49), 0.49) / 0.499)])
    sol = least_squares(residuals if fit_nu else (lambda x: residuals(np.append(x, 0.0))),
                        x0 if fit_nu else x0[:1], xtol=1e-14, ftol=1e-14, gtol=1e-14)
    x = sol.x if fit_nu else np.append(sol.x, 0.0)
    E, v = unpack(x)
    rms = float(np.sqrt(np.mean(residuals(x) ** 2)))
    return MaterialFit(model, float(E), float(v), rms, fit_nu)


def linear_validity(fit: MaterialFit, *, tolerance: float = 0.05,
                    max_strain: float = 0.5) -> float:
    """Largest compressive strain up to which linear elasticity with the fitted E and nu stays
    within ``tolerance`` (relative force) of the fitted neo-Hookean law (``max_strain`` if it
    always does): the squeeze depth range where the linear model suffices for this material.
    """
    strain = np.linspace(1e-4, max_strain, 2000)
    P_lin, _ = uniaxial_response(MaterialModel.LINEAR, 1 - strain, E=fit.E, nu=fit.nu)
    P_nh, _ = uniaxial_response(MaterialModel.NEO_HOOKEAN, 1 - strain, E=fit.E, nu=fit.nu)
    off = np.abs(P_lin / P_nh - 1.0) > tolerance
    return float(strain[np.argmax(off)]) if off.any() else max_strain
