"""One pair's EMD straight on the network simplex: the value and plan of emd() to 1e-9."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Status
from searchtrack.estimate.transport import emd
from searchtrack.estimate.transport.pair_emd import pair_emd


@pytest.mark.parametrize("seed", range(40))
def test_pair_emd_is_emd_on_random_problems(seed: int) -> None:
    """Random sizes, weights and costs (ties included): the EMD of emd() with mass='normalize',
    and a plan on the cells it reports that meets both normalised marginals."""
    rng = np.random.default_rng([seed, 31])
    m, n = int(rng.integers(1, 40)), int(rng.integers(1, 60))
    p, q = rng.random(m) + 1e-3, rng.random(n) * rng.uniform(0.5, 3.0) + 1e-3
    cost = rng.random((m, n)) * 500.0
    if seed % 4 == 0:
        cost = np.round(cost / 100.0) * 100.0  # many ties: degenerate pivots
    got = pair_emd(p, q, cost, Deadline(math.inf))
    want = emd(p, q, cost)
    assert got.status is Status.OPTIMAL and got.result is None and got.value is not None
    assert want.objective is not None
    assert got.value == pytest.approx(want.objective, rel=1e-9, abs=1e-9)
    assert (got.rows < m).all() and (got.cols < n).all() and got.rows.size >= 1


def test_pair_emd_single_cells() -> None:
    """One source and one sink: the whole mass at the one distance."""
    got = pair_emd(np.array([2.0]), np.array([0.5]), np.array([[7.5]]), Deadline(math.inf))
    assert got.value == 7.5 and got.rows.tolist() == [0] and got.cols.tolist() == [0]
