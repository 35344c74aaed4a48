# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner's error codes and how exceptions map onto them."""

from __future__ import annotations

from enum import IntEnum

from squeeze_grasp_ros.mechanics.errors import (
    InfeasibleError,
    InternalError,
    InvalidInputError,
    NumericalError,
    SqueezeGraspError,
)


class ErrorCode(IntEnum):
    """Error codes of every planner response (the constants of the .srv/.action files)."""

    OK = 0
    INVALID_ARGUMENT = 1
    UNKNOWN_OBJECT = 2
    NOT_FEASIBLE = 3
    INTERNAL_ERROR = 4
    CANCELLED = 5
    BUSY = 6
    NUMERICAL_FAILURE = 7


class PlannerError(Exception):
    """A request the planner refuses; ``code`` says why in one word, the message in full."""

    def __init__(self, code: ErrorCode, message: str) -> None:
        super().__init__(message)
        self.code = code


class Cancelled(PlannerError):
    """The client cancelled the goal, or the node is shutting down."""

    def __init__(self, message: str = "cancelled") -> None:
        super().__init__(ErrorCode.CANCELLED, message)


def invalid(message: str) -> PlannerError:
    """A :class:`PlannerError` with code INVALID_ARGUMENT."""
    return PlannerError(ErrorCode.INVALID_ARGUMENT, message)


ERROR_CODES: dict[type[SqueezeGraspError], ErrorCode] = {
    InvalidInputError: ErrorCode.INVALID_ARGUMENT,
    InfeasibleError: ErrorCode.NOT_FEASIBLE,
    NumericalError: ErrorCode.NUMERICAL_FAILURE,
    InternalError: ErrorCode.INTERNAL_ERROR,
}
"""The service error code of each error kind."""


def classify(exc: Exception) -> tuple[ErrorCode, str]:
    """The error code and message of a failed request.

    Parameters
    ----------
    exc : Exception
        What the computation raised.

    Returns
    -------
    (ErrorCode, str)
        :class:`PlannerError` keeps its code; the error kinds of
        :mod:`squeeze_grasp_ros.mechanics.errors` map to INVALID_ARGUMENT, NOT_FEASIBLE,
        NUMERICAL_FAILURE and INTERNAL_ERROR; anything else is INTERNAL_ERROR too (a bug: its
        type is named in the message).
    """
    if isinstance(exc, PlannerError):
        return exc.code, str(exc)
    for kind, code in ERROR_CODES.items():
        if isinstance(exc, kind):
            return code, str(exc)
    return ErrorCode.INTERNAL_ERROR, f"internal error ({type(exc).__name__}): {exc}"
