"""3-D range–bearing–elevation sensor (paper 004, eqs. 1–3): π, h, h⁻¹, likelihood, clutter."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.models.particle_models import DetectionSensor
from searchtrack.models.range_sensor import RangeBearingElevationSensor

POSE = np.array([5.0, -3.0, 40.0])


def test_satisfies_detection_sensor_protocol() -> None:
    """The sensor is a DetectionSensor with 3-D measurements."""
    sensor = RangeBearingElevationSensor()
    assert isinstance(sensor, DetectionSensor)
    assert sensor.meas_dim == 3


def test_inverse_map_recovers_positions() -> None:
    """h⁻¹(h(x)) = x for points all around the sensor (every bearing quadrant, up and down)."""
    sensor = RangeBearingElevationSensor()
    rng = np.random.default_rng(0)
    pts = POSE + rng.uniform(-100.0, 100.0, (200, 3))
    np.testing.assert_allclose(sensor.to_position(POSE, sensor.measurement(POSE, pts)), pts,
                               atol=1e-9)


def test_measurement_hand_values() -> None:
    """A point 3 m east, 4 m north and 12 m up has d = 13, θ = atan2(4, 3), ϖ = asin(12/13)."""
    sensor = RangeBearingElevationSensor()
    z = sensor.measurement(POSE, POSE[None, :] + np.array([[3.0, 4.0, 12.0]]))[0]
    np.testing.assert_allclose(z, [13.0, math.atan2(4.0, 3.0), math.asin(12.0 / 13.0)])


def test_pd_at_the_sensor_is_the_gain_and_decays_as_printed() -> None:
    """π(q, q) = G; at ‖ζ‖ = 2 it is G e^{−1} (printed norm) or G e^{−2} (squared)."""
    fov = np.array([10.0, 20.0, 5.0])
    plain = RangeBearingElevationSensor(gain=0.8, fov_m=fov)
    squared = RangeBearingElevationSensor(gain=0.8, fov_m=fov, squared=True)
    here = POSE[None, :]
    away = POSE[None, :] + np.array([[0.0, 0.0, 10.0]])  # ζ = (0, 0, 2)
    assert plain.detection_probability(POSE, here)[0] == pytest.approx(0.8)
    assert squared.detection_probability(POSE, here)[0] == pytest.approx(0.8)
    assert plain.detection_probability(POSE, away)[0] == pytest.approx(0.8 * math.exp(-1.0))
    assert squared.detection_probability(POSE, away)[0] == pytest.approx(0.8 * math.exp(-2.0))


def test_measurement_at_the_sensor_is_finite() -> None:
    """A target exactly at the sensor has d = 0 and finite angles."""
    z = RangeBearingElevationSensor().measurement(POSE, POSE[None, :])
    assert np.all(np.isfinite(z)) and z[0, 0] == 0.0


def test_likelihood_integrates_to_one_and_wraps_bearing() -> None:
    """g(z | x) sums to 1 over a fine grid in (d, θ, ϖ), also across the ±π bearing seam."""
    sensor = RangeBearingElevationSensor(sigma=[2.0, 0.05, 0.04])
    x = POSE[None, :] + np.array([[-50.0, -0.5, 10.0]])  # bearing just below −π … near +π
    h = sensor.measurement(POSE, x)[0]
    step = np.array([0.25, 0.005, 0.004])
    axes = [h[i] + step[i] * np.arange(-40, 41) for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    grid[:, 1] = wrap_angle(grid[:, 1])
    total = sensor.likelihood(POSE, grid, x).sum() * float(np.prod(step))
    assert total == pytest.approx(1.0, abs=2e-3)
    seam = np.array([[h[0], h[1] + (2 * math.pi if h[1] < 0 else -2 * math.pi), h[2]]])
    assert sensor.likelihood(POSE, seam, x)[0, 0] == pytest.approx(
        sensor.likelihood(POSE, h[None, :], x)[0, 0])


def test_no_clutter_by_default_and_uniform_clutter_when_asked() -> None:
    """Clutter PHD is 0 by default and rate / (R_max 2π π) inside the range with clutter."""
    z = np.array([[10.0, 0.0, 0.0], [2000.0, 0.0, 0.0]])
    assert np.all(RangeBearingElevationSensor().clutter_intensity(POSE, z) == 0.0)
    sensor = RangeBearingElevationSensor(clutter_rate=4.0, max_range_m=500.0)
    np.testing.assert_allclose(sensor.clutter_intensity(POSE, z),
                               [4.0 / (500.0 * 2 * math.pi * math.pi), 0.0])


def test_measure_is_seeded_and_detects_near_targets() -> None:
    """Simulated scans repeat for a seed; a target at the sensor with G = 1 is always seen."""
    sensor = RangeBearingElevationSensor(gain=1.0, fov_m=5.0, sigma=0.01)
    targets = np.vstack([POSE, POSE + 5000.0])
    z1, o1 = sensor.measure(POSE, targets, np.random.default_rng(2))
    z2, o2 = sensor.measure(POSE, targets, np.random.default_rng(2))
    np.testing.assert_array_equal(z1, z2)
    np.testing.assert_array_equal(o1, o2)
    assert o1.tolist() == [0]
    assert np.all((z1[:, 1] >= -math.pi) & (z1[:, 1] < math.pi))


@pytest.mark.parametrize(("field", "value"), [
    ("gain", 0.0), ("gain", 1.2), ("fov_m", [1.0, 0.0, 1.0]), ("fov_m", [1.0, 2.0]),
    ("sigma", -1.0), ("sigma", [1.0, math.inf, 1.0]), ("squared", "yes"),
    ("clutter_rate", -0.1), ("max_range_m", 0.0),
])
def test_bad_constructor_input(field: str, value: object) -> None:
    """Every bad constructor argument raises InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        RangeBearingElevationSensor(**{field: value})  # type: ignore[arg-type]
    assert err.value.field == field


def test_bad_pose_and_positions() -> None:
    """A pose shorter than 3 or 2-D positions are refused."""
    sensor = RangeBearingElevationSensor()
    with pytest.raises(InvalidInputError, match="pose"):
        sensor.detection_probability(np.array([1.0, 2.0]), np.zeros((1, 3)))
    with pytest.raises(InvalidInputError, match="positions"):
        sensor.detection_probability(POSE, np.zeros((1, 2)))


def test_innovation_distance_is_the_mahalanobis_distance() -> None:
    """Without position uncertainty it is ``‖(z − h(x)) / σ‖`` (bearing wrapped) and the
    likelihood is ``exp(−d²/2)`` over its peak; a position uncertainty ``s`` adds ``s²`` to the
    range variance and ``s²/d²`` to the elevation's (hand values at 100 m due east)."""
    sensor = RangeBearingElevationSensor(sigma=(1.0, 0.02, 0.03))
    x = POSE[None, :] + np.array([[100.0, 0.0, 0.0]])
    z = np.array([[102.0, 0.04 - 2.0 * math.pi, -0.03], [100.0, 0.0, 0.0]])
    d = sensor.innovation_distance(POSE, z, x)
    np.testing.assert_allclose(d[:, 0], [math.sqrt(4.0 + 4.0 + 1.0), 0.0], atol=1e-9)
    peak = sensor.likelihood(POSE, z[1:], x)[0, 0]
    np.testing.assert_allclose(sensor.likelihood(POSE, z[:1], x)[0, 0],
                               peak * math.exp(-0.5 * 9.0))
    s = 2.0  # range variance 1 + 4, bearing 0.02² + 4e-4, elevation 0.03² + 4e-4
    wide = sensor.innovation_distance(POSE, z[:1], x, position_sigma_m=s)[0, 0]
    assert wide == pytest.approx(math.sqrt(4.0 / 5.0 + 0.04 ** 2 / 8e-4 + 0.03 ** 2 / 13e-4))
    with pytest.raises(InvalidInputError, match="position_sigma_m"):
        sensor.innovation_distance(POSE, z, x, position_sigma_m=-1.0)
