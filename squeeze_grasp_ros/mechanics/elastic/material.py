# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Isotropic linear-elastic material under plane stress (paper Sec. 2.1, eq. 2)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel

E_RANGE = (1e-3, 1e13)
"""Young's moduli a :class:`Material` takes, Pa, inclusive: gels to diamond (the scene's range
too). Far beyond, E h leaves the floats' normal range: E = 1e-320 Pa (subnormal) gave
compliances of inf and NaN work and dissipation in an event-driven squeeze's result, and
E h = 1e310 N/m "reduced stiffness must be finite"."""

THICKNESS_RANGE = (1e-9, 1e3)
"""Out-of-plane thicknesses a :class:`Material` takes, m, inclusive: a nanometre (no plane-stress
continuum is thinner) to a kilometre. With E in :data:`E_RANGE`, E h stays in [1e-12, 1e16] N/m;
a thickness of 1e-320 m gave compliances of inf (with numpy overflow warnings)."""


@dataclass(frozen=True)
class Material:
    """Isotropic plane-stress material of a planar object.

    Parameters
    ----------
    E : float
        Young's modulus, Pa, in :data:`E_RANGE` ([1e-3, 1e13]).
    nu : float
        Poisson's ratio, dimensionless, in (-1, 0.5].
    thickness : float
        Out-of-plane thickness h, m, in :data:`THICKNESS_RANGE` ([1e-9, 1e3]). Forces, energies
        and stiffnesses scale with E*h.

    Examples
    --------
    >>> foam = Material(E=1e5, nu=0.3, thickness=0.01)
    >>> foam.force_scale
    1000.0
    >>> Material(E=1e5, nu=0.6, thickness=0.01)
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: material.nu must be in (-1, 0.5], got 0.6
    """

    E: float
    nu: float
    thickness: float

    def __post_init__(self) -> None:
        for name in ("E", "nu", "thickness"):
            require_finite(f"material.{name}", getattr(self, name))
        if not E_RANGE[0] <= self.E <= E_RANGE[1]:
            raise InvalidInputError(f"material.E must be in [{E_RANGE[0]:g}, {E_RANGE[1]:g}] Pa, "
                                    f"got {self.E}")
        if not -1.0 < self.nu <= 0.5:
            raise InvalidInputError(f"material.nu must be in (-1, 0.5], got {self.nu}")
        lo, hi = THICKNESS_RANGE
        if not lo <= self.thickness <= hi:
            raise InvalidInputError(f"material.thickness must be in [{lo:g}, {hi:g}] m, got "
                                    f"{self.thickness}")

    @property
    def force_scale(self) -> float:
        """E*h, N/m: the factor between the dimensionless and the SI stiffness."""
        return self.E * self.thickness

    def elasticity_matrix(self) -> np.ndarray:
        """Plane-stress elasticity matrix D (3x3, Pa), Voigt order (xx, yy, 2xy)."""
        return self.E * unit_elasticity_matrix(self.nu)


def unit_elasticity_matrix(nu: float) -> np.ndarray:
    """Plane-stress elasticity matrix divided by E (dimensionless), Voigt order (xx, yy, 2xy).

    Valid for nu = 0.5 too: plane stress stays well posed for incompressible sheets, since the
    out-of-plane strain is free (unlike plane strain, whose lambda diverges).
    """
    c = 1.0 / (1.0 - nu * nu)
    return c * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])


POISSON_RANGES: dict[str, tuple[float, float]] = {
    MaterialModel.LINEAR: (-0.9, 0.5),
    MaterialModel.COROTATIONAL: (-0.9, 0.5),
    MaterialModel.NEO_HOOKEAN: (-0.3, 0.4999),
}
"""Poisson's ratios each constitutive model represents in an event-driven squeeze, inclusive.

Linear and corotational: plane stress is well posed up to 0.5 (no volumetric locking); toward
-1 the shear modulus E / (2 (1 + nu)) outgrows the in-plane bulk modulus E / (2 (1 - nu)) by
(1 - nu) / (1 + nu) and the linear triangles lock in shear. Timoshenko's disk under diametral
loads (the perpendicular diameter change, a far-field quantity) was off by 4.8 %, 1.8 % and
0.6 % at 600, 1,500 and 4,800 nodes at nu = -0.9; by 37 %, 19 % and 5.8 % at -0.99, and by
60 % at -0.999 with 1,500 nodes; at -1 + 1e-8 the stiffness's condition passed 1e12.
Neo-Hookean (Lame lambda / mu = 2 nu / (1 - 2 nu)), measured on the foam square (E = 5e4 Pa,
mu = 0.4, 400 and 2,000 nodes; 2026-11-26, before the solver's loops got the bounds of
docs/reliability.md, "Squeezes with no equilibrium ahead", so the times of the failures are
upper bounds): 0.4999 (lambda / mu = 5,000) and 0.49995 squeezed to 12 % in
seconds, 0.49998 and 0.49999 failed after 42-48 s of substep halvings; below 0 lambda is
negative, the plane-stress thickness equation mu (l3^2 - 1) + lambda ln(J2 l3) = 0 loses
monotonicity at l3^2 = -nu / (1 - 2 nu), and the law stiffens at ever smaller strains (its
energy at a 2 % squeeze is 1 % from linear at -0.4, 12 % at -0.8): -0.2 squeezed to 50 % and
-0.3 to 30 %, -0.4 failed at 30 % after 72 s and -0.5 did not finish a 12 % squeeze in 300 s.
"""


def require_poisson_ratio(nu: float, model: str) -> None:
    """Refuse a Poisson's ratio outside :data:`POISSON_RANGES` for constitutive ``model``.

    >>> require_poisson_ratio(-0.5, "neo_hookean")
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: material.nu must be in [-0.3, \
0.4999] for the neo_hookean model, got -0.5: beyond, its solves fail or lose digits \
(docs/reliability.md)
    """
    lo, hi = POISSON_RANGES[MaterialModel(model)]
    if not lo <= nu <= hi:
        raise InvalidInputError(f"material.nu must be in [{lo:g}, {hi:g}] for the {model} "
                                f"model, got {nu:g}: beyond, its solves fail or lose digits "
                                "(docs/reliability.md)")
