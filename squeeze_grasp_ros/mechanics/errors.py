# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Exceptions and warnings raised by the mechanics core."""


class MechanicsError(ValueError):
    """Invalid input to a mechanics computation; the message names the field and allowed range."""


class InfeasibleError(MechanicsError):
    """A well-formed request that the mechanics cannot satisfy (e.g. no stable squeeze exists)."""


class ConditioningWarning(RuntimeWarning):
    """A solve whose condition estimate passed the documented threshold; results may lose digits."""


def require_finite(name: str, value) -> None:
    """Raise :class:`MechanicsError` if ``value`` (scalar or array) has NaN or inf entries."""
    import numpy as np

    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise MechanicsError(f"{name} must be finite, got {value!r}")
