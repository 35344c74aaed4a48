# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Errors by meaning, and the warning of a poorly conditioned solve.

Every error the package raises on purpose is a :class:`SqueezeGraspError`, of one of four kinds
that say who has to act:

============================  ==========================================  ======  ==============
error                         meaning                                     exit    service code
============================  ==========================================  ======  ==============
:class:`InvalidInputError`    the caller's input is wrong; the message    2       INVALID_ARGUMENT
                              names the field and the allowed range
:class:`InfeasibleError`      a physical answer: no such grasp exists     1       NOT_FEASIBLE
:class:`NumericalError`       a solver failed; carries its residuals      3       NUMERICAL_FAILURE
:class:`InternalError`        a broken invariant (a bug)                  4       INTERNAL_ERROR
============================  ==========================================  ======  ==============

>>> err = NumericalError("Newton did not converge", residuals={"cone": 2.5e-3})
>>> str(err), err.residuals["cone"], isinstance(err, SqueezeGraspError)
('Newton did not converge (residuals: cone 0.0025)', 0.0025, True)
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = ["ConditioningWarning", "InfeasibleError", "InternalError", "InvalidInputError",
           "NumericalError", "QUATERNION_TOLERANCE", "SqueezeGraspError", "node_indices",
           "require_finite", "require_relative_depth", "unit_quaternion"]


class SqueezeGraspError(Exception):
    """Base of every error the package raises on purpose."""


class InvalidInputError(SqueezeGraspError, ValueError):
    """Invalid input to a computation; the message names the field and the allowed range."""


class InfeasibleError(SqueezeGraspError):
    """A well-formed request whose physical answer is "no" (e.g. no stable squeeze exists)."""


class NumericalError(SqueezeGraspError, ArithmeticError):
    """A solver failed (no convergence, a singular system, an inverted element).

    Parameters
    ----------
    message : str
        What failed.
    residuals : mapping of str to float, optional
        The solver's last residuals by name (dimensionless unless the name says otherwise);
        they are appended to the message.
    depth : float, optional
        Where a squeeze failed: its depth, m (the last point it had solved); the message then
        starts with it.
    relative_depth : float, optional
        The same depth over the initial contact distance, shown beside it.

    Attributes
    ----------
    reason : str
        ``message`` alone (without the depth and the residuals).

    >>> err = NumericalError("Newton did not converge", residuals={"cone": 2.5e-3})
    >>> str(err.located(0.0079, 0.079))
    'at depth 0.0079 m (relative depth 0.079): Newton did not converge (residuals: cone 0.0025)'
    """

    def __init__(self, message: str, *, residuals: Mapping[str, float] | None = None,
                 depth: float | None = None, relative_depth: float | None = None) -> None:
        self.reason = message
        self.residuals: dict[str, float] = {k: float(v) for k, v in (residuals or {}).items()}
        self.depth = None if depth is None else float(depth)
        self.relative_depth = None if relative_depth is None else float(relative_depth)
        if self.residuals:
            listed = ", ".join(f"{k} {v:.3g}" for k, v in self.residuals.items())
            message = f"{message} (residuals: {listed})"
        if self.depth is not None:
            relative = ("" if self.relative_depth is None
                        else f" (relative depth {self.relative_depth:.6g})")
            message = f"at depth {self.depth:.6g} m{relative}: {message}"
        super().__init__(message)

    def located(self, depth: float | None,
                relative_depth: float | None = None) -> NumericalError:
        """This error (its type, reason and residuals) at a squeeze's ``depth``, m, and
        ``relative_depth``: a new error whose message starts with them (a copy of this one
        where ``depth`` is None).
        """
        return type(self)(self.reason, residuals=self.residuals, depth=depth,
                          relative_depth=relative_depth)


class InternalError(SqueezeGraspError, RuntimeError):
    """A broken invariant: a bug to report, not something the caller can fix."""


class ConditioningWarning(RuntimeWarning):
    """A solve whose condition estimate passed the documented threshold; results may lose
    digits.
    """


def shown(value) -> str:
    """``value`` as a message shows it: plain numbers (``nan``, ``1e+308``, ``[0.1, nan]``),
    never a numpy repr such as ``np.float64(nan)``.
    """
    arr = np.asarray(value)
    if arr.dtype.kind in "fiub":
        return str(arr.tolist()) if arr.ndim else f"{arr.item():.6g}"
    return repr(value)


def require_finite(name: str, value) -> None:
    """Raise :class:`InvalidInputError` if ``value`` (scalar or array) is not numeric or has NaN
    or inf entries.

    >>> require_finite("slope angle", np.float64("nan"))
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: slope angle must be finite, got nan
    >>> require_finite("material.E", "1e5")
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: material.E must be a number or an \
array of numbers, got '1e5'
    """
    try:
        arr = np.asarray(value)
    except ValueError:  # a ragged sequence
        arr = None
    if arr is None or arr.dtype.kind not in "fiub":
        raise InvalidInputError(f"{name} must be a number or an array of numbers, got "
                                f"{value!r:.80}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(f"{name} must be finite, got {shown(value)}")


QUATERNION_TOLERANCE = 0.01
"""Largest distance of a quaternion's squared norm from 1 at which it is taken as a rotation
(and normalised): tf2's own (``QUATERNION_NORMALIZATION_TOLERANCE`` of its ``BufferCore``,
which ignores a transform beyond it), so what tf2 and ``geometry_msgs`` users send passes."""


def unit_quaternion(name: str, values) -> np.ndarray:
    """The quaternion ``values`` (x, y, z, w) normalised; :class:`InvalidInputError` naming
    ``name`` and the norm unless it is finite with its squared norm within
    :data:`QUATERNION_TOLERANCE` of 1 (a zero quaternion is no rotation).

    >>> unit_quaternion("pose.orientation", [0.0, 0.0, 0.7072, 0.7072]).round(6).tolist()
    [0.0, 0.0, 0.707107, 0.707107]
    >>> unit_quaternion("pose.orientation", [0.0, 0.0, 0.0, 0.0])
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: pose.orientation must be a unit \
quaternion (x, y, z, w): finite, its squared norm within 0.01 of 1 (as tf2 takes it), got \
[0.0, 0.0, 0.0, 0.0] of norm 0
    """
    q = np.asarray(values, float).reshape(4)
    norm = float(np.linalg.norm(q))
    if not abs(norm * norm - 1.0) < QUATERNION_TOLERANCE:  # also NaN
        raise InvalidInputError(f"{name} must be a unit quaternion (x, y, z, w): finite, its "
                                f"squared norm within {QUATERNION_TOLERANCE:g} of 1 (as tf2 "
                                f"takes it), got {shown(values)} of norm {norm:.6g}")
    return q / norm


def node_indices(name: str, values, n: int | None = None) -> np.ndarray:
    """``values`` as a flat int array of node indices; :class:`InvalidInputError` if any is not
    a whole number (a float index is not truncated to another node) or, with ``n`` (the mesh's
    node count), outside [0, n - 1].

    >>> node_indices("contacts", [3, 7.0]).tolist()
    [3, 7]
    >>> node_indices("contacts", [3, 7.5])
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: contacts must be whole node indices, \
got [3.0, 7.5]
    >>> node_indices("contacts", [3, 12], 10)
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: contacts must be node indices in \
[0, 9], got [3, 12]
    """
    arr = np.asarray(values)
    if not (arr.dtype.kind in "iu" or arr.dtype.kind == "f" and np.all(np.isfinite(arr))
            and np.all(arr == np.round(arr))):
        raise InvalidInputError(f"{name} must be whole node indices, got {shown(values)}")
    arr = arr.astype(int).reshape(-1)
    if n is not None and len(arr) and (arr.min() < 0 or arr.max() >= n):
        raise InvalidInputError(f"{name} must be node indices in [0, {n - 1}], got "
                                f"{shown(arr.tolist())}")
    return arr


FINGERS_MEET = "at 1 the fingers would meet"
"""Why a relative depth (finger approach / initial contact distance) must stay below 1, as
every error and every schema's range states it."""


def require_relative_depth(relative: float, depth: float | None = None) -> None:
    """Refuse a relative depth outside [0, 1): at 1 the fingers would meet. With ``depth``
    (rho, m), the relative depth is the one that depth gives and the message says so. Every
    verb, service and scene applies this one rule.

    >>> require_relative_depth(5.0)
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.mechanics.errors.InvalidInputError: relative depth must be in [0, 1) \
(at 1 the fingers would meet), got 5
    """
    require_finite("depth" if depth is not None else "relative depth",
                   relative if depth is None else depth)
    if depth is not None and depth < 0:
        raise InvalidInputError(f"depth must be >= 0 m, got {shown(depth)}")
    if not 0 <= relative < 1:
        if depth is None:
            raise InvalidInputError(f"relative depth must be in [0, 1) ({FINGERS_MEET}), "
                                    f"got {shown(relative)}")
        raise InvalidInputError(f"depth {depth:.6g} m is a relative depth of {relative:.6g}: it "
                                f"must be in [0, 1) ({FINGERS_MEET})")
