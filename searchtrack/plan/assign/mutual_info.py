"""Mutual information between a Poisson-RFS belief and binary detections (paper 003 §2.5).

Measurement ``j`` (a pose ``q_j``) reports ``y_j = 1(Z_j ≠ ∅)``. With ``a_j(x) = 1 − p_d(x | q_j)``
and clutter rate ``λ_c``, given the target set ``X`` the ``y_j`` are independent with
``π_j(X) = P(y_j = 0 | X) = e^{−λ_c} Π_{x∈X} a_j(x)``. For a Poisson RFS of intensity ``v`` (the
particle PHD ``Σ_i w_i δ_{x_i}``) the probability-generating functional gives, for every set ``S``,

    P(y_S = 0) = exp(−|S| λ_c − Σ_i w_i (1 − Π_{j∈S} a_j(x_i)))

and the joint pmf follows by inclusion–exclusion over the ones (a superset Möbius transform):
``H[Y]`` exactly over the ``2^M`` outcomes. ``H[Y | X] = Σ_j E[h_b(π_j)]`` is modular; by the
Mecke formula ``E[π log π] = e^{−λ_c} G (−λ_c + Σ_i w_i a_i log a_i)`` with
``G = exp(−Σ_i w_i p_d(x_i))``, and ``E[(1 − π) log(1 − π)] = −Σ_k (E π^k − E π^{k+1}) / k`` with
``E π^k = exp(−k λ_c + Σ_i w_i (a_i^k − 1))``, summed with a bounded error however small the
``p_d`` (:mod:`.binary_entropy`).
``I = H[Y] − H[Y | X]`` in nats. Above ``exact_max`` measurements ``H[Y]`` is estimated by Monte
Carlo over target sets drawn from the Poisson RFS, with the same draws for every call of a seed.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from scipy import sparse
from scipy.special import logsumexp

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.plan.assign.binary_entropy import Bounded, conditional_entropy_bounded

_LOG_FLOOR = 1e-12
#: Round-off allowed per measurement in the exact MI before a negative value is an error.
ROUND_OFF = 1e-10


def _check(pd: FloatArray, weights: FloatArray) -> None:
    if pd.ndim != 2 or pd.shape[1] != weights.shape[0]:
        raise InvalidInputError("pd", pd.shape, f"must be (M, {weights.shape[0]})")


def zero_probabilities(pd: FloatArray, weights: FloatArray, clutter_rate: float) -> FloatArray:
    """``(2^M,)`` values ``P(y_S = 0)``, index ``S = Σ_{j∈S} 2^j``."""
    m, n = pd.shape
    size = 1 << m
    miss = 1.0 - pd
    seen = np.zeros(size)
    chunk = max(1, (1 << 21) // size)
    for lo in range(0, n, chunk):
        a = miss[:, lo:lo + chunk]
        prods = np.empty((size, a.shape[1]))
        prods[0] = 1.0
        for j in range(m):
            half = 1 << j
            np.multiply(prods[:half], a[j], out=prods[half:2 * half])
        seen += (1.0 - prods) @ weights[lo:lo + chunk]
    popcount = np.array([bin(s).count("1") for s in range(size)], dtype=np.float64)
    out: FloatArray = np.exp(-popcount * clutter_rate - seen)
    return out


def outcome_pmf(zero_probs: FloatArray) -> FloatArray:
    """Joint pmf of ``y`` indexed by its zero set (superset Möbius transform of ``P(y_S = 0)``)."""
    size = zero_probs.shape[0]
    m = size.bit_length() - 1
    g = zero_probs.copy()
    for j in range(m):
        view = g.reshape(1 << (m - 1 - j), 2, 1 << j)
        view[:, 0, :] -= view[:, 1, :]
    return np.clip(g, 0.0, 1.0)


def measurement_entropy(pd: FloatArray, weights: FloatArray, clutter_rate: float = 0.0) -> float:
    """``H[Y]`` in nats, exact over the ``2^M`` outcomes."""
    _check(pd, weights)
    if pd.shape[0] > 24:
        raise InvalidInputError("pd", pd.shape, "exact H[Y] takes at most 24 measurements")
    if pd.shape[0] == 0:
        return 0.0
    p = outcome_pmf(zero_probabilities(pd, weights, clutter_rate))
    nz = p[p > 0.0]
    return float(-np.sum(nz * np.log(nz)))


def conditional_entropy_one(pd_row: FloatArray, weights: FloatArray,
                            clutter_rate: float = 0.0) -> float:
    """``E_X[h_b(π(X))]`` for one binary measurement (error at most
    :data:`~searchtrack.plan.assign.binary_entropy.TOLERANCE` nats or so; see
    :func:`~searchtrack.plan.assign.binary_entropy.conditional_entropy_bounded`)."""
    return conditional_entropy_bounded(pd_row, weights, clutter_rate).value


def conditional_entropy_with_error(pd: FloatArray, weights: FloatArray,
                                   clutter_rate: float = 0.0) -> Bounded:
    """``H[Y | X] = Σ_j E[h_b(π_j)]`` in nats and a bound on its absolute error."""
    _check(pd, weights)
    parts = [conditional_entropy_bounded(row, weights, clutter_rate) for row in pd]
    return Bounded(sum(p.value for p in parts), sum(p.error for p in parts))


def conditional_entropy(pd: FloatArray, weights: FloatArray, clutter_rate: float = 0.0) -> float:
    """``H[Y | X] = Σ_j E[h_b(π_j)]`` in nats."""
    return conditional_entropy_with_error(pd, weights, clutter_rate).value


def sample_target_sets(weights: FloatArray, samples: int,
                       rng: np.random.Generator) -> sparse.csr_matrix:
    """``(samples, N)`` counts: each row a target set drawn from the Poisson RFS of the PHD."""
    total = float(np.sum(weights))
    n = weights.shape[0]
    counts = rng.poisson(total, size=samples) if total > 0 else np.zeros(samples, dtype=np.int64)
    idx = rng.choice(n, size=int(counts.sum()), p=weights / total) if total > 0 else \
        np.zeros(0, dtype=np.int64)
    rows = np.repeat(np.arange(samples), counts)
    mat = sparse.csr_matrix((np.ones(idx.size), (rows, idx)), shape=(samples, n))
    mat.sum_duplicates()
    return mat


def binary_mi_monte_carlo(
    pd: FloatArray, weights: FloatArray, clutter_rate: float, *, samples: int,
    rng: np.random.Generator, conditional: Literal["closed", "sampled"] = "closed",
) -> float:
    """Monte Carlo ``I[X; Y]``: ``H[Y]`` from ``samples`` draws of ``(X, y)`` with the marginal
    ``P(y)`` averaged over the same draws; ``H[Y | X]`` closed form or sampled."""
    _check(pd, weights)
    if pd.shape[0] == 0:
        return 0.0
    h_y, pi, log_pi, log_1mpi = _sampled(pd, weights, clutter_rate, samples, rng)
    if conditional == "closed":
        h_cond = conditional_entropy(pd, weights, clutter_rate)
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            hb = -(pi * log_pi + (1.0 - pi) * log_1mpi)
        h_cond = float(np.mean(np.sum(np.nan_to_num(hb), axis=1)))
    return max(0.0, h_y - h_cond)


def monte_carlo_entropy(pd: FloatArray, weights: FloatArray, clutter_rate: float, *,
                        samples: int, rng: np.random.Generator) -> float:
    """Monte Carlo ``H[Y]`` (nats) from ``samples`` draws of ``(X, y)``."""
    _check(pd, weights)
    if pd.shape[0] == 0:
        return 0.0
    return _sampled(pd, weights, clutter_rate, samples, rng)[0]


def _sampled(pd: FloatArray, weights: FloatArray, clutter_rate: float, samples: int,
             rng: np.random.Generator) -> tuple[float, FloatArray, FloatArray, FloatArray]:
    m = pd.shape[0]
    sets = sample_target_sets(weights, samples, rng)
    log_a = np.log(np.maximum(1.0 - pd, _LOG_FLOOR))
    log_pi = np.asarray(sets @ log_a.T) - clutter_rate  # (S, M)
    pi = np.exp(log_pi)
    y = rng.random((samples, m)) >= pi  # y = 1 with probability 1 − π
    log_1mpi = np.log(np.maximum(-np.expm1(log_pi), 1e-300))
    yf = y.astype(np.float64)
    log_lik = yf @ log_1mpi.T + (1.0 - yf) @ log_pi.T  # [s, s'] = log P(y_s | X_s')
    h_y = -float(np.mean(logsumexp(log_lik, axis=1) - math.log(samples)))
    return h_y, pi, log_pi, log_1mpi


def binary_mi(pd: FloatArray, weights: FloatArray, clutter_rate: float = 0.0, *,
              exact_max: int = 12, samples: int = 2000, seed: int = 0,
              h_cond: float | None = None) -> float:
    """``I[X; Y]`` (nats) of the ``(M, N)`` detection probabilities: exact for
    ``M ≤ exact_max``, else ``H[Y]`` by Monte Carlo with ``samples`` draws from ``seed``.
    ``h_cond`` passes a precomputed ``H[Y | X]`` (it is modular, so callers cache it).

    The exact value is off by at most the error of ``H[Y | X]``
    (:func:`conditional_entropy_with_error`) plus round-off; a difference below
    ``-ROUND_OFF`` cannot come from either and raises :class:`ArithmeticError`, a smaller
    negative one is round-off of a zero MI and gives 0. The Monte Carlo estimate can fall
    below zero by sampling noise; it is clipped at 0."""
    _check(pd, weights)
    if h_cond is None:
        h_cond = conditional_entropy(pd, weights, clutter_rate)
    if pd.shape[0] > exact_max:
        return max(0.0, monte_carlo_entropy(pd, weights, clutter_rate, samples=samples,
                                            rng=np.random.default_rng(seed)) - h_cond)
    mi = measurement_entropy(pd, weights, clutter_rate) - h_cond
    if mi < -ROUND_OFF * max(1.0, pd.shape[0]):
        raise ArithmeticError(f"exact binary MI came out negative ({mi:.3g} nats)")
    return max(0.0, mi)
