"""Simulated sensor output (thesis 001 §3.3, §4.3): LRT scans per node and per footprint,
position scans with detections, noise and Poisson clutter, and bad input named."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork
from searchtrack.models.lrt_sensor import SensorModel
from searchtrack.models.measurements import (
    FALSE_ALARM,
    LrtScan,
    lrt_measurements,
    position_measurements,
)


def test_resolution_cell_marks_nearby_nodes(grid: RoadNetwork) -> None:
    """With a resolution cell, every footprint node within ``cell_radius_m`` of a target is
    'present'; the footprint itself is unchanged."""
    sensor = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=60.0, cell_radius_m=20.0)
    target = grid.nearest_nodes([[100.0, 100.0]])
    scan = lrt_measurements(grid, [[100.0, 100.0]], target, sensor, np.random.default_rng(0))
    near = np.linalg.norm(grid.coords[scan.node] - grid.coords[target[0]], axis=1) <= 20.0
    np.testing.assert_array_equal(scan.target_present, near)
    assert near.sum() == 9  # the junction and two nodes along each of its four roads
    with pytest.raises(InvalidInputError, match="cell_radius_m"):
        SensorModel(pd=0.95, pf=0.10, footprint_radius_m=60.0, cell_radius_m=-1.0)


def test_lrt_measurements_statistics(grid: RoadNetwork) -> None:
    """Per node, ζ ~ N(m, 1) on target nodes and N(0, 1) on the other footprint nodes."""
    sensor = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=40.0, cell_radius_m=0.0)
    uavs = np.tile([100.0, 100.0], (1000, 1))
    targets = grid.nearest_nodes([[100.0, 100.0], [120.0, 100.0], [100.0, 70.0]])
    scan = lrt_measurements(grid, uavs, targets, sensor, np.random.default_rng(7))
    in_view = np.flatnonzero(np.linalg.norm(grid.coords - [100.0, 100.0], axis=1) <= 40.0)
    assert scan.zeta.size == 1000 * in_view.size
    np.testing.assert_array_equal(scan.target_present, np.isin(scan.node, targets))
    hit, miss = scan.zeta[scan.target_present], scan.zeta[~scan.target_present]
    assert hit.size == 3000
    assert hit.mean() == pytest.approx(sensor.sensitivity, abs=0.08)
    assert hit.var() == pytest.approx(1.0, abs=0.08)
    assert miss.mean() == pytest.approx(0.0, abs=0.03)
    assert miss.var() == pytest.approx(1.0, abs=0.03)
    llr = scan.log_likelihood_ratio(sensor)
    assert llr[scan.target_present].mean() == pytest.approx(sensor.sensitivity**2 / 2, rel=0.06)


def test_lrt_measurements_per_footprint_share_one_zeta(grid: RoadNetwork) -> None:
    """With per_node=False each UAV's nodes share one ζ, N(m, 1) if any target is in view."""
    sensor = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=30.0)
    uavs = np.array([[0.0, 0.0], [200.0, 200.0]] * 2000)
    targets = grid.nearest_nodes([[10.0, 0.0]])
    scan = lrt_measurements(grid, uavs, targets, sensor, np.random.default_rng(3), per_node=False)
    for j in (0, 1, 2):
        assert np.unique(scan.zeta[scan.uav == j]).size == 1
    per_uav = np.array([scan.zeta[np.flatnonzero(scan.uav == j)[0]] for j in range(4000)])
    seen = np.array([scan.target_present[scan.uav == j].all() for j in range(4000)])
    np.testing.assert_array_equal(seen, np.arange(4000) % 2 == 0)
    assert per_uav[seen].mean() == pytest.approx(sensor.sensitivity, abs=0.1)
    assert per_uav[~seen].mean() == pytest.approx(0.0, abs=0.1)


def test_lrt_measurements_are_seeded(grid: RoadNetwork) -> None:
    """The same seed gives the same scan."""
    sensor = SensorModel(pd=0.9, pf=0.1, footprint_radius_m=50.0)
    a, b = (lrt_measurements(grid, [[50.0, 50.0]], [0], sensor, np.random.default_rng(11))
            for _ in range(2))
    np.testing.assert_array_equal(a.zeta, b.zeta)


def test_position_noise_and_detection_rate() -> None:
    """A target in view is reported with probability Pd, offset by N(0, s²) on each axis."""
    sensor = SensorModel(pd=0.9, pf=0.05, footprint_radius_m=100.0, position_noise_m=10.0,
                         false_alarms_per_scan=0.0)
    truth = np.array([[30.0, -40.0], [500.0, 0.0]])  # the second is out of view
    scan = position_measurements(np.zeros((20000, 2)), truth, sensor, np.random.default_rng(5))
    assert set(scan.target.tolist()) == {0}
    assert scan.target.size / 20000 == pytest.approx(0.9, abs=0.01)
    err = scan.xy_m - truth[0]
    np.testing.assert_allclose(err.mean(axis=0), 0.0, atol=0.25)
    np.testing.assert_allclose(err.std(axis=0), 10.0, rtol=0.03)


def test_false_alarms_are_poisson_and_uniform_in_the_footprint() -> None:
    """Clutter counts per footprint have Poisson mean = variance; points fill the disc evenly."""
    sensor = SensorModel(pd=0.9, pf=0.05, footprint_radius_m=50.0, false_alarms_per_scan=2.5)
    uavs = np.column_stack([np.arange(20000) * 1000.0, np.zeros(20000)])
    scan = position_measurements(uavs, np.empty((0, 2)), sensor, np.random.default_rng(9))
    assert np.all(scan.target == FALSE_ALARM) and scan.n_false_alarms == scan.target.size
    counts = np.bincount(scan.uav, minlength=20000)
    assert counts.mean() == pytest.approx(2.5, abs=0.05)
    assert counts.var() == pytest.approx(2.5, rel=0.05)
    r2 = np.sum((scan.xy_m - uavs[scan.uav]) ** 2, axis=1)
    assert r2.max() <= 50.0**2
    assert r2.mean() == pytest.approx(50.0**2 / 2, rel=0.02)  # uniform disc: E r² = ρ²/2
    assert np.all(np.diff(scan.uav) >= 0)


def test_measurements_refuse_bad_input(grid: RoadNetwork) -> None:
    """NaN UAV positions, bad target nodes and a seed instead of a Generator are named."""
    sensor = SensorModel(pd=0.9, pf=0.1, footprint_radius_m=50.0)
    rng = np.random.default_rng(0)
    cases = [
        (lambda: lrt_measurements(grid, [[math.nan, 0.0]], [0], sensor, rng), "uav_xy_m"),
        (lambda: lrt_measurements(grid, [[0.0, 0.0]], [grid.n_nodes], sensor, rng),
         "target_nodes"),
        (lambda: lrt_measurements(grid, [[0.0, 0.0]], [0], sensor, 1), "rng"),  # type: ignore[arg-type]
        (lambda: position_measurements([[0.0, 0.0]], [[0.0, math.inf]], sensor, rng),
         "target_xy_m"),
        (lambda: position_measurements([0.0, 1.0, 2.0], [[0.0, 0.0]], sensor, rng), "uav_xy_m"),
    ]
    for call, field in cases:
        with pytest.raises(InvalidInputError) as err:
            call()
        assert err.value.field == field


def test_scan_increments_are_m_times_zeta_minus_half_m() -> None:
    """LrtScan.log_likelihood_ratio gives m(ζ − m/2) for each row (§3.3)."""
    sensor = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=50.0)
    m = sensor.sensitivity
    scan = LrtScan(uav=np.zeros(3, dtype=np.int64), node=np.arange(3),
                   zeta=np.array([0.0, m, -1.0]), target_present=np.zeros(3, dtype=bool))
    np.testing.assert_allclose(scan.log_likelihood_ratio(sensor),
                               [-m * m / 2, m * m / 2, -m * (1 + m / 2)], atol=1e-12)


def test_no_targets_means_nothing_present(grid: RoadNetwork) -> None:
    """Without targets every footprint node is measured and none is marked present."""
    sensor = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=25.0, cell_radius_m=20.0)
    for per_node in (True, False):
        scan = lrt_measurements(grid, [[0.0, 0.0]], np.empty(0, dtype=np.int64), sensor,
                                np.random.default_rng(1), per_node=per_node)
        assert scan.node.size == 5 and not scan.target_present.any()  # the corner and 2 × 2
