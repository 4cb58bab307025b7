"""OPTW instance construction: validation errors name the field, builders convert times exactly."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.optw import OPTWInstance
from searchtrack.plan.optw.instance import euclidean_ticks


def _tiny(**changes: object) -> OPTWInstance:
    base: dict[str, object] = {
        "travel": [[0, 5, 7], [5, 0, 3], [7, 3, 0]],
        "service": [0, 1, 1],
        "profit": [0.0, 1.0, 2.0],
        "open": [0, 0, 0],
        "close": [100, 50, 50],
    }
    base.update(changes)
    return OPTWInstance(**base)  # type: ignore[arg-type]


def test_valid_instance_is_frozen_and_read_only() -> None:
    """A valid instance exposes read-only arrays and refuses attribute assignment."""
    inst = _tiny()
    assert inst.n == 3 and list(inst.customers) == [1, 2]
    with pytest.raises(ValueError):
        inst.travel[0, 1] = 3
    with pytest.raises(AttributeError):
        inst.start = 1  # type: ignore[misc]


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"travel": [[0, 1], [1, 0]]}, "service"),
        ({"travel": [[0, -1, 1], [1, 0, 1], [1, 1, 0]]}, "travel"),
        ({"travel": [[0, np.nan, 1], [1, 0, 1], [1, 1, 0]]}, "travel"),
        ({"profit": [0.0, -1.0, 2.0]}, "profit"),
        ({"profit": [0.0, np.inf, 2.0]}, "profit"),
        ({"close": [100, 50, -1]}, "close[2]"),
        ({"open": [-5, 0, 0]}, "open"),
        ({"service": [0, -1, 0]}, "service"),
        ({"start": 3}, "start"),
        ({"end": -1}, "end"),
        ({"vehicles": 0}, "vehicles"),
        ({"tmax": -4}, "tmax"),
        ({"service": [0, 1.5, 1]}, "service"),
    ],
)
def test_bad_input_names_the_field(changes: dict[str, object], field: str) -> None:
    """Each invalid field raises InvalidInputError naming that field."""
    with pytest.raises(InvalidInputError) as info:
        _tiny(**changes)
    assert info.value.field == field


def test_exact_truncation_matches_integer_arithmetic() -> None:
    """Truncated distances equal floor(10 * d) computed with exact integer square roots."""
    rng = np.random.default_rng(1)
    xy = np.round(rng.uniform(-100, 100, size=(60, 2)), 3)
    ticks = euclidean_ticks(xy, 2, "truncate")
    from math import isqrt

    q = np.round(xy * 1000).astype(int)
    for i in range(0, 60, 7):
        for j in range(0, 60, 5):
            d2 = int(((q[i] - q[j]) ** 2).sum()) * 100**2
            assert ticks[i, j] == isqrt(d2) // 1000


def test_from_travel_times_is_conservative() -> None:
    """Float travel times round up and windows round inward when converted to ticks."""
    inst = OPTWInstance.from_travel_times(
        [[0, 1.0004], [1.0004, 0]], [0, 1], open=[0, 0.0004], close=[5, 4.9996], tmax=5,
        time_scale=1000,
    )
    assert inst.travel[0, 1] == 1001
    assert inst.open[1] == 1 and inst.close[1] == 4999


def test_from_travel_times_needs_horizon() -> None:
    """Without windows the time budget tmax is required."""
    with pytest.raises(InvalidInputError, match="tmax"):
        OPTWInstance.from_travel_times([[0, 1], [1, 0]], [0, 1])


def test_open_end_and_budget() -> None:
    """An open end has no end vertex; tmax caps the finish time after departure."""
    inst = _tiny(end=None, tmax=40, open=[10, 0, 0])
    assert inst.end is None and list(inst.customers) == [1, 2]
    assert inst.latest_finish == 50
    assert inst.with_vehicles(3).vehicles == 3


def test_profit_step_is_the_gcd_of_integral_profits() -> None:
    """The step every plan's profit is a multiple of: the gcd, 1 for all zeros, 0 for fractions."""
    from searchtrack.plan.optw.instance import profit_step

    assert profit_step(np.array([0.0, 10.0, 30.0, 20.0, 0.0])) == 10
    assert profit_step(np.array([0.0, 6.0, 9.0])) == 3
    assert profit_step(np.array([0.0, 7.0, 9.0])) == 1
    assert profit_step(np.zeros(4)) == 1
    assert profit_step(np.array([10.0, 20.5])) == 0
