"""The numba kernels of the road filters against their NumPy references."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate import road_filter_kernels as kern
from searchtrack.estimate.road_pf import RoadClouds
from searchtrack.estimate.road_resampling import ResamplePolicy, systematic_indices
from searchtrack.models import grid_network
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads, RoadMotion
from searchtrack.models.road_synthetic import random_network


@pytest.fixture(scope="module")
def roads() -> DirectedRoads:
    """The paper's 3×3 map."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def _cloud(roads: DirectedRoads, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    edge, s = roads.uniform((6, 400), rng)
    w = rng.random((6, 400))
    return edge, s, w / w.sum(axis=1, keepdims=True)


def test_detection_likelihood_is_eq_10(roads: DirectedRoads) -> None:
    """Per-particle values equal DiscSensor.likelihood at G(x); sums are Σ w p."""
    edge, s, w = _cloud(roads, 0)
    sensor = DiscSensor()
    y = np.array([103.0, 60.0])
    density = sensor.clutter_density(roads)
    lik, sums = np.empty(edge.shape), np.empty(6)
    kern.detection_likelihood(edge, s, w, np.ascontiguousarray(roads.tail_xy),
                              np.ascontiguousarray(roads.step_xy), y[0], y[1],
                              sensor.detection_gain, 0.5 / sensor.sigma2_m2,
                              sensor.p_fa * density, lik, sums)
    ref = sensor.likelihood(roads.point(edge, s), y, density)
    np.testing.assert_allclose(lik, ref, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(sums, (w * ref).sum(axis=1), rtol=1e-12)
    w2 = w.copy()
    kern.weigh_rows(w2, lik, np.array([1, 4]))
    post = w[[1, 4]] * ref[[1, 4]]
    np.testing.assert_allclose(w2[[1, 4]], post / post.sum(axis=1, keepdims=True), rtol=1e-12)
    np.testing.assert_array_equal(w2[[0, 2, 3, 5]], w[[0, 2, 3, 5]])


def test_miss_update_is_eq_11(roads: DirectedRoads) -> None:
    """Weights follow DiscSensor.miss_likelihood; untouched rows are flagged and unchanged."""
    edge, s, w = _cloud(roads, 1)
    edge[5] = 0  # row 5 entirely on edge 0, far from the UAV at the centre
    s[5] = 10.0
    sensor = DiscSensor()
    uav = np.array([100.0, 100.0])
    rows = np.array([0, 2, 5])
    w2, sums, touched = w.copy(), np.empty(3), np.zeros(3, dtype=np.bool_)
    kern.miss_update(edge, s, w2, rows, np.ascontiguousarray(roads.tail_xy),
                     np.ascontiguousarray(roads.step_xy), uav[0], uav[1],
                     sensor.negative_radius_m ** 2, sensor.p_fn, sums, touched)
    ref = sensor.miss_likelihood(roads.point(edge, s), uav)
    post = w[rows] * ref[rows]
    np.testing.assert_allclose(sums, post.sum(axis=1), rtol=1e-12)
    np.testing.assert_array_equal(touched, [True, True, False])
    np.testing.assert_allclose(w2[rows[:2]], (post / post.sum(axis=1, keepdims=True))[:2],
                               rtol=1e-12)
    np.testing.assert_array_equal(w2[[1, 3, 4, 5]], w[[1, 3, 4, 5]])


def test_resample_rows_matches_systematic_indices(roads: DirectedRoads) -> None:
    """In-place resampling of some rows copies the particles (positions and speeds) the NumPy
    reference picks."""
    edge, s, w = _cloud(roads, 2)
    w = w ** 3
    v = np.random.default_rng(3).random(edge.shape) * 20.0
    rows, u = np.array([0, 3, 4]), np.array([0.2, 0.7, 0.0])
    e2, s2, v2, w2 = edge.copy(), s.copy(), v.copy(), w.copy()
    kern.resample_rows(e2, s2, v2, w2, rows, u)
    idx = systematic_indices(w[rows], u)
    for i, r in enumerate(rows):
        np.testing.assert_array_equal(e2[r], edge[r][idx[i]])
        np.testing.assert_array_equal(s2[r], s[r][idx[i]])
        np.testing.assert_array_equal(v2[r], v[r][idx[i]])
        np.testing.assert_allclose(w2[r], 1 / 400)
    for r in (1, 2, 5):
        np.testing.assert_array_equal(e2[r], edge[r])
        np.testing.assert_array_equal(w2[r], w[r])


def test_join_rows_is_systematic_resampling_of_the_union() -> None:
    """Each listed row becomes the low-variance resample of its particles (weighed by the
    row's mass) joined with its draws: the same copies as systematic_indices on the union;
    an unlisted row and a row whose union weighs nothing stay as they were."""
    rng = np.random.default_rng(4)
    n, k = 9, 4
    edge = rng.integers(0, 5, (3, n)).astype(np.int64)
    s = rng.random((3, n))
    w = rng.random((3, n))
    w /= w.sum(axis=1, keepdims=True)
    add_e = rng.integers(5, 9, (2, k)).astype(np.int64)
    add_s = rng.random((2, k)) + 10.0
    add_w = rng.random((2, k)) * 0.2
    v, add_v = rng.random((3, n)), rng.random((2, k)) + 5.0
    rows, mass = np.array([0, 2]), np.array([0.7, 0.0])
    u = np.array([0.3, 0.6])
    union_e = np.concatenate([edge[rows], add_e], axis=1)
    union_s = np.concatenate([s[rows], add_s], axis=1)
    union_v = np.concatenate([v[rows], add_v], axis=1)
    union_w = np.concatenate([w[rows] * mass[:, None], add_w], axis=1)
    before = (edge.copy(), s.copy(), w.copy())
    kern.join_rows(edge, s, v, w, rows, mass, add_e, add_s, add_v, add_w, u)
    for i, r in enumerate(rows):
        cum = np.cumsum(union_w[i]) / union_w[i].sum()
        idx = np.minimum(np.searchsorted(cum, (u[i] + np.arange(n)) / n, side="right"), n + k - 1)
        np.testing.assert_array_equal(edge[r], union_e[i, idx])
        np.testing.assert_array_equal(s[r], union_s[i, idx])
        np.testing.assert_array_equal(v[r], union_v[i, idx])
        np.testing.assert_allclose(w[r], 1.0 / n)
    assert np.all(s[2] >= 10.0)          # mass 0: only the draws survive
    np.testing.assert_array_equal(edge[1], before[0][1])
    np.testing.assert_array_equal(w[1], before[2][1])
    empty = np.zeros((1, k))
    kern.join_rows(edge, s, v, w, np.array([1]), np.array([0.0]), add_e[:1], add_s[:1],
                   add_v[:1], empty, np.array([0.5]))
    np.testing.assert_array_equal(s[1], before[1][1])


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
