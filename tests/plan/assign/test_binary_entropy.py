"""``E[h_b(π)]`` of one binary measurement against enumeration of the target counts, with the
reported error bound holding, down to nearly invisible particles (``p_d`` = 1e-12)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.stats import poisson

from searchtrack.plan.assign.binary_entropy import conditional_entropy_bounded


def enumerated(pd: np.ndarray, w: np.ndarray, clutter: float, n_max: int) -> float:
    """``Σ_counts P(counts) h_b(π(counts))`` with ``π = e^{−λ} Π (1 − p_i)^{N_i}``."""
    log_miss = np.log1p(-pd)
    total = 0.0
    for counts in itertools.product(range(n_max + 1), repeat=len(w)):
        prob = float(np.prod(poisson.pmf(counts, w)))
        big_l = clutter - float(np.dot(counts, log_miss))
        if big_l == 0.0:
            continue
        one_minus = -math.expm1(-big_l)
        total += prob * (big_l * math.exp(-big_l) - one_minus * math.log(one_minus))
    return total


@pytest.mark.parametrize("seed", range(40))
def test_matches_enumeration_within_its_bound(seed: int) -> None:
    """Random rows of 1–2 particles with ``p_d`` from 1e-12 to 0.9, with and without clutter."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 3))
    pd = 10.0 ** rng.uniform(-12, -0.05, size=n)
    w = rng.uniform(0.05, 1.0, size=n)
    clutter = 0.0 if seed % 3 else float(rng.uniform(0.0, 0.5))
    got = conditional_entropy_bounded(pd, w, clutter)
    truth = enumerated(pd, w, clutter, n_max=28 if n == 1 else 24)
    assert got.error < 1e-11
    assert abs(got.value - truth) <= got.error + 1e-14 + 1e-12 * truth


def test_no_visible_particle_and_no_clutter_is_certain() -> None:
    """``p_d = 0`` everywhere: π = 1 surely, entropy 0 with error 0."""
    got = conditional_entropy_bounded(np.zeros(3), np.ones(3))
    assert got.value == 0.0 and got.error == 0.0


def test_certain_detection_has_entropy_of_the_count() -> None:
    """``p_d = 1``: π is 1 with probability e^{−w}, else 0, so E h_b(π) = 0."""
    got = conditional_entropy_bounded(np.array([1.0]), np.array([0.8]))
    assert got.value == pytest.approx(0.0, abs=1e-13)
