"""The ILS search loop: ruin operators, route reordering, local search and the annealing loop.

The kernels work on the flat arrays documented in :mod:`searchtrack.plan.optw.ils_kernels`; the
instances here have integer Manhattan travel times (a metric) and wide windows, so removing
visits never forces a repair and every customer is a candidate.
"""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.plan.optw import OPTWInstance, Routes, validate
from searchtrack.plan.optw import ils_kernels as K
from searchtrack.plan.optw import ils_search as KS
from searchtrack.plan.optw.ils import Tuning

Arrays = tuple[np.ndarray, ...]


def _instance(seed: int, n: int = 12, vehicles: int = 2, horizon: int = 60) -> OPTWInstance:
    """``n`` vertices on an integer grid, Manhattan travel, windows at least horizon / 2 wide."""
    rng = np.random.default_rng(seed)
    xy = rng.integers(0, 12, size=(n, 2))
    travel = np.abs(xy[:, None, :] - xy[None, :, :]).sum(axis=2)
    opn = rng.integers(0, horizon // 2, size=n)
    close = np.minimum(opn + rng.integers(horizon // 2, horizon, size=n), horizon)
    opn[0], close[0] = 0, horizon
    return OPTWInstance(travel=travel, service=rng.integers(0, 3, size=n),
                        profit=rng.integers(1, 10, size=n), open=opn, close=close,
                        vehicles=vehicles)


def _square() -> OPTWInstance:
    """Depot (0, 0) and customers A (0, 10), B (10, 10), C (10, 0): the best tour is 40 long."""
    xy = np.array([[0, 0], [0, 10], [10, 10], [10, 0]])
    travel = np.abs(xy[:, None, :] - xy[None, :, :]).sum(axis=2)
    return OPTWInstance(travel=travel, service=[0, 0, 0, 0], profit=[0, 1, 1, 1],
                        open=[0, 0, 0, 0], close=[100, 100, 100, 100])


def _pack(inst: OPTWInstance) -> tuple[Arrays, Arrays]:
    """Kernel arrays ``ins`` (sink ``n`` for the end, every customer a candidate) and an empty
    solution of ``vehicles`` routes."""
    n = inst.n
    end = inst.end if inst.end is not None else 0
    T = np.zeros((n + 1, n + 1), dtype=np.int64)
    T[:n, :n] = inst.travel
    T[:n, n] = inst.travel[:, end]
    ins = (T, np.append(inst.service, 0).astype(np.int64),
           np.append(inst.open, 0).astype(np.int64),
           np.append(inst.close, min(inst.latest_finish, int(inst.close[end]))).astype(np.int64),
           np.append(inst.profit, 0.0).astype(np.float64), inst.customers.astype(np.int64))
    m, cap = inst.vehicles, n + 1
    rt = np.zeros((m, cap), dtype=np.int64)
    rt[:, 1] = n
    sol = (rt, np.full(m, 2, dtype=np.int64), np.zeros((m, cap), dtype=np.int64),
           np.zeros((m, cap), dtype=np.int64), np.zeros((m, cap), dtype=np.int64),
           np.full(n + 1, -1, dtype=np.int64))
    for r in range(m):
        K.schedule(ins, sol, r)
    return ins, sol


def _rng(seed: int) -> np.ndarray:
    """A splitmix64 state."""
    return np.array([seed], dtype=np.uint64)


def _filled(inst: OPTWInstance, seed: int = 0) -> tuple[Arrays, Arrays]:
    """A greedy first solution (no noise)."""
    ins, sol = _pack(inst)
    K.insert_greedy(ins, sol, _rng(seed), 2.0, 0.0)
    return ins, sol


def _routes(inst: OPTWInstance, sol: Arrays) -> Routes:
    """The solution's routes as vertex tuples, the sink replaced by the end vertex."""
    rt, ln = sol[0], sol[1]
    tail = () if inst.end is None else (inst.end,)
    return tuple((inst.start, *(int(v) for v in rt[r, 1:ln[r] - 1]), *tail)
                 for r in range(ln.shape[0]))


def _consistent(inst: OPTWInstance, sol: Arrays) -> Routes:
    """Assert the solution validates and its owner table matches its routes; return them."""
    routes = _routes(inst, sol)
    check = validate(inst, routes)
    assert check.feasible, check.violations
    own = sol[5]
    for r, route in enumerate(routes):
        assert all(own[v] == r for v in route[1:-1])
    visited = {v for route in routes for v in route[1:-1]}
    assert all(own[v] == -1 for v in range(inst.n) if v not in visited)
    assert np.all(sol[4][np.arange(len(routes)), 0] >= 0)  # MaxShift of the start
    return routes


def _visits(routes: Routes) -> list[int]:
    """The customers visited, route after route."""
    return [v for route in routes for v in route[1:-1]]


def _scratch(inst: OPTWInstance) -> tuple[np.ndarray, ...]:
    """Work arrays ``buf, mark, key, vst`` of the ruin operators."""
    n = inst.n
    return (np.zeros(n + 1, dtype=np.int64), np.zeros(n + 1, dtype=np.bool_),
            np.zeros(n + 1, dtype=np.int64), np.zeros(n + 1, dtype=np.int64))


@pytest.mark.parametrize("seed", range(4))
def test_remove_vertex_takes_out_exactly_that_visit(seed: int) -> None:
    """Removing a visited customer leaves every other visit in its place and order."""
    inst = _instance(seed)
    ins, sol = _filled(inst)
    before = _consistent(inst, sol)
    w = _visits(before)[seed % len(_visits(before))]
    KS.remove_vertex(ins, sol, w)
    after = _consistent(inst, sol)
    assert after == tuple(tuple(v for v in route if v != w) for route in before)
    assert sol[5][w] == -1


@pytest.mark.parametrize("k", [1, 3, 100])
def test_ruin_random_removes_k_visits(k: int) -> None:
    """k visits (all of them if fewer) are removed, the rest keep their order, marks are reset."""
    inst = _instance(1)
    ins, sol = _filled(inst)
    before = _consistent(inst, sol)
    buf, mark, _, _ = _scratch(inst)
    KS.ruin_random(ins, sol, _rng(3), k, buf, mark)
    after = _consistent(inst, sol)
    kept = set(_visits(after))
    assert len(kept) == max(0, len(_visits(before)) - k)
    assert after == tuple(tuple(v for v in route if v in kept or v in (route[0], route[-1]))
                          for route in before)
    assert not mark.any()


@pytest.mark.parametrize(("seed", "k"), [(0, 1), (1, 2), (2, 3), (3, 50)])
def test_ruin_segment_cuts_one_block_per_route(seed: int, k: int) -> None:
    """Each non-empty route loses one block of consecutive visits, at most k long and at least
    one; the others stay in order."""
    inst = _instance(seed)
    ins, sol = _filled(inst)
    before = _consistent(inst, sol)
    KS.ruin_segment(ins, sol, _rng(seed + 10), k)
    after = _consistent(inst, sol)
    for old, new in zip(before, after, strict=True):
        inner_old, inner_new = old[1:-1], new[1:-1]
        if not inner_old:
            continue
        cut = len(inner_old) - len(inner_new)
        assert 1 <= cut <= k
        assert any(inner_old[:i] + inner_old[i + cut:] == inner_new
                   for i in range(len(inner_old) - cut + 1))


@pytest.mark.parametrize("seed", range(5))
def test_ruin_related_removes_the_visits_nearest_a_visited_seed(seed: int) -> None:
    """Mode 0 removes k visits that are, for one of them (the seed), the k nearest in
    T[u, w] + T[w, u] + the gap between service starts."""
    inst = _instance(seed, n=14, vehicles=2)
    ins, sol = _filled(inst)
    before = _consistent(inst, sol)
    starts = {v: int(sol[3][r, p]) for r in range(inst.vehicles)
              for p, v in enumerate(sol[0][r, :sol[1][r]]) if 0 < p < sol[1][r] - 1}
    buf, mark, key, vst = _scratch(inst)
    k = 3
    KS.ruin_related(ins, sol, _rng(seed), k, buf, mark, key, vst, 0)
    after = _consistent(inst, sol)
    removed = set(_visits(before)) - set(_visits(after))
    assert len(removed) == k

    def near(u: int, w: int) -> int:
        return int(inst.travel[u, w] + inst.travel[w, u]) + abs(starts[w] - starts[u])

    kept = set(_visits(after))
    assert any(max(near(u, w) for w in removed) <= min(near(u, w) for w in kept)
               for u in removed)


@pytest.mark.parametrize("mode", [1, 2])
def test_targeted_ruins_keep_a_valid_solution(mode: int) -> None:
    """Modes 1 and 2 (seeded by an unvisited customer) leave a valid, consistent solution that
    lost at most k visits and gained at most the seed; over a few seeds some seed gets in."""
    brought_in = 0
    for seed in range(6):
        inst = _instance(seed, n=14, horizon=30)
        ins, sol = _filled(inst)
        before = _consistent(inst, sol)
        assert len(_visits(before)) < len(inst.customers)  # an unvisited seed exists
        buf, mark, key, vst = _scratch(inst)
        KS.ruin_related(ins, sol, _rng(seed), 2, buf, mark, key, vst, mode)
        after = _consistent(inst, sol)
        assert len(set(_visits(before)) - set(_visits(after))) <= 2
        gained = set(_visits(after)) - set(_visits(before))
        assert len(gained) <= 1
        brought_in += len(gained)
    assert brought_in >= 1


def test_reorder_uncrosses_a_route() -> None:
    """0 → B → A → C → 0 (60 long) is reordered to a 40-long tour; then nothing changes."""
    inst = _square()
    ins, sol = _pack(inst)
    sol[0][0, :5] = [0, 2, 1, 3, inst.n]
    sol[1][0] = 5
    sol[5][[1, 2, 3]] = 0
    K.schedule(ins, sol, 0)
    seq = np.zeros(inst.n + 1, dtype=np.int64)
    assert KS.reorder(ins, sol, 0, seq)
    (route,) = _consistent(inst, sol)
    assert sorted(route[1:-1]) == [1, 2, 3]
    assert sum(int(inst.travel[a, b]) for a, b in itertools.pairwise(route)) == 40
    assert not KS.reorder(ins, sol, 0, seq)


@pytest.mark.parametrize("seed", range(4))
def test_local_search_never_loses_profit(seed: int) -> None:
    """After a random ruin, local search returns a valid solution at least as profitable."""
    inst = _instance(seed, n=14)
    ins, sol = _filled(inst)
    buf, mark, _, _ = _scratch(inst)
    KS.ruin_random(ins, sol, _rng(seed), 4, buf, mark)
    profit = validate(inst, _consistent(inst, sol)).profit
    KS.local_search(ins, sol, _rng(seed), np.zeros(inst.n + 1, dtype=np.int64))
    assert validate(inst, _consistent(inst, sol)).profit >= profit


def _search_state(inst: OPTWInstance, tuning: Tuning) -> dict[str, object]:
    """Everything run_search needs, set up as solve_ils does."""
    ins, cur = _filled(inst)
    best = tuple(a.copy() for a in cur)
    work = tuple(a.copy() for a in cur)
    ctl = np.zeros(8, dtype=np.int64)
    fst = np.zeros(8, dtype=np.float64)
    fst[KS.F_BEST_P] = fst[KS.F_CUR_P] = K.profit_of(ins, cur)
    fst[KS.F_BEST_T] = fst[KS.F_CUR_T] = K.time_of(cur)
    fst[KS.F_TEMP] = fst[KS.F_T0] = 3.0
    ctl[KS.C_CYCLE_LEN] = tuning.cycle0
    buf, mark, key, vst = _scratch(inst)
    return {"ins": ins, "cur": cur, "best": best, "work": work, "rng": _rng(7), "ctl": ctl,
            "fst": fst, "par": replace(tuning, pool=0.0).array(inst.vehicles), "buf": buf,
            "mark": mark, "key": key, "vst": vst, "seq": np.zeros(inst.n + 1, dtype=np.int64),
            "rbuf": np.zeros((0, 3), dtype=np.int64), "seen": np.zeros((1, 2), dtype=np.int64)}


def _run(s: dict[str, object], n_iter: int) -> None:
    """``n_iter`` more iterations on the state ``s``."""
    KS.run_search(s["ins"], s["cur"], s["best"], s["work"], s["rng"], s["ctl"], s["fst"],
                  s["par"], n_iter, s["buf"], s["mark"], s["key"], s["vst"], s["seq"], s["rbuf"],
                  s["seen"])


def test_run_search_is_the_same_in_one_call_or_in_batches() -> None:
    """All search state lives in the arrays: 40 iterations at once equal 4 + 16 + 20."""
    inst = _instance(5, n=14, horizon=30)
    one, many = _search_state(inst, Tuning()), _search_state(inst, Tuning())
    _run(one, 40)
    for n_iter in (4, 16, 20):
        _run(many, n_iter)
    for name in ("best", "cur"):
        for a, b in zip(one[name], many[name], strict=True):  # type: ignore[call-overload]
            np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(one["ctl"], many["ctl"])
    np.testing.assert_array_equal(one["fst"], many["fst"])
    np.testing.assert_array_equal(one["rng"], many["rng"])
    assert one["ctl"][KS.C_ITER] == 40  # type: ignore[index]


def test_run_search_counts_cycles_and_cools_geometrically() -> None:
    """Cycles of 5 then int(5 · 1.5) + 1 = 8 iterations: after 12 iterations one restart, 7
    iterations into the second cycle, at temperature T0 · t_end^(7/8)."""
    inst = _instance(2)
    s = _search_state(inst, Tuning(cycle0=5, grow=1.5, t_end=0.01))
    _run(s, 12)
    ctl, fst = s["ctl"], s["fst"]
    assert ctl[KS.C_ITER] == 12  # type: ignore[index]
    assert ctl[KS.C_RESTARTS] == 1 and ctl[KS.C_CYCLE_LEN] == 8  # type: ignore[index]
    assert ctl[KS.C_CYCLE_IT] == 7  # type: ignore[index]
    assert fst[KS.F_TEMP] == pytest.approx(3.0 * 0.01 ** (7 / 8))  # type: ignore[index]


@pytest.mark.parametrize("seed", range(3))
def test_run_search_keeps_the_best_valid_and_recorded(seed: int) -> None:
    """The best solution validates, improves on the greedy start (on these instances) and its
    recorded profit is the validator's."""
    inst = _instance(seed, n=14, horizon=30)
    s = _search_state(inst, Tuning())
    first = float(s["fst"][KS.F_BEST_P])  # type: ignore[index]
    _run(s, 150)
    routes = _consistent(inst, s["best"])  # type: ignore[arg-type]
    profit = validate(inst, routes).profit
    assert profit > first
    assert s["fst"][KS.F_BEST_P] == pytest.approx(profit)  # type: ignore[index]
    since = s["ctl"][KS.C_SINCE_BEST]  # type: ignore[index]
    assert 0 <= since <= 150
