"""Systematic resampling of a particle PHD: mass kept, weights equal, particle cap."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate.phd import PHDConfig, PHDState, resample, systematic_indices

from .helpers import cloud as _cloud
from .helpers import phd_state as _state


def test_resampling_keeps_mass_and_caps_particles() -> None:
    """Systematic resampling keeps Σw, equalises weights and honours the particle cap."""
    st = _state(_cloud((100, 100), 1000, 3.0), _cloud((700, 700), 10, 0.25))
    rng = np.random.default_rng(0)
    out = resample(st, PHDConfig(particles_per_target=100), rng)
    assert out.expected_count() == pytest.approx(st.expected_count())
    assert out.n_particles == round(100 * 3.25)
    assert np.ptp(out.weights) == 0.0
    capped = resample(st, PHDConfig(particles_per_target=1000, max_particles=500), rng)
    assert capped.n_particles == 500
    assert capped.expected_count() == pytest.approx(3.25)


@pytest.mark.parametrize("seed", range(5))
def test_systematic_indices_by_hand(seed: int) -> None:
    """Weights (1, 0, 3), four pointers u, 1 + u, 2 + u, 3 + u: whatever u ∈ [0, 1), one copy
    of particle 0 and three of particle 2."""
    idx = systematic_indices(np.array([1.0, 0.0, 3.0]), 4, np.random.default_rng(seed))
    assert idx.tolist() == [0, 2, 2, 2] and idx.dtype == np.int64


@pytest.mark.parametrize("seed", range(5))
def test_systematic_copies_are_floor_or_ceil_of_the_expected_count(seed: int) -> None:
    """Each particle is drawn ⌊n w_i / W⌋ or ⌈n w_i / W⌉ times (low variance), zero weights
    never."""
    rng = np.random.default_rng(seed)
    w = rng.random(12) * (rng.random(12) < 0.7)
    w[0] += 0.1
    n = 50
    copies = np.bincount(systematic_indices(w, n, rng), minlength=12)
    expected = n * w / w.sum()
    assert copies.sum() == n
    assert np.all(copies >= np.floor(expected - 1e-9))
    assert np.all(copies <= np.ceil(expected + 1e-9))
    assert np.all(copies[w == 0.0] == 0)


def test_resample_floor_and_empty_states() -> None:
    """A tiny mass still gets min_particles particles sharing it; an empty or massless PHD
    resamples to no particles."""
    rng = np.random.default_rng(0)
    st = PHDState.from_particles(np.zeros((3, 2)), np.array([0.004, 0.0, 0.006]))
    out = resample(st, PHDConfig(particles_per_target=100, min_particles=20), rng)
    assert out.n_particles == 20 and out.weights == pytest.approx(np.full(20, 0.01 / 20))
    assert resample(PHDState.empty(4), PHDConfig(), rng).n_particles == 0
    massless = PHDState.from_particles(np.zeros((3, 2)), np.zeros(3))
    assert resample(massless, PHDConfig(), rng).n_particles == 0


def test_resample_keeps_the_update_record() -> None:
    """The record of the last update survives resampling (extraction may run after it)."""
    st = _state(_cloud((100, 100), 30, 1.0))
    rec = st.record
    assert resample(st, PHDConfig(), np.random.default_rng(0)).record is rec
