"""The catalogue of association backends: every backend of ``BACKENDS`` on hand-built cost
matrices with known optimal pairs."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Sense, Status
from searchtrack.estimate.association import (
    BACKENDS,
    Association,
    AssociationProblem,
    answer_problems,
    gated_objective,
    greedy_pairs,
    solve,
)

INF = math.inf
NAMES = BACKENDS.names()

#: (costs, gate, optimal pairs, optimal saving Σ(gate − c), Algorithm 1's pairs in its order)
CATALOGUE = [
    ([[10.0, 20.0], [20.0, INF]], 300.0, {(0, 1), (1, 0)}, 560.0, ((0, 0),)),
    ([[50.0, 10.0, 400.0], [20.0, 5.0, 250.0]], 300.0, {(0, 1), (1, 0)}, 570.0,
     ((1, 1), (0, 0))),
    ([[1.0, 100.0], [100.0, 1.0]], 300.0, {(0, 0), (1, 1)}, 598.0, ((0, 0), (1, 1))),
    ([[300.0, 400.0]], 300.0, set(), 0.0, ()),
    ([[5.0], [3.0], [4.0]], 10.0, {(1, 0)}, 7.0, ((1, 0),)),
    ([[INF, INF], [INF, 2.0]], 10.0, {(1, 1)}, 8.0, ((1, 1),)),
    (np.zeros((0, 3)), 300.0, set(), 0.0, ()),
    (np.zeros((2, 0)), 300.0, set(), 0.0, ()),
]


def test_catalogue_lists_the_backends() -> None:
    """greedy is the heuristic, optimal and auto are exact."""
    assert NAMES == ["greedy", "optimal", "auto"]
    assert [BACKENDS.get(n).exact for n in NAMES] == [False, True, True]


@pytest.mark.parametrize("case", range(len(CATALOGUE)))
@pytest.mark.parametrize("backend", NAMES)
def test_known_answers(backend: str, case: int) -> None:
    """Exact backends find the known optimum (OPTIMAL, bound = objective); greedy finds
    Algorithm 1's pairs, never a larger saving."""
    costs, gate, best, saving, greedy = CATALOGUE[case]
    problem = AssociationProblem(np.asarray(costs, dtype=float), gate)
    result = solve(problem, backend=backend, time_limit_s=1.0)
    assert result.plan is not None and result.sense is Sense.MAXIMIZE
    pairs = result.plan.pairs
    assert result.objective == pytest.approx(problem.saving(pairs))
    assert result.objective == pytest.approx(-gated_objective(problem.costs, pairs, gate))
    assert result.objective <= saving + 1e-9
    if BACKENDS.get(backend).exact:
        assert result.status is Status.OPTIMAL and set(pairs) == best
        assert result.objective == pytest.approx(saving) and result.bound == result.objective
    else:
        assert result.status is Status.FEASIBLE and result.bound is None
        assert pairs == greedy


@pytest.mark.parametrize("seed", range(4))
def test_greedy_never_beats_optimal(seed: int) -> None:
    """On random gated matrices: greedy's Σ(c − gate) ≥ optimal's = auto's; auto answers with an
    optimal plan (greedy's when it ties), says how it got there and is OPTIMAL."""
    rng = np.random.default_rng(seed)
    for _ in range(30):
        k, q = rng.integers(1, 6, size=2)
        costs = rng.uniform(0.0, 600.0, size=(k, q))
        costs[rng.random((k, q)) < 0.2] = INF
        problem = AssociationProblem(costs, 300.0)
        g, o, a = (solve(problem, backend=n) for n in NAMES)
        assert g.plan is not None and o.plan is not None and a.plan is not None
        assert gated_objective(costs, g.plan.pairs, 300.0) >= gated_objective(
            costs, o.plan.pairs, 300.0) - 1e-9
        assert a.status is Status.OPTIMAL and a.objective == pytest.approx(o.objective)
        assert a.message.startswith("auto") and a.backend in ("greedy", "optimal")
        assert g.plan.pairs == greedy_pairs(costs, 300.0)


def test_problem_is_validated_and_read_only() -> None:
    """Bad matrices or gates name the field; the stored costs are a read-only copy."""
    costs = np.array([[1.0, 2.0]])
    problem = AssociationProblem(costs, 5.0)
    costs[0, 0] = 99.0
    assert problem.costs[0, 0] == 1.0 and not problem.costs.flags.writeable
    assert problem.shape == (1, 2)
    for bad, field in [([1.0, 2.0], "costs"), ([[math.nan]], "costs"), ([[-INF]], "costs"),
                       ([["x"]], "costs")]:
        with pytest.raises(InvalidInputError) as err:
            AssociationProblem(bad, 5.0)  # type: ignore[arg-type]
        assert err.value.field == field
    for gate in (0.0, -1.0, INF, math.nan, True):
        with pytest.raises(InvalidInputError) as err:
            AssociationProblem(costs, gate)
        assert err.value.field == "gate_m"
    with pytest.raises(InvalidInputError, match="backend"):
        solve(problem, backend="hungarian")
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(problem, time_limit_s=-1.0)


def test_association_pairs_are_one_to_one() -> None:
    """An Association refuses a tracker or a measurement used twice."""
    assert Association(((0, 1), (1, 0))).unassociated(3) == (2,)
    with pytest.raises(InvalidInputError, match="pairs"):
        Association(((0, 1), (0, 2)))


def test_validator_rejects_wrong_associations() -> None:
    """A pair over the gate, a misreported saving and an out-of-range index are named; every
    backend's answer passes."""
    problem = AssociationProblem(np.array([[10.0, 400.0], [50.0, 20.0]]), gate_m=300.0)
    for name in BACKENDS.names():
        result = BACKENDS.solve(name, problem, time_limit_s=1.0, seed=0)
        assert result.status is not Status.ERROR and answer_problems(problem, result) == []
    good = BACKENDS.solve("optimal", problem, time_limit_s=1.0, seed=0)
    assert good.objective == pytest.approx(570.0)
    over = dataclasses.replace(good, plan=Association(((0, 1),)), objective=-100.0)
    assert any("gate" in p for p in answer_problems(problem, over))
    lie = dataclasses.replace(good, objective=571.0)
    assert any("saving" in p for p in answer_problems(problem, lie))
    outside = dataclasses.replace(good, plan=Association(((2, 0),)))
    assert any("outside" in p for p in answer_problems(problem, outside))
    assert BACKENDS.validated(problem, lie).status is Status.ERROR
