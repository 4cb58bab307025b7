"""Signatures: truncation to the heaviest nodes, and the lower bounds that let the EMD matrix
skip pairs."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.signatures import (
    centroid_bound,
    nearest_support_bound,
    truncate_rows,
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


def _reference_truncate(w: np.ndarray, mass: float) -> tuple[np.ndarray, np.ndarray]:
    """The truncation by NumPy sorting alone (lexsort of the candidates, cumsum, searchsorted)."""
    total = float(w.sum())
    cand = np.flatnonzero(w > (1.0 - mass) * total / w.size)
    order = cand[np.lexsort((cand, -w[cand]))]
    k = int(np.searchsorted(np.cumsum(w[order]), mass * total)) + 1
    nodes = np.sort(order[:min(k, order.size)])
    return nodes, w[nodes] / w[nodes].sum()


@pytest.mark.parametrize("seed", range(8))
def test_one_pass_truncation_equals_the_sorting_one(seed: int) -> None:
    """The one-pass kernel keeps exactly the nodes and weights of a NumPy sort, ties (repeated
    and quantised weights), zeros and heavy tails included."""
    rng = np.random.default_rng(seed)
    for _ in range(40):
        n = int(rng.integers(1, 3000))
        kind = rng.integers(4)
        w = (rng.random(n) if kind == 0 else np.round(rng.random(n), 2) if kind == 1
             else rng.pareto(1.5, n) if kind == 2 else np.repeat(rng.random(n // 7 + 1), 7)[:n])
        w[rng.random(n) < 0.3] = 0.0
        if w.sum() <= 0.0:
            w[0] = 1.0
        for mass in (0.5, 0.9, 0.999, float(rng.uniform(0.01, 1.0))):
            sig = truncate_signature(w, mass)
            nodes, weights = _reference_truncate(w, mass)
            np.testing.assert_array_equal(sig.nodes, nodes)
            np.testing.assert_array_equal(sig.weights, weights)


@pytest.mark.parametrize("order", ["C", "F", "strided"])
def test_truncating_all_rows_equals_one_row_at_a_time(order: Literal["C", "F", "strided"]) -> None:
    """Rows of a C- or Fortran-ordered array (a transposed bank) or of a strided view truncate
    as the sorting reference does row by row, totals summed as NumPy sums a row."""
    rng = np.random.default_rng(7)
    for n in (1, 7, 8, 9, 129, 1000, 4099, 9001):  # 9001: rows past the candidate buffer
        rows = rng.pareto(1.2, (11, n)) * (rng.random((11, n)) < 0.6)
        rows[:, 0] += 1e-3
        arr = (np.repeat(rows, 2, axis=1)[:, ::2] if order == "strided"
               else np.asfortranarray(rows) if order == "F" else np.ascontiguousarray(rows))
        for mass in (0.3, 0.9, 0.999):
            sigs = truncate_rows(arr, mass)
            for row, sig in zip(arr, sigs, strict=True):
                nodes, weights = _reference_truncate(row, mass)
                np.testing.assert_array_equal(sig.nodes, nodes)
                np.testing.assert_array_equal(sig.weights, weights)


def test_distributions_checks_name_the_first_fault() -> None:
    """The fast row-sum checks fall back to naming NaN, infinite, negative and empty rows."""
    from searchtrack.estimate.signatures import distributions

    good = np.random.default_rng(1).random((3, 5))
    assert distributions("x", good, 5) is not None
    for value, what in ((np.nan, "finite"), (np.inf, "finite"), (-1e-300, "non-negative")):
        bad = good.copy()
        bad[1, 2] = value
        with pytest.raises(InvalidInputError, match=what):
            distributions("x", bad, 5)
    both = good.copy()
    both[0, 0], both[0, 1] = np.inf, -np.inf
    with pytest.raises(InvalidInputError, match="finite"):
        distributions("x", both, 5)
    empty = good.copy()
    empty[2] = 0.0
    with pytest.raises(InvalidInputError, match="row 2 has no mass"):
        distributions("x", empty, 5)
    huge = np.full((1, 5), 1e308)  # finite entries whose sum overflows
    with np.errstate(over="ignore"):
        assert distributions("x", huge, 5) is not None
