"""The look-ahead tree: path counts, exhaustive search against brute force (also in chunks),
beam search, and the deadline."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.plan.road_search import tree
from searchtrack.plan.road_search.tree import all_leaves, path_count, search

from .helpers import grid_roads, random_problem, random_roads
from .test_scenario import every_plan


def test_path_count_on_the_grid() -> None:
    """From the centre of the 3×3 grid: 4 paths of one edge, 4·3 = 12 of two."""
    for lookahead, count in ((1, 4), (2, 12)):
        p = random_problem(grid_roads(), np.random.default_rng(0), lookahead=lookahead)
        p = type(p)(p.roads, (4,), p.particle_edge, p.particle_s, p.particle_weight, p.entropy,
                    p.settings)
        assert path_count(p.scenario.lattices[0]) == count
        assert len(every_plan(p)) == count


@pytest.mark.parametrize("seed", range(6))
def test_exhaustive_search_is_brute_force(seed: int) -> None:
    """The exhaustive search finds the best score over every path."""
    roads = grid_roads() if seed % 2 else random_roads(seed)
    p = random_problem(roads, np.random.default_rng(seed), lookahead=1 + seed % 4)
    sc = p.scenario
    found = search(sc, 0, np.zeros(sc.n_groups), Deadline(60.0))
    assert found.arcs is not None and found.complete and not found.pruned
    best = max(sc.score(plan) for plan in every_plan(p))
    assert sc.score(sc.plan_of([found.arcs])) == pytest.approx(best, rel=1e-12)
    assert found.value == pytest.approx(best, rel=1e-12)


def test_chunked_search_gives_the_same_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """Splitting every level into one-path chunks changes nothing."""
    p = random_problem(grid_roads(), np.random.default_rng(3), lookahead=4)
    sc = p.scenario
    whole = search(sc, 0, np.zeros(sc.n_groups), Deadline(60.0))
    monkeypatch.setattr(tree, "CHUNK_FLOATS", 1)
    split = search(sc, 0, np.zeros(sc.n_groups), Deadline(60.0))
    assert whole.arcs is not None and split.arcs is not None
    assert np.array_equal(whole.arcs, split.arcs) and whole.value == split.value


def test_beam_prunes_and_a_wide_beam_is_exhaustive() -> None:
    """Width 1 prunes; a width above the path count prunes nothing and matches exhaustive."""
    p = random_problem(grid_roads(), np.random.default_rng(4), lookahead=3)
    sc = p.scenario
    zero = np.zeros(sc.n_groups)
    full = search(sc, 0, zero, Deadline(60.0))
    narrow = search(sc, 0, zero, Deadline(60.0), width=1)
    wide = search(sc, 0, zero, Deadline(60.0), width=10_000)
    assert narrow.pruned and not wide.pruned
    assert narrow.value <= full.value
    assert wide.arcs is not None and full.arcs is not None
    assert np.array_equal(wide.arcs, full.arcs)


def test_base_coverage_counts_what_others_see() -> None:
    """With every group already seen at β = 1 nothing is left to gain."""
    p = random_problem(grid_roads(), np.random.default_rng(6), lookahead=2)
    sc = p.scenario
    found = search(sc, 0, np.ones(sc.n_groups), Deadline(60.0))
    assert found.value == pytest.approx(sc.group_value.sum())


def test_expired_deadline_finds_nothing() -> None:
    """A deadline already past stops the search before any complete path."""
    p = random_problem(grid_roads(), np.random.default_rng(7), lookahead=3)
    sc = p.scenario
    found = search(sc, 0, np.zeros(sc.n_groups), Deadline(1e-9))
    assert found.arcs is None and not found.complete
    arcs, cov = all_leaves(sc, 0, Deadline(1e-9))
    assert arcs.shape[0] == 0 and cov.shape[0] == 0


def test_all_leaves_scores_every_path() -> None:
    """all_leaves returns every path with its coverage vector."""
    p = random_problem(random_roads(2), np.random.default_rng(2), lookahead=3)
    sc = p.scenario
    arcs, cov = all_leaves(sc, 0, Deadline(60.0))
    assert arcs.shape == (path_count(sc.lattices[0]), 3)
    for a, c in zip(arcs, cov, strict=True):
        assert sc.value_of(c) == pytest.approx(sc.score(sc.plan_of([a])), rel=1e-12)
