# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Benchmark tables, timing and Markdown rendering."""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Sequence


@dataclass(frozen=True)
class Table:
    """One benchmark table.

    Attributes
    ----------
    title : str
    columns : sequence of str
        Column headers, with units.
    rows : list of sequence
        Cell values (numbers are formatted with 4 significant digits).
    notes : str
        What was measured and how to read it (printed under the table).
    plots : tuple of str
        PNG files belonging to the table (relative to the report).
    """

    title: str
    columns: Sequence[str]
    rows: list
    notes: str = ""
    plots: tuple[str, ...] = field(default_factory=tuple)

    def markdown(self) -> str:
        """GitHub-flavoured Markdown of the table, notes and plots."""
        head = "| " + " | ".join(self.columns) + " |"
        sep = "|" + "|".join("---:" for _ in self.columns) + "|"
        body = ["| " + " | ".join(fmt(v) for v in row) + " |" for row in self.rows]
        parts = [f"### {self.title}", "", head, sep, *body]
        if self.notes:
            parts += ["", self.notes]
        parts += [f"\n![{p}]({p})" for p in self.plots]
        return "\n".join(parts) + "\n"


def fmt(value) -> str:
    """Format a cell: floats with 4 significant digits, everything else with str()."""
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def best_time(fn: Callable[[], object], repeat: int = 3, min_time: float = 0.05) -> float:
    """Best wall time (s) of ``fn`` over ``repeat`` rounds, each looping until ``min_time``."""
    best = float("inf")
    for _ in range(repeat):
        count, start = 0, time.perf_counter()
        while True:
            fn()
            count += 1
            elapsed = time.perf_counter() - start
            if elapsed >= min_time:
                break
        best = min(best, elapsed / count)
    return best


def timed(fn: Callable[[], object]) -> tuple[object, float]:
    """Run ``fn`` once and return ``(result, seconds)``."""
    start = time.perf_counter()
    result = fn()
    return result, time.perf_counter() - start
