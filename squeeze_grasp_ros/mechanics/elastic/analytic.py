# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Closed-form elasticity solutions used as references for the solid FEM model."""
from __future__ import annotations

import numpy as np
from scipy.integrate import quad

from squeeze_grasp_ros.mechanics.errors import InvalidInputError


def disk_diameter_change_across(E: float, nu: float, thickness: float, radius: float,
                                load: float) -> float:
    """Increase (m) of the diameter perpendicular to two opposite diametral point loads.

    Plane-stress disk of ``radius`` m and ``thickness`` m under equal and opposite loads
    ``load`` N at the ends of a diameter (Hertz' solution, Timoshenko & Goodier Sec. 41):
    integrates eps_x = (sigma_x - nu sigma_y) / E along the perpendicular diameter. This is a
    far-field quantity: it converges under mesh refinement although the displacement under
    each point load does not.
    """
    if not (E > 0 and thickness > 0 and radius > 0 and -1 < nu <= 0.5):
        raise InvalidInputError("disk_diameter_change_across needs E, thickness, radius > 0 and "
                             "nu in (-1, 0.5]")
    D = 2.0 * radius
    c = 2.0 * load / (np.pi * thickness * D)

    def eps_x(x: float) -> float:
        q = D * D + 4.0 * x * x
        sx = c * ((D * D - 4.0 * x * x) / q) ** 2
        sy = -c * (4.0 * D**4 / q**2 - 1.0)
        return (sx - nu * sy) / E

    return quad(eps_x, -radius, radius, epsabs=0.0, epsrel=1e-12)[0]
