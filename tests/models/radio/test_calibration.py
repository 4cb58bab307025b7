"""The named calibrations of the radio signal model and the range they give."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.radio import RadioSignal
from searchtrack.models.radio.calibration import (
    CALIBRATIONS,
    DEFAULT_CALIBRATION,
    calibrated,
    zero_db_range_m,
)


def test_the_default_signal_holds_the_default_calibration() -> None:
    """RadioSignal() is the "fig5" calibration; "unscaled" has no calibration gain."""
    cal = CALIBRATIONS[DEFAULT_CALIBRATION]
    signal = RadioSignal()
    assert DEFAULT_CALIBRATION == "fig5"
    assert (signal.calibration_gain_db, signal.front_to_back_db) == (
        cal.calibration_gain_db, cal.front_to_back_db)
    assert calibrated(signal, "unscaled").calibration_gain_db == 0.0
    assert calibrated(calibrated(signal, "unscaled"), "fig5") == signal


@pytest.mark.parametrize("name", list(CALIBRATIONS))
def test_zero_db_range_is_where_the_peak_cell_meets_the_noise(name: str) -> None:
    """At the printed range, the strongest cell of a tag straight ahead has SNR 0 dB: a little
    nearer it is above, a little farther below; the gain moves it by 10^(G/(10κ))."""
    signal = calibrated(RadioSignal(), name)
    reach = zero_db_range_m(signal)
    peak = np.max(np.abs(signal.tag_leakage()), axis=1)
    for lab in range(signal.n_labels):
        for scale, above in ((0.99, True), (1.01, False)):
            gamma = float(signal.amplitude([scale * reach[lab], 0.0], [0.0, 0.0, 0.0]))
            snr = (gamma * peak[lab]) ** 2 / (2.0 * signal.cell_var)
            assert (snr > 1.0) == above
    louder = zero_db_range_m(RadioSignal(calibration_gain_db=signal.calibration_gain_db + 6.0))
    d3 = np.hypot(reach, signal.height_difference_m)
    d3_louder = np.hypot(louder, signal.height_difference_m)
    np.testing.assert_allclose(d3_louder / d3, 10 ** (6.0 / (10 * signal.path_loss_exponent)),
                               rtol=1e-9)
    back = zero_db_range_m(signal, behind=True)      # the back gain costs FB dB
    np.testing.assert_allclose(np.hypot(back, signal.height_difference_m) / d3,
                               10 ** (-signal.front_to_back_db / (10 * signal.path_loss_exponent)),
                               rtol=1e-9)


def test_a_tag_too_faint_to_reach_0_db_has_no_range() -> None:
    """A gain so low that even straight below the SNR is under 0 dB gives range 0."""
    faint = RadioSignal(calibration_gain_db=-120.0)
    assert np.all(zero_db_range_m(faint) == 0.0)
    assert math.isfinite(float(zero_db_range_m(RadioSignal()).max()))


def test_an_unknown_calibration_is_named() -> None:
    with pytest.raises(InvalidInputError, match="calibration"):
        calibrated(RadioSignal(), "literal")
