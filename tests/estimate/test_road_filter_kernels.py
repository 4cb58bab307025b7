"""The numba kernels of the road filters against their NumPy references."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate import road_filter_kernels as kern
from searchtrack.estimate.road_pf import RoadClouds
from searchtrack.estimate.road_resampling import ResamplePolicy, systematic_indices
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads, RoadMotion
from searchtrack.models.road_synthetic import random_network

from .conftest import weighted_clouds


def test_detection_likelihood_is_eq_10(grid3: DirectedRoads) -> None:
    """Per-particle values equal DiscSensor.likelihood at G(x); sums are Σ w p."""
    edge, s, w = weighted_clouds(grid3, 0)
    sensor = DiscSensor()
    y = np.array([103.0, 60.0])
    density = sensor.clutter_density(grid3)
    lik, sums = np.empty(edge.shape), np.empty(6)
    full = np.full(6, 400, dtype=np.int64)
    kern.detection_likelihood(edge, s, w, full, np.ascontiguousarray(grid3.tail_xy),
                              np.ascontiguousarray(grid3.step_xy), y[0], y[1],
                              sensor.detection_gain, 0.5 / sensor.sigma2_m2,
                              sensor.p_fa * density, lik, sums)
    ref = sensor.likelihood(grid3.point(edge, s), y, density)
    np.testing.assert_allclose(lik, ref, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(sums, (w * ref).sum(axis=1), rtol=1e-12)
    w2 = w.copy()
    kern.weigh_rows(w2, lik, np.array([1, 4]), full)
    post = w[[1, 4]] * ref[[1, 4]]
    np.testing.assert_allclose(w2[[1, 4]], post / post.sum(axis=1, keepdims=True), rtol=1e-12)
    np.testing.assert_array_equal(w2[[0, 2, 3, 5]], w[[0, 2, 3, 5]])


def test_miss_update_is_eq_11(grid3: DirectedRoads) -> None:
    """Weights follow DiscSensor.miss_likelihood; untouched rows are flagged and unchanged."""
    edge, s, w = weighted_clouds(grid3, 1)
    edge[5] = 0  # row 5 entirely on edge 0, far from the UAV at the centre
    s[5] = 10.0
    sensor = DiscSensor()
    uav = np.array([100.0, 100.0])
    rows = np.array([0, 2, 5])
    w2, sums, touched = w.copy(), np.empty(3), np.zeros(3, dtype=np.bool_)
    kern.miss_update(edge, s, w2, np.full(6, 400, dtype=np.int64), rows,
                     np.ascontiguousarray(grid3.tail_xy),
                     np.ascontiguousarray(grid3.step_xy), uav[0], uav[1],
                     sensor.negative_radius_m ** 2, sensor.p_fn, sums, touched)
    ref = sensor.miss_likelihood(grid3.point(edge, s), uav)
    post = w[rows] * ref[rows]
    np.testing.assert_allclose(sums, post.sum(axis=1), rtol=1e-12)
    np.testing.assert_array_equal(touched, [True, True, False])
    np.testing.assert_allclose(w2[rows[:2]], (post / post.sum(axis=1, keepdims=True))[:2],
                               rtol=1e-12)
    np.testing.assert_array_equal(w2[[1, 3, 4, 5]], w[[1, 3, 4, 5]])


@pytest.fixture(scope="module")
def town() -> DirectedRoads:
    """A random planar road graph with edges of many lengths and directions."""
    return DirectedRoads(random_network(40, 900.0, spacing_m=150.0, seed=4))


@pytest.mark.parametrize("seed", range(6))
def test_disc_intervals_equal_the_numpy_form(town: DirectedRoads, seed: int) -> None:
    """Arcs inside a disc (some edges crossing it, some inside, some missing it) equal
    DirectedRoads.disc_intervals, and the returned length is their sum."""
    rng = np.random.default_rng(seed)
    centre = rng.uniform(-100.0, 1000.0, 2)
    radius = float(rng.uniform(0.0, 400.0))
    s0, s1 = np.empty(town.n_edges), np.empty(town.n_edges)
    inside = kern.disc_intervals(town.tail_xy, town.step_xy, town.length, centre[0], centre[1],
                                 radius, s0, s1)
    r0, r1 = town.disc_intervals(centre, radius)
    np.testing.assert_allclose(s0, r0, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(s1, r1, rtol=0.0, atol=1e-9)
    assert inside == pytest.approx(float((r1 - r0).sum()), abs=1e-6)


@pytest.mark.parametrize("seed", range(8))
def test_systematic_row_equals_systematic_indices(seed: int) -> None:
    """One row, zero weights and spikes included, gives the NumPy form's indices."""
    rng = np.random.default_rng(seed)
    w = rng.random(int(rng.integers(1, 40))) ** 4
    w[rng.random(w.size) < 0.3] = 0.0
    w[int(rng.integers(w.size))] += 1.0
    u = float(rng.random())
    np.testing.assert_array_equal(kern.systematic_row(w, u),
                                  systematic_indices(w[None], np.array([u]))[0])


def test_miss_jumps_are_uniform_draws_weighed_by_eq_11(town: DirectedRoads) -> None:
    """From the same uniforms: the positions of DirectedRoads.uniform and the weights
    scale · DiscSensor.miss_likelihood."""
    sensor = DiscSensor(fov_radius_m=250.0)
    uav = np.array([450.0, 400.0])
    uniforms = np.random.default_rng(2).random((2, 5, 300))
    edge, s, w = np.empty((5, 300), dtype=np.int64), np.empty((5, 300)), np.empty((5, 300))
    kern.miss_jumps(town.cum_length, town.length, town.tail_xy, town.step_xy, uav[0], uav[1],
                    sensor.negative_radius_m ** 2, sensor.p_fn, 0.01, uniforms, edge, s, w)

    class Replay:  # replays the uniforms as DirectedRoads.uniform draws them
        def __init__(self) -> None:
            self.k = 0

        def random(self, shape: tuple[int, int]) -> np.ndarray:
            self.k += 1
            return np.asarray(uniforms[self.k - 1], dtype=np.float64)

    ref_edge, ref_s = town.uniform((5, 300), Replay())  # type: ignore[arg-type]
    np.testing.assert_array_equal(edge, ref_edge)
    np.testing.assert_array_equal(s, ref_s)
    ref_w = 0.01 * sensor.miss_likelihood(town.point(ref_edge, ref_s), uav)
    assert 0 < np.count_nonzero(ref_w < 0.01) < ref_w.size  # some draws in view, some not
    np.testing.assert_allclose(w, ref_w, rtol=1e-12)


@pytest.mark.parametrize("dt", [0.1, 3.0, 40.0])
def test_cloud_motion_kernels_equal_road_motion_step(town: DirectedRoads, dt: float) -> None:
    """RoadClouds.predict (move + turn kernels, in place) gives RoadMotion.step's positions
    from the same seed, several node crossings per step included."""
    motion = RoadMotion(speed_mps=12.0, sigma_mps=5.0)
    edge, s = town.uniform((4, 250), np.random.default_rng(0))
    clouds = RoadClouds(town, edge, s, sensor=DiscSensor(), resample=ResamplePolicy())
    clouds.predict(motion, dt, np.random.default_rng(9))
    ref_edge, ref_s = motion.step(town, edge, s, dt, np.random.default_rng(9))
    np.testing.assert_array_equal(clouds.edge, ref_edge)
    np.testing.assert_allclose(clouds.s, ref_s, rtol=0.0, atol=1e-9)
    town.check_positions(clouds.edge, clouds.s)


@pytest.mark.parametrize("dt", [0.3, 5.0, 60.0])
def test_courier_kernels_equal_courier_road_motion_step(town: DirectedRoads, dt: float) -> None:
    """RoadClouds.predict with the drive-and-stop motion (courier_move + turn, in place) gives
    CourierRoadMotion.step's positions and speeds from the same seed: stops, drive-offs and
    node crossings included."""
    motion = CourierRoadMotion(min_speed_mps=4.0, max_speed_mps=15.0, mean_drive_s=8.0,
                               mean_stop_s=5.0)
    rng = np.random.default_rng(1)
    clouds = RoadClouds.uniform(town, 4, 250, rng, sensor=DiscSensor(),
                                resample=ResamplePolicy(), speeds=motion)
    edge, s, v = clouds.edge.copy(), clouds.s.copy(), clouds.v.copy()
    assert 0 < np.count_nonzero(v == 0.0) < v.size      # stopped and driving particles
    clouds.predict(motion, dt, np.random.default_rng(9))
    ref_edge, ref_s, ref_v = motion.step(town, edge, s, v, dt, np.random.default_rng(9))
    np.testing.assert_array_equal(clouds.edge, ref_edge)
    np.testing.assert_array_equal(clouds.v, ref_v)
    np.testing.assert_allclose(clouds.s, ref_s, rtol=0.0, atol=1e-9)
    assert np.any((v > 0.0) & (ref_v == 0.0)) and np.any((v == 0.0) & (ref_v > 0.0))
    town.check_positions(clouds.edge, clouds.s)


def test_kernels_skip_the_columns_beyond_each_rows_count(grid3: DirectedRoads) -> None:
    """Rows holding fewer particles than the capacity (weight 0 beyond): the likelihoods, the
    Bayes and miss updates and both motions read and change only each row's first ``count``
    particles, and give what the row's live particles give alone."""
    edge, s, w = weighted_clouds(grid3, 9)
    count = np.array([400, 150, 1, 400, 37, 200], dtype=np.int64)
    for r, c in enumerate(count):
        w[r, c:] = 0.0
        w[r] /= w[r].sum()
    sensor = DiscSensor()
    y, uav = np.array([103.0, 60.0]), np.array([100.0, 100.0])
    lik, sums = np.full(edge.shape, np.nan), np.empty(6)
    args = (np.ascontiguousarray(grid3.tail_xy), np.ascontiguousarray(grid3.step_xy))
    kern.detection_likelihood(edge, s, w, count, *args, y[0], y[1], sensor.detection_gain,
                              0.5 / sensor.sigma2_m2, 0.01, lik, sums)
    ref = sensor.likelihood(grid3.point(edge, s), y, 0.01 / sensor.p_fa)
    live = np.arange(400) < count[:, None]
    np.testing.assert_allclose(lik[live], ref[live], rtol=1e-12, atol=1e-300)
    np.testing.assert_array_equal(lik[~live], 0.0)
    np.testing.assert_allclose(sums, (w * ref).sum(axis=1), rtol=1e-12)
    w2 = w.copy()
    kern.weigh_rows(w2, lik, np.arange(6), count)
    np.testing.assert_array_equal(w2[~live], 0.0)
    np.testing.assert_allclose(w2.sum(axis=1), 1.0)
    w3, msum, touched = w.copy(), np.empty(6), np.zeros(6, dtype=np.bool_)
    kern.miss_update(edge, s, w3, count, np.arange(6), *args, uav[0], uav[1],
                     sensor.negative_radius_m ** 2, sensor.p_fn, msum, touched)
    post = w * sensor.miss_likelihood(grid3.point(edge, s), uav)
    np.testing.assert_allclose(msum, post.sum(axis=1), rtol=1e-12)
    np.testing.assert_array_equal(w3[~live], 0.0)
    e_flat, s_flat = edge.copy().reshape(-1), s.copy().reshape(-1)
    over = kern.move(e_flat, s_flat, np.ones(s_flat.size), 8.0, 0.0, 1.0, grid3.length, count)
    moved = (s_flat.reshape(6, 400) != s) | (e_flat.reshape(6, 400) != edge)
    np.testing.assert_array_equal(moved[~live], False)
    assert moved[live].mean() > 0.99
    assert np.all(live.reshape(-1)[over])
    v = np.full(s.size, 5.0)
    e_flat, s_flat = edge.copy().reshape(-1), s.copy().reshape(-1)
    kern.courier_move(e_flat, s_flat, v, np.ones(s.size), np.zeros(s.size), 0.0, 0.0, 5.0,
                      10.0, 1.0, grid3.length, count)
    np.testing.assert_array_equal(s_flat.reshape(6, 400)[~live], s[~live])
    np.testing.assert_array_equal(v.reshape(6, 400)[~live], 5.0)
