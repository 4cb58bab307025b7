"""The fused update and reward of a batch of children equal the step-by-step reference: the
kernel's log-likelihoods, the log-space update of eqs. 29–30 and the divergences on the
posterior's weights."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models.radio import RadioSignal
from searchtrack.plan.radio import fused
from searchtrack.plan.radio.divergences import cauchy_schwarz, renyi
from searchtrack.plan.radio.fused import score_children
from searchtrack.plan.radio.ideal import IdealLikelihood, amplitudes
from searchtrack.plan.radio.kernels import ideal_log_likelihoods
from searchtrack.plan.radio.reference import update


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize(("reward", "order"), [("renyi", 0.5), ("renyi", 1.0), ("renyi", 2.0),
                                               ("cs", 1.0), ("cs", 3.0)])
def test_scores_equal_the_reference(seed: int, reward: str, order: float,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """Random clouds, parents (unequal weights, r from 0 to 1), poses (one right above a
    particle), estimates (one absent) and frame overlaps, in blocks of every size."""
    rng = np.random.default_rng(seed)
    signal = RadioSignal(path_loss_exponent=2.6 + 0.1 * (seed % 5))
    table = IdealLikelihood.of(signal)
    labels, n, parents, children = 4, int(rng.integers(1, 40)), 3, int(rng.integers(1, 12))
    xy = rng.uniform(0.0, 900.0, (labels, n, 2))
    poses = np.c_[rng.uniform(0.0, 900.0, (children, 2)), rng.uniform(-np.pi, np.pi, children)]
    poses[0, :2] = xy[1, 0]
    gamma_hat = amplitudes(signal, rng.uniform(0.0, 900.0, (labels, 2)), poses)
    gamma_hat[:, 2] = 0.0
    counts = rng.integers(0, 3, (labels, n))
    overlap = np.minimum(counts, rng.integers(0, 3, (labels, n)))
    w = rng.uniform(0.01, 1.0, (parents, labels, n))
    log_w = np.log(w / w.sum(axis=2, keepdims=True))
    r = rng.uniform(0.0, 1.0, (parents, labels))
    r[0, 0], r[1, 1] = 0.0, 1.0
    parent = rng.integers(0, parents, children)
    r1, w1 = np.array([0.9, 0.5, 0.5, 0.2]), np.full((labels, n), 1.0 / n)
    log_g = ideal_log_likelihoods(signal, table, xy, poses, gamma_hat, counts, overlap)
    want_w, want_r = update(log_w[parent], r[parent], log_g)
    want = (cauchy_schwarz(r1, w1, want_r, np.exp(want_w), order) if reward == "cs"
            else renyi(r1, w1, want_r, np.exp(want_w), order))
    monkeypatch.setattr(fused, "BLOCK_ELEMENTS", int(rng.integers(1, 3 * labels * n)))
    got = score_children(signal, table, xy, poses, gamma_hat, counts, overlap, log_w, r,
                         parent, r1, w1, reward, order)
    np.testing.assert_allclose(got.log_w, want_w, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(got.r, want_r, rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(got.reward, want, rtol=1e-9, atol=1e-12)
    leaf = score_children(signal, table, xy, poses, gamma_hat, counts, overlap, log_w, r,
                          parent, r1, w1, reward, order, keep=False)
    assert leaf.log_w.shape == (children, labels, 0)
    assert np.array_equal(leaf.reward, got.reward) and np.array_equal(leaf.r, got.r)


def test_hermite_coefficients_give_the_tables_interpolant() -> None:
    """The cubic of each interval in powers of f equals the table's Hermite form (h), at the
    nodes, inside the intervals and at the top; one read-only array per table."""
    table = IdealLikelihood.of(RadioSignal())
    coef = fused.hermite_coefficients(table)
    assert coef is fused.hermite_coefficients(table) and not coef.flags.writeable
    rng = np.random.default_rng(0)
    u = np.r_[rng.uniform(0.0, table.log_t.size - 1.0, 500), 0.0, 7.0, table.log_t.size - 1.0]
    k = np.minimum(u.astype(np.int64), table.log_t.size - 2)
    f = u - k
    step = (table.log_t[-1] - table.log_t[0]) / (table.log_t.size - 1)
    t = np.exp(table.log_t[0] + u * step)
    for lab in range(coef.shape[0]):
        c = coef[lab, k]
        got = c[:, 0] + f * (c[:, 1] + f * (c[:, 2] + f * c[:, 3]))
        np.testing.assert_allclose(np.exp(got), table.h(lab, t), rtol=1e-11)
