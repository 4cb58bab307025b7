"""The DTT baseline of paper 002: peak detector, detection likelihood and the DTT-LMB filter."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import rayleigh, rice

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.radio.dtt import (
    DttConfig,
    DttLmbFilter,
    cell_log_likelihood_ratio,
    detect_peaks,
    detection_probability,
    estimate_cell_var,
    find_frame_peaks,
    peak_log_likelihood_ratio,
)
from searchtrack.estimate.radio.filter import FilterConfig
from searchtrack.estimate.radio.tbd import TbdLmbFilter
from searchtrack.models.radio import RadioScenario, RadioSignal, TagSpec, simulate_stft
from searchtrack.models.radio.calibration import calibrated

SIGMA2 = 0.02  # a cell noise variance Σ_z (V²)
SIGNAL = RadioSignal()
POSE0 = np.array([0.0, 0.0, 0.0])
TAG_XY = np.array([600.0, 600.0])
TAG_TAU = 0.3


def _noise(rng: np.random.Generator, shape: tuple[int, int], var: float = SIGMA2) -> np.ndarray:
    """Rayleigh magnitudes of complex Gaussian cells with ``var`` per component."""
    s = math.sqrt(var)
    return np.abs(rng.normal(0.0, s, shape) + 1j * rng.normal(0.0, s, shape))


# ---------------------------------------------------------------- peak detector on plain arrays


def test_cell_var_estimate_is_robust_to_a_few_strong_cells() -> None:
    """The median estimate recovers Σ_z within 3 % even with strong tones in some cells."""
    z = _noise(np.random.default_rng(0), (111, 256))
    z[10:12, 20:29] = 5.0
    assert estimate_cell_var(z) == pytest.approx(SIGMA2, rel=0.03)


def test_strong_tone_is_found_at_its_bin_only() -> None:
    """A tone in two frames gives one peak per frame at its bin and nothing else there."""
    z = _noise(np.random.default_rng(1), (111, 256))
    z[40:42, 48:55] += 3.0 * np.array([0.02, 0.2, 0.68, 1.0, 0.68, 0.2, 0.02])
    t = math.sqrt(-2.0 * SIGMA2 * math.log(1e-3))
    frame, bins = find_frame_peaks(z, t, 8)
    in_tone = (frame >= 40) & (frame <= 41) & (np.abs(bins - 51) <= 4)
    assert frame[in_tone].tolist() == [40, 41]
    assert bins[in_tone].tolist() == [51, 51]


@pytest.mark.parametrize(("gap", "n_peaks"), [(5, 1), (7, 1), (8, 2), (12, 2)])
def test_minimum_separation_is_respected(gap: int, n_peaks: int) -> None:
    """Two peaks closer than the minimum separation keep only the higher one."""
    z = np.zeros((1, 64))
    z[0, 20] = 2.0
    z[0, 20 + gap] = 1.5
    _, bins = find_frame_peaks(z, 1.0, 8)
    assert bins.size == n_peaks
    assert bins[0] == 20
    if n_peaks == 2:
        assert np.diff(bins)[0] >= 8


def test_false_alarms_on_noise_match_the_design_rate() -> None:
    """On pure Rayleigh noise the peak rate per cell is close to P_FA (seeded, ±25 %)."""
    rng = np.random.default_rng(2)
    p_fa = 1e-3
    found = 0
    for _ in range(20):
        z = _noise(rng, (111, 256), var=rng.uniform(0.005, 0.05))
        t = math.sqrt(-2.0 * estimate_cell_var(z) * math.log(p_fa))
        found += find_frame_peaks(z, t, 8)[0].size
    assert found / (20 * 111 * 256) == pytest.approx(p_fa, rel=0.25)


# ------------------------------------------------------------------------- likelihood math


def test_detection_probability_is_marcum_q() -> None:
    """The tabulated P_D matches scipy's Rice survival function, is P_FA at ν = 0 and → 1."""
    nu = np.linspace(0.0, 3.0, 301)
    t = math.sqrt(-2.0 * math.log(1e-3))
    exact = rice.sf(t, nu / math.sqrt(SIGMA2))
    np.testing.assert_allclose(detection_probability(nu, SIGMA2, 1e-3), exact, atol=1e-5)
    assert detection_probability(0.0, SIGMA2, 1e-3) == pytest.approx(1e-3, rel=1e-6)
    assert detection_probability(100.0, SIGMA2, 1e-3) == 1.0


def test_cell_ratio_is_rice_over_rayleigh() -> None:
    """The cell log-ratio equals log Rice(z; ν) − log Rayleigh(z) (eq. 22), also for large z ν."""
    z = np.array([0.1, 0.5, 1.0, 3.0])
    nu = np.array([0.0, 0.2, 1.0, 2.5])
    s = math.sqrt(SIGMA2)
    want = rice.logpdf(z, nu / s, scale=s) - rayleigh.logpdf(z, scale=s)
    np.testing.assert_allclose(cell_log_likelihood_ratio(z, nu, SIGMA2), want, rtol=1e-9,
                               atol=1e-12)
    assert np.isfinite(cell_log_likelihood_ratio(np.array([50.0]), np.array([50.0]), 1e-3)).all()


def _brute_force(pf: np.ndarray, pz: np.ndarray, pw: np.ndarray, gamma: np.ndarray,
                 frame: np.ndarray, *, cells: int, n_frames: int, wmax: float) -> np.ndarray:
    """The per-particle Bernoulli ratio as a plain double loop over frames and peaks."""
    p_fa = 1e-3
    lam_c = cells * p_fa
    out = np.zeros(gamma.size)
    for i, (g, m) in enumerate(zip(gamma, frame, strict=True)):
        pd = rice.sf(math.sqrt(-2 * math.log(p_fa)), g * wmax / math.sqrt(SIGMA2))
        for f in (m, m + 1):
            if not 0 <= f < n_frames:
                continue
            val = 1.0 - pd
            for fj, zj, wj in zip(pf, pz, pw, strict=True):
                if fj == f:
                    s = math.sqrt(SIGMA2)
                    ratio = rice.pdf(zj, g * wj / s, scale=s) / rayleigh.pdf(zj, scale=s)
                    val += p_fa / lam_c * ratio
            out[i] += math.log(val)
    return out


def test_bernoulli_ratio_matches_the_brute_force_formula() -> None:
    """Vectorised log ratio = Σ_f log[1 − P_D + (P_FA/λ_c) Σ_peaks Rice/Rayleigh]."""
    pf = np.array([3, 4, 4, 9])
    pz = np.array([0.7, 0.9, 0.5, 0.6])
    pw = np.array([1.0, 0.9, 0.3, 1.0])
    gamma = np.array([0.0, 0.2, 0.6, 0.8, 0.8, 0.8, 1.5])
    frame = np.array([3, 3, 3, 3, 2, 9, 10])       # 10 has its second frame outside M = 11
    got = peak_log_likelihood_ratio(pf, pz, pw, gamma, frame, cell_var=SIGMA2,
                                    false_alarm_probability=1e-3, gate_cells=9, n_frames=11,
                                    peak_leak=1.0)
    want = _brute_force(pf, pz, pw, gamma, frame, cells=9, n_frames=11, wmax=1.0)
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6)
    # ν = 0: a detection is as likely as clutter, each peak adds P_D g/κ = P_FA/λ_c = 1/9
    assert got[0] == pytest.approx(math.log(1 - 1e-3 + 1 / 9) + math.log(1 - 1e-3 + 2 / 9))


def test_ratio_prefers_the_right_frame_and_penalises_missed_strong_tags() -> None:
    """Particles on the peaks' frames gain; strong particles elsewhere lose (1 − P_D)."""
    pf, pz, pw = np.array([5, 6]), np.array([1.0, 1.1]), np.array([1.0, 1.0])
    gamma = np.array([1.0, 1.0, 0.01])
    frame = np.array([5, 50, 50])
    llr = peak_log_likelihood_ratio(pf, pz, pw, gamma, frame, cell_var=SIGMA2,
                                    false_alarm_probability=1e-3, gate_cells=9, n_frames=111,
                                    peak_leak=1.0)
    assert llr[0] > 10.0
    assert llr[1] < -10.0
    assert abs(llr[2]) < 0.01
    empty = peak_log_likelihood_ratio(pf[:0], pz[:0], pw[:0], gamma, frame, cell_var=SIGMA2,
                                      false_alarm_probability=1e-3, gate_cells=9, n_frames=111,
                                      peak_leak=1.0)
    assert empty[1] == pytest.approx(llr[1])


# ------------------------------------------------------------- with the radio signal model


def test_detector_finds_a_tag_in_its_two_frames() -> None:
    """A close tag gives a peak at its strongest bin in frames m(τ) and m(τ)+1."""
    tau = 0.3
    z = simulate_stft(SIGNAL, np.array([[100.0, 0.0]]), [2], [tau], POSE0,
                      np.random.default_rng(3))
    det = detect_peaks(SIGNAL, z)
    m = int(SIGNAL.frame_of(tau))
    lam_bins = SIGNAL.tag_bins()[2]
    mine = (det.bin >= lam_bins[0]) & (det.bin <= lam_bins[-1]) & (np.abs(det.frame - m) <= 2)
    assert det.frame[mine].tolist() == [m, m + 1]
    strongest = lam_bins[np.argmax(SIGNAL.tag_leakage()[2])]
    assert det.bin[mine].tolist() == [strongest, strongest]
    assert np.all(det.magnitude > det.threshold)
    assert det.cell_var == pytest.approx(SIGNAL.cell_var, rel=0.05)


def test_detector_false_alarm_rate_on_simulated_noise() -> None:
    """With no tag, peaks per cell ≈ P_FA for two design rates (seeded, ±30 %)."""
    rng = np.random.default_rng(4)
    nothing = (np.zeros((0, 2)), np.zeros(0, dtype=np.int64), np.zeros(0))
    for p_fa in (1e-3, 1e-2):
        found = sum(len(detect_peaks(SIGNAL, simulate_stft(SIGNAL, *nothing, POSE0, rng),
                                     false_alarm_probability=p_fa)) for _ in range(10))
        # at 1e-2 the 8-bin separation merges some neighbours: the rate is a little lower
        assert found / (10 * SIGNAL.frames * SIGNAL.fft_size) == pytest.approx(p_fa, rel=0.3)


def _scenario(noise_var_v2: float) -> RadioScenario:
    """One static-ish tag of label 0 at (600, 600) m, births 36 m off with a 50 m spread; the
    ``"unscaled"`` calibration (the ranges below are chosen for it)."""
    signal = calibrated(RadioSignal(noise_var_v2=noise_var_v2), "unscaled")
    tag = TagSpec(0, 0.0, 100.0, (TAG_XY[0], 0.0, TAG_XY[1], 0.0), TAG_TAU)
    return RadioScenario(signal=signal, tags=(tag,), duration_s=100.0,
                         birth_means=((TAG_XY[0] + 30.0, 0.0, TAG_XY[1] - 20.0, 0.0),),
                         birth_cov_diag=(2500.0, 4.0, 2500.0, 4.0))


def _orbit(k: int, steps: int, range_m: float) -> np.ndarray:
    """UAV pose on a half orbit of radius ``range_m`` around the tag, heading at it."""
    a = math.pi * k / steps
    return np.array([TAG_XY[0] - range_m * math.cos(a), TAG_XY[1] - range_m * math.sin(a), a])


def _run(filters: list[TbdLmbFilter | DttLmbFilter], scenario: RadioScenario, *, steps: int,
         range_m: float, seed: int) -> np.ndarray:
    """Feed every filter the same seeded measurements; ``(steps, len(filters))`` r of label 0."""
    rng = np.random.default_rng(seed)
    r = np.empty((steps, len(filters)))
    for k in range(steps):
        pose = _orbit(k, steps, range_m)
        z = simulate_stft(scenario.signal, np.array([TAG_XY]), [0], [TAG_TAU], pose, rng)
        for j, f in enumerate(filters):
            f.step(z, pose)
            r[k, j] = f.state.r[0]
    return r


def test_dtt_detects_and_locates_a_close_tag_at_low_noise() -> None:
    """At Σ_η = 0.01² and 175 m the DTT filter confirms the tag and places it within 80 m."""
    scenario = _scenario(0.01**2)
    dtt = DttLmbFilter(scenario, FilterConfig(particles_per_label=1000), seed=0)
    r = _run([dtt], scenario, steps=15, range_m=175.0, seed=0)
    assert r[-1, 0] > 0.9
    ((label, xy),) = dtt.estimates()
    assert label == 0
    assert np.hypot(*(xy - TAG_XY)) < 80.0
    assert dtt.state.frame_mode(scenario.signal)[0] == scenario.signal.frame_of(TAG_TAU)
    assert np.all(dtt.state.r[1:] < 0.01)          # clutter peaks do not confirm empty labels
    assert dtt.cardinality_mean() == pytest.approx(dtt.state.r.sum())


def test_tbd_beats_dtt_at_high_noise() -> None:
    """At Σ_η = 0.05² and 175 m, on the same measurements, TBD believes in the tag far more."""
    scenario = _scenario(0.05**2)
    config = FilterConfig(particles_per_label=300)
    means = []
    for seed in (0, 1):
        pair: list[TbdLmbFilter | DttLmbFilter] = [TbdLmbFilter(scenario, config, seed=seed),
                                                   DttLmbFilter(scenario, config, seed=seed)]
        means.append(_run(pair, scenario, steps=20, range_m=175.0, seed=seed).mean(axis=0))
    tbd, dtt = np.mean(means, axis=0)
    assert tbd > 0.5
    assert tbd > dtt + 0.3


def test_filter_is_deterministic_and_keeps_the_peaks() -> None:
    """Equal seeds give equal states; the filter keeps the peaks of its last measurement."""
    scenario = _scenario(0.025**2)
    config = FilterConfig(particles_per_label=50)
    a, b = DttLmbFilter(scenario, config, seed=7), DttLmbFilter(scenario, config, seed=7)
    assert a.detections is None
    _run([a], scenario, steps=3, range_m=150.0, seed=1)
    _run([b], scenario, steps=3, range_m=150.0, seed=1)
    np.testing.assert_array_equal(a.state.x, b.state.x)
    np.testing.assert_array_equal(a.state.r, b.state.r)
    assert a.steps == 3
    assert a.detections is not None
    assert a.detections.cell_var == pytest.approx(scenario.signal.cell_var, rel=0.1)


def test_detector_bad_input() -> None:
    """NaN, negative or mis-shaped z and bad detector settings are rejected naming the field."""
    good = np.ones((SIGNAL.frames, SIGNAL.fft_size))
    bad_z = [good[:, :-1], good[0], np.where(good > 0, np.nan, 0.0), -good]
    for z in bad_z:
        with pytest.raises(InvalidInputError, match="z"):
            detect_peaks(SIGNAL, z)
    with pytest.raises(InvalidInputError, match="min_separation"):
        detect_peaks(SIGNAL, good, min_separation=0)
    with pytest.raises(InvalidInputError, match="false_alarm_probability"):
        detect_peaks(SIGNAL, good, false_alarm_probability=1.5)


def test_bad_config() -> None:
    """Out-of-range detector settings are rejected naming the field."""
    with pytest.raises(InvalidInputError, match="false_alarm_probability"):
        DttConfig(false_alarm_probability=0.0)
    with pytest.raises(InvalidInputError, match="false_alarm_probability"):
        DttConfig(false_alarm_probability=float("nan"))
    with pytest.raises(InvalidInputError, match="min_separation_bins"):
        DttConfig(min_separation_bins=0)
    with pytest.raises(InvalidInputError, match="config"):
        DttLmbFilter(RadioScenario(), DttConfig())  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="detector"):
        DttLmbFilter(RadioScenario(), detector=FilterConfig())  # type: ignore[arg-type]
