"""Iterated local search for the (team) OPTW, after Vansteenwegen et al. (2009), with extensions.

The hot loops live in :mod:`searchtrack.plan.optw.ils_kernels` (Numba); this module packs the
instance into flat arrays, drives the search in short batches so the deadline is honoured, and
turns the best solution back into routes.
"""

from __future__ import annotations

import itertools
import logging
import time

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw import ils_kernels as K
from searchtrack.plan.optw import ils_search as KS
from searchtrack.plan.optw.ils_pool import Recombiner, pack_routes
from searchtrack.plan.optw.ils_tuning import Tuning
from searchtrack.plan.optw.instance import OPTWInstance, Routes
from searchtrack.plan.optw.reach import Reach, reach

__all__ = ["Tuning", "solve_ils", "warm_up"]

log = logging.getLogger("searchtrack.plan.optw.ils")

_BATCH_S = 2e-3  # target wall-clock seconds per kernel call

Arrays = tuple[NDArray[np.int64], ...]
Kernel = tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64],
               NDArray[np.float64], NDArray[np.int64]]


def _pack(inst: OPTWInstance) -> tuple[Kernel, Reach]:
    """Kernel arrays ``(T, S, O, C, P, cand)`` with a sink vertex ``n`` for the end."""
    n = inst.n
    rc = reach(inst)
    T = np.zeros((n + 1, n + 1), dtype=np.int64)
    T[:n, :n] = inst.travel
    if inst.end is not None:
        T[:n, n] = inst.travel[:, inst.end]
    S = np.append(inst.service, 0).astype(np.int64)
    Op = np.append(inst.open, 0).astype(np.int64)
    end_close = inst.latest_finish
    if inst.end is not None:
        end_close = min(end_close, int(inst.close[inst.end]))
    C = np.append(inst.close, end_close).astype(np.int64)
    P = np.append(inst.profit, 0.0).astype(np.float64)
    cand = np.flatnonzero(rc.vertex_ok & (inst.profit > 0)).astype(np.int64)
    return (T, S, Op, C, P, cand), rc


def _empty(inst: OPTWInstance, cap: int, sink: int) -> Arrays:
    m = inst.vehicles
    rt = np.zeros((m, cap), dtype=np.int64)
    rt[:, 0] = inst.start
    rt[:, 1] = sink
    ln = np.full(m, 2, dtype=np.int64)
    arr = np.zeros((m, cap), dtype=np.int64)
    st = np.zeros((m, cap), dtype=np.int64)
    ms = np.zeros((m, cap), dtype=np.int64)
    own = np.full(sink + 1, -1, dtype=np.int64)
    return (rt, ln, arr, st, ms, own)


def _routes(inst: OPTWInstance, sol: Arrays) -> Routes:
    rt, ln = sol[0], sol[1]
    out = []
    for r in range(ln.shape[0]):
        inner = tuple(int(v) for v in rt[r, 1 : ln[r] - 1])
        tail = () if inst.end is None else (inst.end,)
        out.append((inst.start, *inner, *tail))
    return tuple(out)


def solve_ils(
    instance: OPTWInstance,
    *,
    time_limit_s: float = 1.0,
    seed: int = 0,
    initial: Routes | None = None,
    max_iterations: int | None = None,
) -> Result[Routes]:
    """Solve a (team) OPTW heuristically within ``time_limit_s`` seconds.

    Parameters
    ----------
    instance
        The problem; ``instance.vehicles`` routes are planned.
    time_limit_s
        Wall-clock limit, checked between short batches of iterations (a few ms each). The first
        call in a process also compiles or loads the Numba kernels: call :func:`warm_up` first
        when that must not count.
    seed
        Seed of every random choice. With ``max_iterations`` set (and a limit that does not bind)
        the answer is identical run to run.
    initial
        A feasible plan to start from (at most ``vehicles`` routes, as :func:`validate` accepts).
    max_iterations
        Stop after this many ruin-and-recreate iterations (``None``: only the time limit).

    Returns
    -------
    Result
        ``FEASIBLE`` with the best plan found (exactly ``vehicles`` routes, unused ones
        ``(start, end)``), or ``OPTIMAL`` when it collects every reachable profit.

    Raises
    ------
    InvalidInputError
        For a bad time limit, seed, iteration budget or initial plan.
    """
    return _solve(instance, time_limit_s, seed, initial, max_iterations, Tuning())


def _check_args(seed: int, max_iterations: int | None) -> None:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError("seed", seed, "must be a non-negative integer")
    if max_iterations is not None and (
        isinstance(max_iterations, bool)
        or not isinstance(max_iterations, (int, np.integer))
        or max_iterations < 0
    ):
        raise InvalidInputError("max_iterations", max_iterations, "must be None or an integer ≥ 0")


def _load_initial(inst: OPTWInstance, initial: Routes, ins: Kernel, sol: Arrays) -> None:
    """Check ``initial`` independently of the kernels and copy it into ``sol``."""
    if len(initial) > inst.vehicles:
        raise InvalidInputError("initial", initial, f"has more than {inst.vehicles} routes")
    cand = set(int(v) for v in ins[5])
    seen: set[int] = set()
    customers = set(int(v) for v in inst.customers)
    rt, ln, own = sol[0], sol[1], sol[5]
    for r, route in enumerate(initial):
        route = tuple(int(v) for v in route)
        tail = () if inst.end is None else (inst.end,)
        inner = route[1 : len(route) - len(tail)]
        if (len(route) < 1 + len(tail) or route[0] != inst.start
                or route[len(route) - len(tail):] != tail):
            raise InvalidInputError(f"initial[{r}]", route,
                                    f"must run from vertex {inst.start} to {inst.end}")
        bad = [v for v in inner if v not in customers or v in seen or inner.count(v) > 1]
        if bad:
            raise InvalidInputError(f"initial[{r}]", route,
                                    f"visits vertex {bad[0]} twice or is not a customer")
        seen.update(inner)
        if not _route_ok(inst, route):
            raise InvalidInputError(f"initial[{r}]", route, "misses a window or the deadline")
        kept = [v for v in inner if v in cand]
        rt[r, 1 : len(kept) + 1] = kept
        rt[r, len(kept) + 1] = inst.n
        ln[r] = len(kept) + 2
        own[kept] = r
        K.schedule(ins, sol, r)
        K.repair(ins, sol, r)


def _route_ok(inst: OPTWInstance, route: tuple[int, ...]) -> bool:
    """Plain-Python schedule check of one route (windows, then the finish deadline)."""
    t = int(inst.open[route[0]])
    for u, v in itertools.pairwise(route):
        arrival = t + int(inst.service[u]) + int(inst.travel[u, v])
        t = max(arrival, int(inst.open[v]))
        if t > int(inst.close[v]):
            return False
    finish = arrival if len(route) > 1 and inst.end is not None else t + int(
        inst.service[route[-1]])
    return finish <= inst.latest_finish


def _solve(
    instance: OPTWInstance,
    time_limit_s: float,
    seed: int,
    initial: Routes | None,
    max_iterations: int | None,
    tuning: Tuning,
) -> Result[Routes]:
    """:func:`solve_ils` with explicit search parameters (for tuning)."""
    deadline = Deadline(check_time_limit(time_limit_s))
    _check_args(seed, max_iterations)
    inst = instance
    ins, rc = _pack(inst)
    vertex_ok = rc.vertex_ok
    cand = ins[5]
    nc = int(cand.shape[0])
    sink = inst.n
    empty = _empty(inst, nc + 2, sink)
    cur = _empty(inst, nc + 2, sink)
    for r in range(inst.vehicles):
        K.schedule(ins, empty, r)
    if int(empty[4][0, 0]) < 0:  # the direct route misses the deadline
        if int(rc.latest[inst.start]) < inst.departure:
            return Result(Status.INFEASIBLE, None, None, deadline.elapsed(), "ils", None,
                          message="no route can reach the end in time")
        return Result(Status.NO_SOLUTION, None, None, deadline.elapsed(), "ils", None,
                      message="the direct route misses the end's deadline; routes that make up "
                      "time through customers (travel times far from a metric) are not searched")
    rng = np.array([np.random.default_rng(seed).integers(0, 2**63)], dtype=np.uint64)
    K.copy_sol(cur, empty)
    if initial is not None:
        _load_initial(inst, initial, ins, cur)
    K.insert_greedy(ins, cur, rng, 2.0, 0.0)
    seq = np.zeros(nc + 2, dtype=np.int64)
    if tuning.local_search:
        KS.local_search(ins, cur, rng, seq, tuning.relocate, tuning.replace)
    best = _empty(inst, nc + 2, sink)
    work = _empty(inst, nc + 2, sink)
    K.copy_sol(best, cur)
    ctl = np.zeros(8, dtype=np.int64)
    fst = np.zeros(8, dtype=np.float64)
    fst[KS.F_BEST_P] = fst[KS.F_CUR_P] = K.profit_of(ins, cur)
    fst[KS.F_BEST_T] = fst[KS.F_CUR_T] = K.time_of(cur)
    mean_p = float(np.mean(inst.profit[cand])) if nc else 1.0
    fst[KS.F_TEMP] = fst[KS.F_T0] = tuning.temperature * mean_p
    ctl[KS.C_CYCLE_LEN] = tuning.cycle0
    par = tuning.array(inst.vehicles)
    buf = np.zeros(nc + 1, dtype=np.int64)
    key = np.zeros(nc + 1, dtype=np.int64)
    mark = np.zeros(sink + 1, dtype=np.bool_)
    vst = np.zeros(sink + 1, dtype=np.int64)
    total = float(inst.profit[vertex_ok].sum())
    complete = total - 1e-9 * max(1.0, total)  # collecting this much is provably optimal
    first = float(fst[KS.F_BEST_P])
    batch = 1
    pool: list[tuple[float, float, Arrays]] = []
    rec = Recombiner(ins, (cur, best, work), (fst, ctl, rng, seq), tuning)
    reserve = 0.0 if rec.pool is None else min(tuning.pack_s, 0.05 * deadline.remaining())
    while nc and fst[KS.F_BEST_P] < complete and deadline.remaining() > reserve:
        done = int(ctl[KS.C_ITER])
        if max_iterations is not None and done >= max_iterations:
            break
        k = batch if max_iterations is None else min(batch, max_iterations - done)
        t0 = time.perf_counter()
        KS.run_search(ins, cur, best, work, rng, ctl, fst, par, k, buf, mark, key, vst, seq,
                      rec.rbuf, rec.seen)
        rec.after_batch(deadline.end - reserve)
        if tuning.elite > 1 and ctl[KS.C_CYCLE_IT] == 0:
            _restart_elite(pool, tuning.elite, cur, best, fst, rng)
        dt = time.perf_counter() - t0
        if dt < _BATCH_S / 2:
            batch *= 2
        elif dt > _BATCH_S and batch > 1:
            batch //= 2
    if fst[KS.F_BEST_P] < complete:
        rec.finish(deadline.end - reserve / 2)
    plan = _routes(inst, best)
    profit = float(K.profit_of(ins, best))
    status = Status.OPTIMAL if profit >= complete else Status.FEASIBLE
    stats = {
        "iterations": float(ctl[KS.C_ITER]),
        "best_iteration": float(ctl[KS.C_ITER] - ctl[KS.C_SINCE_BEST]),
        "restarts": float(ctl[KS.C_RESTARTS]),
        "construction_profit": first,
        "packings": float(rec.packings), "packing_gains": float(rec.gains),
    }
    log.debug("ils %s: profit %g after %d iterations", inst.name, profit, ctl[KS.C_ITER])
    return Result(
        status=status,
        objective=profit,
        bound=profit if status is Status.OPTIMAL else None,
        runtime_s=deadline.elapsed(),
        backend="ils",
        plan=plan,
        stats=stats,
    )


def _restart_elite(pool: list[tuple[float, float, Arrays]], size: int, cur: Arrays, best: Arrays,
                   fst: NDArray[np.float64], rng: NDArray[np.uint64]) -> None:
    """Add the best and the current solution to ``pool`` (distinct profit and time, at most
    ``size``, best first) and copy a random member into ``cur``."""
    for sol, p, t in ((best, fst[KS.F_BEST_P], fst[KS.F_BEST_T]),
                      (cur, fst[KS.F_CUR_P], fst[KS.F_CUR_T])):
        if all(abs(p - q) > 1e-9 or t != u for q, u, _ in pool):
            pool.append((float(p), float(t), tuple(a.copy() for a in sol)))
    pool.sort(key=lambda e: (-e[0], e[1]))
    del pool[size:]
    p, t, pick = pool[K.rand_int(rng, len(pool))]
    K.copy_sol(cur, pick)
    fst[KS.F_CUR_P] = p
    fst[KS.F_CUR_T] = t


def warm_up() -> None:
    """Compile (or load from Numba's cache) every kernel by solving a tiny instance.

    Compiling takes about half a minute the first time; Numba caches the machine code next to
    the sources, so later processes load it in about a second.
    """
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    # windows closing at 1.5 let a route visit only one customer: the search loop must run
    tiny = OPTWInstance.from_coordinates(
        xy, [0, 1, 2, 3], np.zeros(4), np.zeros(4), [10.0, 1.5, 1.5, 1.5], decimals=1
    )
    solve_ils(tiny, time_limit_s=60.0, max_iterations=5)
    pack_routes(np.ones((1, 1), dtype=np.uint64), np.ones(1), np.ones(1, dtype=np.int64), 2,
                0.0, 0, 10)
