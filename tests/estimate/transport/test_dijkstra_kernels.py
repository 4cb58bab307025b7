"""The bounded Dijkstra kernel: SciPy's distances within the limit, early stop, inf beyond."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.estimate.transport.dijkstra_kernels import bounded_rows
from searchtrack.estimate.transport.road_blocks import graph_arrays
from searchtrack.models import random_network


@pytest.mark.parametrize("seed", range(4))
def test_rows_match_scipy_within_the_limit(seed: int) -> None:
    """Each entry is SciPy's distance where that is ≤ the limit, and stays inf beyond it."""
    net = random_network(8, 400.0, seed=seed)
    rng = np.random.default_rng(seed)
    sources = rng.choice(net.n_nodes, 5, replace=False)
    targets = rng.choice(net.n_nodes, 30, replace=False)
    want = net.shortest_paths(sources)[:, targets]
    limit = float(np.median(want))
    col = np.full(net.n_nodes, -1, dtype=np.int64)
    col[targets] = np.arange(targets.size)
    for lim in (limit, math.inf):
        out = np.full(want.shape, math.inf)
        work = bounded_rows(*graph_arrays(net), sources.astype(np.int64), col, targets.size,
                            lim, out)
        inside = want <= lim
        np.testing.assert_allclose(out[inside], want[inside], rtol=1e-12)
        assert np.isinf(out[~inside]).all() and 0 < work <= sources.size * net.n_nodes


def test_stops_once_every_target_is_settled() -> None:
    """A target next to the source settles after a handful of nodes, not the whole graph."""
    net = random_network(8, 400.0, seed=1)
    nbr = int(net.edges[0, 1])
    col = np.full(net.n_nodes, -1, dtype=np.int64)
    col[nbr] = 0
    out = np.full((1, 1), math.inf)
    work = bounded_rows(*graph_arrays(net), net.edges[:1, 0].copy(), col, 1, math.inf, out)
    assert out[0, 0] == pytest.approx(net.lengths_m[0]) and work <= 4
