"""LRT sensor model: sensitivity, criterion, ROC, altitude model (6.4)–(6.7), bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.lrt_sensor import (
    THESIS_ALTITUDES_M,
    AltitudeModel,
    SensorModel,
    roc,
    sensitivity,
    z_score,
)

# z(0.95) = 1.644854, z(0.925) = 1.439531, z(0.90) = 1.281552, z(0.875) = 1.150349,
# z(0.10) = −1.281552, z(0.075) = −1.439531, z(0.05) = −1.644854, z(0.025) = −1.959964
# (standard normal tables); m = z(Pd) − z(Pf) (3.9), c = m/2 (§4.1).
SENSITIVITY = [
    (0.95, 0.10, 2.9264),
    (0.95, 0.05, 3.2897),
    (0.95, 0.025, 3.6048),
    (0.925, 0.05, 3.0844),
    (0.90, 0.075, 2.7211),
    (0.875, 0.10, 2.4319),
]

# P(ζ > c | target), P(ζ > c | no target) at c = m/2 (§4.1)
EFFECTIVE = [
    (0.95, 0.10, 0.928, 0.072),
    (0.95, 0.025, 0.964, 0.036),
    (0.925, 0.05, 0.939, 0.062),
    (0.90, 0.075, 0.913, 0.087),
    (0.875, 0.10, 0.888, 0.112),
]

# Table 6.3: altitude (m), Pd, Pf, s (m), ρ (m)
TABLE_6_3 = [
    (457.2, 0.95, 0.025, 5.0, 93.5),
    (914.4, 0.925, 0.05, 10.0, 187.0),
    (1372.0, 0.90, 0.075, 15.0, 280.0),
    (1828.8, 0.875, 0.10, 20.0, 374.0),
]


# ----- detection statistics ---------------------------------------------------------------------


def test_z_score_hand_values() -> None:
    """The quantile z(p) is 0 at ½, ±1.959964 at 0.975/0.025 and vectorises."""
    assert z_score(0.5) == 0.0
    assert z_score(0.975) == pytest.approx(1.959964, abs=1e-6)
    np.testing.assert_allclose(z_score([0.025, 0.5]), [-1.959964, 0.0], atol=1e-6)


@pytest.mark.parametrize(("pd", "pf", "m"), SENSITIVITY)
def test_sensitivity_and_criterion_match_hand_values(pd: float, pf: float, m: float) -> None:
    """m = z(Pd) − z(Pf) (3.9) and c = m/2 match the hand-computed table to 1e-4."""
    assert sensitivity(pd, pf) == pytest.approx(m, abs=1e-4)
    sensor = SensorModel(pd=pd, pf=pf, footprint_radius_m=120.0)
    assert sensor.sensitivity == pytest.approx(m, abs=1e-4)
    assert sensor.criterion == pytest.approx(m / 2, abs=1e-4)


def test_thesis_example_sensitivity() -> None:
    """The thesis's example Pd = 0.95, Pf = 0.1 gives m = 2.92 (§3.3), exactly 2.926405."""
    assert sensitivity(0.95, 0.10) == pytest.approx(2.926405, abs=1e-6)


@pytest.mark.parametrize(("pd", "pf", "hit", "false_hit"), EFFECTIVE)
def test_rates_at_the_criterion(pd: float, pf: float, hit: float, false_hit: float) -> None:
    """Thresholding ζ at c = m/2 gives the effective hit and false-hit rates."""
    sensor = SensorModel(pd=pd, pf=pf, footprint_radius_m=1.0)
    assert sensor.hit_rate == pytest.approx(hit, abs=1e-3)
    assert sensor.false_hit_rate == pytest.approx(false_hit, abs=1e-3)


def test_roc_passes_through_the_operating_point() -> None:
    """The ROC at criterion z(1 − Pf) is (Pf, Pd), and Pd rises with Pf along the curve."""
    m = sensitivity(0.95, 0.10)
    pf, pd = roc(m, [z_score(0.90), 0.0, -1.0, 3.0])
    assert pf[0] == pytest.approx(0.10) and pd[0] == pytest.approx(0.95)
    order = np.argsort(pf)
    assert np.all(np.diff(pd[order]) > 0)


def test_log_likelihood_ratio_is_m_times_zeta_minus_half_m() -> None:
    """The LRT increment is m(ζ − m/2): −m²/2 at ζ = 0, +m²/2 at ζ = m, 0 at ζ = c."""
    sensor = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=120.0)
    m = sensor.sensitivity
    np.testing.assert_allclose(sensor.log_likelihood_ratio([0.0, m, m / 2]),
                               [-m * m / 2, m * m / 2, 0.0], atol=1e-12)
    # the same value from the Gaussian densities (3.10), (3.11) at ζ = 0.7
    zeta = 0.7
    assert sensor.log_likelihood_ratio(zeta) == pytest.approx(
        -((zeta - m) ** 2) / 2 + zeta**2 / 2)


def test_false_alarm_mean_defaults_to_pf() -> None:
    """Without false_alarms_per_scan the Poisson clutter mean is Pf per footprint per step."""
    assert SensorModel(pd=0.9, pf=0.05, footprint_radius_m=10.0).false_alarm_mean == 0.05
    sensor = SensorModel(pd=0.9, pf=0.05, footprint_radius_m=10.0, false_alarms_per_scan=2.0)
    assert sensor.false_alarm_mean == 2.0


# ----- altitude model (6.4)–(6.7) ----------------------------------------------------------------


@pytest.mark.parametrize(("h", "pd", "pf", "s", "rho"), TABLE_6_3)
def test_altitude_model_reproduces_table_6_3(
    h: float, pd: float, pf: float, s: float, rho: float
) -> None:
    """With h_ref = 457.2 m, (6.4)–(6.7) give Table 6.3 (ρ at 1372 m: 280.5 by (6.7), not 280.0)."""
    sensor = AltitudeModel(reference_altitude_m=457.2).sensor(h)
    assert sensor.pd == pytest.approx(pd, abs=1e-4)
    assert sensor.pf == pytest.approx(pf, abs=1e-4)
    assert sensor.position_noise_m == pytest.approx(s, abs=0.01)
    if h == 1372.0:  # the table's erratum: 18.4/90 · 1372 = 280.50
        assert sensor.footprint_radius_m == pytest.approx(280.50, abs=0.01)
    else:
        assert sensor.footprint_radius_m == pytest.approx(rho, abs=0.15)  # table rounds


@pytest.mark.parametrize(("h", "pd", "pf", "s", "rho"), TABLE_6_3)
def test_printed_altitude_model_is_close_to_table(
    h: float, pd: float, pf: float, s: float, rho: float
) -> None:
    """The formulas as printed (h/457) stay within 1e-4 of Table 6.3's Pd and Pf and 0.03 m of s."""
    model = AltitudeModel()
    assert float(model.pd(h)) == pytest.approx(pd, abs=1e-4)
    assert float(model.pf(h)) == pytest.approx(pf, abs=1e-4)
    assert float(model.position_noise_m(h)) == pytest.approx(s, abs=0.03)
    assert float(model.footprint_radius_m(h)) == pytest.approx(rho, abs=0.6)


def test_altitude_model_is_monotone() -> None:
    """With altitude Pd and m fall while Pf, s and ρ rise (§6.2)."""
    model = AltitudeModel()
    h = np.linspace(100.0, 5000.0, 50)
    assert np.all(np.diff(model.pd(h)) < 0)
    assert np.all(np.diff(model.sensitivity(h)) < 0)
    for rising in (model.pf(h), model.position_noise_m(h), model.footprint_radius_m(h)):
        assert np.all(np.diff(rising) > 0)
    assert np.all(model.sensitivity(THESIS_ALTITUDES_M) > 0)


def test_altitude_model_ends_where_pd_meets_pf() -> None:
    """Pd = Pf at max_altitude_m (19.5·457 m); at or above it the altitude is refused."""
    model = AltitudeModel()
    assert model.max_altitude_m == pytest.approx(19.5 * 457.0)
    h_top = model.max_altitude_m * (1 - 1e-9)
    assert float(model.pd(h_top)) == pytest.approx(float(model.pf(h_top)), abs=1e-6)
    for bad in (model.max_altitude_m, -10.0, 0.0, math.nan):
        with pytest.raises(InvalidInputError) as err:
            model.pd(bad)
        assert err.value.field == "altitude_m"


# ----- bad input -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"pd": 1.0}, "pd"),
        ({"pd": 0.0}, "pd"),
        ({"pd": 1.2}, "pd"),
        ({"pd": math.nan}, "pd"),
        ({"pf": 0.0}, "pf"),
        ({"pf": -0.1}, "pf"),
        ({"pf": 0.97}, "pd"),  # pd must exceed pf
        ({"footprint_radius_m": 0.0}, "footprint_radius_m"),
        ({"footprint_radius_m": math.inf}, "footprint_radius_m"),
        ({"position_noise_m": -1.0}, "position_noise_m"),
        ({"position_noise_m": math.nan}, "position_noise_m"),
        ({"false_alarms_per_scan": -0.5}, "false_alarms_per_scan"),
        ({"pd": True}, "pd"),
    ],
)
def test_sensor_model_refuses_bad_values(kwargs: dict[str, object], field: str) -> None:
    """SensorModel names the bad field: Pd, Pf outside (0, 1), Pd ≤ Pf, NaN, ρ ≤ 0, s < 0."""
    args: dict[str, object] = {"pd": 0.95, "pf": 0.1, "footprint_radius_m": 120.0,
                               "position_noise_m": 5.0} | kwargs
    with pytest.raises(InvalidInputError) as err:
        SensorModel(**args)  # type: ignore[arg-type]
    assert err.value.field == field


def test_altitude_model_refuses_bad_constants() -> None:
    """AltitudeModel refuses a zero focal length and a NaN reference altitude, naming them."""
    for kwargs, field in (({"focal_length_m": 0.0}, "focal_length_m"),
                          ({"reference_altitude_m": math.nan}, "reference_altitude_m")):
        with pytest.raises(InvalidInputError) as err:
            AltitudeModel(**kwargs)  # type: ignore[arg-type]
        assert err.value.field == field
