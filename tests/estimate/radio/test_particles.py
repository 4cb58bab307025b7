"""Labelled particles: read-outs, birth density, prediction with re-birth, update, resampling."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.radio.particles import (
    LabelledParticles,
    birth_particles,
    initial_state,
    predict,
    resample,
    update,
)
from searchtrack.models.radio.motion import propagate
from searchtrack.models.radio.scenario import RadioScenario

SCENARIO = RadioScenario()


def _state(n_labels: int = 2, n: int = 3, seed: int = 0) -> LabelledParticles:
    rng = np.random.default_rng(seed)
    w = rng.random((n_labels, n)) + 0.1
    return LabelledParticles(rng.normal(0.0, 50.0, (n_labels, n, 4)),
                             rng.integers(0, 2, (n_labels, n)).astype(np.int8),
                             rng.random((n_labels, n)), w / w.sum(axis=1, keepdims=True),
                             rng.random(n_labels))


def test_read_outs_hand_case() -> None:
    """Weighted mean position, mode probabilities and frame mode on a two-particle label."""
    x = np.array([[[0.0, 1.0, 10.0, 2.0], [100.0, 0.0, 20.0, 0.0]]])
    tau = np.array([[0.1, 0.2]])
    state = LabelledParticles(x, np.array([[0, 1]], dtype=np.int8), tau,
                              np.array([[0.25, 0.75]]), np.array([0.4]))
    np.testing.assert_allclose(state.mean_xy(), [[75.0, 17.5]])
    np.testing.assert_allclose(state.mode_probabilities(), [[0.25, 0.75]])
    signal = SCENARIO.signal
    assert state.frame_mode(signal)[0] == signal.frame_of(0.2)
    state.w[0] = [0.75, 0.25]
    assert state.frame_mode(signal)[0] == signal.frame_of(0.1)


def test_cardinality_is_poisson_binomial() -> None:
    """The distribution of Σ Bernoulli(r_λ) matches brute-force enumeration of label sets."""
    state = _state(n_labels=4)
    r = state.r
    brute = np.zeros(5)
    for bits in itertools.product((0, 1), repeat=4):
        b = np.array(bits)
        brute[b.sum()] += np.prod(np.where(b == 1, r, 1.0 - r))
    card = state.cardinality()
    np.testing.assert_allclose(card, brute, atol=1e-15)
    assert card @ np.arange(5) == pytest.approx(r.sum())


def test_copy_is_independent() -> None:
    """Changing a copy leaves the original untouched."""
    state = _state()
    dup = state.copy()
    dup.x[0, 0, 0] += 1.0
    dup.r[0] = 0.0
    assert state.x[0, 0, 0] != dup.x[0, 0, 0]
    assert state.r[0] != 0.0


def test_birth_particles_follow_the_birth_density() -> None:
    """Positions cluster at the birth means (σ 10 m), velocities σ 2 m/s, τ in [0, T0), modes
    from the initial mode probabilities."""
    x, mode, tau = birth_particles(SCENARIO, 20_000, np.random.default_rng(1))
    assert x.shape == (20_000, 4)
    assert mode.dtype == np.int8
    means = np.asarray(SCENARIO.birth_means)
    nearest = np.argmin(((x[:, None, ::2] - means[None, :, ::2]) ** 2).sum(axis=2), axis=1)
    dev = x - means[nearest]
    np.testing.assert_allclose(dev.std(axis=0), np.sqrt(SCENARIO.birth_cov_diag), rtol=0.05)
    np.testing.assert_allclose(np.bincount(nearest) / 20_000, 0.25, atol=0.02)
    assert tau.min() >= 0.0 and tau.max() < SCENARIO.signal.period_s
    assert mode.mean() == pytest.approx(SCENARIO.motion.initial_mode[1], abs=0.02)


def test_initial_state() -> None:
    """Every label starts at r = r_B with equally weighted birth particles."""
    state = initial_state(SCENARIO, 50, np.random.default_rng(2))
    n_labels = SCENARIO.signal.n_labels
    assert state.x.shape == (n_labels, 50, 4)
    np.testing.assert_allclose(state.r, SCENARIO.birth_probability)
    np.testing.assert_allclose(state.w, 1.0 / 50)


def test_predict_mixes_survivors_and_births() -> None:
    """r⁺ = p_S r + r_B (1 − r); survivors carry p_S r / r⁺, births the rest; input unchanged."""
    state = initial_state(SCENARIO, 40, np.random.default_rng(3))
    state.r[:] = [0.9, 0.5, 1e-6, 0.0]
    before = state.copy()
    pred = predict(state, SCENARIO, np.random.default_rng(4), n_birth=10)
    p_s, r_b = SCENARIO.survival_probability, SCENARIO.birth_probability
    r_plus = p_s * before.r + r_b * (1.0 - before.r)
    np.testing.assert_allclose(pred.r, r_plus)
    assert pred.x.shape == (4, 50, 4)
    np.testing.assert_allclose(pred.w.sum(axis=1), 1.0)
    np.testing.assert_allclose(pred.w[:, :40].sum(axis=1), p_s * before.r / r_plus)
    born = np.broadcast_to((r_b * (1.0 - before.r) / r_plus)[:, None] / 10, (4, 10))
    np.testing.assert_allclose(pred.w[:, 40:], born)
    for name in ("x", "mode", "tau", "w", "r"):
        np.testing.assert_array_equal(getattr(state, name), getattr(before, name))
    no_birth = predict(state, SCENARIO, np.random.default_rng(4), n_birth=0)
    assert no_birth.x.shape == (4, 40, 4)
    np.testing.assert_allclose(no_birth.w.sum(axis=1), 1.0)


def test_predict_draws_as_the_motion_model_then_the_births() -> None:
    """The survivors are models.radio.motion.propagate's result and the births birth_particles'
    draws that follow, for the same generator seed (bit for bit)."""
    state = initial_state(SCENARIO, 30, np.random.default_rng(7))
    pred = predict(state, SCENARIO, np.random.default_rng(8), n_birth=6)
    rng = np.random.default_rng(8)
    x, mode, tau = propagate(SCENARIO.motion, state.x, state.mode, state.tau, rng)
    bx, bmode, btau = birth_particles(SCENARIO, 4 * 6, rng)
    np.testing.assert_array_equal(pred.x, np.concatenate([x, bx.reshape(4, 6, 4)], axis=1))
    np.testing.assert_array_equal(pred.mode, np.concatenate([mode, bmode.reshape(4, 6)], axis=1))
    np.testing.assert_array_equal(pred.tau, np.concatenate([tau, btau.reshape(4, 6)], axis=1))
    assert pred.mode.dtype == np.int8


def test_confirmed_label_keeps_a_birth_share() -> None:
    """At r = 1 (evidence beyond float precision) the births still carry r_B · 1e-12 / r⁺."""
    state = initial_state(SCENARIO, 10, np.random.default_rng(5))
    state.r[:] = 1.0
    pred = predict(state, SCENARIO, np.random.default_rng(6), n_birth=5)
    share = SCENARIO.birth_probability * 1e-12 / pred.r
    np.testing.assert_allclose(pred.w[:, 10:].sum(axis=1), share, rtol=1e-9)
    assert np.all(pred.w[:, 10:] > 0.0)


def test_update_hand_case() -> None:
    """Eqs. 29–30 on two particles: η = Σ w g, r ← r η / (1 − r + r η), w ∝ w g."""
    state = _state(n_labels=1, n=2)
    state.w[0] = [0.25, 0.75]
    state.r[0] = 0.3
    g = np.array([2.0, 0.5])
    post = update(state, np.log(g)[None, :])
    eta = 0.25 * 2.0 + 0.75 * 0.5
    assert post.r[0] == pytest.approx(0.3 * eta / (0.7 + 0.3 * eta))
    np.testing.assert_allclose(post.w[0], [0.5 / eta, 0.375 / eta])
    assert post.x is state.x


def test_update_is_stable_for_extreme_log_likelihoods() -> None:
    """Log-likelihoods of ±1e4 give finite weights and existence in [0, 1], no overflow."""
    state = _state(n_labels=3, n=2)
    state.r[:] = [1e-6, 0.5, 0.999]
    ll = np.array([[1e4, -1e4], [-1e4, -1e4], [-1e4, 1e4]])
    with np.errstate(over="raise", invalid="raise"):
        post = update(state, ll)
    assert post.r[0] == pytest.approx(1.0)
    assert post.r[1] == pytest.approx(0.0, abs=1e-300)
    np.testing.assert_allclose(post.w, [[1.0, 0.0], [state.w[1, 0], state.w[1, 1]], [0.0, 1.0]])
    certain = _state(n_labels=2, n=2)
    certain.r[:] = [0.0, 1.0]
    np.testing.assert_allclose(update(certain, np.zeros((2, 2)) + 5.0).r, [0.0, 1.0])


def test_resample_systematic() -> None:
    """Every particle gets ⌊n w⌋ or ⌈n w⌉ copies; weights become 1/n; r is kept."""
    state = _state(n_labels=2, n=5, seed=6)
    out = resample(state, np.random.default_rng(7), 1000)
    assert out.x.shape == (2, 1000, 4)
    np.testing.assert_allclose(out.w, 1e-3)
    np.testing.assert_array_equal(out.r, state.r)
    for lab in range(2):
        counts = np.array([np.sum(np.all(out.x[lab] == state.x[lab, i], axis=1))
                           for i in range(5)])
        assert np.all(np.abs(counts - 1000 * state.w[lab]) < 1.0)
        tau_counts = np.array([np.sum(out.tau[lab] == state.tau[lab, i]) for i in range(5)])
        np.testing.assert_array_equal(tau_counts, counts)
    degenerate = _state(n_labels=1, n=4)
    degenerate.w[0] = [0.0, 0.0, 1.0, 0.0]
    picked = resample(degenerate, np.random.default_rng(8), 4)
    assert np.all(picked.x[0] == degenerate.x[0, 2])


def test_same_seed_same_result() -> None:
    """predict and resample are deterministic for a given generator seed."""
    state = initial_state(SCENARIO, 30, np.random.default_rng(9))
    a = resample(predict(state, SCENARIO, np.random.default_rng(1), n_birth=5),
                 np.random.default_rng(2), 30)
    b = resample(predict(state, SCENARIO, np.random.default_rng(1), n_birth=5),
                 np.random.default_rng(2), 30)
    for name in ("x", "mode", "tau", "w", "r"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


@pytest.mark.parametrize(("call", "field"), [
    (lambda s: LabelledParticles(s.x[:, :, :2], s.mode, s.tau, s.w, s.r), "x"),
    (lambda s: LabelledParticles(s.x, s.mode[:, :2], s.tau, s.w, s.r), "mode"),
    (lambda s: LabelledParticles(s.x, s.mode, s.tau[:1], s.w, s.r), "tau"),
    (lambda s: LabelledParticles(s.x, s.mode, s.tau, s.w.T, s.r), "w"),
    (lambda s: LabelledParticles(s.x, s.mode, s.tau, s.w, s.r[:1]), "r"),
    (lambda s: update(s, np.zeros((2, 4))), "log_lik"),
    (lambda s: update(s, np.full((2, 3), np.nan)), "log_lik"),
    (lambda s: predict(s, SCENARIO, np.random.default_rng(0), n_birth=-1), "n_birth"),
    (lambda s: predict(s, SCENARIO, 0, n_birth=1), "rng"),  # type: ignore[arg-type]
    (lambda s: resample(s, np.random.default_rng(0), 0), "n"),
    (lambda s: birth_particles(SCENARIO, -2, np.random.default_rng(0)), "n"),
    (lambda s: initial_state(SCENARIO, 0, np.random.default_rng(0)), "n"),
])
def test_bad_input(call: object, field: str) -> None:
    """Inconsistent shapes, bad counts and generators raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        call(_state())  # type: ignore[operator]
    assert err.value.field == field
