"""The ideal-measurement likelihood: the table of h against log I0, frame counts and overlaps,
and the whole log g against the filter's likelihood of the simulated noise-free spectrogram."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.radio.likelihood import log_likelihood_ratio_reference
from searchtrack.models.radio import RadioSignal
from searchtrack.models.radio.stft import ideal_stft
from searchtrack.plan.radio.ideal import (
    IdealLikelihood,
    amplitudes,
    frame_counts,
    frame_overlap,
    likelihood_table,
)

SIGNAL = RadioSignal()
TABLE = IdealLikelihood.of(SIGNAL)


def tau_of_frame(m: IntArray) -> FloatArray:
    """A pulse offset in [0, T0) whose first frame m(τ) is ``m`` (for 0 ≤ m ≤ 112)."""
    tau = np.maximum(np.asarray(m) - 0.5, 0.0) * SIGNAL.hop / SIGNAL.sample_rate_hz
    return np.minimum(tau, SIGNAL.period_s - 1e-6)


def test_table_matches_log_i0() -> None:
    """h_λ from the table is within 1e-7 (relative; 1e-12 absolute, where SciPy's log I0 is
    itself only that accurate) of Σ_b log I0 from t = 0 to the top."""
    top = float(SIGNAL.amplitude(np.zeros(2), np.zeros(3))) ** 2
    t = np.concatenate([[0.0], np.geomspace(1e-14, top, 2000), np.linspace(0, top, 500)])
    for lab in range(SIGNAL.n_labels):
        exact = TABLE.h_exact(lab, t)
        assert np.allclose(TABLE.h(lab, t), exact, rtol=1e-7, atol=1e-12)
    assert TABLE.h(0, np.array([0.0]))[0] == 0.0


def test_frame_counts_and_overlap() -> None:
    """n_i counts the frames {m, m+1} inside [0, M); o_i those shared with {m̂, m̂+1}."""
    m = np.array([0, 5, 109, 110, 111, 112, -1])
    assert frame_counts(m, 111).tolist() == [2, 2, 2, 1, 0, 0, 1]
    est = np.array([5])
    assert frame_overlap(np.array([[4, 5, 6, 7, 110]]), est, 111).tolist() == [[1, 2, 1, 0, 0]]
    assert frame_overlap(np.array([[109, 110, 111]]), np.array([110]), 111).tolist() == [[1, 1,
                                                                                           0]]
    assert frame_overlap(np.array([[110, 111]]), np.array([111]), 111).tolist() == [[0, 0]]


def test_amplitudes_equal_the_model_at_each_pose() -> None:
    """Moving the tags into each pose's frame gives the model's amplitude from that pose."""
    rng = np.random.default_rng(0)
    xy = rng.uniform(0.0, 800.0, (3, 7, 2))
    poses = np.c_[rng.uniform(0.0, 800.0, (5, 2)), rng.uniform(-np.pi, np.pi, 5)]
    got = amplitudes(SIGNAL, xy, poses)
    assert got.shape == (5, 3, 7)
    for k in range(5):
        assert np.allclose(got[k], SIGNAL.amplitude(xy, poses[k]), rtol=1e-12)
    above = amplitudes(SIGNAL, poses[:1, :2], poses[:1])
    assert above[0, 0] == pytest.approx(float(SIGNAL.amplitude(np.zeros(2), np.zeros(3))))


@pytest.mark.parametrize("seed", range(4))
def test_log_likelihood_equals_the_filter_likelihood(seed: int) -> None:
    """log g of the tabulated form equals eq. 22 on the noise-free spectrogram of the
    estimates (rel. 1e-6), for estimated and absent labels, estimate frames near the ends,
    particles sharing 0, 1 or 2 frames."""
    rng = np.random.default_rng(seed)
    n = 300
    pose = np.array([*rng.uniform(300.0, 700.0, 2), rng.uniform(-np.pi, np.pi)])
    est_xy = pose[:2] + rng.uniform(-250.0, 250.0, (4, 2))
    est_frame = np.array([37, 110, 0, 111])
    estimated = np.array([True, True, True, False]) if seed % 2 else np.array([True] * 4)
    xy = est_xy[:, None, :] + rng.normal(0.0, 120.0, (4, n, 2))
    frames = est_frame[:, None] + rng.integers(-2, 3, (4, n))
    frames = np.clip(frames, 0, 112)
    frames[:, :3] = [0, 110, 111]
    keep = estimated & (est_frame < SIGNAL.frames)
    z = ideal_stft(SIGNAL, est_xy[keep], np.flatnonzero(keep), tau_of_frame(est_frame[keep]),
                   pose)
    gamma = amplitudes(SIGNAL, xy, pose[None])
    gamma_hat = amplitudes(SIGNAL, est_xy, pose[None]) * estimated
    mine = TABLE.log_likelihood(gamma, frame_counts(frames, SIGNAL.frames),
                                frame_overlap(frames, est_frame, SIGNAL.frames), gamma_hat)[0]
    for lab in range(4):
        assert np.array_equal(SIGNAL.frame_of(tau_of_frame(frames[lab])), frames[lab])
        direct = log_likelihood_ratio_reference(SIGNAL, z, lab, gamma[0, lab], frames[lab])
        assert np.allclose(mine[lab], direct, rtol=1e-6, atol=1e-9)
        assert np.any(np.abs(direct) > 1.0)  # a meaningful comparison


def test_the_shared_table_is_tabulated_once_per_signal() -> None:
    """likelihood_table gives one read-only table per signal, equal to a fresh one."""
    signal = RadioSignal(path_loss_exponent=2.9)
    table = likelihood_table(signal)
    assert likelihood_table(RadioSignal(path_loss_exponent=2.9)) is table
    assert likelihood_table(RadioSignal()) is not table
    fresh = IdealLikelihood.of(signal)
    for name in ("energy", "quadratic", "log_t", "log_h", "slope"):
        assert np.array_equal(getattr(table, name), getattr(fresh, name))
        assert not getattr(table, name).flags.writeable
