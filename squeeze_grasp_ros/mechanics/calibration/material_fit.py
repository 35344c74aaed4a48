# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Material and friction calibration from simple measurements (paper App. B).

Cuboid compression: a cuboid with sides l (loaded direction), w and h is pushed along l by a
force of magnitude f; its sides change by dl (< 0, shortening), dw and dh (> 0, bulging). For
small changes

    E  ~ f l / (w h |dl|),        nu ~ -(dw / w) / (dl / l)   (and likewise with dh / h).

Several cuboids are combined by least squares: E from f = E (w h / l) |dl| through the origin,
nu from the transverse strains against the axial ones. Friction: a sample on a slope of the
fingertip material starts to slide above the critical angle alpha0, found by bisection on
[0, pi/2]; mu = tan(alpha0).
SI units: N, m, Pa, rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite

SIDE_RANGE = (1e-6, 1e3)
"""Sides of a calibration sample, m, inclusive: a micrometre to a kilometre. Beyond, the
cross-section w h underflows or overflows in double precision (a side of 1e308 m gave a NaN
Poisson's ratio, and in a compression curve a scipy traceback)."""


MIN_STRAIN = 1e-9
"""Smallest compressive strain -dl / l a measurement may give (a nanostrain; no compression test
resolves less). At -dl / l = 1e-200 the cuboid fit gave a Poisson's ratio of NaN ("check the
signs"), the linear curve fit scipy's "Residuals are not finite in the initial point" and the
neo-Hookean one a NaN residual."""


def shortened_by(dl: float | np.ndarray, length: float) -> bool:
    """Whether every change ``dl`` (m) shortens a side ``length`` (m) by a strain in
    [:data:`MIN_STRAIN`, 1).
    """
    strain = -np.asarray(dl, float) / length
    return bool(np.all(np.isfinite(strain) & (strain >= MIN_STRAIN) & (strain < 1.0)))


def require_side(name: str, value: float) -> None:
    """Refuse a sample side outside :data:`SIDE_RANGE`.

    Parameters
    ----------
    name : str
        The field, as the message names it (``cuboid.length``, ``--sample-size W``).
    value : float
        The side, m.

    >>> require_side("cuboid.width", 1e308)
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: cuboid.width must be in [1e-06, 1000] \
m, got 1e+308
    """
    require_finite(name, value)
    lo, hi = SIDE_RANGE
    if not lo <= value <= hi:
        raise InvalidInputError(f"{name} must be in [{lo:g}, {hi:g}] m, got {value:g}")


@dataclass(frozen=True)
class Cuboid:
    """One compression measurement.

    Attributes
    ----------
    force : float
        Compressive force magnitude f, N (> 0).
    length, width, height : float
        Undeformed sides l (loaded), w, h, m (in :data:`SIDE_RANGE`).
    dl : float
        Change of l, m (in (-l, 0): compression).
    dw : float
        Change of w, m.
    dh : float or None
        Change of h, m, if measured.
    """

    force: float
    length: float
    width: float
    height: float
    dl: float
    dw: float
    dh: float | None = None

    def __post_init__(self) -> None:
        for name in ("force", "length", "width", "height", "dl", "dw"):
            require_finite(f"cuboid.{name}", getattr(self, name))
        if not self.force > 0:
            raise InvalidInputError(f"cuboid.force must be > 0, got {self.force}")
        for name in ("length", "width", "height"):
            require_side(f"cuboid.{name}", getattr(self, name))
        if not shortened_by(self.dl, self.length):
            raise InvalidInputError(
                f"cuboid.dl must be in (-{self.length:g}, {-MIN_STRAIN * self.length:.3g}] m "
                f"(the cuboid shortens, by at least {MIN_STRAIN:g} of its length), got {self.dl}"
            )
        if self.dh is not None:
            require_finite("cuboid.dh", self.dh)

    @property
    def axial_strain(self) -> float:
        """Dl / l (< 0)."""
        return self.dl / self.length

    @property
    def stress(self) -> float:
        """F / (w h), Pa."""
        return self.force / (self.width * self.height)

    @property
    def transverse_strains(self) -> list[float]:
        """Dw / w and, if measured, dh / h."""
        out = [self.dw / self.width]
        if self.dh is not None:
            out.append(self.dh / self.height)
        return out

    def young(self) -> float:
        """E of this cuboid alone, Pa."""
        return self.stress / abs(self.axial_strain)

    def poisson(self) -> float:
        """Nu of this cuboid alone (mean over the measured transverse sides)."""
        return float(np.mean([-t / self.axial_strain for t in self.transverse_strains]))

    @staticmethod
    def simulate(
        E: float, nu: float, force: float, length: float, width: float, height: float
    ) -> "Cuboid":
        """The measurement a linear-elastic cuboid (E in Pa, nu) would give, for round trips."""
        dl = -force * length / (E * width * height)
        strain = dl / length
        return Cuboid(
            force, length, width, height, dl, -nu * strain * width, -nu * strain * height
        )


@dataclass(frozen=True)
class Elasticity:
    """E and nu fitted to cuboid measurements.

    Attributes
    ----------
    E : float
        Young's modulus, Pa (least squares of stress on |axial strain| through the origin).
    nu : float
        Poisson's ratio (least squares of -transverse on axial strain through the origin).
    per_cuboid : tuple of (float, float)
        (E, nu) of each cuboid alone.
    E_residual, nu_residual : float
        RMS relative residual of each fit (0 for consistent data).
    """

    E: float
    nu: float
    per_cuboid: tuple[tuple[float, float], ...]
    E_residual: float
    nu_residual: float

    def to_json(self) -> dict:
        """All fields."""
        return {
            "E": self.E,
            "nu": self.nu,
            "per_cuboid": [{"E": e, "nu": n} for e, n in self.per_cuboid],
            "E_residual": self.E_residual,
            "nu_residual": self.nu_residual,
        }


def fit_through_origin(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(slope k minimising ||y - k x||, RMS residual relative to RMS y)."""
    k = float(x @ y / (x @ x))
    rms_y = float(np.sqrt(np.mean(y * y)))
    return k, float(np.sqrt(np.mean((y - k * x) ** 2)) / max(rms_y, 1e-300))


def calibrate_elasticity(cuboids: list[Cuboid]) -> Elasticity:
    """E and nu from one or more cuboid compressions (App. B).

    Raises
    ------
    InvalidInputError
        Without measurements or for a fitted nu outside (-1, 0.5].

    Examples
    --------
    A 0.1 x 0.05 x 0.02 m cuboid of E = 2e5 Pa, nu = 0.4 under 10 N shortens by
    f l / (E w h) = 5 mm and widens by nu w |dl| / l:

    >>> cuboid = Cuboid(force=10.0, length=0.1, width=0.05, height=0.02, dl=-0.005,
    ...                 dw=0.4 * 0.05 * 0.005 / 0.1)
    >>> fit = calibrate_elasticity([cuboid])
    >>> print(f"{fit.E:.0f} Pa, nu = {fit.nu:.3f}")
    200000 Pa, nu = 0.400
    """
    if not cuboids:
        raise InvalidInputError("calibration needs at least one cuboid measurement")
    axial = np.array([abs(c.axial_strain) for c in cuboids])
    E, e_res = fit_through_origin(axial, np.array([c.stress for c in cuboids]))
    pairs = [(-c.axial_strain, -t) for c in cuboids for t in c.transverse_strains]
    a = np.array([p[0] for p in pairs])
    nu, n_res = fit_through_origin(a, np.array([p[1] for p in pairs]))
    nu = -nu
    if not -1.0 < nu <= 0.5:
        raise InvalidInputError(
            f"fitted Poisson's ratio {nu:.4g} is outside (-1, 0.5]: check the "
            "signs of dl (< 0) and dw, dh (> 0 when bulging)"
        )
    return Elasticity(E, nu, tuple((c.young(), c.poisson()) for c in cuboids), e_res, n_res)


@dataclass(frozen=True)
class Friction:
    """mu = tan(alpha0) from the critical slope angle.

    Attributes
    ----------
    mu : float
    alpha0 : float
        Critical angle, rad (midpoint of the bracket when estimated from trials).
    bracket : (float, float)
        Largest angle that held and smallest that slid, rad (both alpha0 for a direct angle).
    mu_range : (float, float)
        tan of the bracket.
    """

    mu: float
    alpha0: float
    bracket: tuple[float, float]
    mu_range: tuple[float, float]

    def to_json(self) -> dict:
        """All fields, angles also in degrees."""
        return {
            "mu": self.mu,
            "alpha0": self.alpha0,
            "alpha0_deg": float(np.degrees(self.alpha0)),
            "bracket_deg": [float(np.degrees(b)) for b in self.bracket],
            "mu_range": list(self.mu_range),
        }


def friction_from_angle(alpha0: float) -> Friction:
    """Mu = tan(alpha0) for a critical slope angle ``alpha0`` in rad, in [0, pi/2)."""
    require_finite("slope angle", alpha0)
    if not 0 <= alpha0 < np.pi / 2:
        raise InvalidInputError(
            f"critical slope angle must be in [0, 90) deg, got {np.degrees(alpha0)} deg"
        )
    mu = float(np.tan(alpha0))
    return Friction(mu, float(alpha0), (float(alpha0), float(alpha0)), (mu, mu))


def friction_from_trials(trials: list[tuple[float, bool]]) -> Friction:
    """Mu from slope trials [(angle rad, slid)], e.g. the steps of the paper's bisection.

    The critical angle lies between the largest angle at which the sample held and the
    smallest at which it slid; alpha0 is their midpoint.

    Raises
    ------
    InvalidInputError
        If the trials are inconsistent (a held angle above a slid one) or one side is missing.
    """
    for angle, _ in trials:
        require_finite("slope trial angle", angle)
        if not 0 <= angle <= np.pi / 2:
            raise InvalidInputError(
                f"slope trial angles must be in [0, 90] deg, got {np.degrees(angle):.6g} deg"
            )
    held = [a for a, slid in trials if not slid]
    slid = [a for a, s in trials if s]
    if not held or not slid:
        raise InvalidInputError("slope trials need at least one angle that held and one that slid")
    lo, hi = max(held), min(slid)
    if lo > hi:
        raise InvalidInputError(
            f"inconsistent slope trials: held at {np.degrees(lo):.4g} deg but "
            f"slid at {np.degrees(hi):.4g} deg"
        )
    alpha0 = 0.5 * (lo + hi)
    return Friction(
        float(np.tan(alpha0)), alpha0, (lo, hi), (float(np.tan(lo)), float(np.tan(hi)))
    )


def bisect_slope(slides, tol: float = 1e-3) -> list[tuple[float, bool]]:
    """The paper's bisection on [0, pi/2] for the critical slope angle.

    ``slides(angle)`` reports whether the sample slides at ``angle`` (rad); returns the trials
    made until the bracket is narrower than ``tol`` rad.
    """
    lo, hi = 0.0, np.pi / 2
    trials = [(lo, bool(slides(lo))), (hi, bool(slides(hi)))]
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        slid = bool(slides(mid))
        trials.append((mid, slid))
        lo, hi = (lo, mid) if slid else (mid, hi)
    return trials
