"""END and binary MI: values, monotonicity, submodularity, exact vs Monte Carlo."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.plan.assign.mutual_info import (
    binary_mi,
    binary_mi_monte_carlo,
    conditional_entropy_one,
    outcome_pmf,
    zero_probabilities,
)
from searchtrack.plan.assign.objectives import (
    ExpectedDetections,
    ExpectedDetectionsFunction,
    MutualInformation,
    expected_detections_of_poses,
)

from .helpers import random_problem


@pytest.mark.parametrize("objective", ["end", "mi"])
@pytest.mark.parametrize("seed", range(6))
def test_monotone_and_submodular(objective: str, seed: int) -> None:
    """f(A ∪ e) − f(A) ≥ f(B ∪ e) − f(B) ≥ 0 for A ⊆ B over random (UAV, action) sets."""
    rng = np.random.default_rng(seed)
    p = random_problem(rng, robots=4, actions=3, steps=2, particles=40, objective=objective,
                       gaussian=seed % 2 == 0)
    f = p.objective.evaluator(p)
    ground = [(r, a) for r in range(4) for a in range(3)]
    assert f.value(()) == pytest.approx(0.0, abs=1e-9)
    for _ in range(15):
        idx = rng.permutation(len(ground))
        big = [ground[i] for i in idx[:4]]
        small = big[: rng.integers(0, 4)]
        e = ground[idx[5]]
        gain_small = f.value([*small, e]) - f.value(small)
        gain_big = f.value([*big, e]) - f.value(big)
        assert gain_big >= -1e-9
        assert gain_small >= gain_big - 1e-7


def test_end_closed_form_matches_definition() -> None:
    """END equals Σ w (1 − Π (1 − p_d)) computed pose by pose, and gains match differences."""
    rng = np.random.default_rng(3)
    p = random_problem(rng, robots=3, actions=4, steps=2, gaussian=True)
    f = ExpectedDetectionsFunction(p)
    sel = ((0, 1), (2, 3))
    poses = np.concatenate([p.actions[r][a] for r, a in sel])
    expected = sum(w * (1 - np.prod([1 - p.sensor.detection_probability(q, p.positions)[j]
                                     for q in poses])) for j, w in enumerate(p.weights))
    assert f.value(sel) == pytest.approx(expected, rel=1e-12)
    assert expected_detections_of_poses(p, poses) == pytest.approx(expected, rel=1e-12)
    gains = f.gains(sel, 1)
    for a in range(4):
        assert gains[a] == pytest.approx(f.value([*sel, (1, a)]) - f.value(sel), abs=1e-12)
        assert f.gain(sel, 1, a) == pytest.approx(gains[a], abs=1e-12)


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


def test_objective_specs_build_their_set_functions() -> None:
    """Each spec names itself, declares whether it is a coverage objective and builds its set
    function; MutualInformation checks its settings."""
    from searchtrack.core.errors import InvalidInputError

    p = random_problem(np.random.default_rng(0))
    end, mi = ExpectedDetections(), MutualInformation(clutter_rate=0.1)
    assert (end.name, end.coverage, mi.name, mi.coverage) == ("end", True, "mi", False)
    assert isinstance(end.evaluator(p), ExpectedDetectionsFunction)
    assert mi.evaluator(p).value(()) == pytest.approx(0.0, abs=1e-12)
    for kwargs, field in (({"exact_max": 21}, "exact_max"), ({"samples": 5}, "samples"),
                          ({"clutter_rate": -1.0}, "clutter_rate"), ({"seed": -1}, "seed")):
        with pytest.raises(InvalidInputError, match=field):
            MutualInformation(**kwargs)  # type: ignore[arg-type]
