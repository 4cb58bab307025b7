"""Rejuvenation near detections: the union's total weight is an unbiased estimate of the
regularised prior's predictive likelihood (against quadrature, with the kernel read from all
particles or from a systematic choice of them), the share β follows the cloud's particles near
the detection, a cloud localised elsewhere gives its draws no weight, an RBPF on a long road
localises a target between its particles, and a false alarm in a footprint the sensor has
emptied does not localise a diffuse cloud."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.road_births import (
    DetectionBirths,
    bandwidths,
    birth_draws,
    join_births,
)
from searchtrack.estimate.road_jumps import TargetJumps
from searchtrack.estimate.road_pf import RoadClouds
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.estimate.road_resampling import ResamplePolicy
from searchtrack.models import RoadNetwork
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads, RoadMotion
from searchtrack.models.road_synthetic import random_network

SENSOR = DiscSensor(fov_radius_m=60.0, sigma2_m2=25.0, p_fa=0.05, p_fn=0.1)


@pytest.fixture(scope="module")
def town() -> DirectedRoads:
    """A random planar road graph (edges of many lengths and directions)."""
    return DirectedRoads(random_network(30, 600.0, spacing_m=80.0, seed=2))


def _line(n: int = 41, step: float = 50.0) -> DirectedRoads:
    coords = np.column_stack([np.arange(n) * step, np.zeros(n)])
    edges = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    return DirectedRoads(RoadNetwork(coords, edges, np.full(n - 1, step)))


def _reference(clouds: RoadClouds, births: DetectionBirths, y: np.ndarray, density: float,
               k: int) -> np.ndarray:
    """``∫ p̃ ℓ`` of every cloud by the module's definition, the kernel part by the midpoint
    rule on 5 cm steps along the road inside the disc."""
    roads, sensor = clouds.roads, clouds.sensor
    radius = births.radius_sigmas * math.sqrt(sensor.sigma2_m2)
    s0, s1 = roads.disc_intervals(y, radius)
    pts = clouds.points()
    near = np.einsum("fnk,fnk->fn", pts - y, pts - y) <= radius * radius
    n_in = near.sum(axis=1)
    beta = np.where(n_in < math.ceil(births.full_share * near.shape[1]), k / (k + n_in), 0.0)
    lik = sensor.likelihood(pts, y, density)
    cloud = (clouds.w * lik * np.where(near, 1.0 - beta[:, None], 1.0)).sum(axis=1)
    band = bandwidths(clouds, births)
    out = cloud.copy()
    for d in np.flatnonzero(s1 > s0):
        n = max(int((s1[d] - s0[d]) / 0.05), 1)
        s = s0[d] + (np.arange(n) + 0.5) * (s1[d] - s0[d]) / n
        q = roads.tail_xy[d] + s[:, None] * roads.step_xy[d]
        ell = sensor.likelihood(q, y, density)
        for f in range(clouds.shape[0]):
            d2 = np.einsum("jnk,jnk->jn", q[:, None] - pts[f][None], q[:, None] - pts[f][None])
            kde = (clouds.w[f] * np.exp(-0.5 * d2 / band[f] ** 2)).sum(axis=1) / (
                math.sqrt(2.0 * math.pi) * band[f])
            out[f] += beta[f] * float((kde * ell).sum()) * (s1[d] - s0[d]) / n
    return out


@pytest.mark.parametrize("seed", range(3))
def test_the_union_weighs_the_regularised_predictive_likelihood(town: DirectedRoads,
                                                               seed: int) -> None:
    """The mean over draws of each cloud's total weight is ∫ p̃ ℓ (quadrature) for clouds that
    are diffuse, tight on the detection, tight elsewhere, and half on it and half elsewhere:
    with the capped bandwidth and the kernel read from every particle near the detection
    (seed 0), from 16 of them (seed 1), and with Silverman's bandwidth uncapped and a full
    share of 0.2 (seed 2)."""
    rng = np.random.default_rng(seed)
    births = (DetectionBirths(draw_share=0.2), DetectionBirths(draw_share=0.2, kernel_points=16),
              DetectionBirths(draw_share=0.2, full_share=0.2, max_bandwidth_sigmas=100.0))[seed]
    y = town.point(np.array([7]), np.array([0.4 * town.length[7]]))[0] + rng.normal(0, 3, 2)
    diffuse_e, diffuse_s = town.uniform(60, rng)
    e_near, s_near = town.nearest(y + rng.normal(0.0, 8.0, (60, 2)))
    e_far, s_far = town.nearest(town.point(np.array([40]), np.array([1.0]))
                                + rng.normal(0.0, 8.0, (60, 2)))
    half_e = np.concatenate([e_near[:30], e_far[30:]])
    half_s = np.concatenate([s_near[:30], s_far[30:]])
    clouds = RoadClouds(town, np.stack([diffuse_e, e_near, e_far, half_e]),
                        np.stack([diffuse_s, s_near, s_far, half_s]), rng.random((4, 60)) + 0.2,
                        sensor=SENSOR, resample=ResamplePolicy())
    density = SENSOR.clutter_density(town, y)
    k = births.draws(60)
    clouds.detection_sums(y, density)
    total = np.zeros(4)
    repeats = 2000
    for _ in range(repeats):
        draws = birth_draws(clouds, births, y, density, rng.random((3, 4, k)))
        total += draws.sums
    np.testing.assert_allclose(draws.bandwidth, bandwidths(clouds, births), rtol=1e-9)
    ref = _reference(clouds, births, y, density, k)
    np.testing.assert_allclose(total / repeats, ref, rtol=0.03)


def test_the_chosen_kernel_particles_estimate_the_kernel_without_bias(town: DirectedRoads) -> None:
    """With the draws held (the same first two rows of uniforms), the mean weight of each draw
    over systematic choices of 8 kernel particles is its weight with every particle read, for
    a cloud of 80 unevenly weighted particles within reach of the detection."""
    rng = np.random.default_rng(4)
    y = town.point(np.array([7]), np.array([0.4 * town.length[7]]))[0]
    e, s = town.nearest(y + rng.normal(0.0, 20.0, (1, 80, 2))[0])
    clouds = RoadClouds(town, e[None], s[None], rng.random((1, 80)) ** 3 + 1e-3,
                        sensor=SENSOR, resample=ResamplePolicy())
    density = SENSOR.clutter_density(town, y)
    clouds.detection_sums(y, density)
    uniforms = rng.random((3, 1, 6))
    every = birth_draws(clouds, DetectionBirths(draw_share=0.075, kernel_points=80), y, density,
                        uniforms)
    chosen = DetectionBirths(draw_share=0.075, kernel_points=8)
    repeats = 4000
    mean = np.zeros((1, 6))
    for _ in range(repeats):
        uniforms[2] = rng.random((1, 6))
        mean += birth_draws(clouds, chosen, y, density, uniforms).w / repeats
    assert np.all(every.w > 0.0)
    np.testing.assert_allclose(mean, every.w, rtol=0.02)


def test_beta_follows_the_particles_near_the_detection() -> None:
    """β = K / (K + n_D): the particles inside the disc keep 1 − β of their weight, the others
    all of it; with no road in the disc, or full_share of the particles in it, nothing is
    drawn."""
    line = _line()
    births = DetectionBirths(draw_share=0.25, full_share=1.0)
    e, s = line.nearest(np.array([[100.0, 0.0], [110.0, 0.0], [120.0, 0.0], [900.0, 0.0]]))
    clouds = RoadClouds(line, e[None], s[None], sensor=SENSOR, resample=ResamplePolicy())
    y = np.array([110.0, 0.0])                   # ρ = 25 m: the first three are inside
    clouds.detection_sums(y, SENSOR.clutter_density(line, y))
    draws = birth_draws(clouds, births, y, 1e-3, np.random.default_rng(0).random((3, 1, 1)))
    np.testing.assert_allclose(draws.keep, [[0.75, 0.75, 0.75, 1.0]])
    assert draws.w[0, 0] > 0.0
    off = np.array([110.0, 500.0])                # no road within ρ
    clouds.detection_sums(off, 1e-3)
    none = birth_draws(clouds, births, off, 1e-3, np.random.default_rng(0).random((3, 1, 1)))
    np.testing.assert_array_equal(none.keep, 1.0)
    assert none.w[0, 0] == 0.0
    clouds.detection_sums(y, 1e-3)
    full = birth_draws(clouds, DetectionBirths(draw_share=0.25, full_share=0.75), y, 1e-3,
                       np.random.default_rng(0).random((3, 1, 1)))
    np.testing.assert_array_equal(full.keep, 1.0)
    assert full.w[0, 0] == 0.0


def test_a_cloud_localised_elsewhere_gives_its_draws_no_weight() -> None:
    """The kernel estimate of a tight cloud 1 km away is nothing at the detection."""
    line = _line()
    e, s = line.nearest(np.column_stack([1500.0 + np.arange(50.0), np.zeros(50)]))
    clouds = RoadClouds(line, e[None], s[None], sensor=SENSOR, resample=ResamplePolicy())
    y = np.array([300.0, 0.0])
    clouds.detection_sums(y, 1e-3)
    draws = birth_draws(clouds, DetectionBirths(), y, 1e-3,
                        np.random.default_rng(1).random((3, 1, 5)))
    assert np.all(draws.w < 1e-200)


def test_join_keeps_n_particles_with_their_speeds() -> None:
    """The union is resampled back to N; with a speed state the draws get speeds from its
    stationary law."""
    line = _line()
    motion = CourierRoadMotion(min_speed_mps=5.0, max_speed_mps=9.0)
    rng = np.random.default_rng(3)
    clouds = RoadClouds.uniform(line, 2, 40, rng, sensor=SENSOR, resample=ResamplePolicy(),
                                speeds=motion)
    y = np.array([777.0, 0.0])
    density = SENSOR.clutter_density(line, y)
    clouds.detection_sums(y, density)
    draws = birth_draws(clouds, DetectionBirths(draw_share=0.5), y, density,
                        rng.random((3, 2, 20)))
    join_births(clouds, np.array([1]), draws, rng)
    assert clouds.shape == (2, 40)
    np.testing.assert_allclose(clouds.w.sum(axis=1), 1.0)
    pts = clouds.points()[1]
    assert np.count_nonzero(np.abs(pts[:, 0] - 777.0) < 25.0) > 0
    assert np.all((clouds.v == 0.0) | ((clouds.v >= 5.0) & (clouds.v <= 9.0)))


def test_the_draws_read_only_each_clouds_live_particles() -> None:
    """A cloud holding 30 of its 80 columns (weight 0 beyond, those columns all at the
    detection) gets the draws, weights and predictive likelihood of its 30 particles alone."""
    line = _line()
    rng = np.random.default_rng(5)
    e, s = line.nearest(np.column_stack([600.0 + 400.0 * rng.random(30), np.zeros(30)]))
    y = np.array([777.0, 0.0])
    ey, sy = line.nearest(np.tile(y, (50, 1)))
    w = rng.random(30)
    compact = RoadClouds(line, e[None], s[None], w[None], sensor=SENSOR,
                         resample=ResamplePolicy())
    wide = RoadClouds(line, np.concatenate([e, ey])[None], np.concatenate([s, sy])[None],
                      np.concatenate([w, np.zeros(50)])[None], sensor=SENSOR,
                      resample=ResamplePolicy())
    wide.count[0] = 30
    uniforms = rng.random((3, 1, 6))
    out = []
    for clouds in (compact, wide):
        clouds.detection_sums(y, 1e-3)
        out.append(birth_draws(clouds, DetectionBirths(), y, 1e-3, uniforms))
    np.testing.assert_array_equal(out[0].edge, out[1].edge)
    np.testing.assert_allclose(out[1].w, out[0].w, rtol=1e-12)
    np.testing.assert_allclose(out[1].sums, out[0].sums, rtol=1e-12)
    np.testing.assert_array_equal(out[1].keep[0, :30], out[0].keep[0])
    assert out[1].bandwidth[0] == pytest.approx(out[0].bandwidth[0], rel=1e-12)


def _rbpf(roads: DirectedRoads, births: DetectionBirths | None, x: np.ndarray) -> RoadRBPF:
    """A one-target filter of standing particles at ``x`` on the road along the x axis."""
    config = RBPFConfig(n_targets=1, n_histories=4, n_particles=x.size,
                        motion=RoadMotion(speed_mps=0.0, sigma_mps=0.0), sensor=SENSOR,
                        births=births)
    edge, s = roads.nearest(np.column_stack([x, np.zeros(x.size)]))
    return RoadRBPF.from_particles(roads, config, edge[None], s[None])


def _mass_near(births: DetectionBirths | None, x: np.ndarray, target: np.ndarray,
               scans: int, seed: int) -> float:
    """The filter's mass within 20 m of ``target`` after ``scans`` detections of it."""
    line = _line(n=201, step=100.0)
    f = _rbpf(line, births, x)
    rng = np.random.default_rng(seed)
    for _ in range(scans):
        f.predict(0.3, rng)
        f.update(target + rng.normal(0.0, 3.0, (1, 2)), target[0], rng)
    edge, s, w = f.target_particles()
    near = np.abs(line.point(edge, s)[..., 0] - target[0, 0]) < 20.0
    return float((w * near).sum())


@pytest.mark.parametrize("seed", range(3))
def test_an_rbpf_with_births_localises_a_target_between_its_particles(seed: int) -> None:
    """A standing target in the middle of a 100–115 m gap of a cloud of 100 particles spread
    over 9 km of road (so more than 50 m, ten σ, from any particle): consecutive detections
    localise the cloud with births, at the capped bandwidth, and leave it where it was
    without them."""
    x = np.sort(np.random.default_rng(11 + seed).uniform(0.0, 9000.0, 100))
    gap = np.diff(x)
    i = np.flatnonzero((gap > 100.0) & (gap < 115.0))[0]
    target = np.array([[x[i] + gap[i] / 2.0, 0.0]])
    assert _mass_near(DetectionBirths(), x, target, 6, seed) > 0.9
    assert _mass_near(None, x, target, 6, seed) == 0.0


@pytest.mark.parametrize("seed", range(3))
def test_a_false_alarm_in_an_emptied_footprint_does_not_localise_a_diffuse_cloud(
        seed: int) -> None:
    """300 particles over 6 km of road, none within 200 m of 3 km (a footprint the sensor has
    swept): one detection there is clutter to the exact posterior. At the capped bandwidth the
    draws take none of the mass; with Silverman's bandwidth (about 200 m here) they would take
    most of it."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.0, 5600.0, 300)
    x = np.where(x < 2800.0, x, x + 400.0)
    target = np.array([[3000.0, 0.0]])
    assert _mass_near(DetectionBirths(), x, target, 1, seed) < 1e-3
    assert _mass_near(DetectionBirths(max_bandwidth_sigmas=1e3), x, target, 1, seed) > 0.5


def test_births_configuration() -> None:
    """Bad settings are named; births and jumps are two alternative proposals."""
    for name, value in (("draw_share", 0.0), ("draw_share", 1.5), ("radius_sigmas", 0.0),
                        ("bandwidth_scale", -1.0), ("min_bandwidth_m", 0.0),
                        ("full_share", 0.0), ("full_share", 1.1),
                        ("max_bandwidth_sigmas", 0.0), ("kernel_points", 0)):
        with pytest.raises(InvalidInputError, match=name):
            DetectionBirths(**{name: value})
    assert DetectionBirths(draw_share=0.1).draws(500) == 50
    assert DetectionBirths().draws(500) == 25
    with pytest.raises(InvalidInputError, match="births"):
        RBPFConfig(n_targets=1, births=DetectionBirths(), jumps=TargetJumps())
    with pytest.raises(InvalidInputError, match="births"):
        RBPFConfig(n_targets=1, births=0.1)  # type: ignore[arg-type]
