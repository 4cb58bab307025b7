"""Binary mutual information of a Poisson-RFS belief (paper 003 §2.5): the zero-set
probabilities, the pmf, both entropies, the Monte Carlo estimates and hand-computed cases."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.assign.mutual_info import (
    binary_mi,
    binary_mi_monte_carlo,
    conditional_entropy,
    conditional_entropy_one,
    measurement_entropy,
    monte_carlo_entropy,
    outcome_pmf,
    sample_target_sets,
    zero_probabilities,
)


def h_b(p: float) -> float:
    """Binary entropy in nats."""
    return -(p * math.log(p) + (1.0 - p) * math.log(1.0 - p))


def _brute_mi(pd: np.ndarray, w: np.ndarray, n_max: int = 6) -> float:
    """MI by enumerating target sets of a Poisson RFS on 2 particles (counts up to n_max)."""
    from scipy.stats import poisson

    m = pd.shape[0]
    joint = np.zeros(1 << m)
    h_cond = 0.0
    for counts in itertools.product(range(n_max + 1), repeat=len(w)):
        prob = float(np.prod(poisson.pmf(counts, w)))
        pi = np.prod((1 - pd) ** np.array(counts), axis=1)
        for s in range(1 << m):
            zero = [(s >> j) & 1 for j in range(m)]
            joint[s] += prob * np.prod([pi[j] if zero[j] else 1 - pi[j] for j in range(m)])
        with np.errstate(divide="ignore", invalid="ignore"):
            hb = -(pi * np.log(pi) + (1 - pi) * np.log(1 - pi))
        h_cond += prob * float(np.sum(np.nan_to_num(hb)))
    nz = joint[joint > 0]
    return float(-np.sum(nz * np.log(nz))) - h_cond

def test_binary_mi_exact_matches_enumeration() -> None:
    """The closed form equals MI by enumerating target sets on a two-particle PHD."""
    pd = np.array([[0.7, 0.1], [0.2, 0.6], [0.5, 0.5]])
    w = np.array([0.6, 0.9])
    assert binary_mi(pd, w) == pytest.approx(_brute_mi(pd, w, n_max=12), abs=1e-6)

def test_pmf_sums_to_one_and_matches_zero_probabilities() -> None:
    """The Möbius transform gives a pmf whose all-zero outcome is P(y = 0)."""
    rng = np.random.default_rng(0)
    pd = rng.uniform(0, 0.8, size=(5, 30))
    w = rng.uniform(0, 0.2, size=30)
    z = zero_probabilities(pd, w, 0.1)
    pmf = outcome_pmf(z)
    assert pmf.sum() == pytest.approx(1.0, abs=1e-12)
    assert pmf[-1] == pytest.approx(z[-1])
    assert np.all(pmf >= 0.0)

def test_conditional_entropy_series_matches_sampling() -> None:
    """E[h_b(π)] from the closed form and series agrees with direct sampling of target sets."""
    rng = np.random.default_rng(1)
    pd = rng.uniform(0.0, 0.9, size=50) * (rng.random(50) < 0.5)
    w = rng.uniform(0, 0.1, size=50)
    value = conditional_entropy_one(pd, w, 0.05)
    counts = rng.poisson(w, size=(40000, 50))
    pi = np.exp(-0.05) * np.prod((1 - pd) ** counts, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        hb = np.nan_to_num(-(pi * np.log(pi) + (1 - pi) * np.log(1 - pi)))
    assert value == pytest.approx(float(hb.mean()), abs=0.01)

@pytest.mark.parametrize("seed", range(3))
def test_binary_mi_exact_vs_monte_carlo(seed: int) -> None:
    """Exact MI and the fully sampled Monte Carlo estimate agree within sampling error."""
    rng = np.random.default_rng(seed)
    pd = rng.uniform(0.0, 0.9, size=(5, 40)) * (rng.random((5, 40)) < 0.4)
    w = rng.uniform(0, 0.15, size=40)
    exact = binary_mi(pd, w, 0.02)
    mc = binary_mi_monte_carlo(pd, w, 0.02, samples=3000, rng=np.random.default_rng(seed),
                               conditional="sampled")
    assert mc == pytest.approx(exact, abs=0.03)

def test_mi_fallback_is_deterministic_and_close() -> None:
    """Above exact_max MI uses Monte Carlo: same seed, same value; close to the exact one."""
    rng = np.random.default_rng(5)
    pd = rng.uniform(0.0, 0.8, size=(6, 30)) * (rng.random((6, 30)) < 0.3)
    w = rng.uniform(0, 0.2, size=30)
    a = binary_mi(pd, w, exact_max=3, samples=3000, seed=4)
    b = binary_mi(pd, w, exact_max=3, samples=3000, seed=4)
    assert a == b
    assert a == pytest.approx(binary_mi(pd, w), abs=0.03)

def test_zero_detection_gives_zero() -> None:
    """p_d = 0 everywhere: END and MI are 0."""
    pd = np.zeros((3, 10))
    w = np.ones(10)
    assert binary_mi(pd, w) == pytest.approx(0.0, abs=1e-12)
    assert conditional_entropy_one(pd[0], w) == 0.0


def test_zero_probabilities_by_hand() -> None:
    """One particle of weight 0.5, p_d = (0.4, 0.5), clutter 0.1: P(y_S = 0) is
    exp(−|S| λ_c − w (1 − Π_{j∈S} (1 − p_dj))) for S = ∅, {0}, {1}, {0, 1}."""
    z = zero_probabilities(np.array([[0.4], [0.5]]), np.array([0.5]), 0.1)
    expected = [1.0, math.exp(-0.1 - 0.5 * 0.4), math.exp(-0.1 - 0.5 * 0.5),
                math.exp(-0.2 - 0.5 * (1.0 - 0.6 * 0.5))]
    np.testing.assert_allclose(z, expected, rtol=1e-12)


def test_outcome_pmf_of_one_measurement() -> None:
    """For one measurement the pmf indexed by the zero set is (P(y = 1), P(y = 0))."""
    np.testing.assert_allclose(outcome_pmf(np.array([1.0, 0.3])), [0.7, 0.3])


def test_certain_detection_of_one_particle() -> None:
    """p_d = 1 on one particle of weight w: y = 1 exactly when a target is there, so
    H[Y | X] = 0 and I = H[Y] = h_b(e^{−w})."""
    pd, w = np.array([[1.0]]), np.array([0.5])
    assert conditional_entropy_one(pd[0], w) == pytest.approx(0.0, abs=1e-12)
    assert measurement_entropy(pd, w) == pytest.approx(h_b(math.exp(-0.5)), rel=1e-12)
    assert binary_mi(pd, w) == pytest.approx(h_b(math.exp(-0.5)), rel=1e-12)


def test_clutter_only_measurement_carries_no_information() -> None:
    """p_d = 0 with clutter λ_c: y is independent of X, H[Y] = H[Y | X] = h_b(e^{−λ_c})."""
    pd, w = np.zeros((1, 3)), np.ones(3)
    expected = h_b(math.exp(-0.3))
    assert measurement_entropy(pd, w, 0.3) == pytest.approx(expected, rel=1e-12)
    assert conditional_entropy(pd, w, 0.3) == pytest.approx(expected, rel=1e-9)
    assert binary_mi(pd, w, 0.3) == pytest.approx(0.0, abs=1e-9)


def test_conditional_entropy_is_the_sum_over_measurements() -> None:
    """H[Y | X] is modular: the sum of the one-measurement terms."""
    rng = np.random.default_rng(2)
    pd = rng.uniform(0.0, 0.9, size=(4, 20))
    w = rng.uniform(0.0, 0.2, size=20)
    total = sum(conditional_entropy_one(row, w, 0.05) for row in pd)
    assert conditional_entropy(pd, w, 0.05) == pytest.approx(total, rel=1e-12)


def test_given_conditional_entropy_is_used() -> None:
    """``h_cond`` replaces the computed H[Y | X]: I = H[Y] − h_cond; a negative exact MI beyond
    round-off is an arithmetic error, not a silent 0."""
    rng = np.random.default_rng(3)
    pd = rng.uniform(0.0, 0.9, size=(3, 10))
    w = rng.uniform(0.0, 0.3, size=10)
    h_y = measurement_entropy(pd, w)
    assert binary_mi(pd, w, h_cond=0.1) == pytest.approx(h_y - 0.1, rel=1e-12)
    assert binary_mi(pd, w, h_cond=h_y + 1e-13) == 0.0
    with pytest.raises(ArithmeticError, match="negative"):
        binary_mi(pd, w, h_cond=h_y + 1.0)


def test_monte_carlo_entropy_matches_exact() -> None:
    """The sampled H[Y] agrees with the exact sum over outcomes within three standard errors
    (0.05 nats; leaving out the clutter would move H[Y] by 0.17)."""
    rng = np.random.default_rng(4)
    pd = rng.uniform(0.0, 0.9, size=(4, 30)) * (rng.random((4, 30)) < 0.5)
    w = rng.uniform(0.0, 0.1, size=30)
    mc = monte_carlo_entropy(pd, w, 0.05, samples=1500, rng=np.random.default_rng(0))
    assert mc == pytest.approx(measurement_entropy(pd, w, 0.05), abs=0.05)


def test_sample_target_sets() -> None:
    """Targets land only on particles with weight; the mean count is the total weight; no
    weight, no targets."""
    sets = sample_target_sets(np.array([0.0, 2.0, 0.0]), 20000, np.random.default_rng(0))
    assert sets.shape == (20000, 3)
    counts = np.asarray(sets.sum(axis=0)).ravel()
    assert counts[0] == counts[2] == 0.0
    assert counts[1] / 20000 == pytest.approx(2.0, abs=0.05)
    empty = sample_target_sets(np.zeros(4), 10, np.random.default_rng(0))
    assert empty.shape == (10, 4) and empty.nnz == 0


def test_no_measurement_and_bad_shapes() -> None:
    """No measurement gives 0 everywhere; mismatched shapes and more than 24 exact measurements
    raise naming ``pd``."""
    w = np.ones(3)
    none = np.zeros((0, 3))
    assert measurement_entropy(none, w) == 0.0
    assert monte_carlo_entropy(none, w, 0.0, samples=10, rng=np.random.default_rng(0)) == 0.0
    assert binary_mi_monte_carlo(none, w, 0.0, samples=10, rng=np.random.default_rng(0)) == 0.0
    with pytest.raises(InvalidInputError, match="pd"):
        binary_mi(np.zeros((2, 4)), w)
    with pytest.raises(InvalidInputError, match="pd"):
        measurement_entropy(np.zeros((25, 3)), w)
