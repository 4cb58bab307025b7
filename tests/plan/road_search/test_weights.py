"""Target weights (Eq. 20) and weighted edge values (Eq. 21) against hand computations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.road_search.weights import edge_values, target_weights

from .helpers import edge, grid_roads


def sigmoid(x: float, a: float = 10.0) -> float:
    return 1.0 / (1.0 + math.exp(-a * (x - 0.5)))


def test_sum_normalisation_matches_eq_20() -> None:
    """η = 1/ΣH: weights are the sigmoid of each entropy's share."""
    got = target_weights(np.array([1.0, 3.0]))
    assert got == pytest.approx([sigmoid(0.25), sigmoid(0.75)], rel=1e-12)
    assert got[1] > 0.9 > 0.1 > got[0]


def test_max_normalisation_keeps_the_most_uncertain_target_high() -> None:
    """η = 1/max H: the top target sits at σ(a/2) for any M; with "sum" and M = 4 it is low."""
    h = np.array([1.0, 2.0, 3.0, 4.0])
    by_max = target_weights(h, normalization="max", gain=4.0)
    assert by_max == pytest.approx([sigmoid(x / 4.0, 4.0) for x in h], rel=1e-12)
    assert by_max[-1] == pytest.approx(1.0 / (1.0 + math.exp(-2.0)))
    assert np.all(target_weights(h) < 0.5)  # every share is below 1/2


def test_zero_entropies_and_uniform_weighting() -> None:
    """All-zero entropies count as equal; "uniform" gives γ = 1 (Eq. 17)."""
    assert target_weights(np.zeros(2)) == pytest.approx([0.5, 0.5])
    assert target_weights(np.zeros(3), normalization="max") == pytest.approx(
        [sigmoid(1.0)] * 3)
    assert np.array_equal(target_weights(np.array([0.1, 9.0]), weighting="uniform"), [1.0, 1.0])


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"entropy": np.array([-1.0, 1.0])}, "entropy"),
    ({"entropy": np.array([np.nan])}, "entropy"),
    ({"entropy": np.zeros(0)}, "entropy"),
    ({"entropy": np.ones(2), "gain": -1.0}, "gain"),
    ({"entropy": np.ones(2), "normalization": "mean"}, "normalization"),
    ({"entropy": np.ones(2), "weighting": "naive"}, "weighting"),
])
def test_bad_input_names_the_field(kwargs: dict[str, object], field: str) -> None:
    """Each bad argument raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError) as err:
        target_weights(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_edge_values_count_both_directions_and_divide_by_length() -> None:
    """Two particles on road 3–4 (one per direction) and one on road 0–1, weights γ·w."""
    roads = grid_roads()
    e = np.array([[edge(3, 4), edge(4, 3)], [edge(0, 1), edge(0, 1)]])
    w = np.array([[0.5, 0.5], [0.25, 0.75]])
    gamma = np.array([2.0, 1.0])
    both = edge_values(roads.length, e, w, gamma)
    assert both[edge(3, 4)] == both[edge(4, 3)] == pytest.approx(2.0)
    assert both[edge(0, 1)] == both[edge(1, 0)] == pytest.approx(1.0)
    assert both.sum() == pytest.approx(6.0)
    one = edge_values(roads.length, e, w, gamma, both_directions=False, per_length=True)
    assert one[edge(3, 4)] == one[edge(4, 3)] == pytest.approx(1.0 / 100.0)
    assert one[edge(0, 1)] == pytest.approx(1.0 / 100.0) and one[edge(1, 0)] == 0.0
