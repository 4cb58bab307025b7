"""Route recombination for the team OPTW iterated local search.

The search stages the routes of its good local optima (within a fraction of the best profit,
:func:`~searchtrack.plan.optw.ils_kernels.stage_routes`); :class:`RoutePool` keeps the distinct
ones (by customer set, the earliest finishing order) and :meth:`RoutePool.pack` solves the set
packing problem "at most ``m`` pairwise customer-disjoint routes of the most profit" over them,
exactly by branch and bound (:func:`pack_routes`; small ``m`` keeps it cheap). A packing better
than the search's best, once improved by insertion and local search, becomes its current and best
solution. This is the route recombination component of Hu & Lim (2014, "An iterative
three-component heuristic for the team orienteering problem with time windows", EJOR 232, who
solve the set packing by an integer program), in the spirit of the route pools of Souffriau et al.
(2010, path relinking for the team orienteering problem) and Ke et al. (2016, Pareto mimic
algorithm): routes of different solutions that fit together recombine into plans that
ruin-and-recreate moves reach only slowly. :class:`Recombiner` drives it inside the search loop.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.plan.optw import ils_kernels as K
from searchtrack.plan.optw import ils_search as KS
from searchtrack.plan.optw.ils_tuning import Tuning

Arrays = tuple[NDArray[np.int64], ...]
Kernel = tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64],
               NDArray[np.float64], NDArray[np.int64]]
Route = tuple[int, ...]


_NCAND, _POS, _COST, _CHOSEN, _OUT = range(5)  # rows of the per-depth state ``lev``
_DEPTH, _NODES, _BEST_C = range(3)  # entries of the scalar state ``sc``


@njit(cache=True)
def pack_step(bits, p, c, cand, lev, used, fl, sc, steps):  # type: ignore[no-untyped-def]
    """Resume the depth-first branch and bound of :func:`pack_routes` for at most ``steps``
    nodes; return True once it is complete.

    State: candidate lists ``cand`` per depth; ``lev`` rows (count, next position, cost, chosen
    route, best set) per depth; the union ``used`` of the chosen bit masks per depth; ``fl`` the
    profit per depth then the best profit; ``sc`` the depth, node count and best cost.
    """
    m = lev.shape[1] - 1
    words = bits.shape[1]
    bp = fl[m + 1]
    eps = 1e-9 * max(1.0, abs(bp))
    d = sc[_DEPTH]
    for _ in range(steps):
        if d < 0:
            break
        q0 = lev[_POS, d]
        if q0 >= lev[_NCAND, d]:
            d -= 1
            continue
        i = cand[d, q0]
        ub = fl[d]  # candidates come by decreasing profit: the next ones bound the rest
        for q in range(q0, min(lev[_NCAND, d], q0 + m - d)):
            ub += p[cand[d, q]]
        lev[_POS, d] = q0 + 1
        if ub < bp - eps:
            d -= 1
            continue
        sc[_NODES] += 1
        tp = fl[d] + p[i]
        tc = lev[_COST, d] + c[i]
        lev[_CHOSEN, d] = i
        if tp > bp + eps or (tp >= bp - eps and tc < sc[_BEST_C]):
            bp = fl[m + 1] = tp
            sc[_BEST_C] = tc
            lev[_OUT, :] = -1
            lev[_OUT, : d + 1] = lev[_CHOSEN, : d + 1]
        if d + 1 == m:
            continue
        for w in range(words):
            used[d + 1, w] = used[d, w] | bits[i, w]
        k = 0
        for q in range(q0 + 1, lev[_NCAND, d]):
            j = cand[d, q]
            ok = True
            for w in range(words):
                if bits[j, w] & used[d + 1, w]:
                    ok = False
                    break
            if ok:
                cand[d + 1, k] = j
                k += 1
        d += 1
        lev[_NCAND, d] = k
        lev[_POS, d] = 0
        lev[_COST, d] = tc
        fl[d] = tp
    sc[_DEPTH] = d
    return d < 0


def pack_routes(bits: NDArray[np.uint64], p: NDArray[np.float64], c: NDArray[np.int64], m: int,
                floor_p: float, floor_c: int, budget: int,
                stop: float = math.inf) -> NDArray[np.int64]:
    """Best set of at most ``m`` pairwise disjoint routes, by depth-first branch and bound.

    Route ``i`` visits the customers of bit mask ``bits[i]``, collects ``p[i]`` and costs
    ``c[i]``; routes come sorted by decreasing profit, so the bound of a node is its profit plus
    that of the next candidates (a maximum-weight clique search of at most ``m`` vertices in the
    graph of disjoint routes). Only sets better than ``(floor_p, floor_c)`` (more profit, or as
    much and less cost) count. It stops after about ``budget`` nodes or at ``perf_counter``
    time ``stop``. Returns the chosen indices padded with −1 (all −1 when none beats the floor).
    """
    n = int(p.shape[0])
    cand = np.zeros((m + 1, n), dtype=np.int64)
    cand[0] = np.arange(n)
    lev = np.zeros((5, m + 1), dtype=np.int64)
    lev[_NCAND, 0] = n
    lev[_OUT] = -1
    used = np.zeros((m + 1, bits.shape[1]), dtype=np.uint64)
    fl = np.zeros(m + 2, dtype=np.float64)
    fl[m + 1] = floor_p
    sc = np.array([0, 0, floor_c], dtype=np.int64)
    while not pack_step(bits, p, c, cand, lev, used, fl, sc, min(4096, budget - sc[_NODES])):
        if sc[_NODES] >= budget or time.perf_counter() >= stop:
            break
    return lev[_OUT, :m].copy()


def load(ins: Kernel, sol: Arrays, routes: Sequence[Route]) -> None:
    """Make ``sol`` the plan of ``routes`` (customer tuples, feasible, at most one per route of
    ``sol``); the remaining routes are left empty."""
    rt, ln, own = sol[0], sol[1], sol[5]
    sink = rt[0, ln[0] - 1]
    own[:] = -1
    for r in range(ln.shape[0]):
        inner = routes[r] if r < len(routes) else ()
        rt[r, 1 : len(inner) + 1] = inner
        rt[r, len(inner) + 1] = sink
        ln[r] = len(inner) + 2
        own[list(inner)] = r
        K.schedule(ins, sol, r)


class RoutePool:
    """The distinct routes the search staged, at most ``size`` (the least profitable dropped
    first), and the staging buffers of :func:`~searchtrack.plan.optw.ils_search.run_search`.

    Each route is kept as its customers, profit, arrival at the sink and customer bit mask.
    """

    def __init__(self, profit: NDArray[np.float64], vehicles: int, customers: int,
                 size: int, rows: int = 256, base: int = 0) -> None:
        self.profit = profit
        self.base = base  # arrival of an empty route: a route costs its arrival beyond it
        self.vehicles = vehicles
        self.size = size
        self.words = (profit.shape[0] + 63) // 64
        self.rbuf = np.zeros((max(rows, vehicles), customers + 3), dtype=np.int64)
        self.seen = np.zeros((1 << max(10, (4 * size).bit_length()), 2), dtype=np.int64)
        self.routes: dict[int, tuple[Route, float, int, NDArray[np.uint64]]] = {}
        self.added = 0  # routes new since the last packing

    def full(self, ctl: NDArray[np.int64]) -> bool:
        """True when the search returned because the staging buffer might overflow."""
        return int(ctl[KS.C_STAGED]) + self.vehicles > self.rbuf.shape[0]

    def drain(self, ctl: NDArray[np.int64]) -> None:
        """Move the staged routes into the pool and empty the buffer."""
        k = int(ctl[KS.C_STAGED])
        rows = self.rbuf[:k]
        for i, (key, n, arrival) in enumerate(rows[:, :3].tolist()):
            self._add(key, arrival, rows[i, 3 : 3 + n])
        ctl[KS.C_STAGED] = 0
        if len(self.routes) > self.size:
            keep = sorted(self.routes.items(), key=lambda e: (-e[1][1], e[1][2]))
            self.routes = dict(keep[: self.size // 2])

    def _add(self, key: int, arrival: int, visits: NDArray[np.int64]) -> None:
        old = self.routes.get(key)
        if old is None:
            bits = np.zeros(self.words, dtype=np.uint64)
            np.bitwise_or.at(bits, visits >> 6, np.left_shift(np.uint64(1),
                                                              (visits & 63).astype(np.uint64)))
            self.routes[key] = (tuple(visits.tolist()), float(self.profit[visits].sum()),
                                arrival, bits)
            self.added += 1
        elif arrival < old[2]:
            self.routes[key] = (tuple(visits.tolist()), old[1], arrival, old[3])

    def add_solution(self, sol: Arrays) -> list[int]:
        """Add the routes of ``sol`` (with customers); return their keys."""
        rt, ln, arr = sol[0], sol[1], sol[2]
        keys = []
        for r in range(ln.shape[0]):
            n = int(ln[r])
            if n > 2:
                key = int(K.route_key(rt, r, n))
                self._add(key, int(arr[r, n - 1]), rt[r, 1 : n - 1])
                keys.append(key)
        return keys

    def pack(self, best: Arrays, budget: int, stop: float = math.inf) -> list[Route] | None:
        """The routes of the best packing of the pool (``best``'s routes added first) within
        ``budget`` nodes of :func:`pack_routes` and ``perf_counter`` time ``stop``; ``None``
        when none beats ``best``'s routes."""
        keys = self.add_solution(best)
        self.added = 0
        entries = list(self.routes.values())
        p = np.array([e[1] for e in entries])
        c = np.array([e[2] for e in entries], dtype=np.int64) - self.base
        order = np.lexsort((c, -p))
        bits = np.stack([entries[i][3] for i in order.tolist()])
        floor_p = sum(self.routes[key][1] for key in keys)
        floor_c = sum(self.routes[key][2] - self.base for key in keys)
        chosen = pack_routes(bits, p[order], c[order], self.vehicles, floor_p, floor_c, budget,
                             stop)
        if chosen[0] < 0:
            return None
        return [entries[int(order[i])][0] for i in chosen.tolist() if i >= 0]


def recombine(ins: Kernel, pool: RoutePool, cur: Arrays, best: Arrays, work: Arrays,
              fst: NDArray[np.float64], ctl: NDArray[np.int64], rng: NDArray[np.uint64],
              seq: NDArray[np.int64], flags: tuple[bool, bool], budget: int,
              stop: float = math.inf) -> bool:
    """Pack the pool into ``work``, improve it by insertion and local search (``flags``: the
    ``relocate`` and ``replace`` options), and make it the current and best solution if it beats
    ``best``; return True if it did. The packing stops at ``perf_counter`` time ``stop``."""
    routes = pool.pack(best, budget, stop)
    if routes is None:
        return False
    load(ins, work, routes)
    K.insert_greedy(ins, work, rng, 2.0, 0.0)
    KS.local_search(ins, work, rng, seq, flags[0], flags[1])
    p, t = K.profit_of(ins, work), K.time_of(work)
    if not K.better(p, t, fst[KS.F_BEST_P], fst[KS.F_BEST_T]):
        return False
    pool.add_solution(work)
    K.copy_sol(best, work)
    K.copy_sol(cur, work)
    fst[KS.F_BEST_P] = fst[KS.F_CUR_P] = p
    fst[KS.F_BEST_T] = fst[KS.F_CUR_T] = t
    ctl[KS.C_SINCE_BEST] = 0
    return True


class Recombiner:
    """Route recombination inside the search loop of :mod:`searchtrack.plan.optw.ils`: the staging
    buffers to hand to :func:`~searchtrack.plan.optw.ils_search.run_search` (empty when off: at
    most one vehicle or ``tuning.pool`` 0), and the packing calls, on the search's own arrays.

    ``tuning`` (:class:`searchtrack.plan.optw.ils_tuning.Tuning`, which validates them) gives the
    pool share and size, the new routes between packings, each packing's node budget, and the
    ``relocate`` and ``replace`` options of the local search after a packing.
    """

    def __init__(self, ins: Kernel, sols: tuple[Arrays, Arrays, Arrays],
                 state: tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.uint64],
                              NDArray[np.int64]],
                 tuning: Tuning) -> None:
        self.ins, self.sols, self.state = ins, sols, state
        self.every, self.nodes = tuning.pack_every, tuning.pack_nodes
        self.flags = (tuning.relocate, tuning.replace)
        m, nc = sols[0][1].shape[0], ins[5].shape[0]
        rows = max(2 * m, min(256, self.every))  # a buffer no larger than a packing's worth
        s, sink = int(sols[0][0][0, 0]), ins[0].shape[0] - 1
        base = int(ins[2][s] + ins[1][s] + ins[0][s, sink])
        self.pool = RoutePool(ins[4], m, nc, tuning.pool_size, rows, base) \
            if tuning.pool > 0.0 and m > 1 and nc else None
        self.rbuf = self.pool.rbuf if self.pool else np.zeros((0, 3), dtype=np.int64)
        self.seen = self.pool.seen if self.pool else np.zeros((1, 2), dtype=np.int64)
        self.packings = 0
        self.gains = 0

    def after_batch(self, stop: float) -> None:
        """Drain a full staging buffer; pack once enough routes are new, unless the
        ``perf_counter`` time is past ``stop`` (which also ends the packing).

        Only a full buffer is drained, so the packings fall on the same iterations whatever the
        batch sizes (a seeded search with an iteration budget stays deterministic)."""
        if self.pool is not None and self.pool.full(self.state[1]):
            self.pool.drain(self.state[1])
            if self.pool.added >= self.every and time.perf_counter() < stop:
                self._pack(stop)

    def finish(self, stop: float) -> None:
        """Drain the buffer and pack once more, until ``perf_counter`` time ``stop``."""
        if self.pool is not None:
            self.pool.drain(self.state[1])
            self._pack(stop)

    def _pack(self, stop: float) -> None:
        assert self.pool is not None
        cur, best, work = self.sols
        fst, ctl, rng, seq = self.state
        self.packings += 1
        self.gains += recombine(self.ins, self.pool, cur, best, work, fst, ctl, rng, seq,
                                self.flags, self.nodes, stop)
