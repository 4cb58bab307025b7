"""Printing helpers shared by the benchmark scripts."""

from __future__ import annotations

import sys

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats


def table(header: list[str], rows: list[list[str]]) -> None:
    """Print an aligned, right-justified text table and flush."""
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    print("  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True)))
    print("  ".join("-" * w for w in widths))
    for r in rows:
        print("  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)))
    sys.stdout.flush()


def table_with_header(rows: list[list[str]]) -> None:
    """:func:`table` for rows whose first row is the header."""
    table(rows[0], rows[1:])


def interval(values: ArrayLike) -> tuple[float, float]:
    """Mean and half-width of its 95 % t-interval (nan for one value)."""
    v = np.asarray(values, dtype=float)
    if v.size < 2:
        return float(v.mean()), float("nan")
    return float(v.mean()), float(stats.t.ppf(0.975, v.size - 1) * v.std(ddof=1)
                                  / np.sqrt(v.size))
