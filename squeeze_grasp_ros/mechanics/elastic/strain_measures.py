# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Principal strains of deformation gradients in every :class:`StrainMeasure`.

For an element's deformation gradient F = I + H = R U (polar decomposition; U has the
principal stretches lambda_1 >= lambda_2), the principal strains of each measure are

==================  ==================================================================
``small``           eigenvalues of sym(H) (not a function of U: a rotation shows)
``biot``            lambda_i - 1 (nominal: change of length per reference length)
``log``             ln lambda_i
``green_lagrange``  (lambda_i^2 - 1) / 2, the eigenvalues e_i of (H + H^T + H^T H) / 2
==================  ==================================================================

The stretches are taken from the Green-Lagrange eigenvalues e_i, which are computed from H
without cancellation: lambda_i - 1 = 2 e_i / (1 + sqrt(1 + 2 e_i)) and ln lambda_i =
log1p(2 e_i) / 2 keep full relative accuracy at small strain, where all four measures agree
to first order.

>>> import numpy as np
>>> F = np.array([[[0.8, 0.0], [0.0, 1.0]]])  # 20 % uniaxial compression
>>> {str(m): round(float(principal_strains(F, m)[0, 1]), 6) for m in StrainMeasure}
{'small': -0.2, 'biot': -0.2, 'log': -0.223144, 'green_lagrange': -0.18}
"""
from __future__ import annotations

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.fem import principal_pair
from squeeze_grasp_ros.mechanics.elastic.fem import principal_strains as voigt_principal
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.ties import first_tied
from squeeze_grasp_ros.mechanics.vocabulary import StrainMeasure

__all__ = ["COMMON_STRAIN_MEASURE", "largest_pair_entry", "log_strain", "max_principal_strain",
           "max_principal_strains", "principal_strains"]

COMMON_STRAIN_MEASURE = StrainMeasure.BIOT
"""The measure in which fields of different material models are compared like for like (the
nominal strain: what a length change per reference length means, and frame indifferent)."""


def _small(H: np.ndarray) -> np.ndarray:
    """Principal small strains (t, 2) of displacement gradients H (t, 2, 2)."""
    return voigt_principal(np.column_stack([H[:, 0, 0], H[:, 1, 1], H[:, 0, 1] + H[:, 1, 0]]))


def _green_lagrange(H: np.ndarray) -> np.ndarray:
    """Principal Green-Lagrange strains (t, 2) of H: of (H + H^T + H^T H) / 2."""
    return voigt_principal(np.column_stack(_green_lagrange_voigt(
        H[:, 0, 0], H[:, 0, 1], H[:, 1, 0], H[:, 1, 1])))


def _green_lagrange_voigt(h00, h01, h10, h11) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Green-Lagrange strains (xx, yy, 2 xy) (engineering, Voigt) of H by its components."""
    # the three entries of H^T H that enter, summed over k in einsum's order (k = 0, then 1)
    return (h00 + 0.5 * (h00 * h00 + h10 * h10), h11 + 0.5 * (h01 * h01 + h11 * h11),
            h01 + h10 + (h00 * h01 + h10 * h11))


def _stretch_ratio(e: np.ndarray) -> np.ndarray:
    """2 e = lambda^2 - 1 of the Green-Lagrange strains ``e``, clipped at -1 (lambda^2 >= 0;
    round-off below it).
    """
    return np.maximum(2.0 * e, -1.0)


def _biot(two_e: np.ndarray) -> np.ndarray:
    """Biot strains lambda - 1 of :func:`_stretch_ratio` ``two_e``."""
    return two_e / (1.0 + np.sqrt(1.0 + two_e))


def log_strain(two_e: np.ndarray) -> np.ndarray:
    """Log strains ln lambda of :func:`_stretch_ratio` ``two_e``."""
    with np.errstate(divide="ignore"):
        return 0.5 * np.log1p(two_e)


def _of_stretch(e: np.ndarray, measure: StrainMeasure) -> np.ndarray:
    """Principal strains in a measure of the stretch from the Green-Lagrange ones ``e``."""
    if measure == StrainMeasure.GREEN_LAGRANGE:
        return e
    return (_biot if measure == StrainMeasure.BIOT else log_strain)(_stretch_ratio(e))


def principal_strains(F: np.ndarray, measure: StrainMeasure | str) -> np.ndarray:
    """Principal strains (t, 2), largest first, of deformation gradients ``F`` (t, 2, 2).

    Parameters
    ----------
    F : (t, 2, 2) ndarray
        Deformation gradients I + grad u (dimensionless).
    measure : StrainMeasure or str
        ``small``, ``biot``, ``log`` or ``green_lagrange``.

    Returns
    -------
    (t, 2) ndarray
        Dimensionless principal strains. An element collapsed to a line (a zero stretch) has
        a log strain of -inf; callers check finiteness (no element reaches it: squeezes end
        at ``element_inverted`` first).
    """
    try:
        measure = StrainMeasure(measure)
    except ValueError:
        raise InvalidInputError(f"strain measure must be one of {StrainMeasure.values()}, got "
                                f"{measure!r}") from None
    H = np.asarray(F, float) - np.eye(2)
    if measure == StrainMeasure.SMALL:
        return _small(H)
    return _of_stretch(_green_lagrange(H), measure)


def largest_pair_entry(pair: np.ndarray) -> tuple[float, int]:
    """(largest |entry| of ``pair`` (t, 2), its row): the largest max(|a|, |b|) (a NaN wins,
    as in argmax) and the first row where it is reached to
    :data:`~squeeze_grasp_ros.mechanics.ties.TIE` (of two mirror twins, the same on every
    machine).
    """
    magnitude = np.abs(pair).reshape(-1)
    k = int(magnitude.argmax())
    return float(magnitude[k]), first_tied(magnitude, k) // 2


def max_principal_strain(F: np.ndarray, measure: StrainMeasure | str) -> tuple[float, int]:
    """(largest max(|eps_1|, |eps_2|) over the elements, its element) in ``measure``."""
    return largest_pair_entry(principal_strains(F, measure))


def max_principal_strains(F: np.ndarray) -> dict[StrainMeasure, float]:
    """Largest absolute principal strain of the elements in every measure, by measure.

    One pass over the displacement gradients' four components, each a contiguous row: the
    small and Green-Lagrange principal pairs are :func:`principal_strains`' arithmetic term
    for term (:func:`_green_lagrange`, :func:`_small`), the three measures of the stretch
    share one stretch ratio, and each maximum is the largest absolute entry (the value of
    :func:`max_principal_strain`, without its element).
    """
    h00, h01, h10, h11 = (np.asarray(F, float) - np.eye(2)).reshape(-1, 4).T.copy()
    e = principal_pair(*_green_lagrange_voigt(h00, h01, h10, h11))
    two_e = _stretch_ratio(e)
    fields = {StrainMeasure.SMALL: principal_pair(h00, h11, h01 + h10),
              StrainMeasure.BIOT: _biot(two_e),
              StrainMeasure.LOG: log_strain(two_e), StrainMeasure.GREEN_LAGRANGE: e}
    return {m: float(np.abs(fields[m]).max()) for m in StrainMeasure}
