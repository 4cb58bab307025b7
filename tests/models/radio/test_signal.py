"""RadioSignal: the window's DTFT, influence regions, calibration and validation of the design."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.radio.calibration import CALIBRATIONS, calibrated
from searchtrack.models.radio.signal import FIG5_GAIN_DB, RadioSignal, blackman_harris, window_dtft

FS, L = 2e6, 256
BIN_HZ = FS / L  # 7812.5 Hz


@pytest.fixture(scope="module")
def paper() -> RadioSignal:
    return RadioSignal()


def test_paper_defaults_derive_the_frame_design(paper: RadioSignal) -> None:
    """R = 18000, Σw = 91.84, E_w ≈ 66.04, Σ_z = E_w Σ_η / 2, frames of τ = 0.1..0.4 s."""
    assert paper.n_labels == 4
    assert paper.hop == 18_000
    assert paper.window.shape == (256,)
    assert math.isclose(float(paper.window.sum()), 91.84, rel_tol=1e-12)
    assert paper.window_energy == pytest.approx(66.04, abs=0.005)
    assert paper.cell_var == pytest.approx(paper.window_energy * 0.025**2 / 2, rel=1e-12)
    np.testing.assert_array_equal(paper.frame_of([0.1, 0.2, 0.3, 0.4]), [12, 23, 34, 45])
    np.testing.assert_array_equal(paper.frame_of([1.1, -0.9]), [12, 12])  # τ mod T0
    np.testing.assert_array_equal(paper.tag_bins()[:, 4], [17, 26, 51, 108])
    assert paper.tag_bins().shape == paper.tag_leakage().shape == (4, 9)
    with pytest.raises(ValueError, match="read-only"):
        paper.window[0] = 1.0


def test_on_bin_leakage_ratios() -> None:
    """|W[±k]|/|W[0]| = 0.6805, 0.1969, 0.0163, 0 for k = 1..4 (periodic BH4, N = 256)."""
    sig = RadioSignal(frequencies_hz=(16 * BIN_HZ, 48 * BIN_HZ))  # on-bin tones
    leak = sig.tag_leakage()
    for row in leak:
        ratio = row / row[4]
        np.testing.assert_allclose(ratio[[3, 5]], 0.6805, atol=5e-5)
        np.testing.assert_allclose(ratio[[2, 6]], 0.1969, atol=5e-5)
        np.testing.assert_allclose(ratio[[1, 7]], 0.0163, atol=5e-5)
        np.testing.assert_allclose(ratio[[0, 8]], 0.0, atol=1e-12)
    assert leak[0, 4] == pytest.approx(91.84)


def test_dtft_matches_the_fft_of_a_windowed_tone(paper: RadioSignal) -> None:
    """spectrum(λ) is the L-point DFT of the windowed unit tone e^{j2π f n/f_s}, off-bin too."""
    n = np.arange(paper.window_size)
    for lam, f in enumerate(paper.frequencies_hz):
        direct = np.fft.fft(paper.window * np.exp(2j * np.pi * f * n / FS), L)
        np.testing.assert_allclose(paper.spectrum(lam), direct, atol=1e-9)
        np.testing.assert_allclose(np.abs(direct[paper.tag_bins()[lam]]), paper.tag_leakage()[lam],
                                   atol=1e-9)
    # Scalloping: the off-bin 131 kHz tone peaks below Σw.
    assert paper.tag_leakage()[0].max() < 0.99 * 91.84
    w = blackman_harris(8)
    np.testing.assert_allclose(window_dtft(w, np.zeros((2, 3)), 8), np.full((2, 3), w.sum()))


@pytest.mark.parametrize("name", list(CALIBRATIONS))
def test_calibration_gives_17_8_db_at_100_m_plus_its_gain(paper: RadioSignal, name: str) -> None:
    """Per-cell SNR ν²/(2Σ_z) of an on-bin tone straight ahead at 100 m ground range ≈ 17.8 dB
    without the calibration gain G_c, and G_c dB more with it."""
    signal = calibrated(paper, name)
    g_c = CALIBRATIONS[name].calibration_gain_db
    gamma = float(signal.amplitude([100.0, 0.0], [0.0, 0.0, 0.0]))
    nu = gamma * signal.window.sum()
    snr_db = 10 * math.log10(nu**2 / (2 * signal.cell_var))
    assert snr_db == pytest.approx(17.8 + g_c, abs=0.1)
    d = math.hypot(100.0, 29.0)
    expected = 0.0059 * 10 ** ((72 + g_c) / 20) * d ** (-3.1068 / 2)
    assert gamma == pytest.approx(expected, rel=1e-12)
    assert paper.calibration_gain_db == FIG5_GAIN_DB == CALIBRATIONS["fig5"].calibration_gain_db


def test_antenna_gain_and_amplitude_geometry(paper: RadioSignal) -> None:
    """G_a is 1 ahead, b = 10^(−FB/20) behind; γ falls with range and is vectorised."""
    b = 10 ** (-10 / 20)
    np.testing.assert_allclose(paper.antenna_gain([1.0, 0.0, -1.0]), [1.0, (1 + b) / 2, b])
    pose = [500.0, 500.0, math.pi / 2]  # heading north
    ahead, behind = paper.amplitude([[500.0, 700.0], [500.0, 300.0]], pose)
    assert behind / ahead == pytest.approx(b)
    xy = np.random.default_rng(0).uniform(0, 1500, (3, 5, 2))
    gamma = paper.amplitude(xy, pose)
    assert gamma.shape == (3, 5)
    assert paper.amplitude([500.0, 500.0], pose) == pytest.approx(  # below counts as ahead
        0.0059 * 10 ** ((72 + paper.calibration_gain_db) / 20) * 29.0 ** (-3.1068 / 2))
    near, far = paper.amplitude([[600.0, 500.0], [900.0, 500.0]], [500.0, 500.0, 0.0])
    assert near > far > 0


def test_with_noise_returns_a_validated_copy(paper: RadioSignal) -> None:
    """with_noise changes Σ_η only (and Σ_z with it); bad variances name noise_var_v2."""
    loud = paper.with_noise(0.05**2)
    assert loud.noise_var_v2 == 0.05**2 and paper.noise_var_v2 == 0.025**2
    assert loud.cell_var == pytest.approx(4 * paper.cell_var)
    assert loud.frequencies_hz == paper.frequencies_hz
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(InvalidInputError) as err:
            paper.with_noise(bad)
        assert err.value.field == "noise_var_v2"


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"frequencies_hz": (5e3, 200e3)}, "window_size"),        # eq. 9: f_s/f > N_w
    ({"pulse_width_s": 2e-4}, "window_size"),                 # eq. 9: N_w ≥ R = 200
    ({"frequencies_hz": (131e3, 140e3)}, "window_size"),      # eq. 19: Δf too small
    ({"frames": 112}, "frames"),                              # M·R + N_w > T0 f_s
    ({"fft_size": 128}, "fft_size"),
    ({"frequencies_hz": (2 * BIN_HZ, 40 * BIN_HZ)}, "frequencies_hz"),  # S(λ) below bin 0
    ({"frequencies_hz": (16 * BIN_HZ, 24 * BIN_HZ)}, "frequencies_hz"),  # regions overlap
    ({"frequencies_hz": (131e3, 131e3)}, "frequencies_hz"),
    ({"frequencies_hz": (131e3, 1.2e6)}, "frequencies_hz"),   # above f_s/2
    ({"frequencies_hz": ()}, "frequencies_hz"),
    ({"frequencies_hz": "131e3"}, "frequencies_hz"),
    ({"frequencies_hz": (131e3, math.nan)}, "frequencies_hz"),
    ({"noise_var_v2": -1.0}, "noise_var_v2"),
    ({"amplitude_v": math.nan}, "amplitude_v"),
    ({"sample_rate_hz": 0.0}, "sample_rate_hz"),
    ({"frames": 0}, "frames"),
    ({"frames": 11.0}, "frames"),
    ({"half_width_bins": -1}, "half_width_bins"),
    ({"height_difference_m": -1.0}, "height_difference_m"),
    ({"front_to_back_db": -3.0}, "front_to_back_db"),
    ({"receiver_gain_db": math.inf}, "receiver_gain_db"),
    ({"pulse_width_s": 2.0}, "pulse_width_s"),
])
def test_bad_designs_name_the_field(kwargs: dict[str, object], field: str) -> None:
    """Each violated condition raises InvalidInputError naming the field at fault."""
    with pytest.raises(InvalidInputError) as err:
        RadioSignal(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_eq19_boundary_is_accepted() -> None:
    """Tones exactly N_m bins apart with h = 3 satisfy eq. 19 and do not overlap."""
    sig = RadioSignal(frequencies_hz=(16 * BIN_HZ, 24 * BIN_HZ), half_width_bins=3)
    assert sig.tag_bins()[0, -1] < sig.tag_bins()[1, 0]
    assert RadioSignal(frequencies_hz=[131e3]).frequencies_hz == (131e3,)


def test_bad_calls(paper: RadioSignal) -> None:
    """Bad labels, positions and poses raise InvalidInputError naming the argument."""
    for label, field in ((4, "label"), (-1, "label"), (1.0, "label")):
        with pytest.raises(InvalidInputError) as err:
            paper.spectrum(label)  # type: ignore[arg-type]
        assert err.value.field == field
    with pytest.raises(InvalidInputError, match="tag_xy"):
        paper.amplitude([1.0, 2.0, 3.0], [0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="uav_pose"):
        paper.amplitude([1.0, 2.0], [0.0, 0.0])
    with pytest.raises(InvalidInputError, match="uav_pose"):
        paper.amplitude([1.0, 2.0], [0.0, math.nan, 0.0])
