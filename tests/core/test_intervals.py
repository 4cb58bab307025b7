"""Interval counts that floating-point round-off cannot change."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from searchtrack.core.intervals import interval_count


def test_round_off_in_the_division_adds_no_interval() -> None:
    """(89.9 − 49.9) / 10 is 4.000000000000001 in floating point: still 4 intervals."""
    assert (89.9 - 49.9) / 10 > 4
    assert interval_count(89.9 - 49.9, 10.0) == 4


@pytest.mark.parametrize("seed", range(5))
def test_matches_exact_decimal_arithmetic(seed: int) -> None:
    """On one-decimal numbers the count is ⌈length / step⌉ computed exactly."""
    rng = np.random.default_rng(seed)
    for _ in range(400):
        lo = round(float(rng.uniform(-500, 500)), 1)
        hi = round(lo + float(rng.uniform(0.1, 300)), 1)
        step = round(float(rng.choice([0.1, 0.3, 2.5, 7.5, 10.0, 12.2])), 1)
        exact = math.ceil((Fraction(str(hi)) - Fraction(str(lo))) / Fraction(str(step)))
        assert interval_count(hi - lo, step) == max(1, exact), (lo, hi, step)


def test_at_least_one_interval() -> None:
    """A length shorter than a step is one interval."""
    assert interval_count(0.5, 10.0) == 1
