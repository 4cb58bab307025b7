"""Exact single-vehicle OPTW by bounded labelling with ng/DSSR relaxation (Righini & Salani 2009).

The search runs *passes*. A pass is one labelling dynamic program (kernel in
:mod:`searchtrack.plan.optw.labelling_kernels`) over a relaxation of the elementary path problem:
a path may revisit a customer unless the customer is in the label's ng-memory (Baldacci, Mingozzi
& Roberti 2011: each customer remembers its 8 nearest customers; with at most 16 customers, all).

* Passes alternate between the instance graph and its time reversal, and each prunes its labels
  with the profit table of the previous pass: the best relaxed profit collected from the other
  end up to each (vertex, time), a valid completion bound (bounded DP, Righini & Salani 2009 §4).
  The first pass has no table and prunes with the best known route only.
* When no non-elementary path of a pass beats the best elementary route found, that route is
  optimal. Otherwise the cycles of the best such paths are forbidden by adding the repeated
  customer to the ng-sets of the vertices on the cycle (decremental state-space relaxation,
  Righini & Salani 2008, in the form of Martinelli, Pecin & Poggi 2014) and the next pass runs.

Every relaxed optimum is a valid upper bound, reported when the time limit stops the search.
"""

from __future__ import annotations

import itertools
import logging
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw import labelling_kernels as K
from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes
from searchtrack.plan.optw.labelling_primitives import shortest_paths
from searchtrack.plan.optw.reach import reach

log = logging.getLogger("searchtrack.plan.optw.labelling")

_BIG = np.int64(1) << np.int64(40)
_MAX_BUCKETS = 8192
_MAX_QUEUE_LOG2 = 22  # at most 2**22 time buckets in the label queue
_NG_SIZE = 8
_FULL_MEMORY = 16  # up to this many customers, labels remember every visit
_CAP_MAX = 1 << 22  # labels per pass (about 100 bytes each)
_PATHS_PER_PASS = 20
_SCAN = 256  # other-memory labels a new label is compared with


@dataclass(frozen=True, eq=False)
class Core:
    """The graph one labelling pass runs on, in that pass's time axis.

    Vertex 0 is the source, ``n − 1`` the sink, ``1 … n − 2`` the customers some route can visit
    (instance vertex ``orig[c]``). ``dur[i, j]`` is service at ``i`` plus travel to ``j`` in ticks
    (``_BIG`` when no feasible route uses the arc), ``sp`` the shortest such durations over any
    path; ``[opn, cls]`` the window on the service start.
    """

    dur: NDArray[np.int64]
    sp: NDArray[np.int64]
    succ_ptr: NDArray[np.int64]
    succ: NDArray[np.int64]
    opn: NDArray[np.int64]
    cls: NDArray[np.int64]
    prof: NDArray[np.float64]
    thr: NDArray[np.int64]
    cum: NDArray[np.uint64]
    src: int
    snk: int
    horizon: int

    @property
    def n(self) -> int:
        """Number of core vertices."""
        return int(self.dur.shape[0])


def _finish(dur: NDArray[np.int64], sp: NDArray[np.int64], opn: NDArray[np.int64],
            cls: NDArray[np.int64], prof: NDArray[np.float64], src: int, snk: int,
            horizon: int) -> Core:
    """Add successor lists and the out-of-reach tables to a core graph."""
    n = dur.shape[0]
    nw = (n + 63) // 64
    ok = dur < _BIG
    succ_ptr = np.zeros(n + 1, dtype=np.int64)
    succ_ptr[1:] = np.cumsum(ok.sum(axis=1))
    # successors by increasing duration: good labels are found early
    order = np.argsort(np.where(ok, dur, _BIG), axis=1, kind="stable")
    succ = order[np.take_along_axis(ok, order, axis=1)].astype(np.int64)
    customers = np.arange(1, n - 1)
    thr_all = cls[None, customers] - sp[:, customers]  # unreachable from v at t iff t > thr
    order = np.argsort(thr_all, axis=1, kind="stable")
    thr = np.ascontiguousarray(np.take_along_axis(thr_all, order, axis=1), dtype=np.int64)
    onehot = np.zeros((customers.size, nw), dtype=np.uint64)
    onehot[customers - 1, customers >> 6] = np.uint64(1) << (customers & 63).astype(np.uint64)
    cum = np.zeros((n, customers.size + 1, nw), dtype=np.uint64)
    cum[:, 1:] = np.bitwise_or.accumulate(onehot[order], axis=1)
    return Core(dur, sp, succ_ptr, succ, opn, cls, prof, thr, cum, src, snk, horizon)


def build_cores(inst: OPTWInstance) -> tuple[Core, Core, NDArray[np.int64]]:
    """The forward core graph, its time reversal and the core → instance vertex map.

    The reversal maps service start ``τ`` to ``H − τ`` and every arc ``i → j`` to ``j → i`` with
    the same duration, so a forward pass on it is a backward pass on the instance.
    """
    rc = reach(inst)
    cust = rc.useful.astype(np.int64)
    k = cust.size
    n = k + 2
    src, snk = 0, n - 1
    limit = inst.latest_finish
    dep = inst.departure
    s, t = inst.service.astype(np.int64), inst.travel.astype(np.int64)
    opn = np.zeros(n, dtype=np.int64)
    cls = np.zeros(n, dtype=np.int64)
    opn[1:-1] = inst.open[cust]
    cls[1:-1] = np.minimum(inst.close[cust], rc.latest[cust])
    opn[src] = cls[src] = dep
    opn[snk], cls[snk] = 0, limit
    early = np.empty(n, dtype=np.int64)
    early[1:-1] = rc.earliest[cust]
    early[src] = dep
    early[snk] = 0
    prof = np.zeros(n, dtype=np.float64)
    prof[1:-1] = inst.profit[cust]
    dur = np.full((n, n), _BIG, dtype=np.int64)
    dur[1:-1, 1:-1] = s[cust, None] + t[np.ix_(cust, cust)]
    dur[src, 1:-1] = s[inst.start] + t[inst.start, cust]
    if inst.end is None:
        dur[1:-1, snk] = s[cust]
        dur[src, snk] = s[inst.start]
    else:
        dur[1:-1, snk] = s[cust] + t[cust, inst.end]
        dur[src, snk] = s[inst.start] + t[inst.start, inst.end]
    np.fill_diagonal(dur, _BIG)
    feasible = np.maximum(opn[None, :], early[:, None] + dur) <= cls[None, :]
    dur = np.where(feasible & (dur < _BIG), dur, _BIG)
    into_sink = dur[:, snk] < _BIG
    # the sink's own limit may be "never": clip it to the latest possible arrival
    cls[snk] = min(limit, int((cls + dur[:, snk])[into_sink].max(initial=0)))
    horizon = int(max(int(cls.max()), dep))
    sp = shortest_paths(dur, _BIG)  # a lower bound on any path's duration
    fwd = _finish(dur, sp, opn, cls, prof, src, snk, horizon)
    rev = _finish(np.ascontiguousarray(dur.T), np.ascontiguousarray(sp.T), horizon - cls,
                  horizon - opn, prof, snk, src, horizon)
    orig = np.concatenate([[inst.start], cust, [-1 if inst.end is None else inst.end]])
    return fwd, rev, orig.astype(np.int64)


def _set_bits(masks: NDArray[np.uint64], row: int, vertices: NDArray[np.intp]) -> None:
    """Set the bits of ``vertices`` in ``masks[row]``."""
    for v in vertices.tolist():
        masks[row, v >> 6] |= np.uint64(1) << np.uint64(v & 63)


def initial_ng(core: Core, size: int) -> NDArray[np.uint64]:
    """ng-neighbourhoods: each customer remembers itself and its ``size`` nearest customers.

    Nearness is ``min(dur[i, j], dur[j, i])`` among the customers with which a cycle fits the
    windows; source and sink remember nothing (they cannot be revisited anyway).
    """
    n = core.n
    ng = np.zeros((n, (n + 63) // 64), dtype=np.uint64)
    customers = np.arange(1, n - 1)
    near = np.minimum(core.dur, core.dur.T).astype(np.float64)
    # a cycle through i and j needs j reachable after i and i after j
    near[(core.sp + core.sp.T) >= _BIG] = np.inf
    for i in customers.tolist():
        row = near[i, customers]
        row[i - 1] = np.inf
        picks = customers[np.argsort(row, kind="stable")[:size]]
        _set_bits(ng, i, np.append(picks[np.isfinite(near[i, picks])], i))
    return ng


def base_ng(core: Core) -> NDArray[np.uint64]:
    """ng-neighbourhoods that make every customer remember itself, and the customers joined by
    zero-duration arcs remember each other: no cycle of zero duration, which would let a relaxed
    path collect profit for free, can then be repeated."""
    n = core.n
    ng = np.zeros((n, (n + 63) // 64), dtype=np.uint64)
    inner = core.dur[1:-1, 1:-1] == 0
    zero = 1 + np.flatnonzero(inner.any(axis=0) | inner.any(axis=1))
    for i in range(1, n - 1):
        _set_bits(ng, i, zero if i in zero else np.array([i]))
    return ng


def _path(lv: NDArray[np.int64], par: NDArray[np.int64], leaf: int) -> list[int]:
    out = []
    x = leaf
    while x >= 0:
        out.append(int(lv[x]))
        x = int(par[x])
    return out[::-1]


def _forbid_cycles(ng: NDArray[np.uint64], path: list[int],
                   pairs: list[tuple[int, int]] | None = None) -> int:
    """Grow ng-sets so that each cycle ``i … i`` of ``path`` is forbidden; return bits added.
    Every pair ``(u, i)`` of a cycle (``u`` inside it) is also appended to ``pairs``."""
    added = 0
    last: dict[int, int] = {}
    for pos, v in enumerate(path):
        if v in last:
            word, bit = v >> 6, np.uint64(1) << np.uint64(v & 63)
            for u in path[last[v] + 1 : pos]:
                if pairs is not None:
                    pairs.append((u, v))
                if not ng[u, word] & bit:
                    ng[u, word] |= bit
                    added += 1
        last[v] = pos
    return added


def _route(inst: OPTWInstance, orig: NDArray[np.int64], core_path: list[int]) -> Route:
    inner = tuple(int(orig[c]) for c in core_path[1:-1])
    tail = () if inst.end is None else (inst.end,)
    return (inst.start, *inner, *tail)


def _collected(inst: OPTWInstance, route: Route) -> float:
    """Profit of ``route``'s customers, summed in visiting order."""
    inner = route[1:] if inst.end is None else route[1:-1]
    return float(sum(float(inst.profit[v]) for v in inner))


def _check_initial(inst: OPTWInstance, plan: Routes) -> Route:
    """The route of a one-route plan, if it respects every constraint of ``inst``."""
    def bad(reason: str) -> InvalidInputError:
        return InvalidInputError("initial", plan, reason)

    if len(plan) != 1:
        raise bad("must hold exactly one route")
    route = tuple(int(v) for v in plan[0])
    inner = route[1:] if inst.end is None else route[1:-1]
    if not route or route[0] != inst.start:
        raise bad("must start at the start vertex")
    if inst.end is not None and (len(route) < 2 or route[-1] != inst.end):
        raise bad("must finish at the end vertex")
    if len(set(inner)) != len(inner) or not set(inner) <= set(inst.customers.tolist()):
        raise bad("must visit distinct customers")
    arrival = begin = inst.departure
    for a, b in itertools.pairwise(route):
        arrival = begin + int(inst.service[a]) + int(inst.travel[a, b])
        begin = max(arrival, int(inst.open[b]))
        if begin > int(inst.close[b]):
            raise bad(f"reaches vertex {b} after its window closes")
    finish = arrival if inst.end is not None else begin + int(inst.service[route[-1]])
    if finish > inst.latest_finish:
        raise bad(f"finishes at {finish}, after the limit {inst.latest_finish}")
    return route


def _profit_gap(inst: OPTWInstance) -> float:
    """Least improvement worth searching for: 1 for integer profits, else a round-off margin."""
    p = inst.profit
    if np.all(p == np.round(p)):
        return 1.0 - 1e-6
    return 1e-9 * max(1.0, float(p.sum()))


@dataclass
class _Search:
    """What the passes share: the graphs, the ng-sets, the bounds and the best route so far."""

    inst: OPTWInstance
    fwd: Core
    rev: Core
    orig: NDArray[np.int64]
    ng: NDArray[np.uint64]
    gap: float
    lb: float
    route: Route | None
    upper: float
    deadline: Deadline
    tables: list[NDArray[np.float64] | None] = field(default_factory=lambda: [None, None])
    stats: dict[str, float] = field(
        default_factory=lambda: dict.fromkeys(("passes", "labels", "expanded", "checks"), 0.0)
    )

    def run_pass(self, direction: int) -> int | None:
        """Run one pass (0 forward, 1 backward); the kernel's stop code, or None if proven."""
        core = self.fwd if direction == 0 else self.rev
        width = max(1, math.ceil((core.horizon + 1) / _MAX_BUCKETS))
        buckets = core.horizon // width + 1
        tab = self.tables[1 - direction]
        out = K.label_pass(
            core.dur, core.succ_ptr, core.succ, core.opn, core.cls, core.prof, self.ng,
            core.thr, core.cum, core.src, core.snk,
            np.zeros((core.n, buckets)) if tab is None else tab, tab is not None,
            core.horizon, width, (core.horizon >> _MAX_QUEUE_LOG2).bit_length(),
            self.lb, self.upper, self.gap, _CAP_MAX, self.deadline.end, _SCAN, 0, core.prof,
        )
        code, lb, best, sinks, n_sinks, lv, lp, par, n_lab, own, pops, work = out[:12]
        for key, value in zip(("passes", "labels", "expanded", "checks"), (1, n_lab, pops, work),
                              strict=True):
            self.stats[key] += float(value)
        if best >= 0 and lb > self.lb:
            path = _path(lv, par, int(best))
            self.lb = float(lb)
            self.route = _route(self.inst, self.orig, path if direction == 0 else path[::-1])
        if code != K.DONE:
            return int(code)
        # the non-elementary paths that beat the best route: their cycles are forbidden next
        better = np.asarray(sinks[:n_sinks])
        better = better[lp[better] >= self.lb + self.gap]
        relaxed = float(lp[better].max()) if better.size else -np.inf
        self.upper = min(self.upper, max(self.lb, relaxed))
        log.debug("pass %d (%s): %d labels, %d expanded, lb %g, relaxed %g, %.2f s",
                  int(self.stats["passes"]), "fwd" if direction == 0 else "bwd", n_lab, pops,
                  self.lb, relaxed, self.deadline.elapsed())
        if not better.size:
            return None
        added = 0
        for s in better[np.argsort(-lp[better], kind="stable")[:_PATHS_PER_PASS]]:
            added += _forbid_cycles(self.ng, _path(lv, par, int(s)))
        if not added:  # cannot happen (a forbidden cycle is gone); full memory is exact anyway
            log.warning("no cycle to forbid after pass %d: remembering every visit",
                        int(self.stats["passes"]))
            self.ng |= initial_ng(self.fwd, self.fwd.n)
        self.tables[direction] = np.maximum.accumulate(own, axis=1)
        return int(code)


def solve_labelling(
    instance: OPTWInstance,
    *,
    time_limit_s: float = 60.0,
    seed: int = 0,
    initial: Routes | None = None,
    ng_size: int | None = None,
) -> Result[Routes]:
    """Solve a single-vehicle OPTW to proven optimality (or to the time limit).

    Parameters
    ----------
    instance
        The instance; ``vehicles`` must be 1.
    time_limit_s
        Wall-clock limit; on expiry the best route found and a proven upper bound are returned.
    seed
        Unused (the method is deterministic); accepted for the backend signature.
    initial
        A feasible one-route plan whose profit is a lower bound for pruning; returned if nothing
        better is found.
    ng_size
        Nearest customers each customer remembers from the first pass on (0: the first pass is
        the non-elementary relaxation). Any value gives the same optimum. ``None`` picks 8
        (fastest on the benchmark), or every customer when there are at most 16.

    Returns
    -------
    Result
        ``OPTIMAL`` with the route when proven; ``FEASIBLE`` (or ``NO_SOLUTION``) with the best
        route found and a proven upper bound when the time limit or the label store (about
        4 million labels) stops the search; ``INFEASIBLE`` when no route can reach the end.

    Raises
    ------
    InvalidInputError
        If ``instance.vehicles != 1``, ``ng_size`` is negative or ``initial`` is not a feasible
        one-route plan.
    """
    deadline = Deadline(check_time_limit(time_limit_s))
    inst = instance
    del seed
    if inst.vehicles != 1:
        raise InvalidInputError(
            "vehicles", inst.vehicles, "labelling solves the single-vehicle OPTW only"
        )
    if ng_size is not None and (not isinstance(ng_size, int) or ng_size < 0):
        raise InvalidInputError("ng_size", ng_size, "must be a non-negative integer or None")
    start = None if initial is None else _check_initial(inst, initial)
    fwd, rev, orig = build_cores(inst)
    if ng_size is None:
        ng_size = fwd.n if fwd.n - 2 <= _FULL_MEMORY else _NG_SIZE
    search = _Search(
        inst, fwd, rev, orig, ng=np.bitwise_or(base_ng(fwd), initial_ng(fwd, ng_size)),
        gap=_profit_gap(inst), lb=-np.inf, route=None, upper=float(fwd.prof.sum()),
        deadline=deadline,
    )
    if fwd.dur[fwd.src, fwd.snk] < _BIG:
        search.lb, search.route = 0.0, _route(inst, orig, [fwd.src, fwd.snk])
    if start is not None and _collected(inst, start) > search.lb:
        search.lb, search.route = _collected(inst, start), start
    code = None
    direction = 0
    while search.lb + search.gap <= search.upper:
        code = search.run_pass(direction)
        if code is None or code != K.DONE:
            break
        direction = 1 - direction
    stats = search.stats
    if code is not None and code != K.DONE:
        message = ("label store full" if code != K.TIMEOUT
                   else "stopped on request" if stop_requested() else "time limit")
        if search.route is None:
            return Result(Status.NO_SOLUTION, None, None, deadline.elapsed(), "labelling", None,
                          message=message, stats=stats)
        profit = _collected(inst, search.route)
        return Result(Status.FEASIBLE, profit, max(search.upper, profit), deadline.elapsed(),
                      "labelling", (search.route,), message=message, stats=stats)
    if search.route is None:
        return Result(Status.INFEASIBLE, None, None, deadline.elapsed(), "labelling", None,
                      message="no route reaches the end in time", stats=stats)
    profit = _collected(inst, search.route)
    return Result(Status.OPTIMAL, profit, profit, deadline.elapsed(), "labelling",
                  (search.route,), message="proven optimal", stats=stats)


def warm_up() -> None:
    """Compile (or load from Numba's cache) the kernel by solving a tiny instance."""
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    tiny = OPTWInstance.from_coordinates(
        xy, [0, 1, 2, 3], np.zeros(4), np.zeros(4), np.full(4, 10.0), decimals=1
    )
    solve_labelling(tiny, time_limit_s=60.0)
