"""The fused Numba kernel equals its NumPy reference (model amplitudes and the tabulated
log-likelihood)."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models.radio import RadioSignal
from searchtrack.plan.radio.ideal import IdealLikelihood, amplitudes
from searchtrack.plan.radio.kernels import ideal_log_likelihoods


@pytest.mark.parametrize("seed", range(3))
def test_kernel_equals_the_numpy_reference(seed: int) -> None:
    """Random particles, poses (one right above a particle), estimates (one absent) and frame
    overlaps: the kernel's log g equals amplitudes + IdealLikelihood.log_likelihood."""
    signal = RadioSignal(path_loss_exponent=2.6 + 0.3 * seed, front_to_back_db=6.0 * seed)
    table = IdealLikelihood.of(signal)
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0.0, 900.0, (4, 50, 2))
    poses = np.c_[rng.uniform(0.0, 900.0, (6, 2)), rng.uniform(-np.pi, np.pi, 6)]
    poses[0, :2] = xy[1, 3]
    gamma_hat = amplitudes(signal, rng.uniform(0.0, 900.0, (4, 2)), poses)
    gamma_hat[:, 2] = 0.0
    counts = rng.integers(0, 3, (4, 50))
    overlap = np.minimum(counts, rng.integers(0, 3, (4, 50)))
    got = ideal_log_likelihoods(signal, table, xy, poses, gamma_hat, counts, overlap)
    ref = table.log_likelihood(amplitudes(signal, xy, poses), counts, overlap, gamma_hat)
    assert got.shape == (6, 4, 50)
    assert np.allclose(got, ref, rtol=1e-10, atol=1e-13)
    assert np.any(got > 0.0) and np.any(got < -1.0)
