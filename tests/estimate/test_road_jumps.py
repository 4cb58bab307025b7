"""The robust road prior: exact integrals against quadrature and Monte Carlo, the proposals'
importance weights unbiased, the union resampled back to N, and an RBPF that finds a target
where none of its particles were."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate import road_filter_kernels as kern
from searchtrack.estimate.road_jumps import (
    TargetJumps,
    detection_prior_likelihood,
    detection_proposal,
    gaussian_integral_reference,
    join_draws,
    miss_prior_likelihood,
    near_detection,
    road_gaussian_integral,
)
from searchtrack.estimate.road_pf import RoadClouds
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.estimate.road_resampling import ResamplePolicy, SpeedRoughening
from searchtrack.models import RoadNetwork, grid_network
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads, RoadMotion

SENSOR = DiscSensor()


@pytest.fixture(scope="module")
def grid3() -> DirectedRoads:
    """The paper's 3 × 3 map of 100 m roads."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


@pytest.fixture(scope="module")
def slanted() -> DirectedRoads:
    """A small irregular map: slanted roads of unequal length."""
    coords = np.array([[0.0, 0.0], [70.0, 20.0], [130.0, -15.0], [60.0, 90.0]])
    edges = np.array([[0, 1], [1, 2], [1, 3], [0, 3]])
    lengths = np.linalg.norm(coords[edges[:, 1]] - coords[edges[:, 0]], axis=1)
    return DirectedRoads(RoadNetwork(coords, edges, lengths))


def _quadrature(roads: DirectedRoads, y: np.ndarray, sigma2: float) -> float:
    """The road integral by the midpoint rule on 2 cm steps."""
    total = 0.0
    for d in range(roads.n_edges):
        n = max(int(roads.length[d] / 0.02), 1)
        s = (np.arange(n) + 0.5) * roads.length[d] / n
        pts = roads.tail_xy[d] + s[:, None] * roads.step_xy[d]
        q = np.einsum("ij,ij->i", pts - y, pts - y)
        total += float(np.exp(-0.5 * q / sigma2).sum()) * roads.length[d] / n
    return total


@pytest.mark.parametrize("y", [[100.0, 100.0], [31.0, 102.5], [70.0, 20.0], [400.0, 400.0],
                               [65.0, 55.0]])
def test_road_gaussian_integral_is_the_quadrature(grid3: DirectedRoads, slanted: DirectedRoads,
                                                  y: list[float]) -> None:
    """On a junction, beside a road, on a slanted junction, far from every road, between roads:
    the closed form (kernel and NumPy reference) is the quadrature to 1e-6 (relative) or 1e-9
    (absolute), and the two agree to round-off."""
    for roads in (grid3, slanted):
        for sigma2 in (5.0, 60.0):
            exact = road_gaussian_integral(roads, np.array(y), sigma2)
            assert exact == pytest.approx(_quadrature(roads, np.array(y), sigma2),
                                          rel=1e-6, abs=1e-9)
            assert exact == pytest.approx(
                gaussian_integral_reference(roads, np.array(y), sigma2), rel=1e-12, abs=1e-300)


def test_prior_likelihoods_are_the_monte_carlo_means(grid3: DirectedRoads) -> None:
    """``∫ p(y|x) u`` and ``∫ p(z|x) u`` against the mean over 400 000 uniform road points."""
    rng = np.random.default_rng(1)
    edge, s = grid3.uniform(400_000, rng)
    pts = grid3.point(edge, s)
    sensor = DiscSensor(sigma2_m2=40.0, fov_radius_m=60.0)
    y, uav = np.array([104.0, 60.0]), np.array([90.0, 110.0])
    c = sensor.clutter_density(grid3)
    mc = sensor.likelihood(pts, y, c)
    exact = detection_prior_likelihood(grid3, sensor, y, c)
    assert exact == pytest.approx(mc.mean(), abs=4 * mc.std() / math.sqrt(mc.size))
    miss = sensor.miss_likelihood(pts, uav)
    exact = miss_prior_likelihood(grid3, sensor, uav)
    assert exact == pytest.approx(miss.mean(), abs=4 * miss.std() / math.sqrt(miss.size))


@pytest.mark.parametrize("y", [[100.0, 97.0], [150.0, 3.0], [42.0, 58.0], [900.0, 900.0]])
def test_detection_proposal_weights_are_unbiased(slanted: DirectedRoads,
                                                 y: list[float]) -> None:
    """``ℓ(x) u(x) / g(x)`` over draws of ``g`` averages to ``∫ ℓ u``: on a road, near one,
    between roads (the disc holds little road) and far away (no road in the disc: ``g = u``)."""
    yy = np.array(y)
    jumps = TargetJumps()
    c = SENSOR.clutter_density(slanted)
    exact = detection_prior_likelihood(slanted, SENSOR, yy, c)
    edge, s, ratio = near_detection(slanted, SENSOR, jumps, yy,
                                    np.random.default_rng(7).random((3, 200, 2000)))
    slanted.check_positions(edge, s)
    est = SENSOR.likelihood(slanted.point(edge, s), yy, c) * ratio
    per_batch = est.mean(axis=1)                       # 200 independent estimates
    assert per_batch.mean() == pytest.approx(
        exact, abs=4 * per_batch.std(ddof=1) / math.sqrt(per_batch.size) + 1e-15)


@pytest.mark.parametrize("y", [[100.0, 97.0], [150.0, 3.0], [42.0, 58.0], [900.0, 900.0]])
def test_the_kernel_draws_what_the_reference_draws(slanted: DirectedRoads,
                                                   y: list[float]) -> None:
    """The numba kernel of the detection jumps: the same positions as the NumPy reference from
    the same uniforms, and weights ``scale · ℓ(x) · u(x) / g(x)``."""
    yy = np.array(y)
    jumps = TargetJumps()
    c = SENSOR.clutter_density(slanted)
    uniforms = np.random.default_rng(11).random((3, 7, 300))
    edge, s, ratio = near_detection(slanted, SENSOR, jumps, yy, uniforms)
    s0, s1, l_disc, alpha, radius = detection_proposal(slanted, SENSOR, jumps, yy)
    assert radius == jumps.radius_sigmas * math.sqrt(SENSOR.sigma2_m2)
    k_edge, k_s, k_w = np.empty((7, 300), np.int64), np.empty((7, 300)), np.empty((7, 300))
    kern.detection_jumps(np.cumsum(slanted.length), slanted.length, slanted.total_length_m,
                         slanted.tail_xy, slanted.step_xy, s0, s1 - s0, np.cumsum(s1 - s0),
                         l_disc, alpha, radius * radius, yy[0], yy[1], SENSOR.detection_gain,
                         0.5 / SENSOR.sigma2_m2, SENSOR.p_fa * c, 0.25, uniforms, k_edge, k_s,
                         k_w)
    assert np.array_equal(k_edge, edge) and np.allclose(k_s, s, rtol=1e-12, atol=1e-9)
    lik = SENSOR.likelihood(slanted.point(edge, s), yy, c)
    assert np.allclose(k_w, 0.25 * lik * ratio, rtol=1e-9, atol=0.0)


def test_jumps_configuration() -> None:
    jumps = TargetJumps(rate_per_s=0.5)
    assert jumps.probability(0.0) == 0.0
    assert jumps.probability(2.0) == pytest.approx(1.0 - math.exp(-1.0))
    assert jumps.draws(500, detection=True) == 100 and jumps.draws(500, detection=False) == 10
    assert TargetJumps(miss_share=1e-6).draws(10, detection=False) == 1
    for bad in ({"rate_per_s": -1.0}, {"detection_share": 0.0}, {"global_share": 1.5},
                {"radius_sigmas": 0.0}):
        with pytest.raises(InvalidInputError):
            TargetJumps(**bad)  # type: ignore[arg-type]


def test_join_keeps_n_and_the_mass_split(grid3: DirectedRoads) -> None:
    """A row whose cloud counts mass 3 and whose draws count mass 1 keeps N particles, a quarter
    of them from the draws (systematic resampling: exactly, up to one)."""
    n = 400
    rng = np.random.default_rng(3)
    edge, s = grid3.uniform((2, n), rng)
    clouds = RoadClouds(grid3, edge, s, sensor=SENSOR, resample=ResamplePolicy())
    new_e = np.full((2, 50), 5)
    new_s = np.full((2, 50), 1.2345)
    clouds_before = clouds.s.copy()
    join_draws(clouds, np.array([0, 1]), np.array([3.0, 0.0]), new_e, new_s,
               np.full((2, 50), 1.0 / 50), rng)
    assert clouds.shape == (2, n) and np.allclose(clouds.w, 1.0 / n)
    from_draws = np.count_nonzero(clouds.s == 1.2345, axis=1)
    assert abs(from_draws[0] - n // 4) <= 1 and from_draws[1] == n   # row 1: the draws only
    assert np.isin(clouds.s[0][clouds.s[0] != 1.2345], clouds_before[0]).all()


def _rbpf(line: DirectedRoads, jumps: TargetJumps | None) -> RoadRBPF:
    """One target on a straight road, all its particles in [0, 100] m, standing still."""
    n = 500
    rng = np.random.default_rng(0)
    s = rng.random((1, n)) * 100.0
    edge = np.zeros((1, n), dtype=np.int64) + 2 * (s // 50.0).astype(np.int64)
    config = RBPFConfig(n_targets=1, n_histories=1, n_particles=n, motion=RoadMotion(0.0, 0.0),
                        jumps=jumps)
    return RoadRBPF.from_particles(line, config, edge, s % 50.0)


def test_an_rbpf_with_jumps_finds_a_target_its_particles_missed() -> None:
    """Detections at x = 310 m, far from every particle: paper 000's prior keeps the cloud where
    it was; with jumps the cloud moves to the detections within a few scans."""
    coords = np.column_stack([np.arange(9) * 50.0, np.zeros(9)])
    line = DirectedRoads(RoadNetwork(coords, np.column_stack([np.arange(8), np.arange(1, 9)]),
                                     np.full(8, 50.0)))
    far = np.array([[310.0, 0.0]])
    means = {}
    for name, jumps in (("paper", None), ("jumps", TargetJumps(rate_per_s=0.05))):
        f = _rbpf(line, jumps)
        rng = np.random.default_rng(5)
        for _ in range(5):
            f.predict(0.1, rng)
            f.update(far, np.array([300.0, 0.0]), rng)
        means[name] = float(f.map_positions()[0, 0])
    assert means["paper"] < 100.0
    assert abs(means["jumps"] - 310.0) < 5.0


def test_jump_rate_zero_is_the_paper_filter() -> None:
    """With ``λ = 0`` the filter draws nothing more: the same particles as without jumps."""
    coords = np.column_stack([np.arange(9) * 50.0, np.zeros(9)])
    line = DirectedRoads(RoadNetwork(coords, np.column_stack([np.arange(8), np.arange(1, 9)]),
                                     np.full(8, 50.0)))
    runs = []
    for jumps in (None, TargetJumps(rate_per_s=0.0)):
        f = _rbpf(line, jumps)
        rng = np.random.default_rng(2)
        for y in ([[40.0, 0.0]], [], [[45.0, 0.0]]):
            f.predict(0.1, rng)
            f.update(np.array(y).reshape(-1, 2), np.array([40.0, 0.0]), rng)
        runs.append(f.target_particles())
    for a, b in zip(runs[0], runs[1], strict=True):
        np.testing.assert_array_equal(a, b)


def test_at_rate_is_none_at_zero() -> None:
    assert TargetJumps.at_rate(0.0) is None
    assert TargetJumps.at_rate(0.3) == TargetJumps(rate_per_s=0.3)
    with pytest.raises(InvalidInputError):
        TargetJumps.at_rate(-0.1)


def test_a_join_is_not_roughened(grid3: DirectedRoads) -> None:
    """With roughening on, a join keeps every speed it copies: each output speed is one of the
    row's or of the draws' (the draws bring fresh speeds; the union is not blurred)."""
    n = 300
    rng = np.random.default_rng(5)
    edge, s = grid3.uniform((1, n), rng)
    motion = CourierRoadMotion(min_speed_mps=5.0, max_speed_mps=20.0)
    v = np.where(rng.random((1, n)) < 0.5, 12.0, 14.0)
    clouds = RoadClouds(grid3, edge, s, sensor=SENSOR, resample=ResamplePolicy(), speeds=motion,
                        v=v, roughening=SpeedRoughening())
    join_draws(clouds, np.array([0]), np.array([1.0]), np.full((1, 20), 5), np.full((1, 20), 1.0),
               np.full((1, 20), 0.05), rng)
    from_draws = clouds.s[0] == 1.0
    assert from_draws.any() and np.isin(clouds.v[0][~from_draws], [12.0, 14.0]).all()
