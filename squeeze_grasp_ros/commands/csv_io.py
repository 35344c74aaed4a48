# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Small CSV readers and writers for measured data (points, cuboids, slope trials).

Lines starting with ``#`` and blank lines are ignored; a first line that is not numeric is a
header naming the columns.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from squeeze_grasp_ros.inputs import InputError, read_text
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.outputs import write_atomically


def read_table(path: str | Path) -> tuple[list[str] | None, list[list[str]]]:
    """(header or None, rows of cells) of a CSV file (a regular file, read up to
    :data:`~squeeze_grasp_ros.inputs.MAX_FILE_BYTES`).
    """
    path = Path(path)
    try:
        text = read_text(path, what="CSV")
    except InputError as exc:
        raise InvalidInputError(str(exc)) from None
    rows = [[c.strip() for c in row] for row in csv.reader(io.StringIO(text, newline=""))
            if row and not row[0].lstrip().startswith("#") and any(c.strip() for c in row)]
    if not rows:
        raise InvalidInputError(f"{path}: no data rows")
    try:
        float(rows[0][0])
    except ValueError:
        return [c.lower() for c in rows[0]], rows[1:]
    return None, rows


def read_points(path: str | Path) -> np.ndarray:
    """Points (n, 2), m, from ``x,y`` rows: exactly two columns (a third, such as a z, is
    refused rather than dropped).
    """
    header, rows = read_table(path)
    if header is not None and header != ["x", "y"]:
        raise InvalidInputError(f"{path}: point columns must be x,y, got {','.join(header)}")
    for line, row in enumerate(rows, 1 if header is None else 2):
        if len(row) != 2:
            raise InvalidInputError(f"{path}: every row must be 'x,y' (metres); data row "
                                    f"{line} has {len(row)} cells")
    try:
        return np.array([[float(x), float(y)] for x, y in rows]).reshape(-1, 2)
    except ValueError:
        raise InvalidInputError(f"{path}: every row must be 'x,y' (metres)") from None


def read_columns(path: str | Path, required: tuple[str, ...],
                 optional: tuple[str, ...] = ()) -> list[dict[str, str]]:
    """Rows as {column: cell} of a CSV whose header has the ``required`` columns."""
    header, rows = read_table(path)
    if header is None:
        raise InvalidInputError(f"{path}: needs a header line with columns {', '.join(required)}")
    missing = [c for c in required if c not in header]
    unknown = [c for c in header if c not in required + optional]
    if missing or unknown:
        raise InvalidInputError(f"{path}: columns must be {', '.join(required)}"
                             f"{' [, ' + ', '.join(optional) + ']' if optional else ''}, got "
                             f"{', '.join(header)}")
    return [dict(zip(header, r)) for r in rows]


def write_points(path: str | Path, points: np.ndarray) -> str:
    """Write ``x,y`` rows (m) with a header, atomically; returns the path."""
    write_atomically(path, lambda tmp: np.savetxt(tmp, np.asarray(points, float), delimiter=",",
                                                  header="x,y", comments="", fmt="%.10g"),
                     "CSV")
    return str(path)
