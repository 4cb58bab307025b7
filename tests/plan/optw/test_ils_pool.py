"""Route recombination of the team ILS: staging, the pool, exact set packing, recombined plans."""

from __future__ import annotations

import itertools
import time
from pathlib import Path

import numpy as np
import pytest

from searchtrack.plan.optw import ils_kernels as K
from searchtrack.plan.optw import ils_pool as KP
from searchtrack.plan.optw import ils_search as KS
from searchtrack.plan.optw import read_optw, validate
from searchtrack.plan.optw.ils import Tuning, _solve, solve_ils, warm_up
from tests.plan.optw.test_ils import random_instance
from tests.plan.optw.test_ils_moves import valid_and_deterministic
from tests.plan.optw.test_ils_search import _consistent, _filled, _instance, _rng

CORDEAU = Path(__file__).parents[3] / "searchtrack" / "data" / "optw" / "cordeau"


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    """Compile (or load) the Numba kernels once, outside the timed tests."""
    warm_up()


def _bits(routes: list[tuple[int, ...]], words: int) -> np.ndarray:
    out = np.zeros((len(routes), words), dtype=np.uint64)
    for i, route in enumerate(routes):
        for v in route:
            out[i, v >> 6] |= np.uint64(1) << np.uint64(v & 63)
    return out


def _brute(routes: list[tuple[int, ...]], p: np.ndarray, c: np.ndarray,
           m: int) -> tuple[float, int]:
    """Most profit, then least cost, of at most ``m`` pairwise disjoint routes (none: (0, 0))."""
    best = (0.0, 0)
    for k in range(1, m + 1):
        for combo in itertools.combinations(range(len(routes)), k):
            seen = [v for i in combo for v in routes[i]]
            if len(seen) == len(set(seen)):
                value = (float(p[list(combo)].sum()), int(c[list(combo)].sum()))
                if value[0] > best[0] or (value[0] == best[0] and value[1] < best[1]):
                    best = value
    return best


@pytest.mark.parametrize("seed", range(12))
def test_pack_routes_matches_brute_force(seed: int) -> None:
    """On random pools (customers over two bit words) the packing is disjoint, has at most ``m``
    routes and the brute-force optimum's profit and cost; with that optimum as the floor it
    finds nothing better."""
    rng = np.random.default_rng(seed)
    routes = [tuple(rng.choice(90, size=rng.integers(1, 7), replace=False).tolist())
              for _ in range(13)]
    p = rng.integers(1, 20, size=len(routes)).astype(np.float64)
    c = rng.integers(0, 50, size=len(routes)).astype(np.int64)
    order = np.lexsort((c, -p))
    routes = [routes[i] for i in order]
    p, c = p[order], c[order]
    m = 1 + seed % 4
    bits = _bits(routes, 2)
    chosen = KP.pack_routes(bits, p, c, m, 0.0, 10**9, 10**6)
    picked = [int(i) for i in chosen if i >= 0]
    assert 1 <= len(picked) <= m
    seen = [v for i in picked for v in routes[i]]
    assert len(seen) == len(set(seen))
    assert (float(p[picked].sum()), int(c[picked].sum())) == _brute(routes, p, c, m)
    floor_p, floor_c = _brute(routes, p, c, m)
    assert np.all(KP.pack_routes(bits, p, c, m, floor_p, floor_c, 10**6) == -1)


def test_staging_keeps_the_earliest_order_of_a_customer_set() -> None:
    """The same customers in another order share a key; a later arrival is not staged again,
    an earlier one is, and the pool keeps one route: the earliest order."""
    rt = np.array([[0, 3, 5, 9, 0, 0]], dtype=np.int64)
    sol = (rt, np.array([4]), np.zeros((1, 6), dtype=np.int64))
    old = (np.zeros((1, 6), dtype=np.int64), np.array([2]))
    pool = KP.RoutePool(np.arange(10, dtype=np.float64), 1, 8, 100, rows=8)
    ctl = np.zeros(8, dtype=np.int64)
    for order, arrival in (((3, 5), 50), ((5, 3), 60), ((5, 3), 40), ((3, 5), 45)):
        rt[0, 1:3] = order
        sol[2][0, 3] = arrival
        K.stage_routes(sol, old, pool.rbuf, pool.seen, ctl, KS.C_STAGED, KS.C_SEEN)
    assert ctl[KS.C_STAGED] == 2
    assert K.route_key(rt, 0, 4) == K.route_key(np.array([[0, 5, 3, 9]]), 0, 4)
    pool.drain(ctl)
    assert ctl[KS.C_STAGED] == 0
    assert next(iter(pool.routes.values()))[:3] == ((5, 3), 8.0, 40)
    assert len(pool.routes) == 1


@pytest.mark.parametrize("seed", range(8))
def test_recombination_never_loses_and_packs_the_pool_optimally(seed: int) -> None:
    """Solutions of randomised greedy insertions fill the pool; recombining gives a valid plan
    (customer-disjoint routes), no worse than the best it started from and at least as good
    as the brute-force best packing of the pool."""
    inst = _instance(seed, n=13, vehicles=2 + seed % 2, horizon=40)
    ins, best = _filled(inst)
    pool = KP.RoutePool(ins[4], inst.vehicles, int(ins[5].shape[0]), 1000)
    for s in range(6):
        _, sol = _filled(inst)
        K.copy_sol(sol, best)
        sol[5][:] = -1
        KP.load(ins, sol, [])
        K.insert_greedy(ins, sol, _rng(s + 10 * seed), 1.0 + s % 3, 2.0)
        pool.add_solution(sol)
    cur, work = tuple(a.copy() for a in best), tuple(a.copy() for a in best)
    fst = np.zeros(8, dtype=np.float64)
    fst[KS.F_BEST_P] = fst[KS.F_CUR_P] = start = K.profit_of(ins, best)
    fst[KS.F_BEST_T] = fst[KS.F_CUR_T] = K.time_of(best)
    pool.add_solution(best)
    entries = list(pool.routes.values())
    packed, _ = _brute([e[0] for e in entries], np.array([e[1] for e in entries]),
                       np.array([e[2] for e in entries]), inst.vehicles)
    gained = KP.recombine(ins, pool, cur, best, work, fst, np.zeros(8, dtype=np.int64), _rng(1),
                          np.zeros(inst.n + 1, dtype=np.int64), (False, True), 10**6)
    _consistent(inst, best)
    assert K.profit_of(ins, best) == fst[KS.F_BEST_P] >= start
    assert K.profit_of(ins, best) >= packed
    assert gained == (packed > start) or gained
    for a, b in zip(cur, best, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("seed", range(4))
def test_search_with_recombination_is_valid_and_deterministic(seed: int) -> None:
    """Frequent packings on random non-metric team instances: valid plans, profit as validated,
    and the same plan for the same seed."""
    inst = random_instance(seed, 24, vehicles=2 + seed % 3)
    a = valid_and_deterministic(inst, seed, Tuning(pool=0.5, pack_every=3), 2000)
    assert a.stats["packings"] >= 2


def test_recombining_search_honours_the_time_limit() -> None:
    """On the largest Cordeau instance with four vehicles the search returns within its limit."""
    inst = read_optw(CORDEAU / "pr10.txt", vehicles=4)
    started = time.perf_counter()
    res = _solve(inst, 0.3, 1, None, None, Tuning(pool=0.05, pack_every=20))
    assert time.perf_counter() - started < 0.3 + 0.2
    assert res.plan is not None and validate(inst, res.plan).feasible
    assert solve_ils(inst, time_limit_s=0.05).plan is not None


def test_one_vehicle_searches_as_without_a_pool() -> None:
    """With one vehicle there is nothing to recombine: the same search, step for step."""
    inst = random_instance(3, 20)
    a = _solve(inst, 60.0, 3, None, 300, Tuning(pool=0.5, pack_every=3))
    b = _solve(inst, 60.0, 3, None, 300, Tuning())
    assert a.plan == b.plan and a.stats == b.stats
