"""The eq. 22 likelihood: Numba kernels against the SciPy reference, the Rice/Rayleigh pdfs
and the signal model's amplitudes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import i0e
from scipy.stats import rayleigh, rice

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.radio.likelihood import (
    amplitude,
    correlated_cells_temper,
    label_log_likelihoods,
    log_likelihood_ratio,
    log_likelihood_ratio_reference,
)
from searchtrack.models.radio import RadioSignal
from searchtrack.models.radio.stft import simulate_stft, simulate_time_domain

SIGNAL = RadioSignal()
M, L = SIGNAL.frames, SIGNAL.fft_size


def _noise(seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).rayleigh(math.sqrt(SIGNAL.cell_var), (M, L))


@pytest.mark.parametrize("label", range(SIGNAL.n_labels))
def test_kernel_matches_reference(label: int) -> None:
    """Kernel and SciPy reference agree to 1e-5 on random data, large arguments (x up to 1e4)
    and frames at and beyond the edges of [0, M)."""
    rng = np.random.default_rng(label)
    z = _noise(label)
    z[rng.random((M, L)) < 0.2] *= 30.0                       # strong cells: large z ν / Σ_z
    n = 4000
    gamma = np.concatenate([np.exp(rng.uniform(-9.0, -2.5, n - 6)), [0.0, 1e-12, 2e-4, 0.2,
                                                                    0.3, 0.02]])
    frame = rng.integers(-3, M + 3, n)
    frame[:8] = [-2, -1, 0, M - 2, M - 1, M, M + 1, 5]
    x_max = float(z.max() * gamma.max() * SIGNAL.tag_leakage()[label].max() / SIGNAL.cell_var)
    assert x_max > 1e4
    fast = log_likelihood_ratio(SIGNAL, z, label, gamma, frame)
    ref = log_likelihood_ratio_reference(SIGNAL, z, label, gamma, frame)
    assert np.all(np.isfinite(fast))
    np.testing.assert_allclose(fast, ref, rtol=1e-10, atol=1e-5)


def test_matches_rice_over_rayleigh_pdfs() -> None:
    """Eq. 22 is the sum of log Rice / Rayleigh pdf ratios (σ² = Σ_z) over the 2 × 9 cells."""
    z = _noise(3)
    sigma = math.sqrt(SIGNAL.cell_var)
    bins, leak = SIGNAL.tag_bins()[1], SIGNAL.tag_leakage()[1]
    gamma, frame = 2e-3, 40
    expect = 0.0
    for m in (frame, frame + 1):
        for b, lk in zip(bins, leak, strict=True):
            nu = gamma * lk
            expect += (rice.logpdf(z[m, b], nu / sigma, scale=sigma)
                       - rayleigh.logpdf(z[m, b], scale=sigma))
    got = log_likelihood_ratio(SIGNAL, z, 1, np.array([gamma]), np.array([frame]))
    assert got[0] == pytest.approx(expect, abs=1e-5)


def _frame_llr(z: np.ndarray, label: int, gamma: float, m: int) -> float:
    """One frame's share of eq. 22, written out with SciPy's i0e."""
    nu = gamma * SIGNAL.tag_leakage()[label]
    x = z[m, SIGNAL.tag_bins()[label]] * nu / SIGNAL.cell_var
    return float(np.sum(-(nu**2) / (2.0 * SIGNAL.cell_var) + np.log(i0e(x)) + x))


def test_frames_outside_contribute_nothing() -> None:
    """Frame M − 1 counts frame M − 1 only, −1 frame 0 only, M and −2 nothing; γ = 0 gives 0."""
    z = _noise(4)
    g = 3e-3
    frames = np.array([M - 2, M - 1, M, -1, -2, M + 40])
    out = log_likelihood_ratio(SIGNAL, z, 2, np.full(frames.size, g), frames)
    expect = [_frame_llr(z, 2, g, M - 2) + _frame_llr(z, 2, g, M - 1),
              _frame_llr(z, 2, g, M - 1), 0.0, _frame_llr(z, 2, g, 0), 0.0, 0.0]
    np.testing.assert_allclose(out, expect, atol=1e-5)
    assert out[1] != 0.0
    np.testing.assert_allclose(log_likelihood_ratio(SIGNAL, z, 2, np.zeros(3),
                                                    np.array([0, 5, 9])), 0.0, atol=1e-12)


def test_true_hypothesis_scores_highest() -> None:
    """On a noise-free tag footprint the true (γ, frame) beats a wrong frame and wrong γ."""
    gamma, frame, label = 4e-3, 30, 0
    z = np.zeros((M, L))
    for m in (frame, frame + 1):
        z[m, SIGNAL.tag_bins()[label]] = gamma * SIGNAL.tag_leakage()[label]
    cands = np.array([gamma, gamma, gamma / 4, gamma * 4])
    frames = np.array([frame, frame + 5, frame, frame])
    ll = log_likelihood_ratio(SIGNAL, z, label, cands, frames)
    assert ll[0] > 0.0
    assert ll[0] == ll.max()
    assert ll[1] < 0.0


def test_no_overflow_for_huge_arguments() -> None:
    """Arguments far beyond 1e4 (x ~ 1e9) stay finite and agree with the reference."""
    z = np.full((M, L), 50.0)
    g = np.array([1.0, 10.0, 100.0])
    f = np.array([3, 3, 3])
    fast = log_likelihood_ratio(SIGNAL, z, 0, g, f)
    ref = log_likelihood_ratio_reference(SIGNAL, z, 0, g, f)
    assert np.all(np.isfinite(fast))
    np.testing.assert_allclose(fast, ref, rtol=1e-9)


def test_label_log_likelihoods_matches_per_label() -> None:
    """The all-label form (γ and m(τ) computed inside the kernel) equals the per-label one with
    γ from the signal model and m(τ) from frame_of, also for τ outside [0, T0), at frame edges
    and for a tag straight below the UAV."""
    rng = np.random.default_rng(5)
    z = _noise(5)
    z[rng.random((M, L)) < 0.1] *= 20.0
    x = rng.uniform(0.0, 400.0, (SIGNAL.n_labels, 300, 4))
    tau = rng.uniform(-2.5, 2.5, (SIGNAL.n_labels, 300))
    edges = np.arange(8) * SIGNAL.hop / SIGNAL.sample_rate_hz        # τ with m(τ) exact
    tau[:, :10] = [*edges, SIGNAL.period_s, -SIGNAL.period_s]
    pose = np.array([150.0, 220.0, 0.7])
    x[:, 0, [0, 2]] = pose[:2]
    out = label_log_likelihoods(SIGNAL, z, x, tau, pose)
    assert out.shape == (SIGNAL.n_labels, 300)
    gamma = SIGNAL.amplitude(x[:, :, [0, 2]], pose)
    frame = SIGNAL.frame_of(tau)
    for lab in range(SIGNAL.n_labels):
        np.testing.assert_allclose(out[lab], log_likelihood_ratio(SIGNAL, z, lab, gamma[lab],
                                                                   frame[lab]),
                                   rtol=1e-12, atol=1e-12)


NEAR = RadioSignal(height_difference_m=0.0, reference_distance_m=5.0, front_to_back_db=20.0)


@pytest.mark.parametrize("signal", [SIGNAL, NEAR])
@pytest.mark.parametrize("pose", [[150.0, 220.0, 0.7], [0.0, 0.0, -3.0], [-40.0, 1e3, 12.0]])
def test_kernel_amplitude_equals_the_signal_model(signal: RadioSignal, pose: list[float]) -> None:
    """The kernel's γ is RadioSignal.amplitude to 1e-14 (relative): ahead, behind, straight
    below, inside the reference distance, far away; any leading shape."""
    rng = np.random.default_rng(6)
    xy = np.array(pose[:2]) + rng.normal(0.0, 300.0, (5, 400, 2))
    xy[0, :6] = np.array(pose[:2]) + np.array([[0.0, 0.0], [1.0, 2.0], [-3.0, 0.5], [1e5, 0.0],
                                               [0.0, -1e5], [2.0, -2.0]])
    got = amplitude(signal, xy, pose)
    assert got.shape == (5, 400)
    np.testing.assert_allclose(got, signal.amplitude(xy, pose), rtol=1e-14, atol=0.0)
    assert amplitude(signal, xy[0, 0], pose).shape == ()


def test_kernel_amplitude_bad_input() -> None:
    """Positions not (..., 2) or a bad pose raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError, match="tag_xy"):
        amplitude(SIGNAL, np.zeros((4, 3)), [0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="uav_pose"):
        amplitude(SIGNAL, np.zeros((4, 2)), [0.0, np.nan, 0.0])


GOOD_Z = np.ones((M, L))
NAN_Z = GOOD_Z.copy()
NAN_Z[3, 4] = np.nan


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"z": np.ones((M, L - 1))}, "z"),
    ({"z": NAN_Z}, "z"),
    ({"z": -GOOD_Z}, "z"),
    ({"label": SIGNAL.n_labels}, "label"),
    ({"label": -1}, "label"),
    ({"gamma": np.array([np.nan, 1.0])}, "gamma"),
    ({"gamma": np.array([-1.0, 1.0])}, "gamma"),
    ({"frame": np.array([1.5, 2.0])}, "frame"),
    ({"frame": np.array([1, 2, 3])}, "frame"),
])
@pytest.mark.parametrize("func", [log_likelihood_ratio, log_likelihood_ratio_reference])
def test_bad_input(func: object, kwargs: dict[str, object], field: str) -> None:
    """Bad magnitudes, labels, amplitudes or frames raise InvalidInputError naming the field."""
    args: dict[str, object] = {"z": GOOD_Z, "label": 0, "gamma": np.array([1e-3, 2e-3]),
                               "frame": np.array([1, 2])}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        func(SIGNAL, **args)  # type: ignore[operator]
    assert err.value.field == field


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"z": NAN_Z}, "z"),
    ({"x": np.zeros((3, 5, 4))}, "x"),
    ({"x": np.zeros((4, 5, 2))}, "x"),
    ({"tau": np.zeros((4, 6))}, "tau"),
    ({"uav_pose": [0.0, 0.0]}, "uav_pose"),
    ({"uav_pose": [0.0, np.inf, 0.0]}, "uav_pose"),
])
def test_label_log_likelihoods_bad_input(kwargs: dict[str, object], field: str) -> None:
    """Bad magnitudes, particle arrays or pose raise InvalidInputError naming the field."""
    args: dict[str, object] = {"z": GOOD_Z, "x": np.zeros((4, 5, 4)), "tau": np.zeros((4, 5)),
                               "uav_pose": [0.0, 0.0, 0.0]}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        label_log_likelihoods(SIGNAL, **args)  # type: ignore[arg-type]
    assert err.value.field == field


def test_correlated_cells_temper_matches_time_domain_noise() -> None:
    """On noise-only spectrograms computed from time-domain windows, neighbouring bins' squared
    magnitudes correlate as ρ(k)² says, and the exponent from the measured correlations is the
    function's; directly simulated STFT cells are independent."""
    rng = np.random.default_rng(3)
    empty = (np.zeros((0, 2)), np.zeros(0, dtype=np.int64), np.zeros(0), [0.0, 0.0, 0.0])
    for route, want in ((simulate_time_domain, None), (simulate_stft, 0.0)):
        power = np.concatenate([route(SIGNAL, *empty, rng) for _ in range(12)])[:, 20:230] ** 2
        corr = [float(np.corrcoef(power[:, :-k].ravel(), power[:, k:].ravel())[0, 1])
                for k in (1, 2, 3, 4)]
        if want is not None:
            assert np.allclose(corr, want, atol=0.03)
            continue
        w2 = SIGNAL.window**2
        n = np.arange(w2.size)
        rho2 = [float(abs(np.sum(w2 * np.exp(-2j * np.pi * k * n / L))) / w2.sum()) ** 2
                for k in (1, 2, 3, 4)]
        np.testing.assert_allclose(corr, rho2, atol=0.03)
        width = 2 * SIGNAL.half_width_bins + 1
        measured = width / (width + 2 * sum((width - k) * c for k, c in zip((1, 2, 3, 4), corr,
                                                                              strict=True)))
        beta = correlated_cells_temper(SIGNAL)
        assert beta == pytest.approx(measured, abs=0.03)
        assert 0.35 < beta < 0.45
