"""The disc camera: Eq. 10 and Eq. 11 by hand, clutter densities, and detect() statistics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import grid_network
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import DirectedRoads

CENTRE = np.array([100.0, 100.0])


@pytest.fixture(scope="module")
def grid3() -> DirectedRoads:
    """The paper's 3×3 map of 100 m roads."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def test_likelihood_by_hand() -> None:
    """Eq. 10: (1 − P_FA)/(2πσ²)·exp(−d²/2σ²) + P_FA·c, over any leading shape."""
    sensor = DiscSensor(sigma2_m2=5.0, p_fa=0.02)
    pts = np.zeros((2, 3, 2))
    pts[0, 1] = [3.0, 4.0]
    lik = sensor.likelihood(pts, [0.0, 0.0], 1e-3)
    assert lik.shape == (2, 3)
    gain = 0.98 / (2 * math.pi * 5.0)
    assert lik[0, 0] == pytest.approx(gain + 2e-5)
    assert lik[0, 1] == pytest.approx(gain * math.exp(-25 / 10) + 2e-5)
    far = sensor.likelihood(np.array([[1e4, 0.0]]), [0.0, 0.0], 1e-3)
    assert far[0] == pytest.approx(2e-5)
    assert sensor.detection_gain == pytest.approx(gain)


def test_miss_likelihood_uses_the_reduced_disc() -> None:
    """Eq. 11 as intended: P_FN within 0.75·30 = 22.5 m of the UAV, 1 beyond (even in view)."""
    sensor = DiscSensor()
    assert sensor.negative_radius_m == pytest.approx(22.5)
    pts = np.array([[0.0, 0.0], [22.0, 0.0], [23.0, 0.0], [29.0, 0.0], [100.0, 0.0]])
    np.testing.assert_allclose(sensor.miss_likelihood(pts, [0.0, 0.0]),
                               [0.05, 0.05, 1.0, 1.0, 1.0])
    np.testing.assert_array_equal(sensor.in_view(pts, [0.0, 0.0]),
                                  [True, True, True, True, False])


def test_clutter_densities(grid3: DirectedRoads) -> None:
    """'roads': one over the directed road length; 'view': one over the directed road in view."""
    assert DiscSensor().clutter_density(grid3) == pytest.approx(1 / 2400)
    view = DiscSensor(clutter="view")
    assert view.clutter_density(grid3, CENTRE) == pytest.approx(1 / 240)
    assert view.clutter_density(grid3, [50.0, 50.0]) == 0.0
    with pytest.raises(InvalidInputError, match="uav_xy"):
        view.clutter_density(grid3)


def test_detect_rate_and_noise(grid3: DirectedRoads) -> None:
    """A target in view is detected with probability 1 − P_FN, with N(0, σ² I) noise."""
    sensor = DiscSensor(p_fa=0.0, p_fn=0.2, sigma2_m2=4.0)
    rng = np.random.default_rng(0)
    target = np.array([[110.0, 100.0]])
    ys = [sensor.detect(CENTRE, target, rng, grid3) for _ in range(4000)]
    counts = np.array([y.shape[0] for y in ys])
    assert set(counts.tolist()) <= {0, 1}
    assert counts.mean() == pytest.approx(0.8, abs=3 * math.sqrt(0.16 / 4000))
    err = np.concatenate(ys) - target
    np.testing.assert_allclose(err.mean(axis=0), 0.0, atol=0.1)
    np.testing.assert_allclose(err.var(axis=0), 4.0, rtol=0.08)


def test_targets_out_of_view_are_never_detected(grid3: DirectedRoads) -> None:
    """31 m away from a 30 m view: no detections without clutter."""
    sensor = DiscSensor(p_fa=0.0, p_fn=0.0)
    rng = np.random.default_rng(1)
    y, src = sensor.detect_labelled(CENTRE, [[131.0, 100.0], [100.0, 129.0]], rng, grid3)
    np.testing.assert_array_equal(src, [1])
    assert y.shape == (1, 2)


def test_clutter_rate_and_uniformity_on_roads_in_view(grid3: DirectedRoads) -> None:
    """A false alarm comes with probability P_FA, on a road inside the view, spread evenly over
    the four arms at the centre node."""
    sensor = DiscSensor(p_fa=0.3)
    rng = np.random.default_rng(2)
    far = np.array([[0.0, 0.0]])
    fa: list[np.ndarray] = []
    for _ in range(6000):
        y, src = sensor.detect_labelled(CENTRE, far, rng, grid3)
        assert np.all(src == -1)
        fa.extend(y)
    pts = np.array(fa)
    assert len(pts) / 6000 == pytest.approx(0.3, abs=3 * math.sqrt(0.21 / 6000))
    rel = pts - CENTRE
    assert np.all(np.hypot(*rel.T) <= 30.0 + 1e-9)
    assert np.all(np.min(np.abs(rel), axis=1) < 1e-9)  # on the road x = 100 or y = 100
    arm = np.where(np.abs(rel[:, 0]) > np.abs(rel[:, 1]), np.sign(rel[:, 0]) + 1,
                   np.sign(rel[:, 1]) + 2.5)
    _, counts = np.unique(arm, return_counts=True)
    np.testing.assert_allclose(counts / len(pts), 0.25, atol=0.03)
    radius = np.abs(rel).max(axis=1)
    np.testing.assert_allclose(np.quantile(radius, [0.25, 0.5, 0.75]), [7.5, 15.0, 22.5],
                               atol=1.0)


def test_no_clutter_without_roads_in_view(grid3: DirectedRoads) -> None:
    """A view over a block's interior holds no road, so no false alarm can fall there."""
    sensor = DiscSensor(p_fa=0.99)
    rng = np.random.default_rng(3)
    assert all(sensor.detect([50.0, 50.0], np.empty((0, 2)), rng, grid3).shape == (0, 2)
               for _ in range(50))


def test_detect_is_deterministic_and_shuffled(grid3: DirectedRoads) -> None:
    """A seed gives the same scan; the order of the detections carries no identity."""
    sensor = DiscSensor(p_fn=0.0, p_fa=0.0)
    targets = np.array([[100.0, 105.0], [105.0, 100.0]])
    a = sensor.detect_labelled(CENTRE, targets, np.random.default_rng(5), grid3)
    b = sensor.detect_labelled(CENTRE, targets, np.random.default_rng(5), grid3)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    rng = np.random.default_rng(6)
    firsts = {int(sensor.detect_labelled(CENTRE, targets, rng, grid3)[1][0]) for _ in range(40)}
    assert firsts == {0, 1}


@pytest.mark.parametrize(("field", "value"), [
    ("fov_radius_m", 0.0), ("sigma2_m2", -1.0), ("p_fa", 1.0), ("p_fn", -0.1),
    ("negative_radius_factor", 0.0), ("negative_radius_factor", 1.5), ("clutter", "area"),
])
def test_bad_parameters_name_the_field(field: str, value: object) -> None:
    """Each parameter is checked in the constructor."""
    with pytest.raises(InvalidInputError, match=field):
        DiscSensor(**{field: value})  # type: ignore[arg-type]


def test_bad_call_arguments_name_the_field(grid3: DirectedRoads) -> None:
    """NaN or misshapen inputs are refused with the field's name."""
    sensor = DiscSensor()
    rng = np.random.default_rng(0)
    with pytest.raises(InvalidInputError, match="uav_xy"):
        sensor.detect([np.nan, 0.0], [[0.0, 0.0]], rng, grid3)
    with pytest.raises(InvalidInputError, match="target_points"):
        sensor.detect(CENTRE, [[0.0, 0.0, 0.0]], rng, grid3)
    with pytest.raises(InvalidInputError, match="rng"):
        sensor.detect(CENTRE, [[0.0, 0.0]], 0, grid3)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match=r"^y="):
        sensor.likelihood(np.zeros((3, 2)), [np.nan, 0.0], 1e-3)
    with pytest.raises(InvalidInputError, match="clutter_density"):
        sensor.likelihood(np.zeros((3, 2)), [0.0, 0.0], -1.0)
