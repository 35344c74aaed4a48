# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Outlines do not depend on numpy's CPU-dispatched elementary functions.

numpy's float64 sin, cos, power and arctan2 run Intel's SVML on AVX-512 CPUs and the C library
elsewhere, a few units in the last place apart, and the mesher amplifies one unit into another
mesh (one unit on a third of a superellipse's samples gave 433 nodes instead of 423). Here
numpy's functions are replaced by ones one unit off (what another CPU may give): every shape
must give the same floats, and so the same mesh.
"""
from __future__ import annotations

import numpy as np
import pytest

from squeeze_grasp_ros.mechanics.elastic import portable_math, shapes

BUILDERS = {
    "ellipse": lambda: shapes.ellipse(0.05, 0.035),
    "disk": lambda: shapes.disk(0.04),
    "superellipse": lambda: shapes.superellipse(0.05, 0.04, 4.3),
    "fourier_blob": lambda: shapes.fourier_blob(0.05, cos=(0.1, 0.05), sin=(0.0, 0.08)),
    "annulus": lambda: shapes.annulus(0.05, 0.03),
    "polygon": lambda: shapes.polygon([[0, 0], [0.1, 0], [0.1, 0.05], [0.05, 0.08], [0, 0.05]]),
}


def _one_unit_off(ufunc):
    """``ufunc`` with every third result moved one unit in the last place."""
    def shifted(*args, **kwargs):
        out = np.array(ufunc(*args, **kwargs), dtype=float)
        flat = out.reshape(-1)
        flat[::3] = np.nextafter(flat[::3], np.inf)
        return out
    return shifted


@pytest.mark.parametrize("name", sorted(BUILDERS))
def test_outline_is_the_same_whatever_numpy_elementary_functions_give(monkeypatch, name):
    reference = BUILDERS[name]()
    for fn in ("cos", "sin", "power", "arctan2"):
        monkeypatch.setattr(np, fn, _one_unit_off(getattr(np, fn)))
    other = BUILDERS[name]()
    assert np.array_equal(other.points, reference.points)
    assert np.array_equal(other.corners, reference.corners)
    assert len(other.holes) == len(reference.holes)
    assert all(np.array_equal(a, b) for a, b in zip(other.holes, reference.holes))


def test_portable_functions_are_the_c_library_element_by_element():
    import math
    x = np.linspace(-7.0, 7.0, 1001)
    assert np.array_equal(portable_math.cos(x), [math.cos(v) for v in x])
    assert np.array_equal(portable_math.sin(x), [math.sin(v) for v in x])
    assert np.array_equal(portable_math.arctan2(x, 1.5 - x), [math.atan2(v, 1.5 - v) for v in x])
    base = np.abs(x)
    assert np.array_equal(portable_math.power(base, 0.4), [math.pow(v, 0.4) for v in base])
    assert portable_math.cos(np.zeros((2, 3))).shape == (2, 3)
