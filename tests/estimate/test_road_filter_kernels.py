"""The numba kernels of the road filters against their NumPy references."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate import road_filter_kernels as kern
from searchtrack.estimate.road_resampling import systematic_indices
from searchtrack.models import grid_network
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import DirectedRoads


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
    """In-place resampling of some rows copies the particles the NumPy reference picks."""
    edge, s, w = _cloud(roads, 2)
    w = w ** 3
    rows, u = np.array([0, 3, 4]), np.array([0.2, 0.7, 0.0])
    e2, s2, w2 = edge.copy(), s.copy(), w.copy()
    kern.resample_rows(e2, s2, w2, rows, u)
    idx = systematic_indices(w[rows], u)
    for i, r in enumerate(rows):
        np.testing.assert_array_equal(e2[r], edge[r][idx[i]])
        np.testing.assert_array_equal(s2[r], s[r][idx[i]])
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
    rows, mass = np.array([0, 2]), np.array([0.7, 0.0])
    u = np.array([0.3, 0.6])
    union_e = np.concatenate([edge[rows], add_e], axis=1)
    union_s = np.concatenate([s[rows], add_s], axis=1)
    union_w = np.concatenate([w[rows] * mass[:, None], add_w], axis=1)
    before = (edge.copy(), s.copy(), w.copy())
    kern.join_rows(edge, s, w, rows, mass, add_e, add_s, add_w, u)
    for i, r in enumerate(rows):
        cum = np.cumsum(union_w[i]) / union_w[i].sum()
        idx = np.minimum(np.searchsorted(cum, (u[i] + np.arange(n)) / n, side="right"), n + k - 1)
        np.testing.assert_array_equal(edge[r], union_e[i, idx])
        np.testing.assert_array_equal(s[r], union_s[i, idx])
        np.testing.assert_allclose(w[r], 1.0 / n)
    assert np.all(s[2] >= 10.0)          # mass 0: only the draws survive
    np.testing.assert_array_equal(edge[1], before[0][1])
    np.testing.assert_array_equal(w[1], before[2][1])
    empty = np.zeros((1, k))
    kern.join_rows(edge, s, w, np.array([1]), np.array([0.0]), add_e[:1], add_s[:1], empty,
                   np.array([0.5]))
    np.testing.assert_array_equal(s[1], before[1][1])
