"""The TBD-LMB filter end to end on simulated spectrograms (its shared plumbing: test_filter)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.radio.tbd import FilterConfig, TbdLmbFilter
from searchtrack.models.radio.scenario import RadioScenario
from searchtrack.models.radio.stft import simulate_stft

SCENARIO = RadioScenario.paper(noise_var_v2=0.01**2)
SIGNAL = SCENARIO.signal
TAG_XY = np.array([[800.0, 300.0]])      # label 0 at its release site, pulse offset 0.1 s
SMALL = FilterConfig(particles_per_label=300, birth_fraction=0.2)


def _pose(k: int) -> np.ndarray:
    """The UAV circles the tag at 100 m, facing along its path."""
    a = 0.3 * k
    return np.array([800.0 + 100.0 * math.cos(a), 300.0 + 100.0 * math.sin(a), a + math.pi])


def _run(seed: int, steps: int, config: FilterConfig = SMALL) -> TbdLmbFilter:
    f = TbdLmbFilter(SCENARIO, config, seed=seed)
    rng = np.random.default_rng(100 + seed)
    for k in range(steps):
        pose = _pose(k)
        f.step(simulate_stft(SIGNAL, TAG_XY, [0], [0.1], pose, rng), pose)
    return f


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_detects_and_localises_a_live_tag(seed: int) -> None:
    """Near one live tag at low noise: its label is confirmed (r > 0.9) within 20 steps at
    its position (< 60 m); labels of absent tags stay below 0.1."""
    f = _run(seed, 20)
    r = f.state.r
    assert r[0] > 0.9
    assert np.all(r[1:] < 0.1)
    (label, xy), = f.estimates()
    assert label == 0
    assert np.hypot(*(xy - TAG_XY[0])) < 60.0
    assert f.state.frame_mode(SIGNAL)[0] == SIGNAL.frame_of(0.1)
    assert f.cardinality_mean() == pytest.approx(r.sum())
    assert np.argmax(f.cardinality()) == 1
    assert f.steps == 20


def test_a_vanished_tag_is_dropped() -> None:
    """When the confirmed tag stops transmitting, its existence falls below 0.1 at once."""
    f = _run(0, 12)
    assert f.state.r[0] > 0.9
    rng = np.random.default_rng(6)
    for k in range(12, 14):
        pose = _pose(k)
        f.step(simulate_stft(SIGNAL, np.empty((0, 2)), [], [], pose, rng), pose)
    assert np.all(f.state.r < 0.1)
    assert f.estimates() == []


def test_noise_only_confirms_nothing() -> None:
    """Without any tag the existence probabilities stay near the birth probability."""
    f = TbdLmbFilter(SCENARIO, SMALL, seed=4)
    rng = np.random.default_rng(5)
    for k in range(10):
        pose = _pose(k)
        f.step(simulate_stft(SIGNAL, np.empty((0, 2)), [], [], pose, rng), pose)
    assert np.all(f.state.r < 1e-3)
    assert f.estimates() == []
    assert f.cardinality()[0] > 0.99


def test_temper_scales_the_log_likelihood_ratios() -> None:
    """FilterConfig.temper β multiplies eq. 22 (the update uses g^β); it must lie in (0, 1]."""
    rng = np.random.default_rng(5)
    z = simulate_stft(SIGNAL, TAG_XY, [0], [0.1], _pose(0), rng)
    plain = TbdLmbFilter(SCENARIO, SMALL, seed=1)
    half = TbdLmbFilter(SCENARIO, FilterConfig(particles_per_label=300, birth_fraction=0.2,
                                               temper=0.5), seed=1)
    state = plain.labelled_particles()
    full = plain._log_likelihoods(z, _pose(0), state)
    np.testing.assert_allclose(half._log_likelihoods(z, _pose(0), state), 0.5 * full)
    for bad in (0.0, 1.5, -0.2, math.nan):
        with pytest.raises(InvalidInputError, match="temper"):
            FilterConfig(temper=bad)
