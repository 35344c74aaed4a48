# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event location on cubic Hermite interpolants: the in-substep test for a double root and the
root bracketing with slopes, as properties against dense sampling and known roots.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from squeeze_grasp_ros.mechanics.squeeze.event_functions import (hermite_dips, hermite_root,
                                                                  locate_sign_change)

coefficient = st.floats(-4.0, 4.0)


@given(coefficient, coefficient, coefficient, st.floats(0.01, 2.0))
def test_a_cubic_is_its_own_interpolant_and_its_dips_are_found(c3, c2, c1, c0):
    """For a cubic p (its Hermite interpolant from the end values and slopes is p itself),
    positive at both ends, the dip test says whether p goes to or below zero inside, as dense
    sampling does (away from tangency), and the first root is p's first sign change.
    """
    def p(t):
        return ((c3 * t + c2) * t + c1) * t + c0

    def dp(t):
        return (3 * c3 * t + 2 * c2) * t + c1

    t = np.linspace(0.0, 1.0, 20001)
    low = p(t).min()
    assume(p(1.0) > 1e-3 and abs(low) > 1e-6)
    assert hermite_dips(0.0, 1.0, p(0.0), p(1.0), dp(0.0), dp(1.0)) == (low <= 0)
    root = hermite_root(0.0, 1.0, p(0.0), p(1.0), dp(0.0), dp(1.0))
    assert (root is None) == (low > 0)
    if root is not None:
        first = t[np.argmax(p(t) <= 0)]
        assert abs(root - first) < 1e-4 and abs(p(root)) < 1e-9


@given(st.floats(0.05, 0.95), st.floats(0.1, 5.0), st.floats(0.0, 6.0),
       st.sampled_from([1e-6, 1e-9, 1e-12]))
def test_with_slopes_the_bracket_holds_the_root_within_the_tolerance(root, k, w, tol):
    """g(s) = (root - s)(k + sin^2 ws) has one sign change, at ``root``: the bracket holds it,
    is no wider than tol, ends past it (the state at an event has the condition met) and takes
    at most 12 evaluations; regula falsi without slopes finds the same root with no fewer
    (less one).
    """
    def g(s):
        return (root - s) * (k + np.sin(w * s) ** 2)

    def dg(s):
        return -(k + np.sin(w * s) ** 2) + (root - s) * w * np.sin(2 * w * s)

    a, b, n = locate_sign_change(lambda s: (g(s), dg(s)), 0.0, 1.0, g(0.0), g(1.0), tol,
                                 slopes=(dg(0.0), dg(1.0)))
    assert a < root <= b + 1e-15 and b - a <= tol and n <= 12
    a0, b0, n0 = locate_sign_change(g, 0.0, 1.0, g(0.0), g(1.0), tol)
    assert a0 < root <= b0 + 1e-15 and n0 >= n - 1
