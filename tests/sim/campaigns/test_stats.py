"""Means of Monte Carlo samples with 95 % t-intervals."""

from __future__ import annotations

import math

import pytest

from searchtrack.sim.campaigns.stats import Estimate, estimate

# Student t quantiles t_{0.975, ν} (tables): ν = 1: 12.706205, ν = 2: 4.302653.


def test_estimate_of_three_values_by_hand() -> None:
    """[1, 2, 3]: mean 2, s.d. 1, half-width t_{0.975,2}·1/√3 = 2.48414."""
    e = estimate([1.0, 2.0, 3.0])
    assert (e.n, e.mean, e.std) == (3, 2.0, 1.0)
    assert e.half_width == pytest.approx(4.302653 / math.sqrt(3), rel=1e-6)
    assert str(e) == "2 ± 2.5"


def test_estimate_drops_missing_values() -> None:
    """None, NaN and ±inf are dropped: [1, 3] gives s.d. √2 and half-width t_{0.975,1}."""
    e = estimate([1.0, None, math.nan, 3.0, math.inf, -math.inf])  # type: ignore[list-item]
    assert (e.n, e.mean) == (2, 2.0)
    assert e.std == pytest.approx(math.sqrt(2.0))
    assert e.half_width == pytest.approx(12.706205, rel=1e-6)


def test_estimate_of_no_or_one_value() -> None:
    """No value gives n = 0 and NaNs, printed "-"; one value has s.d. 0 and an infinite interval."""
    none = estimate([])
    assert none.n == 0 and math.isnan(none.mean) and str(none) == "-"
    assert estimate([None, math.nan]).n == 0  # type: ignore[list-item]
    assert estimate([5.0]) == Estimate(1, 5.0, 0.0, math.inf)


