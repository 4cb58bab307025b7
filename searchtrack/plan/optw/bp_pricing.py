"""Pricing for the team-OPTW branch-and-price: best routes on reduced profits, by labelling.

The pricing problem is ``max_r Σ_{i∈r} (p_i − π_i)`` over the elementary feasible routes the
node allows (Boussier, Feillet & Gendreau 2007). It is solved by the bounded ng/DSSR labelling
shared with the single-vehicle solver (:mod:`searchtrack.plan.optw.labelling_core`; Righini &
Salani 2008, 2009; Baldacci, Mingozzi & Roberti 2011) in its *collect* mode: the floor ``μ + ε``
stays fixed and every elementary path above it is returned as a column.

* **Dropping customers.** When service plus travel satisfies the triangle inequality through a
  customer ``j`` (``dur[i, k] ≤ dur[i, j] + dur[j, k]``; checked once per instance), skipping
  ``j`` keeps a route feasible (waiting allowed) and, when ``p_j − π_j ≤ 0``, does not lower its
  reduced profit: such customers are left out of the pricing graph altogether. This is exact only
  when every shortcut arc exists, so it is switched off at nodes with arc decisions.
* **Negative profits.** The customers that stay may have ``p_j − π_j < 0``; the kernel then bounds
  the unvisited profit with the positive parts only, and its completion tables (relaxed optima of
  the opposite direction) need no sign, so pricing stays exact.
* **Completion table first.** Each exact call starts with a backward pass on small ng-sets
  (``table_ng`` nearest customers, learned cycles ignored): a weaker relaxation, so far fewer
  labels, whose profit table is a valid completion bound for the forward pass that follows
  (bounded DP, Righini & Salani 2009 §4). Without it the first pass could prune only with the
  total profit left, and pricing took about 1.4× the labels on Solomon r103 and c103.
* **Bidirectional pricing** (:attr:`Pricer.bidirectional`): instead of the table pass and a
  whole forward pass, a forward pass of the labels that start service by the half-way time
  ``t_m`` and a backward pass of those whose latest start is after it, joined over the arcs
  (:mod:`searchtrack.plan.optw.labelling_join`; Righini & Salani 2006). Paths are half as
  long, so far fewer labels grow on instances whose routes visit many customers. The split
  moves after each call towards the half that made fewer labels (a dynamic half-way point,
  Tilk et al. 2017). Every finished call returns the ``collect`` best columns, not the first
  ones, and a bound. With :attr:`Pricer.half_tables` a whole table pass each way comes first
  and its profit table bounds the completions of the other way's half pass, so labels no
  column above the floor can extend are pruned (off by default: the table passes are whole
  passes, and the halves they bound are short already).
* **DSSR across iterations.** Cycles forbidden by one pricing call stay forbidden (the learned
  ng-memory is kept for the whole tree): ng-sets only ever grow, so every later pass is a tighter
  relaxation that is still valid.

A completed call returns a valid upper bound on the pricing optimum (the largest relaxed path, or
the floor when none beats it), which gives the Lagrangian bound of the master.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw.bp_cuts import SubsetRowCut, masks, outside_memory
from searchtrack.plan.optw.bp_master import Path, Restrictions
from searchtrack.plan.optw.instance import OPTWInstance
from searchtrack.plan.optw.labelling_core import (
    BIG,
    FULL_MEMORY,
    NG_SIZE,
    PATHS_PER_PASS,
    Core,
    CutMasks,
    PassResult,
    base_ng,
    core_pair,
    forbid_cycles,
    initial_ng,
    run_pass,
)
from searchtrack.plan.optw.labelling_join import backward_stop, join, split_time
from searchtrack.plan.optw.labelling_kernels import DONE

log = logging.getLogger("searchtrack.plan.optw.bp_pricing")

SPLIT_STEP = 0.1  #: how far one call's label imbalance moves the split (share of the way)


def droppable(inst: OPTWInstance, orig: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Core customers through which the triangle inequality of service + travel holds.

    ``raw[i, k]`` is service at ``i`` plus travel to ``k`` (to the end vertex for the sink, or
    nothing for an open end); ``j`` is droppable when ``raw[i, k] ≤ raw[i, j] + raw[j, k]`` for
    every other source-side ``i`` and sink-side ``k``.
    """
    n = orig.size
    s = inst.service.astype(np.int64)
    t = inst.travel.astype(np.int64)
    heads = np.where(orig < 0, orig[0], orig)
    raw = s[heads][:, None] + t[np.ix_(heads, heads)]
    if inst.end is None:
        raw[:, n - 1] = s[heads]
    ok = np.zeros(n, dtype=bool)
    for j in range(1, n - 1):
        bad = raw > raw[:, j][:, None] + raw[j, :][None, :]
        bad[j, :] = bad[:, j] = False
        bad[n - 1, :] = bad[:, 0] = False
        np.fill_diagonal(bad, False)
        ok[j] = not bad.any()
    return ok


def _pack(mem: NDArray[np.bool_]) -> NDArray[np.uint64]:
    """Boolean ``(n, n)`` memory as the kernel's ``(n, W)`` bitmasks."""
    n = mem.shape[0]
    words = (n + 63) // 64
    padded = np.zeros((n, 64 * words), dtype=bool)
    padded[:, :n] = mem
    return np.packbits(padded, axis=1, bitorder="little").view(np.uint64).copy()


@dataclass
class Priced:
    """What one pricing call found."""

    paths: list[Path]  # core paths src … snk
    values: list[float]  # Σ (p_i − π_i) of each path
    upper: float | None  # proven bound on the pricing optimum, None if the call was cut short


@dataclass
class Pricer:
    """Pricing state shared by the whole tree: the root core graph and the learned ng-memory."""

    fwd: Core
    drop_ok: NDArray[np.bool_]
    ng_size: int = NG_SIZE
    table_ng: int | None = 4  # ng-size of the table pass that starts exact pricing (None: off)
    guide: bool = False  # keep forward tables for :meth:`guided`
    bidirectional: bool = False  # half passes joined at a time split instead of whole passes
    half_tables: bool = False  # bidirectional: bound each half with the other way's table pass
    split: float = 0.5  # the split's share of the way from departure to the sink's latest arrival
    memory: NDArray[np.bool_] = field(init=False)
    fixed: NDArray[np.bool_] = field(init=False)  # arcs left out of every pricing graph
    stats: dict[str, float] = field(default_factory=lambda: dict.fromkeys(
        ("pricing_calls", "passes", "labels"), 0.0))

    def __post_init__(self) -> None:
        self.memory = np.zeros((self.fwd.n, self.fwd.n), dtype=bool)
        self.fixed = np.zeros((self.fwd.n, self.fwd.n), dtype=bool)
        self._guide: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None

    def guided(self, dur: NDArray[np.int64], prof: NDArray[np.float64], floor: float, gap: float,
               *, forbidden: frozenset[int], collect: int, cap: int,
               deadline: Deadline) -> Priced:
        """Heuristic pricing: one backward pass pruned with the last forward pass's profit table,
        shifted to the new profits. The duals have moved since, so the table is no bound and
        the pass may miss columns, but it is fast; the paths it returns are exact columns."""
        if self._guide is None:
            return Priced([], [], None)
        self.stats["pricing_calls"] += 1
        keep = np.ones(self.fwd.n, dtype=bool)
        keep[list(forbidden)] = False
        idx = np.flatnonzero(keep)
        fwd, rev = self._cores(dur, prof, idx)
        ng = base_ng(fwd) | initial_ng(fwd, self.ng_size) | _pack(self.memory[np.ix_(idx, idx)])
        table, old = self._guide
        tab = np.ascontiguousarray(table[idx] + (prof[idx] - old[idx])[:, None])
        out = self._pass(rev, ng, tab, floor, gap, cap, collect, np.maximum(rev.prof, 0.0),
                         deadline)
        found = out.found.tolist()
        paths = [tuple(int(idx[v]) for v in out.path(s)[::-1]) for s in found]
        return Priced(paths, [float(out.lp[s]) for s in found], None)

    def _pass(self, core: Core, ng: NDArray[np.uint64], tab: NDArray[np.float64] | None,
              floor: float, gap: float, cap: int, collect: int, bprof: NDArray[np.float64],
              deadline: Deadline, cuts: CutMasks | None = None,
              tstop: int | None = None) -> PassResult:
        """One pass in collect mode, counted in the stats."""
        out = run_pass(core, ng, tab, lb=floor, gap=gap, cap=cap, deadline=deadline,
                       collect=collect, bprof=bprof, cuts=cuts, tstop=tstop)
        self.stats["passes"] += 1
        self.stats["labels"] += float(out.labels)
        return out

    def node_dur(self, node: Restrictions) -> NDArray[np.int64]:
        """The root durations with the fixed arcs removed and the node's arc and customer
        decisions applied."""
        dur = self.fwd.dur.copy()
        dur[self.fixed] = BIG
        src, snk = self.fwd.src, self.fwd.snk
        for v in node.forbidden:
            dur[v, :] = BIG
            dur[:, v] = BIG
        for i, j in node.no_arcs:
            dur[i, j] = BIG
        for i, j in node.arcs:
            keep = dur[i, j]
            if i != src:
                dur[i, :] = BIG
            if j != snk:
                dur[:, j] = BIG
            dur[i, j] = keep
        return dur

    def price(self, dur: NDArray[np.int64], prof: NDArray[np.float64], floor: float,
              gap: float, *, drop: bool, forbidden: frozenset[int], collect: int, cap: int,
              deadline: Deadline, cuts: Sequence[SubsetRowCut] = (),
              sigma: NDArray[np.float64] | None = None) -> Priced:
        """Elementary paths of ``Σ prof > floor + gap`` and a bound on the best one.

        Parameters
        ----------
        dur
            Node durations (:meth:`node_dur`).
        prof
            Reduced profit of every core vertex (0 at source and sink).
        floor, gap
            Paths must reach ``floor + gap``.
        drop
            Leave out the droppable customers of non-positive reduced profit.
        forbidden
            Customers the node forbids.
        collect, cap
            Most paths to return, most labels per pass.
        deadline
            When to stop.
        cuts, sigma
            The master's subset-row cuts and their duals: a path's value is then
            ``Σ prof − Σ_c σ_c α_c(path)``. The completion tables come from passes without the
            cuts (the costs of a path's prefix are among the whole path's, so those tables stay
            bounds), and the passes that follow stay forward. Bidirectional, both halves carry
            the cut states and the join pays for the pair of visits it completes.
        """
        self.stats["pricing_calls"] += 1
        n = self.fwd.n
        duals = np.zeros(len(cuts)) if sigma is None else sigma
        keep = np.ones(n, dtype=bool)
        if drop:
            keep[1:-1] = (prof[1:-1] > 0) | ~self.drop_ok[1:-1]
            keep |= outside_memory(cuts, duals, n)
        for v in forbidden:
            keep[v] = False
        idx = np.flatnonzero(keep)
        cm = masks(cuts, duals, idx)
        fwd, rev = self._cores(dur, prof, idx)
        ng = self._ng(fwd, idx)
        bprof = np.maximum(fwd.prof, 0.0)
        if self.bidirectional:
            return self._bidirectional(fwd, rev, ng, idx, floor, gap, cap, collect, bprof,
                                       deadline, cm)
        tables: list[NDArray[np.float64] | None] = [None, None]
        if self.table_ng is not None:
            # a cheap backward pass on small ng-sets: its profit table bounds every completion
            tables[1] = self._table(fwd, rev, floor, gap, cap, bprof, deadline)
        upper = math.inf
        direction = 0
        while True:
            core = fwd if direction == 0 else rev
            out = self._pass(core, ng, tables[1 - direction], floor, gap, cap, collect, bprof,
                             deadline, cm)
            if self.guide and direction == 0 and out.code == DONE:
                guide = np.full((self.fwd.n, out.own.shape[1]), -np.inf)
                guide[idx] = out.table()
                self._guide = (guide, prof.copy())
            log.debug("pricing pass %s on %d vertices, cap %d: code %d, %d labels, %d found, "
                      "%d relaxed", "fwd" if direction == 0 else "bwd", fwd.n, cap, out.code,
                      out.labels, out.found.size, out.sinks.size)
            paths, values = [], []
            for s in out.found.tolist():
                path = out.path(s)
                if direction == 1:
                    path = path[::-1]
                paths.append(tuple(int(idx[v]) for v in path))
                values.append(float(out.lp[s]))
            if out.code != DONE:
                return Priced(paths, values, None)
            lp, sinks = out.lp, out.sinks
            tops = np.concatenate([lp[out.found], lp[sinks]])
            upper = min(upper, max(floor + gap, float(tops.max(initial=-math.inf))))
            if out.found.size or not sinks.size:
                return Priced(paths, values, upper)
            for s in sinks[np.argsort(-lp[sinks], kind="stable")[:PATHS_PER_PASS]]:
                self._forbid(ng, idx, out.path(int(s)))
            if cm is None:
                tables[direction] = out.table()
                direction = 1 - direction

    def _bidirectional(self, fwd: Core, rev: Core, ng: NDArray[np.uint64],
                       idx: NDArray[np.intp], floor: float, gap: float, cap: int, collect: int,
                       bprof: NDArray[np.float64], deadline: Deadline,
                       cm: CutMasks | None) -> Priced:
        """Exact pricing by half passes joined at the split time
        (:mod:`~searchtrack.plan.optw.labelling_join`), forbidding the cycles of the best
        relaxed paths until an elementary one reaches the floor or none does. Every finished
        call gives a bound; the ``collect`` best columns are returned."""
        tm = split_time(fwd, self.split)
        sig = None if cm is None else cm.dual
        every = 1 << 62
        tables = self._tables(fwd, rev, floor, gap, cap, bprof, deadline)
        while True:
            f = self._pass(fwd, ng, tables[1], floor, gap, cap, every, bprof, deadline, cm, tm)
            found = [(float(f.lp[s]), f.path(s)) for s in f.found.tolist()]
            b = None
            if f.code == DONE:
                b = self._pass(rev, ng, tables[0], floor, gap, cap, every, bprof, deadline, cm,
                               backward_stop(fwd, tm))
            if b is not None and b.code == DONE:
                j = join(fwd, f, b, tm, target=floor + gap, keep=collect, deadline=deadline,
                         sig=sig)
                # move the split towards the half that made fewer labels (Tilk et al. 2017)
                lean = (b.labels - f.labels) / max(1, b.labels + f.labels)
                self.split = min(0.9, max(0.1, self.split + SPLIT_STEP * lean))
                self.stats["joins"] = self.stats.get("joins", 0.0) + 1
                found += zip(j.values, j.paths, strict=True)
            found.sort(key=lambda r: -r[0])
            paths = [tuple(int(idx[v]) for v in p) for _, p in found[:collect]]
            values = [v for v, _ in found[:collect]]
            if b is None or b.code != DONE or j.code != DONE:
                return Priced(paths, values, None)
            relaxed = sorted(((float(f.lp[s]), f.path(s)) for s in f.sinks.tolist()),
                             key=lambda r: -r[0])
            upper = max([floor + gap, j.upper, *(v for v, _ in found), *(v for v, _ in relaxed)])
            loops = [p for _, p in relaxed[:PATHS_PER_PASS]] + j.relaxed[:PATHS_PER_PASS]
            if paths or not loops:
                return Priced(paths, values, upper)
            for p in loops:
                self._forbid(ng, idx, p)

    def _tables(self, fwd: Core, rev: Core, floor: float, gap: float, cap: int,
                bprof: NDArray[np.float64], deadline: Deadline
                ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """With :attr:`half_tables`, a table pass each way (:meth:`_table`): each bounds the
        completions of the other way's half pass, which then prunes the labels no path above
        the floor can extend (Righini & Salani 2006 §3); ``None`` where the option is off."""
        if not self.half_tables or self.table_ng is None:
            return None, None
        return (self._table(fwd, fwd, floor, gap, cap, bprof, deadline),
                self._table(fwd, rev, floor, gap, cap, bprof, deadline))

    def _table(self, fwd: Core, core: Core, floor: float, gap: float, cap: int,
               bprof: NDArray[np.float64], deadline: Deadline) -> NDArray[np.float64] | None:
        """The profit table of a whole pass on ``core`` with ``table_ng``-sets of ``fwd``'s
        vertices (no cuts, learned cycles ignored), a bound on every completion; ``None`` if
        the pass did not finish."""
        assert self.table_ng is not None
        small = base_ng(fwd) | initial_ng(fwd, self.table_ng)
        out = self._pass(core, small, None, floor, gap, cap, 1 << 62, bprof, deadline)
        self.stats["table_passes"] = self.stats.get("table_passes", 0.0) + 1
        return out.table() if out.code == DONE else None

    def graphs(self, dur: NDArray[np.int64], prof: NDArray[np.float64],
               forbidden: frozenset[int]
               ) -> tuple[Core, Core, NDArray[np.intp], NDArray[np.uint64]]:
        """A node's forward and backward graphs on every customer it allows (none dropped),
        their vertices and the pricing's ng-sets on them (learned cycles included): what route
        enumeration and arc fixing run on."""
        keep = np.ones(self.fwd.n, dtype=bool)
        keep[list(forbidden)] = False
        idx = np.flatnonzero(keep)
        fwd, rev = self._cores(dur, prof, idx)
        return fwd, rev, idx, self._ng(fwd, idx)

    def completion_table(self, dur: NDArray[np.int64], prof: NDArray[np.float64], floor: float,
                         *, forbidden: frozenset[int], cap: int, deadline: Deadline
                         ) -> tuple[Core, NDArray[np.intp], NDArray[np.float64] | None]:
        """The node's forward graph and its vertices (:meth:`graphs`), and the profit table of
        a backward pass on the pricing's ng-sets without cuts (cut states weaken dominance so
        much that such a pass costs more than the enumeration it would prune) pruned at
        ``floor``: a bound on the completions of any path that can still reach it (``None``
        when the pass did not finish)."""
        fwd, rev, idx, ng = self.graphs(dur, prof, forbidden)
        out = self.bound_pass(rev, ng, floor, cap, deadline)
        return fwd, idx, out.table() if out.code == DONE else None

    def bound_pass(self, core: Core, ng: NDArray[np.uint64], floor: float, cap: int,
                   deadline: Deadline) -> PassResult:
        """A whole pass on ``core`` (a graph of :meth:`graphs`) with the ng-sets ``ng``, no
        cuts, every label kept that can reach ``floor``: its profit tables bound every path
        through a vertex at a time, for enumeration and arc fixing."""
        return self._pass(core, ng, None, floor, 0.0, cap, 1 << 62, np.maximum(core.prof, 0.0),
                          deadline)

    def _ng(self, fwd: Core, idx: NDArray[np.intp]) -> NDArray[np.uint64]:
        """The ng-sets of exact pricing on the vertices ``idx``: every customer when they are
        few, else the nearest ones, and the cycles learned so far."""
        full = fwd.n - 2 <= FULL_MEMORY
        ng = base_ng(fwd) | initial_ng(fwd, fwd.n if full else self.ng_size)
        return ng | _pack(self.memory[np.ix_(idx, idx)])

    def _cores(self, dur: NDArray[np.int64], prof: NDArray[np.float64],
               idx: NDArray[np.intp]) -> tuple[Core, Core]:
        """Forward and reversed core graphs on the vertices ``idx`` (source and sink kept)."""
        d = np.ascontiguousarray(dur[np.ix_(idx, idx)])
        f = self.fwd
        p = np.ascontiguousarray(prof[idx], dtype=np.float64)
        p[0] = p[-1] = 0.0
        return core_pair(d, f.opn[idx], f.cls[idx], p, 0, idx.size - 1, f.horizon)

    def _forbid(self, ng: NDArray[np.uint64], idx: NDArray[np.intp], path: list[int]) -> None:
        """Forbid each cycle ``i … i`` of ``path`` (sub-graph vertices) in ``ng`` and in the
        learned memory (Martinelli, Pecin & Poggi 2014)."""
        pairs: list[tuple[int, int]] = []
        forbid_cycles(ng, path, pairs)
        for u, v in pairs:
            self.memory[idx[u], idx[v]] = True
