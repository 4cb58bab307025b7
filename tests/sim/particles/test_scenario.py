"""The standard SMC-PHD scenario: shapes, targets kept inside the area, seeding, nearly
constant velocity, scan sizes, and bad arguments named."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.particles.scenario import STANDARD_AREA, standard_scenario


def test_shapes_and_models() -> None:
    """T scans of (k, 2) detections and (T, n, 4) truth, with the models and Δt asked for."""
    sc = standard_scenario(1, n_targets=3, n_scans=12, dt_s=0.5, q=0.2, pd=0.8, sigma_m=4.0,
                           clutter_rate=2.0)
    assert sc.truth.shape == (12, 3, 4) and len(sc.scans) == 12
    assert all(z.ndim == 2 and z.shape[1] == 2 for z in sc.scans)
    assert sc.dt_s == 0.5 and sc.motion.q == 0.2
    assert (sc.sensor.pd, sc.sensor.sigma_m, sc.sensor.clutter_rate) == (0.8, 4.0, 2.0)
    np.testing.assert_array_equal(sc.sensor.area, STANDARD_AREA)


def test_targets_start_inside_and_never_leave() -> None:
    """Every target starts in the inner 80 % of the area and stays in it to the last scan."""
    truth = standard_scenario(2, n_targets=10, n_scans=40).truth
    start = truth[0, :, :2]
    assert np.all((start >= 100.0) & (start <= 900.0))
    assert np.all((truth[:, :, :2] >= 0.0) & (truth[:, :, :2] <= 1000.0))


def test_same_seed_same_run() -> None:
    """The seed fixes truth and scans; another seed changes them."""
    a, b = standard_scenario(3, n_targets=4, n_scans=5), standard_scenario(3, n_targets=4,
                                                                          n_scans=5)
    np.testing.assert_array_equal(a.truth, b.truth)
    for za, zb in zip(a.scans, b.scans, strict=True):
        np.testing.assert_array_equal(za, zb)
    assert not np.array_equal(a.truth, standard_scenario(4, n_targets=4, n_scans=5).truth)


def test_targets_move_at_nearly_constant_velocity() -> None:
    """With almost no process noise and no initial speed spread, targets sit still; with
    q → 0, positions advance by v·Δt each scan."""
    still = standard_scenario(5, n_targets=3, n_scans=6, q=1e-12, speed_sigma_mps=0.0).truth
    np.testing.assert_allclose(still - still[0], 0.0, atol=1e-4)
    run = standard_scenario(5, n_targets=3, n_scans=6, dt_s=2.0, q=1e-12).truth
    np.testing.assert_allclose(np.diff(run[:, :, :2], axis=0), 2.0 * run[:-1, :, 2:], atol=1e-4)


def test_scan_sizes_are_detections_plus_clutter() -> None:
    """A scan holds about p_d·n detections and λ clutter points: 0.9·10 + 10 = 19 on average."""
    scans = standard_scenario(6).scans
    sizes = np.array([z.shape[0] for z in scans])
    assert sizes.size == 100
    assert sizes.mean() == pytest.approx(19.0, abs=1.5)
    assert np.all((np.vstack(scans) >= -100.0) & (np.vstack(scans) <= 1100.0))


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"n_targets": -1}, "n_targets"),
    ({"n_scans": 0}, "n_scans"),
    ({"dt_s": 0.0}, "dt_s"),
    ({"speed_sigma_mps": -1.0}, "speed_sigma_mps"),
    ({"area": [[0.0, 1000.0], [500.0, 500.0]]}, "area"),
    ({"q": 0.0}, "q"),
])
def test_bad_arguments_are_named(kwargs: dict[str, object], field: str) -> None:
    """Negative counts, no scans, non-positive steps, negative speed spreads, empty areas and
    zero process noise are refused by name."""
    with pytest.raises(InvalidInputError) as err:
        standard_scenario(0, **kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_zero_targets_give_clutter_only_scans() -> None:
    """With no targets the truth is empty and every scan holds clutter alone."""
    sc = standard_scenario(0, n_targets=0, n_scans=5, clutter_rate=3.0)
    assert sc.truth.shape == (5, 0, 4) and len(sc.scans) == 5
    assert all(z.ndim == 2 and z.shape[1] == 2 for z in sc.scans)
    assert all(np.all((z >= 0.0) & (z <= 1000.0)) for z in sc.scans)
