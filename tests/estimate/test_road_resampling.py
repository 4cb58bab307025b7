"""Systematic resampling of batches of filters, N_eff and the resampling policy (Eq. 5–6)."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.road_resampling import (
    ResamplePolicy,
    effective_sample_size,
    systematic_indices,
)


def _reference(w: np.ndarray, u: float) -> list[int]:
    """The low-variance sampler of Probabilistic Robotics, one row, written as a loop."""
    n = w.size
    w = w / w.sum()
    out, i, c = [], 0, w[0]
    for j in range(n):
        target = (u + j) / n
        while c <= target and i < n - 1:
            i += 1
            c += w[i]
        out.append(i)
    return out


def test_by_hand() -> None:
    """Weights (0.5, 0.5, 0, 0) with offset 0.1: two copies of each of the first two."""
    idx = systematic_indices(np.array([[0.5, 0.5, 0.0, 0.0]]), np.array([0.1]))
    np.testing.assert_array_equal(idx, [[0, 0, 1, 1]])
    idx = systematic_indices(np.array([[0.0, 0.0, 1.0, 0.0]]), np.array([0.0]))
    np.testing.assert_array_equal(idx, [[2, 2, 2, 2]])


def test_equal_weights_are_the_identity() -> None:
    """With equal weights every particle is kept exactly once, whatever the offset."""
    idx = systematic_indices(np.ones((3, 7)), np.array([0.0, 0.5, 0.999]))
    np.testing.assert_array_equal(idx, np.tile(np.arange(7), (3, 1)))


def test_batch_matches_the_loop_and_keeps_counts_within_one() -> None:
    """Each row equals the one-row loop, and particle n is copied ⌊N w_n⌋ or ⌈N w_n⌉ times."""
    rng = np.random.default_rng(0)
    w = rng.random((20, 50)) ** 4
    u = rng.random(20)
    idx = systematic_indices(w, u)
    for b in range(20):
        assert idx[b].tolist() == _reference(w[b], u[b])
        counts = np.bincount(idx[b], minlength=50)
        expected = 50 * w[b] / w[b].sum()
        assert np.all(counts >= np.floor(expected) - 1e-9)
        assert np.all(counts <= np.ceil(expected) + 1e-9)
        assert np.all(np.diff(idx[b]) >= 0)


def test_effective_sample_size() -> None:
    """Eq. 5: N for equal weights, 1 for a single particle, per row."""
    w = np.array([[0.25] * 4, [1.0, 0.0, 0.0, 0.0], [0.5, 0.5, 0.0, 0.0]])
    np.testing.assert_allclose(effective_sample_size(w), [4.0, 1.0, 2.0])


def test_policy() -> None:
    """Default: always due; with a threshold q, due only when N_eff < q·N."""
    w = np.array([[0.25] * 4, [0.7, 0.1, 0.1, 0.1]])
    np.testing.assert_array_equal(ResamplePolicy().due(w), [True, True])
    np.testing.assert_array_equal(ResamplePolicy(2 / 3).due(w), [False, True])
    with pytest.raises(InvalidInputError, match="threshold"):
        ResamplePolicy(0.0)
    with pytest.raises(InvalidInputError, match="threshold"):
        ResamplePolicy(1.5)


def test_bad_input_names_the_field() -> None:
    """Weights must be non-negative with positive row sums; offsets in [0, 1), one per row."""
    with pytest.raises(InvalidInputError, match=r"^w="):
        systematic_indices(np.zeros((1, 3)), np.array([0.5]))
    with pytest.raises(InvalidInputError, match=r"^w="):
        systematic_indices(np.array([[1.0, -1.0, 1.0]]), np.array([0.5]))
    with pytest.raises(InvalidInputError, match=r"^w="):
        systematic_indices(np.array([[np.nan, 1.0]]), np.array([0.5]))
    with pytest.raises(InvalidInputError, match=r"^u="):
        systematic_indices(np.ones((1, 3)), np.array([1.0]))
    with pytest.raises(InvalidInputError, match=r"^u="):
        systematic_indices(np.ones((2, 3)), np.array([0.5]))
