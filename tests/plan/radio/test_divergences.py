"""Factorised divergences and void probability against the literal sums over every label set
(eqs. 41, 43, 44), and their basic properties."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.plan.radio.divergences import (
    cauchy_schwarz,
    disc_mass,
    renyi,
    void_probability,
)


def random_pair(rng: np.random.Generator, labels: int = 3,
                n: int = 7) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Two LMBs on shared particles: random r in (0, 1), random normalised weights."""
    r1, r2 = rng.uniform(0.05, 0.95, labels), rng.uniform(0.05, 0.95, labels)
    w1, w2 = rng.uniform(0.1, 1.0, (labels, n)), rng.uniform(0.0, 1.0, (labels, n))
    return r1, w1 / w1.sum(1, keepdims=True), r2, w2 / w2.sum(1, keepdims=True)


def label_sets(labels: int) -> list[tuple[int, ...]]:
    """Every subset of range(labels)."""
    return [s for k in range(labels + 1) for s in itertools.combinations(range(labels), k)]


def set_weight(r: FloatArray, subset: tuple[int, ...]) -> float:
    """w(L) = Π_{λ∉L}(1 − r) Π_{λ∈L} r."""
    return math.prod(r[i] if i in subset else 1 - r[i] for i in range(r.size))


def renyi_literal(r1: FloatArray, w1: FloatArray, r2: FloatArray, w2: FloatArray,
                  alpha: float) -> float:
    """Eq. 41 with the sum over label sets written out."""
    c = np.sum(w2**alpha * w1 ** (1 - alpha), axis=1)
    total = sum(set_weight(r2, s) ** alpha * set_weight(r1, s) ** (1 - alpha)
                * math.prod(c[i] for i in s) for s in label_sets(r1.size))
    return math.log(total) / (alpha - 1)


def inner_literal(ra: FloatArray, wa: FloatArray, rb: FloatArray, wb: FloatArray,
                  k: float) -> float:
    """Eq. 43: Σ_L w_a(L) w_b(L) Π_{λ∈L} K Σ ω_a ω_b."""
    c = np.sum(wa * wb, axis=1)
    return sum(set_weight(ra, s) * set_weight(rb, s) * math.prod(k * c[i] for i in s)
               for s in label_sets(ra.size))


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("alpha", [0.1, 0.5, 2.0, 3.5])
def test_renyi_equals_the_label_set_sum(seed: int, alpha: float) -> None:
    """The per-label form equals eq. 41 summed over all 2^|L| label sets."""
    r1, w1, r2, w2 = random_pair(np.random.default_rng(seed), labels=4)
    assert renyi(r1, w1, r2, w2, alpha) == pytest.approx(
        renyi_literal(r1, w1, r2, w2, alpha), rel=1e-10)


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("k", [0.3, 1.0, 20.0])
def test_cauchy_schwarz_equals_the_label_set_sum(seed: int, k: float) -> None:
    """The per-label form equals eq. 42 with eq. 43's inner products over all label sets."""
    r1, w1, r2, w2 = random_pair(np.random.default_rng(seed), labels=4)
    literal = -math.log(inner_literal(r2, w2, r1, w1, k) / math.sqrt(
        inner_literal(r2, w2, r2, w2, k) * inner_literal(r1, w1, r1, w1, k)))
    assert cauchy_schwarz(r1, w1, r2, w2, k) == pytest.approx(literal, rel=1e-10)


def test_alpha_one_is_the_kullback_leibler_limit() -> None:
    """D_R at α = 1 (the KL form) lies between α = 1 ± 1e-5 and equals the KL divergence of
    the LMBs computed over label sets and particles."""
    r1, w1, r2, w2 = random_pair(np.random.default_rng(3))
    kl = float(renyi(r1, w1, r2, w2, 1.0))
    assert kl == pytest.approx(float(renyi(r1, w1, r2, w2, 1 - 1e-6)), rel=1e-4)
    assert kl == pytest.approx(float(renyi(r1, w1, r2, w2, 1 + 1e-6)), rel=1e-4)
    literal = 0.0
    for s in label_sets(r1.size):
        a, b = set_weight(r2, s), set_weight(r1, s)
        literal += a * math.log(a / b)
        for i in s:  # the particle part, weighted by the probability that i exists
            literal += a * float(np.sum(w2[i] * np.log(w2[i] / w1[i])))
    assert kl == pytest.approx(literal, rel=1e-10)


@pytest.mark.parametrize("seed", range(6))
def test_zero_for_equal_densities_and_non_negative(seed: int) -> None:
    """D(π, π) = 0; D(π₂, π₁) ≥ 0 for every order and for CS."""
    r1, w1, r2, w2 = random_pair(np.random.default_rng(seed))
    for alpha in (0.2, 0.5, 1.0, 2.0):
        assert renyi(r1, w1, r1, w1, alpha) == pytest.approx(0.0, abs=1e-12)
        assert renyi(r1, w1, r2, w2, alpha) > 0.0
    assert cauchy_schwarz(r1, w1, r1, w1, 1.0) == pytest.approx(0.0, abs=1e-12)
    assert cauchy_schwarz(r1, w1, r2, w2, 1.0) > 0.0


def test_cauchy_schwarz_is_symmetric() -> None:
    """D_CS(π₂, π₁) = D_CS(π₁, π₂); Rényi is not."""
    r1, w1, r2, w2 = random_pair(np.random.default_rng(9))
    assert cauchy_schwarz(r1, w1, r2, w2, 2.0) == pytest.approx(
        float(cauchy_schwarz(r2, w2, r1, w1, 2.0)), rel=1e-12)
    assert renyi(r1, w1, r2, w2, 0.3) != pytest.approx(float(renyi(r2, w2, r1, w1, 0.3)))


def test_broadcasts_over_leading_axes() -> None:
    """A batch of posteriors against one prediction gives one divergence each."""
    rng = np.random.default_rng(4)
    pairs = [random_pair(rng) for _ in range(5)]
    r1, w1 = pairs[0][0], pairs[0][1]
    r2 = np.stack([p[2] for p in pairs])
    w2 = np.stack([p[3] for p in pairs])
    for f, arg in ((renyi, 0.5), (cauchy_schwarz, 1.0)):
        batch = f(r1, w1, r2, w2, arg)
        assert batch.shape == (5,)
        for b in range(5):
            assert batch[b] == pytest.approx(float(f(r1, w1, r2[b], w2[b], arg)), rel=1e-12)


def test_certain_labels_and_disjoint_support() -> None:
    """r ∈ {0, 1} is handled: a label certain in both contributes only its particles; one that
    π₂ holds certain and π₁ rules out gives an infinite divergence for α ≥ 1."""
    w = np.array([[0.5, 0.5, 0.0]])
    v = np.array([[0.0, 0.5, 0.5]])
    one, zero = np.array([1.0]), np.array([0.0])
    assert renyi(one, w, one, w, 0.5) == pytest.approx(0.0, abs=1e-15)
    assert renyi(zero, w, zero, v, 0.5) == pytest.approx(0.0, abs=1e-15)
    assert math.isinf(float(renyi(zero, w, one, w, 2.0)))
    assert math.isinf(float(renyi(one, w, one, v, 1.0)))
    assert math.isfinite(float(renyi(one, w, one, v, 0.5)))
    assert math.isfinite(float(cauchy_schwarz(one, w, one, v, 1.0)))


def test_void_probability_equals_the_label_set_sum() -> None:
    """Eq. 44 written over label sets, B = Σ_L w(L) Π_{λ∈L} (1 − P_λ), equals Π_λ (1 − r P_λ);
    the mass counts only particles strictly inside the disc."""
    rng = np.random.default_rng(1)
    r = rng.uniform(0.1, 0.9, 3)
    w = rng.uniform(0.1, 1.0, (3, 50))
    w /= w.sum(1, keepdims=True)
    xy = rng.uniform(-100.0, 100.0, (3, 50, 2))
    centres = rng.uniform(-50.0, 50.0, (4, 2))
    got = void_probability(r, w, xy, centres, 40.0)
    for c, b in zip(centres, got, strict=True):
        mass = [float(np.sum(w[i][np.hypot(*(xy[i] - c).T) < 40.0])) for i in range(3)]
        literal = sum(set_weight(r, s) * math.prod(1 - mass[i] for i in s)
                      for s in label_sets(3))
        assert b == pytest.approx(literal, rel=1e-12)
    edge = np.array([[[30.0, 40.0]]])  # exactly 50 m from the origin: not inside
    assert disc_mass(np.ones((1, 1)), edge, np.zeros(2), 50.0) == pytest.approx([0.0])
    assert disc_mass(np.ones((1, 1)), edge, np.zeros(2), 50.001) == pytest.approx([1.0])
    assert void_probability(r, w, xy, centres, 0.0) == pytest.approx(np.ones(4))
    assert disc_mass(w, xy, np.zeros((2, 3, 2)), 10.0).shape == (2, 3, 3)


def test_bad_parameters() -> None:
    """α ≤ 0, K ≤ 0 and a negative radius are refused, naming the field."""
    r1, w1, r2, w2 = random_pair(np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="alpha"):
        renyi(r1, w1, r2, w2, 0.0)
    with pytest.raises(InvalidInputError, match="cs_k"):
        cauchy_schwarz(r1, w1, r2, w2, -1.0)
    with pytest.raises(InvalidInputError, match="radius_m"):
        void_probability(r1, w1, np.zeros((3, 7, 2)), np.zeros(2), -1.0)
