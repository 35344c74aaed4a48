# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The stress each material model reports, and its von Mises value.

- ``linear``: C : eps, the small-strain stress (:attr:`StressMeasure.SMALL_STRAIN`).
- ``corotational`` and ``neo_hookean``: the Cauchy stress sigma = P F^T / J of the finite
  deformation, J = det F lambda3 with the thickness stretch of plane stress
  (:func:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic.thickness_stretch`): force per
  deformed area (:attr:`StressMeasure.CAUCHY`). sigma33 = 0, so the in-plane 2x2 block is the
  whole tensor.

>>> import numpy as np
>>> F = np.array([[[1.1, 0.0], [0.0, 1.0]]])  # 10 % stretch, lateral contraction blocked
>>> s, m = element_stresses("neo_hookean", F, E=1.0, nu=0.0)
>>> str(m), round(float(s[0, 0, 0]), 6)  # nu = 0: mu = 1/2, sigma11 = (1.1^2 - 1) / (2 * 1.1)
('cauchy', 0.095455)
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.hyperelastic import stress_and_tangent, thickness_stretch
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel, StressMeasure

__all__ = ["element_stresses", "von_mises"]


def element_stresses(model: MaterialModel | str, F: np.ndarray, *, E: float,
                     nu: float) -> tuple[np.ndarray, StressMeasure]:
    """The stress (t, 2, 2), Pa, of each element in the model's stress measure.

    Parameters
    ----------
    model : MaterialModel or str
        ``linear``, ``corotational`` or ``neo_hookean``.
    F : (t, 2, 2) ndarray
        Deformation gradients I + grad u (det F > 0 for the nonlinear models).
    E : float
        Young's modulus, Pa.
    nu : float
        Poisson's ratio.

    Returns
    -------
    stress : (t, 2, 2) ndarray
        In-plane stress, Pa, symmetric to round-off (sigma33 = 0: plane stress).
    measure : StressMeasure
        ``model.stress_measure``: small_strain (linear) or cauchy.
    """
    model = MaterialModel(model)
    F = np.asarray(F, float)
    _, P, _ = stress_and_tangent(model, F, nu=nu, tangent=False)
    if model == MaterialModel.LINEAR:
        return E * P, model.stress_measure
    J = (F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]) * thickness_stretch(model, F, nu=nu)
    return E * (P @ np.swapaxes(F, 1, 2)) / J[:, None, None], model.stress_measure


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises stress (t,), Pa, of plane stresses (t, 2, 2), Pa (sigma33 = 0):
    sqrt(s11^2 - s11 s22 + s22^2 + 3 s12^2).

    >>> import numpy as np
    >>> von_mises(np.array([[[0.0, 1.0], [1.0, 0.0]]])).tolist() == [np.sqrt(3.0)]  # shear
    True
    """
    s11, s22, s12 = stress[:, 0, 0], stress[:, 1, 1], 0.5 * (stress[:, 0, 1] + stress[:, 1, 0])
    # scaled by each element's largest power of two first (exact), so that the squares neither
    # overflow to inf - inf = NaN (beyond 1e154 Pa) nor underflow to 0 (below 1e-154 Pa)
    _, k = np.frexp(np.maximum(np.maximum(np.abs(s11), np.abs(s22)), np.abs(s12)))
    s11, s22, s12 = np.ldexp(s11, -k), np.ldexp(s22, -k), np.ldexp(s12, -k)
    return np.ldexp(np.sqrt(s11 * s11 - s11 * s22 + s22 * s22 + 3.0 * s12 * s12), k)
