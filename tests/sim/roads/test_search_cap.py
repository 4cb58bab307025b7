"""The ideal-sweep cap on a mission's MOC: the densest-road curve, the find times and the
expected MOC, each against an independent computation."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import grid_network
from searchtrack.sim.roads.search_cap import densest_road_curve, find_times, ideal_sweep_moc


def test_the_curve_takes_the_densest_squares_first() -> None:
    """With one placement, the curve is the cumulative sum of the per-square road fractions in
    decreasing order (squares counted by looping over the edges), from 0 to 1, one square's
    area per breakpoint; more placements never lower it."""
    net = grid_network(5, 7, 60.0, 20.0)
    side = 75.0
    area, covered = densest_road_curve(net, side, offsets=1)
    lo = net.coords.min(axis=0)
    per_square: dict[tuple[int, int], float] = {}
    for (a, b), length in zip(net.edges, net.lengths_m, strict=True):
        x, y = (net.coords[a] + net.coords[b]) / 2.0
        key = (math.floor((x - lo[0]) / side), math.floor((y - lo[1]) / side))
        per_square[key] = per_square.get(key, 0.0) + length / net.total_length_m
    expect = np.concatenate([[0.0], np.cumsum(sorted(per_square.values(), reverse=True))])
    np.testing.assert_allclose(covered, np.minimum(expect, 1.0), atol=1e-12)
    np.testing.assert_allclose(area, np.arange(expect.size) * side**2)
    assert covered[-1] == pytest.approx(1.0)
    area4, covered4 = densest_road_curve(net, side, offsets=4)
    at = np.linspace(0.0, area[-1], 50)
    assert np.all(np.interp(at, area4, covered4) >= np.interp(at, area, covered) - 1e-12)


@pytest.mark.parametrize("hold", [False, True])
def test_find_times_match_a_stepped_sweep(hold: bool) -> None:
    """Each target is found when the swept area, grown in 1 ms steps by the UAVs still
    searching, first reaches it."""
    rng = np.random.default_rng(3)
    uavs, start, rate, dt = 3, 50.0, 20.0, 1e-3
    at = np.sort(rng.uniform(0.0, 4000.0, (6, 2)), axis=1)
    got = find_times(at, uavs=uavs, start_m2=start, rate_m2_s=rate, hold=hold)
    for row, times in zip(at, got, strict=True):
        swept, t = start, 0.0
        found: list[float] = []
        while len(found) < row.size:
            while len(found) < row.size and swept >= row[len(found)]:
                found.append(t)
            swept += (uavs - (len(found) if hold else 0)) * rate * dt
            t += dt
        np.testing.assert_allclose(times, found, atol=5 * dt)


def test_a_fleet_holding_each_find_never_finds_more_targets_than_uavs() -> None:
    """One UAV and two targets: the second is never found when the first is held."""
    times = find_times(np.array([[10.0, 20.0]]), uavs=1, start_m2=0.0, rate_m2_s=1.0,
                       hold=True)
    assert times[0, 0] == pytest.approx(10.0)
    assert times[0, 1] == math.inf


def test_one_target_moc_is_the_mean_coverage() -> None:
    """For one target, P(found by t) is the road fraction covered by t, so the expected MOC
    equals the coverage curve's mean over the run; holding changes nothing for one target;
    more targets held by the only searcher lower it; an instant sweep finds all at once."""
    net = grid_network(6, 6, 100.0, 25.0)
    kw: dict[str, Any] = {"footprint_radius_m": 30.0, "speed_mps": 2.0, "duration_s": 200.0,
                          "samples": 400_000}
    moc, covered = ideal_sweep_moc(net, uavs=2, targets=1, hold=True, **kw)
    assert covered.shape == (201,)
    assert np.all(np.diff(covered) >= 0.0) and covered[-1] <= 1.0
    assert moc == pytest.approx(float(np.mean(covered[1:] + covered[:-1]) / 2.0), abs=3e-3)
    free, _ = ideal_sweep_moc(net, uavs=2, targets=1, hold=False, **kw)
    assert free == pytest.approx(moc, abs=3e-3)
    held_two, _ = ideal_sweep_moc(net, uavs=1, targets=2, hold=True, **kw)
    free_two, _ = ideal_sweep_moc(net, uavs=1, targets=2, hold=False, **kw)
    assert held_two < free_two and held_two <= 0.5
    fast, _ = ideal_sweep_moc(net, uavs=1, targets=3, footprint_radius_m=30.0,
                              speed_mps=1e6, duration_s=200.0, hold=False)
    assert fast > 0.99


@pytest.mark.parametrize(("change", "field"), [
    ({"uavs": 0}, "uavs"),
    ({"targets": 1.5}, "targets"),
    ({"footprint_radius_m": 0.0}, "footprint_radius_m"),
    ({"speed_mps": -1.0}, "speed_mps"),
    ({"duration_s": math.nan}, "duration_s"),
    ({"hold": 1}, "hold"),
    ({"offsets": 0}, "offsets"),
    ({"samples": 0}, "samples"),
    ({"seed": -1}, "seed"),
])
def test_bad_input_is_named(change: dict[str, object], field: str) -> None:
    """Every argument is checked and a bad one named."""
    kw: dict[str, Any] = {"uavs": 2, "targets": 2, "footprint_radius_m": 30.0,
                          "speed_mps": 10.0, "duration_s": 60.0, "samples": 10}
    kw.update(change)
    with pytest.raises(InvalidInputError) as info:
        ideal_sweep_moc(grid_network(2, 2, 100.0, 50.0), **kw)
    assert info.value.field == field


def test_the_curve_needs_a_road_network() -> None:
    """Anything but a road network is refused by name."""
    with pytest.raises(InvalidInputError) as info:
        densest_road_curve(np.zeros((3, 2)), 10.0)  # type: ignore[arg-type]
    assert info.value.field == "network"
