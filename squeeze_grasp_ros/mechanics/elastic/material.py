# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Isotropic linear-elastic material under plane stress (paper Sec. 2.1, eq. 2)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError, require_finite


@dataclass(frozen=True)
class Material:
    """Isotropic plane-stress material of a planar object.

    Parameters
    ----------
    E : float
        Young's modulus, Pa (> 0).
    nu : float
        Poisson's ratio, dimensionless, in (-1, 0.5].
    thickness : float
        Out-of-plane thickness h, m (> 0). Forces, energies and stiffnesses scale with E*h.

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
        if not self.E > 0:
            raise InvalidInputError(f"material.E must be > 0 Pa, got {self.E}")
        if not -1.0 < self.nu <= 0.5:
            raise InvalidInputError(f"material.nu must be in (-1, 0.5], got {self.nu}")
        if not self.thickness > 0:
            raise InvalidInputError(f"material.thickness must be > 0 m, got {self.thickness}")

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
