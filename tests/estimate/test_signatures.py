"""Signatures: truncation to the heaviest nodes, and the lower bounds that let the EMD matrix
skip pairs."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.signatures import (
    centroid_bound,
    nearest_support_bound,
    truncate_signature,
)
from searchtrack.estimate.transport import emd
from searchtrack.models import random_network
from searchtrack.models.road_metric import RoadMetric
from tests.estimate.test_emd_matrix import _rows


def test_truncation_keeps_the_smallest_heaviest_set() -> None:
    """The kept nodes are the fewest heaviest reaching the mass, renormalised."""
    w = np.array([0.05, 0.4, 0.0, 0.3, 0.25])
    sig = truncate_signature(w, 0.9)
    np.testing.assert_array_equal(sig.nodes, [1, 3, 4])
    np.testing.assert_allclose(sig.weights, np.array([0.4, 0.3, 0.25]) / 0.95)
    np.testing.assert_array_equal(truncate_signature(w, 0.7).nodes, [1, 3])
    np.testing.assert_array_equal(truncate_signature(w, 1.0).nodes, [0, 1, 3, 4])


def test_truncation_ties_go_to_the_lower_index() -> None:
    """Equal weights: the lower node index is kept first."""
    np.testing.assert_array_equal(truncate_signature([0.25] * 4, 0.5).nodes, [0, 1])


@pytest.mark.parametrize("mass", [0.5, 0.9, 0.99, 0.999, 1.0])
def test_truncation_matches_a_full_sort(mass: float) -> None:
    """On random vectors the prefiltered sort gives the same set as sorting everything."""
    rng = np.random.default_rng(int(mass * 1000))
    for _ in range(20):
        w = rng.random(300) ** 8
        sig = truncate_signature(w, mass)
        order = np.lexsort((np.arange(w.size), -w))
        csum = np.cumsum(w[order])
        k = int(np.argmax(csum >= mass * w.sum())) + 1 if mass < 1 else int((w > 0).sum())
        np.testing.assert_array_equal(sig.nodes, np.sort(order[:k]))
        assert sig.weights.sum() == pytest.approx(1.0)
        assert w[sig.nodes].sum() >= mass * w.sum() * (1 - 1e-12)


@pytest.mark.parametrize(("weights", "mass", "field"), [
    ([0.5, 0.5], 0.0, "support_mass"),
    ([0.5, 0.5], 1.5, "support_mass"),
    ([0.5, 0.5], True, "support_mass"),
    ([0.5, -0.5, 1.0], 0.9, "weights"),
    ([0.0, 0.0], 0.9, "weights"),
    ([[0.5, 0.5]], 0.9, "weights"),
    ([np.nan, 1.0], 0.9, "weights"),
])
def test_truncation_bad_input(weights: object, mass: object, field: str) -> None:
    """Bad weights or support mass raise naming the field."""
    with pytest.raises(InvalidInputError) as err:
        truncate_signature(weights, mass)  # type: ignore[arg-type]
    assert err.value.field == field



def test_lower_bounds_hold() -> None:
    """The centroid and nearest-support bounds never exceed the EMD."""
    net = random_network(10, 600.0, seed=8)
    metric = RoadMetric(net)
    rng = np.random.default_rng(8)
    for _ in range(5):
        a = truncate_signature(_rows(rng, 1, net.n_nodes, 0.1)[0], 0.95)
        b = truncate_signature(_rows(rng, 1, net.n_nodes, 0.1)[0], 0.95)
        cost = metric.distances(a.nodes, b.nodes)
        value = emd(a.weights, b.weights, cost).objective
        assert value is not None
        assert centroid_bound(metric, [a], [b])[0, 0] <= value + 1e-9
        assert nearest_support_bound(cost, a.weights, b.weights) <= value + 1e-9
