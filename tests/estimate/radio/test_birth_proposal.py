"""Measurement-driven τ proposals for birth particles: cells, mixtures and unbiased weights."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.radio.birth_proposal import (
    birth_cell_mass,
    detection_proposal,
    draw_tau,
    energy_proposal,
    frame_cells,
)
from searchtrack.estimate.radio.particles import initial_state, predict
from searchtrack.models.radio import RadioScenario, RadioSignal, ideal_stft, simulate_stft

SIGNAL = RadioSignal()


def test_cells_partition_the_period_by_frame_index() -> None:
    low, width = frame_cells(SIGNAL)
    assert low.size == 113 and width[0] == 0.0
    assert width.sum() == pytest.approx(SIGNAL.period_s)
    mid = low[1:] + 0.5 * width[1:]
    assert np.array_equal(SIGNAL.frame_of(mid), np.arange(1, low.size))
    assert birth_cell_mass(SIGNAL).sum() == pytest.approx(1.0)


def test_energy_proposal_points_at_the_tags_frames() -> None:
    pose = np.array([0.0, 0.0, 0.0])
    tau = np.array([0.1, 0.2, 0.3, 0.4])
    xy = np.array([[150.0, 0.0], [0.0, 150.0], [100.0, 100.0], [150.0, 30.0]])
    z = ideal_stft(SIGNAL, xy, np.arange(4), tau, pose)
    q = energy_proposal(SIGNAL, z)
    p_b = birth_cell_mass(SIGNAL)
    assert np.allclose(q.sum(axis=1), 1.0) and np.all(q >= 0.5 * p_b - 1e-15)
    best = q.argmax(axis=1)
    assert np.array_equal(best, SIGNAL.frame_of(tau))
    noise = simulate_stft(SIGNAL, np.empty((0, 2)), np.empty(0, dtype=int), np.empty(0), pose,
                          np.random.default_rng(0))
    flat = energy_proposal(SIGNAL, noise, uniform_share=1.0)
    assert np.allclose(flat, p_b)                         # ε = 1: the birth density itself
    spread = energy_proposal(SIGNAL, noise)
    assert spread.max() < 0.2                             # noise alone: no cell dominates


def test_detection_proposal_uses_the_labels_peaks_only() -> None:
    bins = SIGNAL.tag_bins()
    q = detection_proposal(SIGNAL, np.array([20, 40]), np.array([bins[1, 4], 200]))
    p_b = birth_cell_mass(SIGNAL)
    assert np.allclose(q[[0, 2, 3]], p_b)                       # no peaks: the birth density
    assert q[1, 19] == pytest.approx(0.5 * p_b[19] + 0.25) and q[1, 20] > q[1, 21]
    with pytest.raises(InvalidInputError, match="uniform_share"):
        detection_proposal(SIGNAL, np.array([20]), np.array([3]), uniform_share=0.0)


def test_importance_weights_are_unbiased_for_the_uniform_birth() -> None:
    """E_q[ratio · f(τ)] = E_pB[f(τ)] for any f: check the cell histogram."""
    rng = np.random.default_rng(1)
    q = np.tile(birth_cell_mass(SIGNAL), (4, 1))
    q[:, 30:33] += 2.0
    q /= q.sum(axis=1, keepdims=True)
    tau, ratio = draw_tau(SIGNAL, q, 200_000, rng)
    assert np.all((tau > 0.0) & (tau <= SIGNAL.period_s))
    cells = SIGNAL.frame_of(tau)
    est = np.array([np.bincount(c, weights=r, minlength=113) for c, r in zip(cells, ratio,
                                                                               strict=True)])
    est /= ratio.sum(axis=1, keepdims=True)
    assert np.allclose(est, birth_cell_mass(SIGNAL), atol=2e-3)
    with pytest.raises(InvalidInputError, match="proposal"):
        draw_tau(SIGNAL, q[:2], 10, rng)


def test_predict_with_a_proposal_keeps_the_birth_mass() -> None:
    scenario = RadioScenario.paper()
    rng = np.random.default_rng(0)
    state = initial_state(scenario, 50, rng)
    q = np.tile(birth_cell_mass(scenario.signal), (4, 1))
    q[:, 10] += 1.0
    q /= q.sum(axis=1, keepdims=True)
    plain = predict(state, scenario, np.random.default_rng(3), n_birth=40)
    steered = predict(state, scenario, np.random.default_rng(3), n_birth=40, tau_proposal=q)
    assert np.allclose(steered.r, plain.r)
    assert np.allclose(steered.w[:, 50:].sum(axis=1), plain.w[:, 50:].sum(axis=1))
    share = (scenario.signal.frame_of(steered.tau[:, 50:]) == 10).mean()
    assert share > 0.3                                   # the proposal's cell is over-drawn …
    heavy = steered.w[:, 50:][scenario.signal.frame_of(steered.tau[:, 50:]) == 10]
    light = steered.w[:, 50:][scenario.signal.frame_of(steered.tau[:, 50:]) != 10]
    assert heavy.max() < light.min()                     # … and down-weighted
