"""Tree searches: exhaustive equals brute force over every sequence (with and without the
constraint binding, and when nothing is feasible), beam never beats it, the ranking and the
answer conventions."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Status
from searchtrack.plan.radio import RadioPlan
from searchtrack.plan.radio.search import (
    Key,
    Search,
    answer,
    beam_search,
    exhaustive_search,
    key_of,
)
from searchtrack.plan.radio.tree import Scorer

from .helpers import problem, spread_belief, surrounded, tag_ahead


def every_sequence(scorer: Scorer) -> list[tuple[tuple[int, ...], Key, RadioPlan]]:
    """Each action sequence scored on its own (one child per level), in lexicographic order."""
    out = []
    n_theta = scorer.problem.scenario.uav.n_headings
    for seq in itertools.product(range(n_theta), repeat=scorer.horizon):
        nodes = scorer.root()
        ok = True
        for i in seq:
            heads, paths = scorer.primitives(nodes.pose[0])
            if i >= heads.size:
                ok = False
                break

            def pick(pose: np.ndarray, i: int = i, h: np.ndarray = heads,
                     q: np.ndarray = paths) -> tuple[np.ndarray, np.ndarray]:
                return h[i:i + 1], q[i:i + 1]

            nodes = scorer.expand(nodes, pick)
        if ok:
            plan = scorer.plan(nodes, 0)
            st = scorer.settings
            out.append((seq, key_of(plan, st.discount, st.p_void_min), plan))
    return out


def brute_force(scorer: Scorer) -> tuple[Key, RadioPlan]:
    """The best sequence by rank, the first in lexicographic order on ties."""
    best = None
    for _, key, plan in every_sequence(scorer):
        if best is None or key > best[0]:
            best = (key, plan)
    assert best is not None
    return best


CASES = [("spread", spread_belief(1), "renyi"), ("spread", spread_belief(2), "cs"),
         ("ahead", tag_ahead(), "renyi"), ("ahead", tag_ahead(), "cs"),
         ("surrounded", surrounded(), "renyi")]


@pytest.mark.parametrize(("name", "belief", "reward"), CASES,
                         ids=[f"{n}-{r}" for n, _, r in CASES])
def test_exhaustive_equals_brute_force(name: str, belief: object, reward: str) -> None:
    """Same rank and same sequence as scoring every sequence separately."""
    p = problem(belief, reward=reward, plan_particles=40)  # type: ignore[arg-type]
    sc = Scorer(p, 0)
    key, plan = brute_force(sc)
    found = exhaustive_search(sc, Deadline(60.0))
    assert found.complete and not found.pruned and found.best is not None
    assert found.best.key[0] == key[0]
    assert found.best.key[1:] == pytest.approx(key[1:], rel=1e-12)
    assert np.array_equal(found.best.plan.headings, plan.headings)
    if name == "surrounded":
        assert not key[0]
    if name == "ahead":
        assert key[0] and any(not k[0] for _, k, _ in every_sequence(sc))


def test_beam_never_beats_exhaustive_and_wide_beam_is_exact() -> None:
    """Beam rank ≤ exhaustive rank for every width; a width holding every prefix is exact."""
    p = problem(horizon=3, plan_particles=30)
    sc = Scorer(p, 0)
    full = exhaustive_search(sc, Deadline(60.0))
    assert full.best is not None
    for width in (1, 2, 4):
        beam = beam_search(sc, Deadline(60.0), width)
        assert beam.best is not None and beam.best.key <= full.best.key
        assert beam.pruned
    wide = beam_search(sc, Deadline(60.0), 16)
    assert wide.best is not None and not wide.pruned
    assert wide.best.key == full.best.key


def test_incumbent_prunes_without_changing_the_answer() -> None:
    """Starting from a feasible incumbent drops infeasible subtrees, not the optimum."""
    p = problem(tag_ahead(), plan_particles=40)
    sc = Scorer(p, 0)
    cold = exhaustive_search(sc, Deadline(60.0))
    greedy = beam_search(sc, Deadline(60.0), 1).best
    warm = exhaustive_search(sc, Deadline(60.0), greedy)
    assert cold.best is not None and warm.best is not None
    assert warm.best.key == cold.best.key and warm.nodes <= cold.nodes


def test_expired_deadline() -> None:
    """Out of time before any leaf: exhaustive has nothing and is incomplete; beam finishes
    its best prefix greedily."""
    sc = Scorer(problem(), 0)
    gone = Deadline(1e-9)
    found = exhaustive_search(sc, gone)
    assert found.best is None and not found.complete
    beam = beam_search(sc, gone, 8)
    assert beam.best is not None and not beam.complete


def test_ranking_keys() -> None:
    """Feasible beats infeasible; reward orders the feasible, total violation the infeasible."""
    path = np.zeros((5, 3))

    def plan(reward: float, low: float, ok: bool) -> RadioPlan:
        void = np.full(5, 0.99)
        void[2] = low
        return RadioPlan(np.zeros(1), path, np.array([reward]), void, ok)

    assert key_of(plan(0.1, 0.95, True), 1.0, 0.9) > key_of(plan(9.0, 0.5, False), 1.0, 0.9)
    assert key_of(plan(2.0, 0.91, True), 1.0, 0.9) > key_of(plan(1.0, 0.99, True), 1.0, 0.9)
    assert key_of(plan(0.1, 0.8, False), 1.0, 0.9) > key_of(plan(5.0, 0.7, False), 1.0, 0.9)


def test_answers() -> None:
    """OPTIMAL with its bound when exact and complete; the least-violating plan comes back as
    the fallback of an INFEASIBLE answer, with flags; nothing found is NO_SOLUTION."""
    p = problem(surrounded(), plan_particles=30)
    sc = Scorer(p, 0)
    found = exhaustive_search(sc, Deadline(60.0))
    res = answer(sc, found, "exhaustive", Deadline(1.0), exact=True, note="x")
    assert res.status is Status.INFEASIBLE and res.objective is None and res.plan is not None
    assert not res.plan.feasible and res.stats["proven_infeasible"] == 1.0
    assert res.stats["min_void"] == pytest.approx(res.plan.min_void)
    assert res.plan.min_void < 0.9
    assert "least-violating" in res.message
    ok = problem(spread_belief(), plan_particles=30)
    sc2 = Scorer(ok, 0)
    res2 = answer(sc2, exhaustive_search(sc2, Deadline(60.0)), "exhaustive", Deadline(1.0),
                  exact=True, note="x")
    assert res2.status is Status.OPTIMAL and res2.bound == res2.objective
    assert res2.plan is not None and res2.plan.feasible and res2.stats["infeasible"] == 0.0
    none = answer(sc2, Search(complete=False), "exhaustive", Deadline(1.0), exact=True, note="")
    assert none.status is Status.NO_SOLUTION and none.plan is None
