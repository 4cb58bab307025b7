"""What the OPTW labelling solvers share: core graphs, ng-sets and one bounded labelling pass.

Both the exact single-vehicle solver (:mod:`searchtrack.plan.optw.labelling`) and the pricing of
the team branch-and-price (:mod:`searchtrack.plan.optw.bp_pricing`) run passes of the same
ng/DSSR-relaxed labelling (Righini & Salani 2008, 2009; Baldacci, Mingozzi & Roberti 2011) on
the same graphs. This module holds that common part:

* :class:`Core`, the graph one pass runs on, built from an instance by :func:`build_cores` or
  from any durations by :func:`core_pair` (a graph and its time reversal);
* the ng-neighbourhoods (:func:`initial_ng`, :func:`base_ng`) and their growth by decremental
  state-space relaxation (:func:`forbid_cycles`; Martinelli, Pecin & Poggi 2014);
* :func:`run_pass`, the one place that calls the kernel
  (:func:`searchtrack.plan.optw.labelling_kernels.label_pass`), with what it found as a
  :class:`PassResult`;
* the settings both solvers use (label store size, ng-set size, bucket counts).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw import labelling_kernels as K
from searchtrack.plan.optw.instance import OPTWInstance, Route
from searchtrack.plan.optw.labelling_primitives import shortest_paths
from searchtrack.plan.optw.reach import reach

BIG = np.int64(1) << np.int64(40)  #: duration of an arc no feasible route uses
MAX_BUCKETS = 8192  #: time buckets of a profit table
MAX_QUEUE_LOG2 = 22  #: at most 2**22 time buckets in the label queue
NG_SIZE = 8  #: nearest customers each customer remembers by default
FULL_MEMORY = 16  #: up to this many customers, labels remember every visit
CAP_MAX = 1 << 22  #: labels per pass (about 100 bytes each)
PATHS_PER_PASS = 20  #: non-elementary paths whose cycles one pass forbids
ROOM = 1 << 15  #: labels a pass's store starts with (it grows as needed)


@dataclass(frozen=True, eq=False)
class Core:
    """The graph one labelling pass runs on, in that pass's time axis.

    Vertex 0 is the source, ``n − 1`` the sink, ``1 … n − 2`` the customers some route can visit
    (instance vertex ``orig[c]``). ``dur[i, j]`` is service at ``i`` plus travel to ``j`` in ticks
    (:data:`BIG` when no feasible route uses the arc), ``sp`` the shortest such durations over
    any path; ``[opn, cls]`` the window on the service start. Customer ``c`` is out of reach
    from ``v`` after time ``gone[v, c]``; ``thr`` and ``cum`` hold the same by vertex, in order
    (see :func:`searchtrack.plan.optw.labelling_kernels.label_pass`).
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
    gone: NDArray[np.int64]
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
    ok = dur < BIG
    succ_ptr = np.zeros(n + 1, dtype=np.int64)
    succ_ptr[1:] = np.cumsum(ok.sum(axis=1))
    # successors by increasing duration: good labels are found early
    order = np.argsort(np.where(ok, dur, BIG), axis=1, kind="stable")
    succ = order[np.take_along_axis(ok, order, axis=1)].astype(np.int64)
    customers = np.arange(1, n - 1)
    thr_all = cls[None, customers] - sp[:, customers]  # unreachable from v at t iff t > thr
    order = np.argsort(thr_all, axis=1, kind="stable")
    thr = np.ascontiguousarray(np.take_along_axis(thr_all, order, axis=1), dtype=np.int64)
    onehot = np.zeros((customers.size, nw), dtype=np.uint64)
    onehot[customers - 1, customers >> 6] = np.uint64(1) << (customers & 63).astype(np.uint64)
    cum = np.zeros((n, customers.size + 1, nw), dtype=np.uint64)
    cum[:, 1:] = np.bitwise_or.accumulate(onehot[order], axis=1)
    gone = np.full((n, n), BIG, dtype=np.int64)
    gone[:, customers] = thr_all
    return Core(dur, sp, succ_ptr, succ, opn, cls, prof, thr, cum, gone, src, snk, horizon)


def core_pair(dur: NDArray[np.int64], opn: NDArray[np.int64], cls: NDArray[np.int64],
              prof: NDArray[np.float64], src: int, snk: int, horizon: int) -> tuple[Core, Core]:
    """A core graph and its time reversal.

    The reversal maps service start ``τ`` to ``H − τ`` and every arc ``i → j`` to ``j → i`` with
    the same duration, so a forward pass on it is a backward pass on the original graph.
    """
    sp = shortest_paths(dur, BIG)  # a lower bound on any path's duration
    fwd = _finish(dur, sp, opn, cls, prof, src, snk, horizon)
    rev = _finish(np.ascontiguousarray(dur.T), np.ascontiguousarray(sp.T), horizon - cls,
                  horizon - opn, prof, snk, src, horizon)
    return fwd, rev


def build_cores(inst: OPTWInstance) -> tuple[Core, Core, NDArray[np.int64]]:
    """The forward core graph of an instance, its time reversal and the core → instance map.

    The customers are those some feasible route can visit (:mod:`searchtrack.plan.optw.reach`),
    their windows tightened to the times such a route can serve them; arcs no feasible route
    uses get duration :data:`BIG`. The reversal is that of :func:`core_pair`.
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
    dur = np.full((n, n), BIG, dtype=np.int64)
    dur[1:-1, 1:-1] = s[cust, None] + t[np.ix_(cust, cust)]
    dur[src, 1:-1] = s[inst.start] + t[inst.start, cust]
    if inst.end is None:
        dur[1:-1, snk] = s[cust]
        dur[src, snk] = s[inst.start]
    else:
        dur[1:-1, snk] = s[cust] + t[cust, inst.end]
        dur[src, snk] = s[inst.start] + t[inst.start, inst.end]
    np.fill_diagonal(dur, BIG)
    feasible = np.maximum(opn[None, :], early[:, None] + dur) <= cls[None, :]
    dur = np.where(feasible & (dur < BIG), dur, BIG)
    into_sink = dur[:, snk] < BIG
    # the sink's own limit may be "never": clip it to the latest possible arrival
    cls[snk] = min(limit, int((cls + dur[:, snk])[into_sink].max(initial=0)))
    horizon = int(max(int(cls.max()), dep))
    fwd, rev = core_pair(dur, opn, cls, prof, src, snk, horizon)
    orig = np.concatenate([[inst.start], cust, [-1 if inst.end is None else inst.end]])
    return fwd, rev, orig.astype(np.int64)


def instance_route(inst: OPTWInstance, orig: NDArray[np.int64], core_path: list[int]) -> Route:
    """The instance route of a core path ``src … snk`` (``orig``: core → instance vertex)."""
    inner = tuple(int(orig[c]) for c in core_path[1:-1])
    tail = () if inst.end is None else (inst.end,)
    return (inst.start, *inner, *tail)


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
    near[(core.sp + core.sp.T) >= BIG] = np.inf
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


def forbid_cycles(ng: NDArray[np.uint64], path: list[int],
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


@dataclass(frozen=True, eq=False)
class CutMasks:
    """Subset-row cuts as a labelling pass reads them: ``subset[v]`` and ``memory[v]`` are
    ``(n, W)`` bitmasks of the cuts whose subset (memory) holds vertex ``v``, ``dual`` the cuts'
    non-negative duals (``64 W`` entries, zero-padded)."""

    subset: NDArray[np.uint64]
    memory: NDArray[np.uint64]
    dual: NDArray[np.float64]


def _no_cuts(n: int) -> tuple[NDArray[np.uint64], NDArray[np.uint64], NDArray[np.float64]]:
    none = np.zeros((n, 0), dtype=np.uint64)
    return none, none, np.zeros(0)


@dataclass(frozen=True, eq=False)
class PassResult:
    """What one labelling pass found (see :func:`run_pass`).

    Label ``x`` is at vertex ``lv[x]`` with profit ``lp[x]`` and parent label ``par[x]``.
    """

    code: int  #: the kernel's stop code (``DONE``, ``TIMEOUT``, ``FULL`` or ``ENOUGH``)
    lb: float  #: the best known profit at the end of the pass
    best: int  #: sink label of the best elementary path that beat the given ``lb`` (−1: none)
    sinks: NDArray[np.int64]  #: sink labels of non-elementary paths that reached ``lb + gap``
    found: NDArray[np.int64]  #: sink labels of the elementary paths collected (collect mode)
    lv: NDArray[np.int64]
    lp: NDArray[np.float64]
    par: NDArray[np.int64]
    labels: int  #: labels stored
    own: NDArray[np.float64]  #: this pass's profit table, bucket by bucket
    pops: int  #: labels expanded
    work: int  #: groups and labels visited by dominance checks
    lt: NDArray[np.int64]  #: each label's time
    lmem: NDArray[np.uint64]  #: each label's ng-memory (its own vertex included)
    lc: NDArray[np.uint64]  #: each label's subset-row cut states
    alive: NDArray[np.bool_]  #: False for the labels found dominated

    def path(self, leaf: int) -> list[int]:
        """The core path (in this pass's direction) of the label ``leaf``."""
        lv, par = self.lv, self.par
        out = []
        x = leaf
        while x >= 0:
            out.append(int(lv[x]))
            x = int(par[x])
        return out[::-1]

    def table(self) -> NDArray[np.float64]:
        """This pass's profit table as a completion bound for the opposite direction: the best
        profit at each vertex up to each time bucket."""
        return np.maximum.accumulate(self.own, axis=1)


def bucket_width(horizon: int) -> int:
    """Time ticks per bucket of a pass's profit table (at most :data:`MAX_BUCKETS` buckets):
    what a reader of :attr:`PassResult.own` or :meth:`PassResult.table` must bucket by."""
    return max(1, math.ceil((horizon + 1) / MAX_BUCKETS))


def run_pass(core: Core, ng: NDArray[np.uint64], table: NDArray[np.float64] | None, *,
             lb: float, gap: float, cap: int, deadline: Deadline, ub: float = math.inf,
             collect: int = 0, bprof: NDArray[np.float64] | None = None,
             cuts: CutMasks | None = None, tstop: int | None = None,
             room: int = ROOM) -> PassResult:
    """One bounded labelling pass on ``core`` with ng-sets ``ng``.

    Parameters
    ----------
    core
        The graph, in the pass's time axis.
    ng
        ``(n, W)`` ng-neighbourhood bitmasks.
    table
        The opposite direction's profit table (:meth:`PassResult.table`) as completion bound,
        or ``None`` to bound with the profit outside the label's mask only.
    lb, gap, ub
        A label survives only if its bound reaches ``lb + gap``; the pass stops once
        ``lb + gap > ub``.
    cap
        Most labels to store.
    deadline
        When to stop.
    collect
        0: search for the best path (each elementary path found raises ``lb``); ``K > 0``:
        keep ``lb`` fixed and collect up to ``K`` elementary paths reaching ``lb + gap``.
    bprof
        Non-negative upper bounds on the profits (default ``core.prof``, which must then be
        non-negative).
    cuts
        Limited-memory subset-row cuts priced into the labels (default: none); ``bprof`` and
        ``table`` must then bound the profits without the cuts' costs.
    tstop
        Make no label whose time exceeds ``tstop`` (default: no limit), as the half passes of
        bidirectional labelling do.
    room
        Labels the store starts with; it grows as needed, and the result does not depend on it.
    """
    width = bucket_width(core.horizon)
    buckets = core.horizon // width + 1
    out = K.label_pass(
        core.dur, core.succ_ptr, core.succ, core.opn, core.cls, core.prof, ng,
        core.thr, core.cum, core.gone, core.src, core.snk,
        np.zeros((core.n, buckets)) if table is None else table, table is not None,
        core.horizon, width, (core.horizon >> MAX_QUEUE_LOG2).bit_length(),
        lb, ub, gap, cap, deadline.end, collect, core.prof if bprof is None else bprof,
        *(_no_cuts(core.n) if cuts is None else (cuts.subset, cuts.memory, cuts.dual)),
        core.horizon + 1 if tstop is None else tstop, room,
    )
    (code, lb_out, best, sinks, n_sinks, lv, lp, par, n_lab, own, pops, work, found, n_found,
     lt, lmem, lc, alive) = out
    return PassResult(int(code), float(lb_out), int(best), sinks[:n_sinks], found[:n_found], lv,
                      lp, par, int(n_lab), own, int(pops), int(work), lt, lmem, lc, alive)


def core_path(inst: OPTWInstance, where: dict[int, int], route: Route) -> tuple[int, ...] | None:
    """The core path ``src … snk`` of an instance route (``where``: instance → core customer),
    or ``None`` when it visits a customer that no feasible route can."""
    inner = route[1:] if inst.end is None else route[1:-1]
    if any(v not in where for v in inner):
        return None
    return (0, *(where[v] for v in inner), len(where) + 1)


def feasible_path(core: Core, path: tuple[int, ...]) -> bool:
    """True when the core path ``path`` keeps every window of ``core`` (waiting allowed)."""
    t = int(core.opn[core.src])
    for a, b in itertools.pairwise(path):
        if core.dur[a, b] >= BIG:
            return False
        t = max(int(core.opn[b]), t + int(core.dur[a, b]))
        if t > core.cls[b]:
            return False
    return True
