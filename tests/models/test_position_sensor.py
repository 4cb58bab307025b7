"""Position sensor: p_d inside the area, Gaussian likelihood, clutter PHD, simulated scans."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.particle_models import DetectionSensor
from searchtrack.models.position_sensor import PositionSensor

AREA = [[0.0, 100.0], [0.0, 200.0]]
POSE = np.zeros(3)


def test_sensor_satisfies_protocol_and_pd() -> None:
    """p_d is constant inside the area and 0 outside; it is a DetectionSensor."""
    s = PositionSensor(0.8, 5.0, 2.0, AREA)
    assert isinstance(s, DetectionSensor)
    pd = s.detection_probability(POSE, np.array([[50.0, 50.0], [150.0, 50.0]]))
    np.testing.assert_array_equal(pd, [0.8, 0.0])


def test_likelihood_and_clutter_values() -> None:
    """g(z|x) is the 2-D Gaussian density; c(z) = rate / area inside the area."""
    s = PositionSensor(0.9, 2.0, 4.0, AREA)
    g = s.likelihood(POSE, np.array([[10.0, 10.0]]), np.array([[10.0, 10.0], [13.0, 14.0]]))
    peak = 1.0 / (2 * math.pi * 4.0)
    np.testing.assert_allclose(g, [[peak, peak * math.exp(-25.0 / 8.0)]])
    c = s.clutter_intensity(POSE, np.array([[1.0, 1.0], [-1.0, 1.0]]))
    np.testing.assert_allclose(c, [4.0 / 20000.0, 0.0])


def test_measure_counts() -> None:
    """Simulated scans detect about p_d of the targets and add about clutter_rate false alarms."""
    s = PositionSensor(0.7, 1.0, 3.0, AREA)
    rng = np.random.default_rng(0)
    targets = np.array([[50.0, 100.0]] * 10)
    det = clutter = 0
    for _ in range(400):
        z, origin = s.measure(targets, rng)
        assert z.shape == (origin.shape[0], 2)
        det += int((origin >= 0).sum())
        clutter += int((origin < 0).sum())
    assert det / 4000 == pytest.approx(0.7, abs=0.03)
    assert clutter / 400 == pytest.approx(3.0, abs=0.3)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"pd": 1.2}, "pd"),
    ({"sigma_m": 0.0}, "sigma_m"),
    ({"clutter_rate": -1.0}, "clutter_rate"),
    ({"area": [[0.0, 0.0], [0.0, 1.0]]}, "area"),
    ({"area": [[0.0, 1.0]]}, "area"),
])
def test_bad_parameters(kwargs: dict[str, object], field: str) -> None:
    """Invalid parameters raise InvalidInputError naming the field."""
    args: dict[str, object] = {"pd": 0.9, "sigma_m": 1.0, "clutter_rate": 1.0, "area": AREA}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        PositionSensor(**args)  # type: ignore[arg-type]
    assert err.value.field == field
