"""SMC-PHD update: mass identities, sequential sensors, missed targets, one estimate per target."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan, extract, update

from .helpers import POSE
from .helpers import cloud as _cloud
from .helpers import phd_state as _state
from .helpers import sensor as _sensor


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


def test_one_particle_one_measurement_by_hand() -> None:
    """One particle of weight 1 at a measurement: L = p_d g, C = c + L, w' = 1 − p_d + L / C;
    the record holds ρ = L / C at the particle's state and a seed of the whole birth mass."""
    pd, sigma, clutter_rate = 0.9, 10.0, 10.0
    x = np.array([[500.0, 500.0, 1.0, -1.0]])
    st = PHDState.from_particles(x, np.array([1.0]))
    z = np.array([[500.0, 500.0]])
    cfg = PHDConfig(birth_mass=0.3)
    out = update(st, [SensorScan(_sensor(pd, clutter_rate), POSE, z)], cfg)
    g = 1.0 / (2.0 * math.pi * sigma**2)
    ell = pd * g
    rho = ell / (clutter_rate / 1e6 + ell)
    assert out.weights[0] == pytest.approx(1.0 - pd + rho, rel=1e-12)
    assert out.record.detection_masses == pytest.approx([rho], rel=1e-12)
    np.testing.assert_allclose(out.record.detection_states, x)
    np.testing.assert_array_equal(out.record.seed_positions, z)
    assert out.record.seed_masses == pytest.approx([0.3])
    assert out.tags.tolist() == [0]  # the measurement explains more than half its weight


def test_two_measurements_share_the_birth_mass_by_what_is_unexplained() -> None:
    """Seeds get birth_mass · (1 − ρ_z) / Σ(1 − ρ): a measurement far from every particle
    (ρ ≈ 0) takes almost all of it."""
    st = _state(_cloud((300, 300), 200, 1.0))
    z = np.array([[300.0, 300.0], [900.0, 100.0]])
    out = update(st, [SensorScan(_sensor(), POSE, z)], PHDConfig(birth_mass=0.5))
    rho = out.record.detection_masses
    expected = 0.5 * (1 - rho) / (1 - rho).sum()
    np.testing.assert_allclose(out.record.seed_masses, expected, rtol=1e-12)
    assert rho[1] < 1e-6 and out.record.seed_masses.sum() == pytest.approx(0.5)


def test_no_measurement_scales_by_the_miss_probability() -> None:
    """An empty scan multiplies each weight by 1 − p_d (0 detection probability outside the
    area keeps those weights) and records nothing."""
    x = np.array([[100.0, 100.0], [2000.0, 0.0]])
    st = PHDState.from_particles(x, np.array([1.0, 2.0]))
    out = update(st, [SensorScan(_sensor(pd=0.8), POSE, np.empty((0, 2)))], PHDConfig())
    np.testing.assert_allclose(out.weights, [0.2, 2.0])
    assert out.record.detection_masses.size == 0 and out.record.seed_masses.size == 0
    assert out.tags.tolist() == [-1, -1]


def test_no_scans_keep_the_weights() -> None:
    """An update without scans leaves the weights as they were and records nothing."""
    st = _state(_cloud((300, 300), 20, 1.5))
    out = update(st, [], PHDConfig())
    np.testing.assert_array_equal(out.weights, st.weights)
    assert out.record.detection_masses.size == 0 and out.record.missed_existence.size == 0


def test_sensor_scan_reshapes_empty_measurements_and_checks_the_pose() -> None:
    """An empty measurement list becomes (0, 2); the pose is flattened, frozen and checked
    finite, naming ``pose``."""
    scan = SensorScan(_sensor(), np.array([[1.0, 2.0, 3.0]]), [])  # type: ignore[arg-type]
    assert scan.measurements.shape == (0, 2) and scan.pose.tolist() == [1.0, 2.0, 3.0]
    assert not scan.pose.flags.writeable and not scan.measurements.flags.writeable
    with pytest.raises(InvalidInputError, match="pose"):
        SensorScan(_sensor(), np.array([0.0, np.nan, 0.0]), np.empty((0, 2)))
