"""Lemma 5 of paper 000: P_D(t), the mass fraction in modes of each degree, by the recursion of
Algorithms 1–2, on the step grid, and by Monte Carlo (§5.3, Fig. 8)."""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork, random_network
from searchtrack.plan.fleet import (
    ChainGraph,
    chain_graph,
    mode_probabilities,
    mode_split_mc,
    split_profile,
)

from .conftest import grid_3x3, irregular

TIMES = np.arange(1.0, 20.0, 2.0)
#: P_D(t) on the 3 × 3 map with 50 m blocks at 10 m/s, t = 1, 3, …, 19 s (Fig. 8's setting).
B2 = {
    Fraction(1): [0.867, 0.600, 0.333, 0.200, 0.067, 0, 0, 0, 0, 0],
    Fraction(1, 2): [0.100, 0.300, 0.500, 0.567, 0.633, 0.567, 0.367, 0.167, 0.100, 0.033],
    Fraction(1, 3): [0.033, 0.100, 0.167, 0.100, 0.033, 0, 0, 0, 0, 0],
    Fraction(1, 4): [0, 0, 0, 0, 0, 0.067, 0.200, 0.333, 0.333, 0.333],
    Fraction(1, 6): [0, 0, 0, 0.133, 0.267, 0.333, 0.333, 0.333, 0.200, 0.067],
    Fraction(1, 12): [0, 0, 0, 0, 0, 0.033, 0.100, 0.167, 0.367, 0.567],
}


@pytest.fixture(scope="module")
def b2_graph() -> ChainGraph:
    """Chains of the 3 × 3 map with 50 m blocks."""
    return chain_graph(grid_3x3(50.0))


def test_recursion_reproduces_the_p_d_table(b2_graph: ChainGraph) -> None:
    """Every entry of the P_D table to 1e-3, and no other degree appears by t = 19 s."""
    probs = mode_probabilities(b2_graph, 10.0, TIMES)
    assert set(probs.degrees) == set(B2)
    for degree, row in B2.items():
        np.testing.assert_allclose(probs.of(degree), row, atol=1e-3)
    np.testing.assert_allclose(probs.total, 1.0, atol=1e-12)


def test_grouping_does_not_change_the_result(b2_graph: ChainGraph) -> None:
    """The recursion over subdivisions equals the recursion over single chains."""
    times = np.linspace(0.0, 32.0, 97)
    grouped = mode_probabilities(b2_graph, 10.0, times)
    single = mode_probabilities(b2_graph, 10.0, times, grouped=False)
    assert grouped.degrees == single.degrees
    np.testing.assert_allclose(grouped.probability, single.probability, atol=1e-12)


def test_monte_carlo_agrees_with_the_recursion(b2_graph: ChainGraph) -> None:
    """100,000 seeded Monte Carlo runs match the recursion to within 0.01 in every cell."""
    exact = mode_probabilities(b2_graph, 10.0, TIMES)
    mc = mode_split_mc(b2_graph, 10.0, TIMES, 100_000, seed=7)
    assert set(mc.degrees) == set(exact.degrees)
    for degree in exact.degrees:
        np.testing.assert_allclose(mc.of(degree), exact.of(degree), atol=0.01)
    np.testing.assert_allclose(mc.total, 1.0, atol=1e-12)
    again = mode_split_mc(b2_graph, 10.0, TIMES, 100_000, seed=7)
    np.testing.assert_array_equal(again.probability, mc.probability)


def test_step_grid_equals_the_recursion_on_grids(b2_graph: ChainGraph) -> None:
    """With whole-step traversal times the step-grid propagation is the recursion exactly:
    Σ_D P_D and Σ_D P_D ln(1/D) at every step to 40 s."""
    profile = split_profile(b2_graph, 10.0, 0.1, 400)
    exact = mode_probabilities(b2_graph, 10.0, profile.times_s)
    np.testing.assert_allclose(profile.mass, 1.0, atol=1e-12)
    np.testing.assert_allclose(profile.split_entropy, exact.split_entropy, atol=1e-12)


@pytest.mark.parametrize("roads", [irregular(), random_network(12, 900.0, 30.0, seed=3)],
                         ids=["hand-made", "random"])
def test_p_d_sums_to_one_on_irregular_maps(roads: RoadNetwork) -> None:
    """On maps without symmetry (dead ends, uneven roads) Σ_D P_D(t) = 1 at all t; the Monte
    Carlo agrees with the recursion; the step grid is within its rounding of the exit times."""
    graph = chain_graph(roads)
    times = np.linspace(0.0, 40.0, 81)
    exact = mode_probabilities(graph, 10.0, times)
    np.testing.assert_allclose(exact.total, 1.0, atol=1e-12)
    mc = mode_split_mc(graph, 10.0, times, 20_000, seed=1)
    np.testing.assert_allclose(mc.total, 1.0, atol=1e-12)
    for degree in exact.degrees:
        np.testing.assert_allclose(mc.of(degree), exact.of(degree), atol=0.015)
    profile = split_profile(graph, 10.0, 0.1, 400)
    np.testing.assert_allclose(profile.mass, 1.0, atol=1e-9)
    np.testing.assert_allclose(profile.split_entropy[::5], exact.split_entropy, atol=0.01)


def test_finer_steps_converge_on_irregular_maps() -> None:
    """Where traversal times are not whole steps the step grid converges to the recursion."""
    graph = chain_graph(irregular())
    exact = mode_probabilities(graph, 10.0, np.arange(0, 301) * 0.1).split_entropy
    coarse = split_profile(graph, 10.0, 0.1, 300).split_entropy
    fine = split_profile(graph, 10.0, 0.01, 3000).split_entropy[::10]
    assert np.abs(fine - exact).max() < np.abs(coarse - exact).max()
    assert np.abs(fine - exact).max() < 2e-3


def test_first_mode_leaves_linearly() -> None:
    """Before any mode can leave twice, P_1(t) = Σ_s π(s)(1 − t/T_r(s)) (Eq. 41)."""
    graph = chain_graph(grid_3x3(50.0))
    t = np.array([0.0, 2.5, 4.0])
    probs = mode_probabilities(graph, 10.0, t)
    expected = 4 / 6 * (1 - t / 10.0) + 2 / 6 * (1 - t / 5.0)
    np.testing.assert_allclose(probs.of(1), expected)
    assert probs.of(Fraction(1, 7)).tolist() == [0.0, 0.0, 0.0]
    assert probs.split_entropy[0] == 0.0
    assert probs.split_entropy[1] == pytest.approx(
        probs.of(Fraction(1, 2))[1] * math.log(2) + probs.of(Fraction(1, 3))[1] * math.log(3))


@pytest.mark.parametrize(("name", "call"), [
    ("target_speed_mps", lambda g: mode_probabilities(g, math.nan, [1.0])),
    ("target_speed_mps", lambda g: mode_probabilities(g, -10.0, [1.0])),
    ("times_s", lambda g: mode_probabilities(g, 10.0, [-1.0])),
    ("times_s", lambda g: mode_probabilities(g, 10.0, [math.inf])),
    ("times_s", lambda g: mode_probabilities(g, 10.0, [])),
    ("times_s", lambda g: mode_probabilities(g, 10.0, [400.0], max_modes=1000)),
    ("max_modes", lambda g: mode_probabilities(g, 10.0, [1.0], max_modes=0)),
    ("runs", lambda g: mode_split_mc(g, 10.0, [1.0], 0)),
    ("dt_s", lambda g: split_profile(g, 10.0, 0.0, 10)),
    ("n_steps", lambda g: split_profile(g, 10.0, 0.1, -1)),
    ("n_steps", lambda g: split_profile(g, 10.0, 0.1, 2.5)),  # type: ignore[arg-type]
])
def test_bad_inputs_name_the_field(b2_graph: ChainGraph, name: str,
                                   call: Callable[[ChainGraph], object]) -> None:
    """NaN, negative, infinite, empty and oversized inputs raise InvalidInputError naming the
    field."""
    with pytest.raises(InvalidInputError, match=name):
        call(b2_graph)
