"""Inter-route moves of the team OPTW ILS, the cached greedy insertion and the partial local
search: feasibility, invariants, equivalence with the plain versions, and the search using them.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.result import Result
from searchtrack.plan.optw import OPTWInstance, Routes, read_optw, validate
from searchtrack.plan.optw import ils_kernels as K
from searchtrack.plan.optw import ils_moves as KM
from searchtrack.plan.optw import ils_search as KS
from searchtrack.plan.optw.ils import Tuning, _solve, solve_ils, warm_up
from tests.plan.optw.test_ils import brute_force, random_instance
from tests.plan.optw.test_ils_search import (
    Arrays,
    _consistent,
    _filled,
    _instance,
    _pack,
    _rng,
    _visits,
)

CORDEAU = Path(__file__).parents[3] / "searchtrack" / "data" / "optw" / "cordeau"


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    """Compile (or load) the Numba kernels once, outside the timed tests."""
    warm_up()


def _travel(inst: OPTWInstance, sol: Arrays) -> int:
    """Total travel of the solution's routes (sink included)."""
    rt, ln = sol[0], sol[1]
    T = np.zeros((inst.n + 1, inst.n + 1), dtype=np.int64)
    T[:inst.n, :inst.n] = inst.travel
    T[:inst.n, inst.n] = inst.travel[:, 0]
    return sum(int(T[rt[r, p - 1], rt[r, p]]) for r in range(ln.shape[0])
               for p in range(1, ln[r]))


def _greedy_reference(ins: Arrays, sol: Arrays) -> None:
    """Greedy insertion without noise that recomputes every best position every round (the
    kernel's candidate order and set-aside rule, in plain Python)."""
    P, cand = ins[4], ins[5]
    alive = [int(g) for g in cand if sol[5][g] < 0]
    total = na = len(alive)
    while na > 0:
        best: tuple[float, int, int, int, int] | None = None
        i = 0
        while i < na:
            r, p, d = K.best_position(ins, sol, alive[i])
            if r < 0:
                na -= 1
                alive[i], alive[na] = alive[na], alive[i]
                continue
            score = P[alive[i]] ** 2.0 / (max(d, 0) + 1.0)
            if best is None or score > best[0]:
                best = (score, i, r, p, d)
            i += 1
        if best is None:
            return
        _, bi, r, p, d = best
        K.insert_at(ins, sol, alive[bi], r, p)
        na -= 1
        alive[bi], alive[na] = alive[na], alive[bi]
        total -= 1
        alive[na], alive[total] = alive[total], alive[na]
        if d < 0:
            na = total


@pytest.mark.parametrize("seed", range(6))
def test_cached_insertion_equals_recomputing_every_position(seed: int) -> None:
    """Caching positions per route changes nothing: the same visits in the same order."""
    inst = _instance(seed, n=16, vehicles=3, horizon=40)
    ins, a = _pack(inst)
    _, b = _pack(inst)
    K.insert_greedy(ins, a, _rng(0), 2.0, 0.0)
    _greedy_reference(ins, b)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)
    _consistent(inst, a)


@pytest.mark.parametrize("seed", range(8))
def test_relocate_keeps_visits_and_shortens_travel(seed: int) -> None:
    """Relocation keeps the plan valid with the same customers, never lengthens the travel, and
    flags every route it changed."""
    inst = _instance(seed, n=18, vehicles=3, horizon=50)
    ins, sol = _filled(inst)
    before = _consistent(inst, sol)
    travel = _travel(inst, sol)
    dirty = np.zeros(inst.vehicles, dtype=np.bool_)
    moves = KM.relocate(ins, sol, dirty)
    after = _consistent(inst, sol)
    assert sorted(_visits(after)) == sorted(_visits(before))
    assert _travel(inst, sol) <= travel - moves  # each move saves at least one tick
    for r in range(inst.vehicles):
        if before[r] != after[r]:
            assert dirty[r]
    assert moves == 0 or dirty.any()


def test_relocate_moves_a_visit_to_the_route_that_passes_by() -> None:
    """Route 0 detours to customer 1 near route 1's path: the visit moves to route 1."""
    xy = np.array([[0, 0], [0, 10], [10, 0], [0, 11]])
    travel = np.abs(xy[:, None, :] - xy[None, :, :]).sum(axis=2)
    inst = OPTWInstance(travel=travel, service=[0, 0, 0, 0], profit=[0, 1, 1, 1],
                        open=[0, 0, 0, 0], close=[100, 100, 100, 100], vehicles=2)
    ins, sol = _pack(inst)
    for r, route in enumerate(([2, 1], [3])):
        sol[0][r, 1:len(route) + 1] = route
        sol[0][r, len(route) + 1] = inst.n
        sol[1][r] = len(route) + 2
        sol[5][route] = r
        K.schedule(ins, sol, r)
    dirty = np.zeros(2, dtype=np.bool_)
    assert KM.relocate(ins, sol, dirty) == 1
    routes = _consistent(inst, sol)
    assert routes[0] == (0, 2, 0) and sorted(routes[1][1:-1]) == [1, 3]
    assert dirty.all()


@pytest.mark.parametrize("seed", range(4))
def test_ruin_route_empties_exactly_one_route(seed: int) -> None:
    """One non-empty route loses every visit; the others are untouched."""
    inst = _instance(seed, n=16, vehicles=3, horizon=40)
    ins, sol = _filled(inst)
    before = _consistent(inst, sol)
    KM.ruin_route(ins, sol, _rng(seed))
    after = _consistent(inst, sol)
    changed = [r for r in range(inst.vehicles) if before[r] != after[r]]
    assert len(changed) == 1
    assert after[changed[0]] == (0, 0) and len(before[changed[0]]) > 2


@pytest.mark.parametrize("swap", [False, True])
@pytest.mark.parametrize("seed", range(4))
def test_partial_local_search_equals_the_full_one(seed: int, swap: bool) -> None:
    """On a reordered plan, reordering only the routes a ruin changed gives the full result
    (with and without replacements)."""
    inst = _instance(seed, n=18, vehicles=3, horizon=40)
    ins, sol = _filled(inst)
    seq = np.zeros(inst.n + 1, dtype=np.int64)
    KS.local_search(ins, sol, _rng(0), seq, False, swap)
    ref = tuple(a.copy() for a in sol)
    KM.ruin_route(ins, sol, _rng(seed))
    full = tuple(a.copy() for a in sol)
    dirty = np.zeros(inst.vehicles, dtype=np.bool_)
    KS.changed_routes(sol, ref, dirty)
    assert dirty.sum() == 1
    KS.improve_routes(ins, sol, _rng(0), seq, dirty, False, swap)
    KS.local_search(ins, full, _rng(0), seq, False, swap)
    for x, y in zip(sol, full, strict=True):
        np.testing.assert_array_equal(x, y)
    assert not dirty.any()


@pytest.mark.parametrize("seed", range(6))
def test_search_with_the_team_moves_is_valid_and_deterministic(seed: int) -> None:
    """Route ruin and relocation on random non-metric team instances: valid plans, profit as
    validated, and the same plan for the same seed."""
    _valid_and_deterministic(seed, Tuning(w_route=1.0, relocate=True, k_max=6, split=True))


def valid_and_deterministic(inst: OPTWInstance, seed: int, tuning: Tuning,
                            iterations: int = 300) -> Result[Routes]:
    """The search run twice on ``inst``: the same plan for the same seed, valid, of the
    validated profit; the first run is returned for further checks."""
    a = _solve(inst, 60.0, seed, None, iterations, tuning)
    b = _solve(inst, 60.0, seed, None, iterations, tuning)
    assert a.plan == b.plan
    assert a.plan is not None and a.objective is not None
    check = validate(inst, a.plan)
    assert check.feasible, check.violations
    assert check.profit == pytest.approx(a.objective)
    return a


def _valid_and_deterministic(seed: int, tuning: Tuning) -> None:
    """:func:`valid_and_deterministic` on a random non-metric team instance."""
    valid_and_deterministic(random_instance(seed, 20, vehicles=1 + seed % 3), seed, tuning)


def test_team_search_honours_the_time_limit() -> None:
    """On the largest Cordeau instance with four vehicles the search returns within its limit."""
    inst = read_optw(CORDEAU / "pr10.txt", vehicles=4)
    started = time.perf_counter()
    res = solve_ils(inst, time_limit_s=0.3, seed=1)
    assert time.perf_counter() - started < 0.3 + 0.2
    assert res.plan is not None and validate(inst, res.plan).feasible


@pytest.mark.parametrize("seed", range(4))
def test_elite_restarts_are_valid_and_deterministic(seed: int) -> None:
    """Cycles restarting from an elite pool (short cycles, so many restarts): valid plans, profit
    as validated, and the same plan for the same seed."""
    inst = random_instance(seed, 20, vehicles=1 + seed % 3)
    a = valid_and_deterministic(inst, seed, Tuning(elite=3, cycle0=10, grow=1.2))
    assert a.stats["restarts"] > 3


def _swaps_left(inst: OPTWInstance, routes: tuple[tuple[int, ...], ...]) -> list[tuple[int, int]]:
    """Every (visit, unvisited customer of more profit) whose in-place swap the validator
    accepts."""
    visited = set(_visits(routes))
    left = []
    for r, route in enumerate(routes):
        for q in range(1, len(route) - 1):
            for u in (int(g) for g in inst.customers if int(g) not in visited):
                if inst.profit[u] <= inst.profit[route[q]]:
                    continue
                plan = list(routes)
                plan[r] = (*route[:q], u, *route[q + 1:])
                if validate(inst, plan).feasible:
                    left.append((route[q], u))
    return left


@pytest.mark.parametrize("seed", range(8))
def test_replace_gains_profit_and_leaves_no_swap(seed: int) -> None:
    """Replacement keeps the plan valid with as many visits, adds the profit it claims, flags the
    routes it changed, and leaves no in-place swap for more profit that the validator accepts."""
    inst = _instance(seed, n=18, vehicles=1 + seed % 3, horizon=30)
    ins, sol = _filled(inst)
    buf = np.zeros(inst.n + 1, dtype=np.int64)
    mark = np.zeros(inst.n + 1, dtype=np.bool_)
    KS.ruin_random(ins, sol, _rng(seed), 3, buf, mark)
    before = _consistent(inst, sol)
    dirty = np.zeros(inst.vehicles, dtype=np.bool_)
    moves = KM.replace(ins, sol, dirty)
    after = _consistent(inst, sol)
    assert len(_visits(after)) == len(_visits(before))
    assert validate(inst, after).profit >= validate(inst, before).profit + moves
    assert all(dirty[r] for r in range(inst.vehicles) if before[r] != after[r])
    assert not _swaps_left(inst, after)


def test_replace_takes_the_richer_customer_in_place() -> None:
    """Customer 2 (profit 5) sits where customer 1 (profit 1) is visited: the swap is made."""
    xy = np.array([[0, 0], [0, 10], [0, 11]])
    travel = np.abs(xy[:, None, :] - xy[None, :, :]).sum(axis=2)
    inst = OPTWInstance(travel=travel, service=[0, 0, 0], profit=[0, 1, 5],
                        open=[0, 0, 0], close=[22, 22, 22])
    ins, sol = _pack(inst)
    sol[0][0, :3] = [0, 1, inst.n]
    sol[1][0] = 3
    sol[5][1] = 0
    K.schedule(ins, sol, 0)
    dirty = np.zeros(1, dtype=np.bool_)
    assert KM.replace(ins, sol, dirty) == 1
    assert _consistent(inst, sol) == ((0, 2, 0),) and dirty.all()


@pytest.mark.parametrize("seed", range(8))
def test_search_with_replacement_is_valid_optimal_and_deterministic(seed: int) -> None:
    """With replacement the search stays valid and deterministic on random non-metric
    instances, and on tiny ones reaches (never exceeds) the brute-force optimum."""
    tuning = Tuning(replace=True)
    _valid_and_deterministic(seed, tuning)
    tiny = random_instance(500 + seed, 9, vehicles=1 + seed % 2, horizon=20.0)
    res = _solve(tiny, 60.0, seed, None, 300, tuning)
    assert res.plan is not None and validate(tiny, res.plan).feasible
    assert res.objective == pytest.approx(brute_force(tiny))
