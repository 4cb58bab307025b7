"""Fleet sizing (paper 000, §5.4): 10 targets on the 3 × 3 map with a 16 m² requirement need
3 UAVs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import grid_network
from searchtrack.plan.fleet import BoundConfig, BoundMap, fleet_size

from .conftest import grid_3x3


@pytest.mark.parametrize(("growth", "diagonal"), [("paper", True), ("paper", False),
                                                  ("code", True), ("code", False)])
def test_ten_targets_need_three_uavs(growth: str, diagonal: bool) -> None:
    """σ² ≤ 16 m² means B_L ≤ 2.805 nats, first met by Q = 3 in every variant."""
    config = BoundConfig(10, growth=growth, include_diagonal=diagonal)  # type: ignore[arg-type]
    sizing = fleet_size(BoundMap.from_network(grid_3x3(), config), config, max_variance_m2=16.0)
    assert sizing.required_entropy == pytest.approx(2.805, abs=1e-3)
    assert sizing.uavs == 3
    assert [o.meets for o in sizing.options[:3]] == [False, False, True]
    bounds = [o.bound.bound for o in sizing.options]
    assert np.all(np.diff(bounds) < 0)                     # B_L falls with the fleet size
    assert sizing.options[2].variance_m2 <= 16.0 < sizing.options[1].variance_m2


def test_entropy_requirement_and_no_answer() -> None:
    """An entropy requirement works directly; too small a fleet cap gives no answer."""
    config = BoundConfig(10)
    bound_map = BoundMap.from_network(grid_3x3(), config)
    assert fleet_size(bound_map, config, max_entropy=2.805).uavs == 3
    capped = fleet_size(bound_map, config, max_variance_m2=16.0, max_uavs=2)
    assert capped.uavs is None and len(capped.options) == 2


def test_fleet_list_stops_where_revisits_beat_a_step() -> None:
    """Fleets that would revisit faster than one step are not listed."""
    config = BoundConfig(2, uav_speed_mps=2000.0)
    bound_map = BoundMap.from_network(grid_network(2, 3, 100.0, 100.0), config)
    sizing = fleet_size(bound_map, config, max_variance_m2=100.0, max_uavs=10)
    assert 1 <= len(sizing.options) < 10
    fast = BoundConfig(2, uav_speed_mps=1e6)
    with pytest.raises(InvalidInputError, match="dt_s"):
        fleet_size(BoundMap.from_network(grid_3x3(), fast), fast, max_variance_m2=16.0)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({}, "max_variance_m2"),
    ({"max_variance_m2": 16.0, "max_entropy": 2.8}, "max_variance_m2"),
    ({"max_variance_m2": math.nan}, "max_variance_m2"),
    ({"max_variance_m2": -1.0}, "max_variance_m2"),
    ({"max_variance_m2": 0.1}, "max_variance_m2"),
    ({"max_entropy": math.inf}, "max_entropy"),
    ({"max_variance_m2": 16.0, "max_uavs": 0}, "max_uavs"),
])
def test_bad_requirements_name_the_field(kwargs: dict[str, float], name: str) -> None:
    """Neither or both requirements, NaN, negative, too fine and zero fleet caps are refused."""
    config = BoundConfig(10)
    bound_map = BoundMap.from_network(grid_3x3(), config)
    with pytest.raises(InvalidInputError, match=name):
        fleet_size(bound_map, config, **kwargs)  # type: ignore[arg-type]


def test_a_stop_request_keeps_the_fleet_sizes_done() -> None:
    """Ctrl-C between fleet sizes: the sizes evaluated so far (here none), no error."""
    from searchtrack.core.interrupt import clear_stop, request_stop

    config = BoundConfig(10)
    bound_map = BoundMap.from_network(grid_3x3(), config)
    request_stop()
    try:
        sizing = fleet_size(bound_map, config, max_variance_m2=16.0)
    finally:
        clear_stop()
    assert sizing.options == () and sizing.uavs is None
