# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Elementary functions that give the same floats on every x86-64 CPU, for mesher inputs.

numpy computes float64 ``sin``, ``cos``, ``power``, ``arctan2`` (and more) with Intel's SVML
on CPUs with AVX-512 and with the C library elsewhere; the two differ by up to a few units in
the last place (numpy issues 23523 and 23289). An outline feeds the mesher, and the mesher is
not continuous in its input: one unit in the last place on a third of an outline's samples
turned a 423-node mesh of a superellipse into a 433-node one. So a scene or a sweep would
mesh differently on two machines. The functions here call Python's :mod:`math` (the C
library) element by element: the same floats wherever the C library is the same, at about
0.1 us a value (an outline has a few thousand).

Examples
--------
>>> import math
>>> t = np.linspace(0.0, 2.0 * np.pi, 5)
>>> bool(np.array_equal(cos(t), [math.cos(v) for v in t]))
True
>>> power(np.array([0.25, 4.0]), 0.5).tolist()
[0.5, 2.0]
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["arctan2", "cos", "power", "sin"]

_COS = np.frompyfunc(math.cos, 1, 1)
_SIN = np.frompyfunc(math.sin, 1, 1)
_POW = np.frompyfunc(math.pow, 2, 1)
_ATAN2 = np.frompyfunc(math.atan2, 2, 1)


def _floats(values) -> np.ndarray:
    return np.asarray(values, dtype=float)


def cos(x) -> np.ndarray:
    """Cosine of ``x`` (rad), element-wise, float64."""
    return _floats(_COS(_floats(x)))


def sin(x) -> np.ndarray:
    """Sine of ``x`` (rad), element-wise, float64."""
    return _floats(_SIN(_floats(x)))


def power(base, exponent) -> np.ndarray:
    """``base ** exponent`` element-wise (broadcast), float64.

    ``base`` must be >= 0 where the exponent is not an integer.
    """
    return _floats(_POW(_floats(base), _floats(exponent)))


def arctan2(y, x) -> np.ndarray:
    """Angle of (x, y) in (-pi, pi], rad, element-wise (broadcast), float64."""
    return _floats(_ATAN2(_floats(y), _floats(x)))
