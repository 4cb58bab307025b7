"""Means of Monte Carlo samples with their 95 % Student-t intervals (campaign reports and the
benchmark tables)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

from searchtrack.core.types import FloatArray


@dataclass(frozen=True)
class Estimate:
    """Mean of ``n`` samples with its standard deviation and 95 % t-interval half-width."""

    n: int
    mean: float
    std: float
    half_width: float

    def __str__(self) -> str:
        if self.n == 0:
            return "-"
        return f"{self.mean:.3g} ± {self.half_width:.2g}"


def estimate(values: Sequence[float]) -> Estimate:
    """Mean, s.d. and 95 % half-width of the finite ``values`` (NaN and None dropped)."""
    x = np.array([v for v in values if v is not None and math.isfinite(v)], dtype=float)
    if x.size == 0:
        return Estimate(0, math.nan, math.nan, math.nan)
    if x.size == 1:
        return Estimate(1, float(x[0]), 0.0, math.inf)
    sd = float(x.std(ddof=1))
    return Estimate(int(x.size), float(x.mean()), sd, float(t_half_width(sd, x.size)))


def t_half_width(sd: ArrayLike, n: int) -> FloatArray:
    """Half-width of the 95 % Student-t interval of a mean of ``n ≥ 2`` samples with standard
    deviation ``sd`` (scalar or array)."""
    return np.asarray(stats.t.ppf(0.975, n - 1) * np.asarray(sd) / math.sqrt(n))
