"""SMC-PHD prediction: survival, measurement-driven and grid births, the region."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import (
    NEWBORN,
    PERSISTENT,
    BirthGrid,
    PHDConfig,
    PHDState,
    SensorScan,
    predict,
    update,
)
from searchtrack.models.birth_grids import BirthSurvivalGrid
from searchtrack.models.motion import ConstantVelocity, Static

from .helpers import AREA, POSE
from .helpers import cloud as _cloud
from .helpers import phd_state as _state
from .helpers import sensor as _sensor


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


def test_static_survivors_keep_their_place_and_lose_one_minus_ps() -> None:
    """Without births a static PHD keeps its particles and labels, weights times p_s, and the
    update record is cleared."""
    x = np.array([[10.0, 20.0], [30.0, 40.0]])
    st = update(PHDState.from_particles(x, np.array([1.0, 0.5])),
                [SensorScan(_sensor(), POSE, np.array([[10.0, 20.0]]))], PHDConfig(birth_mass=0.0))
    assert st.record.detection_masses.size == 1
    pred = predict(st, Static(), PHDConfig(survival_probability=0.8, birth_mass=0.0), 1.0,
                   np.random.default_rng(0))
    np.testing.assert_array_equal(pred.states, x)
    np.testing.assert_allclose(pred.weights, 0.8 * st.weights)
    assert pred.labels.tolist() == [PERSISTENT, PERSISTENT]
    assert pred.tags.tolist() == st.tags.tolist()
    assert pred.record.detection_masses.size == 0 and pred.record.seed_masses.size == 0


def test_zero_mass_seeds_and_grids_add_no_particles() -> None:
    """Seeds without birth mass and a grid of mass 0 give no newborns."""
    st = update(PHDState.empty(2), [SensorScan(_sensor(), POSE, np.array([[5.0, 5.0]]))],
                PHDConfig(birth_mass=0.0))
    grid = BirthGrid.uniform(AREA, mass=0.0, particles=10)
    pred = predict(st, Static(), PHDConfig(birth_grid=grid), 1.0, np.random.default_rng(0))
    assert pred.n_particles == 0 and pred.expected_count() == 0.0


def test_newborns_get_velocity_noise_of_the_configured_spread() -> None:
    """Newborn velocity components are zero-mean with birth_velocity_sigma_mps spread (checked
    on many particles of one static seed, no motion noise)."""
    cfg = PHDConfig(birth_mass=1.0, birth_particles_per_measurement=4000,
                    birth_velocity_sigma_mps=3.0, birth_position_sigma_m=1.0)
    st = update(PHDState.empty(4), [SensorScan(_sensor(), POSE, np.array([[500.0, 500.0]]))], cfg)
    pred = predict(st, ConstantVelocity(1e-9), cfg, 1e-9, np.random.default_rng(1))
    velocity = pred.states[:, 2:]
    assert np.abs(velocity.mean(axis=0)).max() < 0.2
    np.testing.assert_allclose(velocity.std(axis=0), 3.0, rtol=0.05)
    np.testing.assert_allclose(pred.weights, 1.0 / 4000)


def test_prediction_is_deterministic_for_a_seed() -> None:
    """The same generator seed gives the same predicted particles."""
    st = update(_state(_cloud((300, 300), 50, 1.0)),
                [SensorScan(_sensor(), POSE, np.array([[700.0, 700.0]]))], PHDConfig())

    def run() -> np.ndarray:
        return predict(st, ConstantVelocity(0.5), PHDConfig(), 1.0,
                       np.random.default_rng(3)).states

    np.testing.assert_array_equal(run(), run())


def test_motion_noise_draws_what_standard_normal_draws_into_a_reused_buffer() -> None:
    """The same draws as ``rng.standard_normal((n, d))``; the buffer is kept between calls and
    grown when a call needs more rows."""
    from searchtrack.estimate.phd.predict import motion_noise

    a, b = np.random.default_rng(7), np.random.default_rng(7)
    first = motion_noise(a, 50, 4)
    np.testing.assert_array_equal(first, b.standard_normal((50, 4)))
    second = motion_noise(a, 30, 4)
    assert np.shares_memory(first, second)
    np.testing.assert_array_equal(second, b.standard_normal((30, 4)))
    bigger = motion_noise(a, 500, 4)
    np.testing.assert_array_equal(bigger, b.standard_normal((500, 4)))
    np.testing.assert_array_equal(motion_noise(a, 0, 6), b.standard_normal((0, 6)))
