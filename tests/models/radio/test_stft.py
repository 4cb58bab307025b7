"""Spectrogram simulation: time-domain and STFT-domain routes agree where the model holds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.radio.signal import RadioSignal
from searchtrack.models.radio.stft import (
    ideal_stft,
    simulate_stft,
    simulate_time_domain,
    stft_magnitude,
)

BIN_HZ = 2e6 / 256
POSE = np.array([0.0, 0.0, 0.0])
#: A small receiver (20 frames) with one on-bin tone at bin 32 and one off-bin tone.
SMALL = RadioSignal(frequencies_hz=(32 * BIN_HZ, 401e3), frames=20, calibration_gain_db=0.0)


def _tau_for_frame(sig: RadioSignal, frame: int) -> float:
    """A pulse offset whose first whole frame is ``frame`` (well inside the hop)."""
    return (frame - 0.5) * sig.hop / sig.sample_rate_hz


def test_stft_magnitude_of_a_windowed_tone() -> None:
    """An on-bin unit tone peaks at Σw in its bin; a bad frame shape is refused."""
    n = np.arange(256)
    frames = np.exp(2j * np.pi * 32 * n / 256)[None, :].repeat(3, axis=0)
    z = stft_magnitude(SMALL, frames)
    assert z.shape == (3, 256)
    np.testing.assert_allclose(z[:, 32], SMALL.window.sum())
    assert z[:, 40].max() < 1e-9
    with pytest.raises(InvalidInputError, match="frames"):
        stft_magnitude(SMALL, np.ones((3, 100), dtype=complex))
    with pytest.raises(InvalidInputError, match="frames"):
        stft_magnitude(SMALL, np.full((1, 256), np.nan, dtype=complex))


def test_ideal_stft_is_gamma_w_on_the_cells_and_zero_elsewhere() -> None:
    """Noise-free |ΣG| equals γ|W(l − fL/f_s)| on {m(τ), m(τ)+1} × S(λ) and 0 elsewhere."""
    xy = np.array([[150.0, 40.0], [-300.0, 200.0]])
    tau = np.array([_tau_for_frame(SMALL, 5), _tau_for_frame(SMALL, 11)])
    z = ideal_stft(SMALL, xy, [0, 1], tau, POSE)
    expected = np.zeros_like(z)
    gamma = SMALL.amplitude(xy, POSE)
    for lam in (0, 1):
        m = int(SMALL.frame_of(tau[lam]))
        expected[m:m + 2, SMALL.tag_bins()[lam]] = gamma[lam] * SMALL.tag_leakage()[lam]
    np.testing.assert_allclose(z, expected, rtol=1e-12, atol=0.0)
    assert np.count_nonzero(z) == 2 * 2 * 9


def test_frames_past_the_last_are_dropped() -> None:
    """m(τ) = M−1 keeps one frame; m(τ) ≥ M keeps none (frames ∩ [0, M))."""
    last = _tau_for_frame(SMALL, SMALL.frames - 1)
    z = ideal_stft(SMALL, [[100.0, 0.0]], [0], [last], POSE)
    assert np.flatnonzero(z.any(axis=1)).tolist() == [SMALL.frames - 1]
    beyond = _tau_for_frame(SMALL, SMALL.frames)
    assert not ideal_stft(SMALL, [[100.0, 0.0]], [0], [beyond], POSE).any()
    rng = np.random.default_rng(0)
    quiet = SMALL.with_noise(1e-30)
    assert simulate_stft(quiet, [[100.0, 0.0]], [0], [beyond], POSE, rng).max() < 1e-10


def test_noise_free_time_domain_matches_the_model_inside_the_pulse() -> None:
    """With negligible noise and a pulse over whole frames both routes equal the ideal γ|W|."""
    quiet = SMALL.with_noise(1e-30)
    xy, labels = np.array([[120.0, 10.0], [80.0, -60.0]]), [0, 1]
    tau = np.array([_tau_for_frame(quiet, 3), _tau_for_frame(quiet, 8)])
    ideal = ideal_stft(quiet, xy, labels, tau, POSE)
    rng = np.random.default_rng(1)
    for z in (simulate_time_domain(quiet, xy, labels, tau, POSE, rng),
              simulate_stft(quiet, xy, labels, tau, POSE, rng)):
        for lam in (0, 1):
            m, cols = int(quiet.frame_of(tau[lam])), quiet.tag_bins()[lam]
            np.testing.assert_allclose(z[m:m + 2, cols], ideal[m:m + 2, cols], rtol=1e-9,
                                       atol=1e-9 * ideal.max())
        assert z[0].max() < 1e-10  # no tag there


def test_a_pulse_straddling_a_frame_gives_partial_signal_only_in_the_time_domain() -> None:
    """τ half-way through frame m0: the time domain sees half a window in m0 and m0 + 2."""
    quiet = SMALL.with_noise(1e-30)
    m0 = 6
    tau = (m0 * quiet.hop + quiet.window_size / 2) / quiet.sample_rate_hz
    assert int(quiet.frame_of(tau)) == m0 + 1
    peak_bin = 32
    full = float(ideal_stft(quiet, [[100.0, 0.0]], [0], [tau], POSE)[m0 + 1, peak_bin])
    rng = np.random.default_rng(2)
    td = simulate_time_domain(quiet, [[100.0, 0.0]], [0], [tau], POSE, rng)[:, peak_bin]
    st = simulate_stft(quiet, [[100.0, 0.0]], [0], [tau], POSE, rng)[:, peak_bin]
    assert 0.05 * full < td[m0] < 0.95 * full
    assert 0.05 * full < td[m0 + 2] < 0.95 * full
    assert td[m0 + 1] == pytest.approx(full, rel=1e-9)
    assert st[m0] < 1e-10
    np.testing.assert_allclose(st[m0 + 1:m0 + 3], full, rtol=1e-9)


def test_off_signal_cells_are_rayleigh_with_the_cell_variance() -> None:
    """Without tags both routes give Rayleigh cells of per-component variance Σ_z (KS test)."""
    rng = np.random.default_rng(3)
    scale = math.sqrt(SMALL.cell_var)
    empty = np.empty((0, 2))
    td = np.concatenate([simulate_time_domain(SMALL, empty, [], [], POSE, rng)[:, 4::8]
                         for _ in range(3)]).ravel()  # bins 8 apart are uncorrelated
    st = simulate_stft(SMALL, empty, [], [], POSE, rng).ravel()
    for sample in (td, st):
        assert stats.kstest(sample, "rayleigh", args=(0.0, scale)).pvalue > 1e-3
    assert stats.kstest(st, "rayleigh", args=(0.0, 1.3 * scale)).pvalue < 1e-6  # can fail


def test_on_signal_cells_are_rice_with_the_same_nu() -> None:
    """The peak cell of a strong on-bin tone is Rice(ν = γΣw, Σ_z) in both routes."""
    rng = np.random.default_rng(4)
    xy, tau = np.array([[200.0, 0.0]]), np.array([_tau_for_frame(SMALL, 4)])
    m = int(SMALL.frame_of(tau[0]))
    nu = float(SMALL.amplitude(xy, POSE)[0] * SMALL.window.sum())
    sigma = math.sqrt(SMALL.cell_var)
    assert 2.0 < nu / sigma < 10.0
    draws = {route: np.concatenate([f(SMALL, xy, [0], tau, POSE, rng)[m:m + 2, 32]
                                    for _ in range(150)])
             for route, f in (("time", simulate_time_domain), ("stft", simulate_stft))}
    rice = stats.rice(nu / sigma, scale=sigma)
    for sample in draws.values():
        assert stats.kstest(sample, rice.cdf).pvalue > 1e-3
        assert sample.mean() == pytest.approx(rice.mean(), rel=0.05)
        np.testing.assert_allclose(np.quantile(sample, [0.1, 0.5, 0.9]),
                                   rice.ppf([0.1, 0.5, 0.9]), rtol=0.08)


def test_simulation_is_deterministic_for_a_seed() -> None:
    """The same seed gives the same measurement in both routes."""
    args = (SMALL, [[50.0, 50.0]], [1], [0.02], POSE)
    for f in (simulate_time_domain, simulate_stft):
        a = f(*args, np.random.default_rng(9))
        b = f(*args, np.random.default_rng(9))
        np.testing.assert_array_equal(a, b)
        assert a.shape == (SMALL.frames, SMALL.fft_size)


@pytest.mark.parametrize(("xy", "labels", "tau", "pose", "field"), [
    ([[0.0, 0.0]], [2], [0.1], POSE, "tag_label"),
    ([[0.0, 0.0]], [0.5], [0.1], POSE, "tag_label"),
    ([[0.0, 0.0]], [0, 1], [0.1], POSE, "tag_label"),
    ([[0.0, math.nan]], [0], [0.1], POSE, "tag_xy"),
    ([[0.0, 0.0]], [0], [math.inf], POSE, "tag_tau"),
    ([[0.0, 0.0]], [0], [0.1], [0.0, 0.0], "uav_pose"),
])
def test_bad_tags_name_the_argument(xy: object, labels: object, tau: object, pose: object,
                                    field: str) -> None:
    """Mismatched or out-of-range tag descriptions raise InvalidInputError."""
    for f in (simulate_stft, simulate_time_domain):
        with pytest.raises(InvalidInputError) as err:
            f(SMALL, xy, labels, tau, pose, np.random.default_rng(0))  # type: ignore[arg-type]
        assert err.value.field == field
    with pytest.raises(InvalidInputError, match="rng"):
        simulate_stft(SMALL, [[0.0, 0.0]], [0], [0.1], POSE, 0)  # type: ignore[arg-type]
