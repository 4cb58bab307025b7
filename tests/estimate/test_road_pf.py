"""Road particle filters: uniform start, detection and miss updates, tracking, the known-
association bank and its belief adapters."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.road_pf import RoadClouds, RoadParticleFilter, node_trackers
from searchtrack.estimate.road_resampling import ResamplePolicy, SpeedRoughening
from searchtrack.models import grid_network
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads, RoadMotion

CENTRE = np.array([100.0, 100.0])


@pytest.fixture(scope="module")
def roads() -> DirectedRoads:
    """The paper's 3×3 map of 100 m roads."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def test_starts_uniform(roads: DirectedRoads) -> None:
    """Eq. 1: N particles on valid positions with weights 1/N."""
    pf = RoadParticleFilter(roads, 300, np.random.default_rng(0))
    edge, s, w = pf.particles()
    assert edge.shape == s.shape == w.shape == (300,)
    roads.check_positions(edge, s)
    np.testing.assert_allclose(w, 1 / 300)
    assert pf.n_eff() == pytest.approx(300)
    assert pf.entropy() > 4.5


def test_detection_concentrates_the_cloud(roads: DirectedRoads) -> None:
    """After a detection the particles sit within a few σ of it; the returned value is the
    weighted mean of Eq. 10 before the update."""
    rng = np.random.default_rng(1)
    pf = RoadParticleFilter(roads, 5000, rng)
    y = np.array([100.0, 42.0])
    sensor = DiscSensor()
    expected = sensor.likelihood(pf.points(), y, 1 / 2400).mean()
    assert pf.likelihood_sum(y) == pytest.approx(expected, rel=1e-12)
    assert pf.update(y, y, rng) == pytest.approx(expected, rel=1e-12)
    dist = np.hypot(*(pf.points() - y).T)
    assert np.median(dist) < 4.0
    np.testing.assert_allclose(pf.map_position(), y, atol=5.0)


def test_miss_moves_mass_out_of_the_view(roads: DirectedRoads) -> None:
    """Eq. 11: the mass within 22.5 m of the UAV drops from f to f·P_FN / (f·P_FN + 1 − f)."""
    rng = np.random.default_rng(2)
    pf = RoadParticleFilter(roads, 40_000, rng)
    near = np.hypot(*(pf.points() - CENTRE).T) <= 22.5
    f = near.mean()
    like = pf.update(None, CENTRE, rng)
    assert like == pytest.approx(f * 0.05 + 1 - f)
    after = (np.hypot(*(pf.points() - CENTRE).T) <= 22.5).mean()
    assert after == pytest.approx(f * 0.05 / (f * 0.05 + 1 - f), abs=0.002)


def test_selective_resampling_lets_weights_accumulate(roads: DirectedRoads) -> None:
    """With threshold 2/3 a mild miss keeps the weights (Eq. 6); the default resamples."""
    gated = RoadParticleFilter(roads, 2000, np.random.default_rng(3),
                               resample=ResamplePolicy(2 / 3))
    always = RoadParticleFilter(roads, 2000, np.random.default_rng(3))
    for pf in (gated, always):
        pf.update(None, CENTRE, np.random.default_rng(4))
    w = gated.particles()[2]
    assert w.max() > 1.5 * w.min() and gated.n_eff() > 2 / 3 * 2000
    np.testing.assert_allclose(always.particles()[2], 1 / 2000)


def test_tracks_a_moving_target(roads: DirectedRoads) -> None:
    """A UAV over the target, scans at 1 Hz: after 20 s the MAP point is within 10 m."""
    rng = np.random.default_rng(5)
    pf = RoadParticleFilter(roads, 500, rng)
    sensor = pf.clouds.sensor
    te, ts = roads.uniform(1, rng)
    for k in range(200):
        te, ts = RoadMotion(10.0, 2.0).step(roads, te, ts, 0.1, rng)
        pf.predict(0.1, rng)
        if k % 10 == 9:
            truth = roads.point(te, ts)
            ys = sensor.detect(truth[0], truth, rng, roads)
            pf.update(ys[0] if len(ys) else None, truth[0], rng)
    assert np.hypot(*(pf.map_position() - roads.point(te, ts)[0])) < 10.0


def test_deterministic_for_a_seed(roads: DirectedRoads) -> None:
    """Same seed, same particles."""
    out = []
    for _ in range(2):
        rng = np.random.default_rng(6)
        pf = RoadParticleFilter(roads, 200, rng)
        pf.predict(1.0, rng)
        pf.update([100.0, 50.0], [100.0, 50.0], rng)
        pf.update(None, CENTRE, rng)
        out.append(pf.particles())
    for a, b in zip(*out, strict=True):
        np.testing.assert_array_equal(a, b)


def test_from_particles_and_bad_input(roads: DirectedRoads) -> None:
    """Given particles are kept; bad inputs are refused with the field's name."""
    pf = RoadParticleFilter.from_particles(roads, [0, 1], [5.0, 6.0], [1.0, 3.0])
    np.testing.assert_allclose(pf.particles()[2], [0.25, 0.75])
    rng = np.random.default_rng(0)
    with pytest.raises(InvalidInputError, match="n_particles"):
        RoadParticleFilter(roads, 0, rng)
    with pytest.raises(InvalidInputError, match=r"^w="):
        RoadParticleFilter.from_particles(roads, [0, 1], [5.0, 6.0], [1.0, -3.0])
    with pytest.raises(InvalidInputError, match="edge"):
        RoadParticleFilter.from_particles(roads, [0, 99], [5.0, 6.0])
    with pytest.raises(InvalidInputError, match=r"^y="):
        pf.update([np.nan, 0.0], CENTRE, rng)
    with pytest.raises(InvalidInputError, match="uav_xy"):
        pf.update(None, [0.0, 0.0, 0.0], rng)
    with pytest.raises(InvalidInputError, match="rng"):
        pf.predict(0.1, 7)  # type: ignore[arg-type]


def test_speed_state_bad_input(roads: DirectedRoads) -> None:
    """Speeds of the wrong shape or not finite are refused by name; the drive-and-stop motion
    needs clouds built with a speed state; counts that are not a KLDSampling are named."""
    edge, s = roads.uniform((2, 5), np.random.default_rng(1))
    for v in (np.zeros((2, 4)), np.full((2, 5), np.nan), np.full((2, 5), -1.0)):
        with pytest.raises(InvalidInputError, match=r"^v="):
            RoadClouds(roads, edge, s, sensor=DiscSensor(), resample=ResamplePolicy(), v=v)
    plain = RoadClouds(roads, edge, s, sensor=DiscSensor(), resample=ResamplePolicy())
    with pytest.raises(InvalidInputError, match="motion"):
        plain.predict(CourierRoadMotion(), 0.1, np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match=r"^counts="):
        RoadClouds(roads, edge, s, sensor=DiscSensor(), resample=ResamplePolicy(),
                   counts=0.05)  # type: ignore[arg-type]


def test_node_trackers_give_mass_to_the_nearer_end(roads: DirectedRoads) -> None:
    """A particle before the middle of its edge counts for the tail, after it for the head."""
    d = 0
    tail, head = int(roads.tail[d]), int(roads.head[d])
    (tr,) = node_trackers(roads, np.array([[d, d, d]]), np.array([[10.0, 40.0, 90.0]]),
                          np.array([[0.5, 0.2, 0.3]]))
    p = tr.node_probability()
    assert p[tail] == pytest.approx(0.7) and p[head] == pytest.approx(0.3)
    assert tr.track_id == 0 and tr.peak_node() == tail


def _speed_clouds(roads: DirectedRoads, roughening: SpeedRoughening | None) -> RoadClouds:
    """Two clouds of 400 driving particles whose weight sits on three of them (speeds 10, 12
    and 15 m/s), the rest of any speed."""
    rng = np.random.default_rng(4)
    edge, s = roads.uniform((2, 400), rng)
    motion = CourierRoadMotion(min_speed_mps=5.0, max_speed_mps=20.0)
    v = rng.uniform(5.0, 20.0, (2, 400))
    v[:, :3] = [10.0, 12.0, 15.0]
    w = np.full((2, 400), 1e-12)
    w[:, :3] = 1.0
    return RoadClouds(roads, edge, s, w, sensor=DiscSensor(), resample=ResamplePolicy(),
                      speeds=motion, v=v, roughening=roughening)


def test_roughening_parts_the_copies_of_a_resampling(roads: DirectedRoads) -> None:
    """Resampled onto three particles, a row keeps three speeds without roughening; with it
    every copy drives at a speed of its own, near its parent's, within the drive range; rows not
    resampled keep theirs."""
    rows = np.array([0])
    plain = _speed_clouds(roads, None)
    plain.resample(rows, np.random.default_rng(0))
    assert set(np.unique(plain.v[0]).tolist()) == {10.0, 12.0, 15.0}
    rough = _speed_clouds(roads, SpeedRoughening())
    before = rough.v[1].copy()
    rough.resample(rows, np.random.default_rng(0))
    assert np.unique(rough.v[0]).size == 400
    assert np.all((rough.v[0] >= 5.0) & (rough.v[0] <= 20.0))
    h = SpeedRoughening().bandwidths(plain.v[[0]])[0]
    assert np.max(np.abs(rough.v[0] - plain.v[0])) < 6.0 * h
    np.testing.assert_array_equal(rough.v[1], before)


def test_roughening_needs_speeds(roads: DirectedRoads) -> None:
    edge, s = roads.uniform((1, 5), np.random.default_rng(0))
    with pytest.raises(InvalidInputError) as info:
        RoadClouds(roads, edge, s, sensor=DiscSensor(), resample=ResamplePolicy(),
                   roughening=SpeedRoughening())
    assert info.value.field == "roughening"


def test_kld_counts_follow_the_spread_and_every_reader_ignores_the_rest(
        roads: DirectedRoads) -> None:
    """With KLD-sampling a cloud that detections localised keeps far fewer particles than the
    cap and a cloud seen by nothing keeps the cap; entropy, MAP position and node beliefs of
    the clouds equal those of their live particles alone, and copy and take carry the
    counts."""
    from searchtrack.estimate.road_entropy import RoadBins, entropy, map_positions
    from searchtrack.estimate.road_resampling import KLDSampling

    rng = np.random.default_rng(11)
    clouds = RoadClouds.uniform(roads, 2, 2000, rng, sensor=DiscSensor(),
                                resample=ResamplePolicy(), counts=KLDSampling())
    y = np.array([150.0, 100.0])
    density = clouds.sensor.clutter_density(roads)
    for _ in range(4):
        clouds.detection_sums(y, density)
        clouds.weigh(np.array([0]), rng)
        clouds.predict(RoadMotion(speed_mps=1.0, sigma_mps=0.5), 0.1, rng)
    clouds.miss(np.array([300.0, 300.0]), np.array([1]), rng)
    assert clouds.count[0] < 400 and clouds.count[1] == 2000
    np.testing.assert_array_equal(clouds.w[0, clouds.count[0]:], 0.0)
    np.testing.assert_allclose(clouds.w.sum(axis=1), 1.0)
    n = int(clouds.count[0])
    live = (clouds.edge[:1, :n], clouds.s[:1, :n], clouds.w[:1, :n])
    bins = RoadBins(roads)
    assert entropy(bins, clouds.edge, clouds.s, clouds.w)[0] == pytest.approx(
        entropy(bins, *live)[0], rel=1e-12)
    np.testing.assert_array_equal(map_positions(bins, clouds.edge, clouds.s, clouds.w)[0],
                                  map_positions(bins, *live)[0])
    np.testing.assert_allclose(node_trackers(roads, clouds.edge, clouds.s, clouds.w)[0]
                               .probability, node_trackers(roads, *live)[0].probability,
                               rtol=1e-12)
    snap = clouds.copy()
    clouds.take(np.array([1, 0, 0]))
    np.testing.assert_array_equal(clouds.count, [2000, n, n])
    np.testing.assert_array_equal(snap.count, [n, 2000])
