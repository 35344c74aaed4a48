# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Where an extreme is reached, named the same on every machine.

A symmetric object squeezed symmetrically reaches its largest displacement at two mirror nodes
whose values agree to round-off (1.2e-16 relative on the shipped foam square), and a resistance
sweep its hardest push at a direction and its opposite (W*_F is even in the push): which of
the twins ``np.argmax`` returns then depends on the machine's arithmetic (SIMD width, BLAS
kernels). These functions return the first index whose value is within :data:`TIE` of the
extreme, so a reported node, element or direction does not change between machines.

>>> first_max([1.0, 3.0 * (1 + 1e-15), 3.0, 2.0]), first_min([2.0, 1.0, 1.0 - 1e-16])
(1, 1)
"""
from __future__ import annotations

import numpy as np

__all__ = ["TIE", "first_max", "first_min", "first_tied"]

TIE = 1e-12
"""Relative difference under which two values tie for an extreme: far above round-off (twins
differ by 1e-16-1e-15), far below any difference the mechanics resolves."""


def first_tied(values: np.ndarray, k: int) -> int:
    """Index of the first entry within :data:`TIE` (relative) below ``values[k]``, the largest
    entry of the flat array ``values`` (its ``np.argmax``, which a caller that needs the value
    has already found); ``k`` itself when that entry is a NaN or infinite.
    """
    top = values[k]
    if not np.isfinite(top):
        return int(k)
    return int(np.argmax(values >= top - TIE * abs(top)))  # the first True


def first_max(values) -> int:
    """Index of the first entry within :data:`TIE` (relative) of the largest; a NaN or an
    infinite largest entry is returned as ``np.argmax`` returns it (the first NaN wins).
    """
    v = np.asarray(values, float).reshape(-1)
    return first_tied(v, int(np.argmax(v)))


def first_min(values) -> int:
    """Index of the first entry within :data:`TIE` (relative) of the smallest (see
    :func:`first_max`).
    """
    return first_max(-np.asarray(values, float))
