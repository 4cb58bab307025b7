"""SMC-PHD filter: mass identities, births, extraction, found targets, determinism, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.particle_belief import ParticleBelief
from searchtrack.estimate.phd import (
    NEWBORN,
    BirthGrid,
    FoundConfig,
    PHDConfig,
    PHDState,
    SensorScan,
    entropy_per_target,
    extract,
    extract_kmeans,
    gate_measurements,
    kmeans_clusters,
    mark_found,
    predict,
    resample,
    step,
    update,
)
from searchtrack.models.birth_grids import BirthSurvivalGrid
from searchtrack.models.motion import ConstantVelocity, Static
from searchtrack.models.position_sensor import PositionSensor
from searchtrack.sim.phd_scenario import standard_scenario

AREA = np.array([[0.0, 1000.0], [0.0, 1000.0]])
POSE = np.zeros(3)


def _sensor(pd: float = 0.9, clutter: float = 10.0) -> PositionSensor:
    return PositionSensor(pd, 10.0, clutter, AREA)


def _cloud(centre: tuple[float, float], n: int, mass: float, spread: float = 5.0,
           seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = np.zeros((n, 4))
    x[:, :2] = np.asarray(centre) + spread * rng.standard_normal((n, 2))
    return x, np.full(n, mass / n)


def _state(*clouds: tuple[np.ndarray, np.ndarray]) -> PHDState:
    return PHDState.from_particles(np.vstack([c[0] for c in clouds]),
                                   np.concatenate([c[1] for c in clouds]))


def test_state_is_a_particle_belief() -> None:
    """PHDState satisfies the ParticleBelief protocol; weights sum to the expected count."""
    st = _state(_cloud((100, 100), 50, 2.0))
    assert isinstance(st, ParticleBelief)
    assert st.expected_count() == pytest.approx(2.0)
    assert st.positions.shape == (50, 2)


def test_pd_zero_leaves_weights_unchanged() -> None:
    """With p_d = 0 the update keeps every weight, whatever is measured."""
    st = _state(_cloud((100, 100), 200, 1.0), _cloud((600, 300), 100, 0.5))
    z = np.array([[100.0, 100.0], [600.0, 300.0], [900.0, 900.0]])
    out = update(st, [SensorScan(_sensor(pd=0.0), POSE, z)], PHDConfig())
    np.testing.assert_array_equal(out.weights, st.weights)


def test_update_mass_identity_without_clutter() -> None:
    """No clutter: Σw' = Σ(1 − p_d)w + number of measurements with C(z) > 0 (paper 004)."""
    st = _state(_cloud((100, 100), 300, 0.7), _cloud((500, 500), 300, 1.2))
    z = np.array([[102.0, 98.0], [505.0, 500.0]])
    out = update(st, [SensorScan(_sensor(clutter=0.0), POSE, z)], PHDConfig())
    assert out.expected_count() == pytest.approx(0.1 * st.expected_count() + 2.0)


def test_isolated_measurement_adds_one_target() -> None:
    """One strong isolated measurement raises the expected count by ≈ 1 over no measurement."""
    st = _state(_cloud((300, 300), 500, 0.8), _cloud((800, 200), 500, 1.0))
    sensor = _sensor(clutter=0.01)
    cfg = PHDConfig()
    none = update(st, [SensorScan(sensor, POSE, np.empty((0, 2)))], cfg)
    one = update(st, [SensorScan(sensor, POSE, np.array([[300.0, 301.0]]))], cfg)
    assert one.expected_count() - none.expected_count() == pytest.approx(1.0, abs=1e-3)


def test_sequential_sensors_equal_two_updates() -> None:
    """Two scans in one update equal two single-scan updates in a row (weights)."""
    st = _state(_cloud((300, 300), 300, 1.0))
    cfg = PHDConfig()
    a = SensorScan(_sensor(), POSE, np.array([[300.0, 300.0]]))
    b = SensorScan(_sensor(pd=0.5), POSE, np.array([[305.0, 295.0], [10.0, 10.0]]))
    both = update(st, [a, b], cfg)
    twice = update(update(st, [a], cfg), [b], cfg)
    np.testing.assert_allclose(both.weights, twice.weights)


def test_resampling_keeps_mass_and_caps_particles() -> None:
    """Systematic resampling keeps Σw, equalises weights and honours the particle cap."""
    st = _state(_cloud((100, 100), 1000, 3.0), _cloud((700, 700), 10, 0.25))
    rng = np.random.default_rng(0)
    out = resample(st, PHDConfig(particles_per_target=100), rng)
    assert out.expected_count() == pytest.approx(st.expected_count())
    assert out.n_particles == round(100 * 3.25)
    assert np.ptp(out.weights) == 0.0
    capped = resample(st, PHDConfig(particles_per_target=1000, max_particles=500), rng)
    assert capped.n_particles == 500
    assert capped.expected_count() == pytest.approx(3.25)


def test_measurement_births_carry_birth_mass() -> None:
    """Unexplained measurements seed NEWBORN particles whose total weight is birth_mass."""
    cfg = PHDConfig(birth_mass=0.4, birth_particles_per_measurement=50)
    z = np.array([[200.0, 200.0], [700.0, 100.0]])
    st = update(PHDState.empty(4), [SensorScan(_sensor(), POSE, z)], cfg)
    assert st.record.seed_masses.sum() == pytest.approx(0.4)
    pred = predict(st, ConstantVelocity(0.5), cfg, 1.0, np.random.default_rng(0))
    assert pred.n_particles == 100
    assert np.all(pred.labels == NEWBORN)
    assert pred.expected_count() == pytest.approx(0.4)
    near = np.linalg.norm(pred.positions[:50] - z[0], axis=1)
    assert np.median(near) < 40.0


def test_grid_birth_and_survival() -> None:
    """Grid births add their mass; survivors are scaled by p_s."""
    grid = BirthGrid(AREA, np.array([[0.0, 1.0], [0.0, 0.0]]), mass=0.3, particles=40)
    cfg = PHDConfig(survival_probability=0.9, birth_grid=grid)
    st = _state(_cloud((100, 100), 10, 1.0))
    pred = predict(st, ConstantVelocity(0.5), cfg, 1.0, np.random.default_rng(0))
    assert pred.expected_count() == pytest.approx(0.9 + 0.3)
    born = pred.positions[pred.labels == NEWBORN]
    assert born.shape == (40, 2)
    assert np.all((born[:, 0] < 500) & (born[:, 1] > 500))  # only cell (0, 1) has weight


def test_survival_map_from_counts_scales_each_particle() -> None:
    """A count grid's survival replaces p_s particle by particle (0 outside its area), and
    BirthGrid.from_counts turns its birth counts into a birth intensity of mass rate · Δt."""
    xy = np.array([[50.0, 50.0], [60.0, 50.0], [70.0, 50.0], [80.0, 50.0]])
    counts = BirthSurvivalGrid.from_tracks(xy, np.zeros(4, dtype=int), np.arange(4.0),
                                           [[0.0, 200.0], [0.0, 100.0]], 100.0, 1.0,
                                           survival_prior=1.0, death_prior=1.0)
    inside, outside = _cloud((50, 50), 10, 1.0, spread=1.0), _cloud((500, 500), 10, 1.0, 1.0)
    cfg = PHDConfig(survival_map=counts, birth_mass=0.0)
    pred = predict(_state(inside, outside), ConstantVelocity(0.5), cfg, 1.0,
                   np.random.default_rng(0))
    ps = float(counts.survival_grid[0, 0])
    assert ps == pytest.approx(4 / 5)  # 3 survivals + 1 prior over 3 + 1 + 0 + 1
    assert pred.expected_count() == pytest.approx(ps)
    grid = BirthGrid.from_counts(counts, dt_s=2.0, particles=50)
    assert grid.mass == pytest.approx(2.0 * counts.birth_rate_per_s)
    np.testing.assert_array_equal(grid.cell_weights, counts.birth_counts)
    with pytest.raises(InvalidInputError, match="survival_map"):
        PHDConfig(survival_map=0.9)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="grid"):
        BirthGrid.from_counts("counts", 1.0, 10)  # type: ignore[arg-type]


def test_region_drops_particles_outside() -> None:
    """Particles predicted outside the surveillance region are removed."""
    x = np.zeros((2, 2))
    x[1] = [2000.0, 0.0]
    st = PHDState.from_particles(x, np.array([1.0, 1.0]))
    pred = predict(st, Static(), PHDConfig(region=AREA), 1.0, np.random.default_rng(0))
    assert pred.n_particles == 1
    assert pred.expected_count() == pytest.approx(PHDConfig().survival_probability)


def test_attribution_extraction_finds_detected_targets() -> None:
    """Each well-explained measurement yields one estimate at the posterior mean."""
    st = _state(_cloud((300, 300), 400, 1.0), _cloud((700, 600), 400, 1.0, seed=1))
    z = np.array([[301.0, 299.0], [698.0, 603.0], [50.0, 950.0]])
    est = extract(update(st, [SensorScan(_sensor(), POSE, z)], PHDConfig()), PHDConfig())
    assert len(est) == 2
    assert ospa(est.positions, [[300.0, 300.0], [700.0, 600.0]], c=100.0) < 3.0


def test_missed_target_is_reported_with_bernoulli_existence() -> None:
    """A tagged unit-mass target left unmeasured is reported with existence r q / (1 − r + r q)."""
    cfg = PHDConfig()
    st = _state(_cloud((300, 300), 400, 1.0))
    first = update(st, [SensorScan(_sensor(), POSE, np.array([[300.0, 300.0]]))], cfg)
    assert np.all(first.tags == 0)
    prior = first.select(np.arange(first.n_particles), np.full(first.n_particles,
                                                               0.95 / first.n_particles))
    missed = update(prior, [SensorScan(_sensor(), POSE, np.empty((0, 2)))], cfg)
    r, q = 0.95, 0.1
    assert missed.record.missed_existence == pytest.approx([r * q / (1 - r + r * q)])
    est = extract(missed, cfg)
    assert len(est) == 1
    assert np.linalg.norm(est.positions[0] - [300.0, 300.0]) < 3.0
    assert len(extract(missed, PHDConfig(report_missed=False))) == 0


def test_one_estimate_per_unit_mass_target() -> None:
    """Clutter next to a target does not give the target a second estimate."""
    cfg = PHDConfig()
    st = _state(_cloud((300, 300), 400, 1.0))
    tagged = update(st, [SensorScan(_sensor(), POSE, np.array([[300.0, 300.0]]))], cfg)
    tagged = tagged.select(np.arange(tagged.n_particles),
                           np.full(tagged.n_particles, 1.0 / tagged.n_particles))
    z = np.array([[301.0, 300.0], [315.0, 300.0]])
    est = extract(update(tagged, [SensorScan(_sensor(), POSE, z)], cfg), cfg)
    assert len(est) == 1
    assert est.positions[0, 0] < 305.0


def test_kmeans_extraction_separates_clusters() -> None:
    """Weighted k-means with round(λ) clusters finds two separated clouds."""
    st = _state(_cloud((200, 200), 300, 1.1), _cloud((600, 800), 300, 0.9, seed=2))
    est, clusters = extract_kmeans(st, PHDConfig(extraction="kmeans"))
    assert len(est) == 2
    assert ospa(est.positions, [[200.0, 200.0], [600.0, 800.0]], c=100.0) < 2.0
    assert sorted(clusters.masses) == pytest.approx([0.9, 1.1])
    assert np.all(clusters.radii_m < 10.0)


def test_entropy_per_target_of_uniform_phd() -> None:
    """Uniform particles on the grid give H[p] − log λ = log(area) − log λ (eq. 15)."""
    g = (np.arange(10) + 0.5) * 100.0
    xy = np.array([[a, b] for a in g for b in g])
    st = PHDState.from_particles(xy, np.full(100, 0.05))
    h = entropy_per_target(st, AREA, 100.0)
    assert h == pytest.approx(math.log(1e6) - math.log(5.0))
    one = PHDState.from_particles(np.array([[50.0, 50.0]]), np.array([1.0]))
    assert entropy_per_target(one, AREA, 100.0) == pytest.approx(math.log(1e4))
    assert math.isnan(entropy_per_target(PHDState.empty(2), AREA, 100.0))


def test_found_targets_removed_and_gated() -> None:
    """A narrow heavy cluster is saved as found and its particles removed; gating drops one
    measurement per found target."""
    st = _state(_cloud((200, 200), 300, 2.5, spread=0.5), _cloud((700, 700), 300, 1.0))
    clusters = kmeans_clusters(st, 2, PHDConfig())
    rest, found = mark_found(st, clusters, FoundConfig(radius_m=1.1, mass=2.2), np.empty((0, 2)))
    assert found.shape == (1, 2)
    assert np.linalg.norm(found[0] - [200.0, 200.0]) < 0.5
    assert rest.expected_count() == pytest.approx(1.0)
    z = np.array([[201.0, 200.0], [199.0, 201.0], [500.0, 500.0]])
    keep = gate_measurements(found, z, gate_m=5.0)
    np.testing.assert_array_equal(keep, [False, True, True])


def test_filter_is_deterministic_for_a_seed() -> None:
    """Two runs with the same seed give identical particles and estimates."""
    sc = standard_scenario(3, n_targets=3, n_scans=15)
    cfg = PHDConfig(region=AREA)

    def run(seed: int) -> tuple[np.ndarray, np.ndarray]:
        rng = np.random.default_rng(seed)
        st = PHDState.empty(4)
        for z in sc.scans:
            st, est = step(st, [SensorScan(sc.sensor, POSE, z)], sc.motion, cfg, 1.0, rng)
        return st.states, est.states

    a, b = run(7), run(7)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])


def test_filter_tracks_the_standard_scenario() -> None:
    """On a 3-target standard-like run the late-scan OSPA stays well under the cut-off."""
    sc = standard_scenario(5, n_targets=3, n_scans=40)
    cfg = PHDConfig(region=AREA)
    rng = np.random.default_rng(0)
    st = PHDState.empty(4)
    dist = []
    for k, z in enumerate(sc.scans):
        st, est = step(st, [SensorScan(sc.sensor, POSE, z)], sc.motion, cfg, 1.0, rng)
        if k >= 15:
            dist.append(ospa(est.positions, sc.truth[k][:, :2], c=100.0))
    assert np.mean(dist) < 30.0


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"survival_probability": 0.0}, "survival_probability"),
    ({"birth_mass": -1.0}, "birth_mass"),
    ({"birth_particles_per_measurement": 0}, "birth_particles_per_measurement"),
    ({"birth_position_sigma_m": float("nan")}, "birth_position_sigma_m"),
    ({"particles_per_target": 2.5}, "particles_per_target"),
    ({"min_particles": 20, "max_particles": 10}, "min_particles"),
    ({"extraction": "dbscan"}, "extraction"),
    ({"region": [[0.0, -1.0], [0.0, 1.0]]}, "region"),
    ({"birth_grid": "uniform"}, "birth_grid"),
])
def test_bad_config(kwargs: dict[str, object], field: str) -> None:
    """Invalid settings raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        PHDConfig(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_bad_scans_and_states() -> None:
    """Malformed measurements, particles and birth grids are rejected with the field named."""
    with pytest.raises(InvalidInputError, match="measurements"):
        SensorScan(_sensor(), POSE, np.zeros((2, 3)))
    with pytest.raises(InvalidInputError, match="measurements"):
        SensorScan(_sensor(), POSE, np.array([[np.nan, 1.0]]))
    with pytest.raises(InvalidInputError, match="weights"):
        PHDState.from_particles(np.zeros((2, 4)), np.array([1.0, -1.0]))
    with pytest.raises(InvalidInputError, match="cell_weights"):
        BirthGrid(AREA, np.zeros((2, 2)), 1.0, 10)
    with pytest.raises(InvalidInputError, match="birth_grid"):
        grid = BirthGrid(np.array([[0.0, 1.0]]), np.ones(3), 1.0, 10)
        predict(PHDState.empty(4), ConstantVelocity(0.5), PHDConfig(birth_grid=grid), 1.0,
                np.random.default_rng(0))


def test_two_sensors_give_one_estimate_per_target() -> None:
    """Two sensors detecting the same tagged target yield a single estimate."""
    cfg = PHDConfig()
    st = _state(_cloud((300, 300), 400, 1.0))
    tagged = update(st, [SensorScan(_sensor(), POSE, np.array([[300.0, 300.0]]))], cfg)
    tagged = tagged.select(np.arange(tagged.n_particles),
                           np.full(tagged.n_particles, 1.0 / tagged.n_particles))
    scans = [SensorScan(_sensor(), POSE, np.array([[302.0, 300.0]])),
             SensorScan(_sensor(), POSE, np.array([[298.0, 301.0]]))]
    est = extract(update(tagged, scans, cfg), cfg)
    assert len(est) == 1
