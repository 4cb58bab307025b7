"""Exact team OPTW by branch-and-price (Boussier, Feillet & Gendreau 2007).

* **Master** (:mod:`~searchtrack.plan.optw.bp_master`): set packing over routes, solved as a
  linear program by HiGHS from the last basis, columns added incrementally; first columns from
  the ILS plan, the ``initial`` plan and the feasible single-customer routes.
* **Plans** (:mod:`~searchtrack.plan.optw.bp_primal`): the ILS before the tree, and again from
  the incumbent when the root leaves a gap (:attr:`Tuning.ils_again_share`); CP-SAT on the
  pool's columns after the root and periodically; every integral master solution.
* **Pricing** (:mod:`~searchtrack.plan.optw.bp_pricing`): the ng/DSSR labelling on reduced
  profits ``p_i − π_i``, exact at every call and returning up to 200 columns; by default
  bidirectional (:attr:`Tuning.bidirectional`: half passes joined at a split time that follows
  the label counts, the best columns of each call returned). Duals are smoothed
  towards the best Lagrangian point (Wentges 1997); a mis-priced round is repeated at the
  master's own duals. A guided heuristic pass (:attr:`Tuning.heuristic_cap`) can run first; on
  the Solomon instances it found columns but more iterations, and more labels overall, than
  exact pricing alone, so it is off by default.
* **Bounds**: every completed pricing gives the Lagrangian bound ``Σ_i π_i + m · U`` (``U`` ≥ the
  best reduced profit of a route), valid for any duals of the right signs; a node's bound is the
  least of them. With integral profits it is rounded down to a multiple of their greatest
  common divisor (:func:`~searchtrack.plan.optw.instance.profit_step`; 10 on the Solomon c1
  instances), since every plan collects such a multiple. Column generation stops at a node
  once the rounded bound equals the rounded master value.
* **Cuts**: limited-memory 3-subset-row cuts (:mod:`~searchtrack.plan.optw.bp_cuts`; Jepsen
  et al. 2008, Pecin et al. 2017) separated once column generation has converged at the nodes
  up to :attr:`Tuning.cut_depth`, their duals priced into the labels; with them the bound is
  ``Σ_i π_i + Σ_c σ_c + m · U``.
* **Branching** (:mod:`~searchtrack.plan.optw.bp_branching`): on a customer's fractional visit,
  then on a fractional arc, chosen among :attr:`Tuning.strong` candidates by strong branching
  on the pooled master; best bound first.
* **Enumeration** (:mod:`~searchtrack.plan.optw.bp_enumeration`): once a node's gap is small,
  every route that can be part of a better plan is listed and a set packing settles the node.
  With :attr:`Tuning.fix_arcs` the arcs no such route uses are first fixed out of pricing at
  the root (:mod:`~searchtrack.plan.optw.bp_fixing`); off by default: on the Cordeau
  instances the arcs it fixes are those the pricing's completion bounds prune already.

A stopped solve reports its best plan with the largest bound of the open nodes.
"""

from __future__ import annotations

import heapq
import itertools
import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.result import Result
from searchtrack.plan.optw.bp_branching import branch
from searchtrack.plan.optw.bp_cuts import separate
from searchtrack.plan.optw.bp_enumeration import Duals, close_node
from searchtrack.plan.optw.bp_fixing import fix_arcs
from searchtrack.plan.optw.bp_master import LPSolution, Master, Path, Restrictions
from searchtrack.plan.optw.bp_pricing import Pricer, droppable
from searchtrack.plan.optw.bp_primal import ils_paths, plan_paths, pool_ip
from searchtrack.plan.optw.bp_result import result
from searchtrack.plan.optw.bp_tuning import Tuning
from searchtrack.plan.optw.instance import OPTWInstance, Routes, profit_step
from searchtrack.plan.optw.labelling_core import (
    BIG,
    CAP_MAX,
    Core,
    build_cores,
    feasible_path,
    instance_route,
)
from searchtrack.plan.optw.routes import idle_routes, initial_plan

__all__ = ["Tree", "Tuning", "solve_bp"]

log = logging.getLogger("searchtrack.plan.optw.bp")


_EPS = 1e-5  # least reduced profit of a new column


@dataclass(order=True)
class _Node:
    key: tuple[float, int, int]
    bound: float = field(compare=False)
    depth: int = field(compare=False)
    restr: Restrictions = field(compare=False)
    duals: Duals | None = field(default=None, compare=False)  # those of its least bound


@dataclass
class Tree:
    """The state of one branch-and-price run: instance, master, pricer, incumbent, stats."""

    inst: OPTWInstance
    fwd: Core
    orig: NDArray[np.int64]
    master: Master
    pricer: Pricer
    deadline: Deadline
    tuning: Tuning
    seed: int
    step: int  # every plan's profit is a multiple of it (0: profits not integral)
    value: float = -math.inf
    enum_failed: float = math.inf  # the gap at which route enumeration last failed
    best: list[Path] = field(default_factory=list)
    stats: dict[str, float] = field(default_factory=dict)

    def tick(self, key: str, since: float) -> None:
        self.stats[key] = self.stats.get(key, 0.0) + time.perf_counter() - since

    def rounded(self, bound: float) -> float:
        s = self.step
        return s * math.floor((bound + 1e-6) / s) if s else bound

    def pruned(self, bound: float) -> bool:
        """True when a node of this bound cannot beat the incumbent (or holds no plan)."""
        b = self.rounded(bound)
        if self.value == -math.inf:
            return b < -1e-6
        return b <= self.value + (0.0 if self.step else 1e-9 * max(1.0, abs(self.value)))

    def offer(self, paths: list[Path]) -> None:
        """Pool ``paths`` (disjoint feasible routes) and make them the incumbent if they collect
        more; ignored unless they are a whole plan (``m`` routes, or fewer when the empty route
        is feasible)."""
        if len(paths) != self.inst.vehicles and not self.master.empty_ok:
            return
        profits = [self.path_profit(p) for p in paths]
        self.master.add(paths, profits)
        value = float(sum(profits))
        if value > self.value + 1e-9:
            self.value, self.best = value, list(paths)
            log.debug("incumbent %g at %.2f s", value, self.deadline.elapsed())

    def path_profit(self, path: Path) -> float:
        return float(sum(float(self.inst.profit[self.orig[v]]) for v in path[1:-1]))

    def primal(self) -> None:
        """CP-SAT over the pool's columns."""
        t0 = time.perf_counter()
        limit = min(self.tuning.primal_s, 0.5 * self.deadline.remaining())
        if limit > 0.05:
            hint = [self.master.index(p) for p in self.best]
            chosen = pool_ip(self.master.paths, self.master.profits, self.inst.vehicles,
                             self.master.empty_ok, self.value, limit, self.seed, hint)
            if chosen is not None:
                self.offer([self.master.paths[k] for k in chosen])
        self.tick("heuristic_s", t0)

    def again(self) -> None:
        """The ILS from the incumbent, its plan offered (and its routes pooled)."""
        t, d = self.tuning, self.deadline
        seconds = min(t.ils_again_max_s, t.ils_again_share * (d.elapsed() + d.remaining()),
                      0.5 * d.remaining())
        if seconds < 0.05 or self.inst.customers.size == 0:
            return
        t0 = time.perf_counter()
        start = self.plan() if any(len(p) > 2 for p in self.best) else None
        paths = ils_paths(self.inst, self.fwd, self.orig, seconds=seconds, seed=self.seed + 1,
                          start=start, iterations=t.ils_again_iterations)
        if paths is not None:
            self.offer(paths)
        self.tick("heuristic_s", t0)

    def plan(self) -> Routes | None:
        """The incumbent as instance routes (idle routes added when the empty route is
        feasible); ``None`` before the first one."""
        if not self.best and self.value == -math.inf:
            return None
        routes = [instance_route(self.inst, self.orig, list(p)) for p in self.best if len(p) > 2]
        if self.master.empty_ok:
            return tuple(routes) + idle_routes(self.inst)[len(routes):]
        return tuple(routes)

    def column_generation(self, node: _Node) -> tuple[LPSolution | None, bool]:
        """Solve the node's master by column generation and tighten ``node.bound``; the last
        master solution (``None`` when the node is pruned or time ran out) and whether the
        node's bound is proven."""
        m, t = self.master, self.tuning
        t0 = time.perf_counter()
        m.restrict(node.restr)
        dur = self.pricer.node_dur(node.restr)
        drop = not node.restr.arcs and not node.restr.no_arcs
        self.tick("branching_s", t0)
        prof = np.zeros(self.fwd.n)
        prof[1:-1] = self.fwd.prof[1:-1]
        centre: tuple[NDArray[np.float64], float, NDArray[np.float64]] | None = None
        centre_bound = math.inf
        rounds = 0
        while True:
            if self.deadline.expired():
                return None, False
            t0 = time.perf_counter()
            lp = m.solve(self.deadline.remaining())
            self.tick("lp_s", t0)
            if lp is None:
                return None, False
            self.stats["cg_iterations"] = self.stats.get("cg_iterations", 0.0) + 1
            if self.pruned(node.bound):
                return None, True
            if self.step and self.rounded(node.bound) <= self.rounded(lp.objective):
                if self.cut(node, lp, rounds):
                    rounds, centre, centre_bound = rounds + 1, None, math.inf
                    continue
                return lp, True  # the rounded bound cannot fall further: branch here
            # the guided heuristic at the master's duals, then exact pricing at the smoothed
            # duals (Wentges 1997) and, if that mis-prices, at the master's duals
            points = [(lp.pi, lp.mu, lp.sigma, True)]
            if centre is not None and t.smoothing > 0:
                a = t.smoothing
                points.insert(0, (a * centre[0] + (1 - a) * lp.pi,
                                  a * centre[1] + (1 - a) * lp.mu,
                                  a * centre[2] + (1 - a) * lp.sigma, True))
            if t.heuristic_cap > 0:
                points.insert(0, (lp.pi, lp.mu, lp.sigma, False))
            added, proven = 0, False
            for pi, mu, sigma, exact in points:
                paths, upper = self.price(dur, prof - pi, mu, sigma, drop, node.restr.forbidden,
                                          exact)
                if upper is not None:
                    lag = float(pi[1:-1].sum() + sigma.sum()) + m.vehicles * upper
                    node.bound = min(node.bound, lag)
                    if node.duals is None or lag < node.duals.lagrangian:
                        node.duals = Duals(pi.copy(), sigma.copy(), upper, lag)
                    if lag < centre_bound:
                        centre_bound, centre = lag, (pi.copy(), upper, sigma.copy())
                gain = [self.path_profit(p) for p in paths]
                good = [(p, c) for p, c in zip(paths, gain, strict=True)
                        if c - float(lp.pi[list(p[1:-1])].sum()) - lp.mu
                        - m.cut_cost(p, lp.sigma) > _EPS]
                added = m.add([p for p, _ in good], [c for _, c in good])
                proven = upper is not None and pi is lp.pi and exact
                if added:
                    break
            if not added:
                if not proven and not self.deadline.expired():
                    log.warning("pricing stalled at %s", node.restr)
                if proven and self.cut(node, lp, rounds):
                    rounds, centre, centre_bound = rounds + 1, None, math.inf
                    continue
                return (lp, True) if proven else (None if self.deadline.expired() else lp, False)

    def cut(self, node: _Node, lp: LPSolution, rounds: int) -> bool:
        """Add the most violated subset-row cuts of the node's master solution; True if any."""
        t, m = self.tuning, self.master
        room = min(t.cuts_per_round, t.cuts_max - len(m.cuts))
        if room <= 0 or rounds >= t.cut_rounds or node.depth > t.cut_depth:
            return False
        t0 = time.perf_counter()
        new = separate(m.paths, lp.values, {c.subset for c in m.cuts}, most=room)
        added = m.add_cuts(new)
        self.stats["cuts"] = self.stats.get("cuts", 0.0) + added
        self.tick("cuts_s", t0)
        return added > 0

    def price(self, dur: NDArray[np.int64], prof: NDArray[np.float64], mu: float,
              sigma: NDArray[np.float64], drop: bool, forbidden: frozenset[int],
              exact: bool) -> tuple[list[Path], float | None]:
        """Columns above ``mu`` and, if proven, a bound on the best reduced profit + ``mu``."""
        t0 = time.perf_counter()
        t = self.tuning
        if not exact:
            got = self.pricer.guided(dur, prof, mu, _EPS, forbidden=forbidden, collect=t.collect,
                                     cap=t.heuristic_cap, deadline=self.deadline)
            self.tick("heuristic_pricing_s", t0)
            if got.paths:
                self.stats["heuristic_pricing_hits"] = self.stats.get(
                    "heuristic_pricing_hits", 0.0) + 1
        else:
            got = self.pricer.price(dur, prof, mu, _EPS, drop=drop, forbidden=forbidden,
                                    collect=t.collect, cap=CAP_MAX, deadline=self.deadline,
                                    cuts=self.master.cuts, sigma=sigma)
            self.stats["exact_pricing_calls"] = self.stats.get("exact_pricing_calls", 0.0) + 1
        self.tick("pricing_s", t0)
        return got.paths, got.upper


def solve_bp(instance: OPTWInstance, *, time_limit_s: float = 60.0, seed: int = 0,
             initial: Routes | None = None, tuning: Tuning | None = None) -> Result[Routes]:
    """Solve the team OPTW to proven optimality by branch-and-price (or to the time limit).

    Parameters
    ----------
    instance
        The instance (``instance.vehicles`` routes).
    time_limit_s
        Wall-clock limit for the heuristic start, the tree, the LPs and every pricing pass.
    seed
        Seed of the ILS start and of CP-SAT on the column pool.
    initial
        A feasible plan (at most ``m`` routes): its routes are first columns and its profit a
        lower bound.
    tuning
        The method's knobs (defaults: the measured best).

    Returns
    -------
    Result
        ``OPTIMAL`` when the tree is closed; ``FEASIBLE`` (or ``NO_SOLUTION``) with the largest
        bound of the open nodes when stopped by the limit or a stop request; ``INFEASIBLE`` when
        no ``m`` routes exist.

    Raises
    ------
    InvalidInputError
        If ``initial`` is not a feasible plan or the time limit is not positive.
    """
    deadline = Deadline(check_time_limit(time_limit_s))
    inst, t = instance, tuning or Tuning()
    start = None if initial is None else initial_plan(inst, initial)
    fwd, _, orig = build_cores(inst)
    empty_ok = bool(fwd.dur[fwd.src, fwd.snk] < BIG)
    total = float(fwd.prof.sum())
    master = Master(fwd.n, inst.vehicles, empty_ok, 100.0 * (total + 1.0))
    pricer = Pricer(fwd, droppable(inst, orig), table_ng=t.table_ng, guide=t.heuristic_cap > 0,
                    bidirectional=t.bidirectional, half_tables=t.half_tables)
    tree = Tree(inst, fwd, orig, master, pricer, deadline, t, seed, profit_step(fwd.prof))
    seeds = [] if start is None else [plan_paths(inst, fwd, orig, start)]
    if fwd.n > 2:
        t0 = time.perf_counter()
        share = max(0.02, min(t.ils_max_s, t.ils_share * time_limit_s))
        first = ils_paths(inst, fwd, orig, seconds=share, seed=seed, start=start,
                          iterations=t.ils_iterations)
        tree.tick("heuristic_s", t0)
        seeds += [] if first is None else [first]
    singles = [(0, c, fwd.n - 1) for c in range(1, fwd.n - 1)]
    columns: list[Path] = [p for p in singles if feasible_path(fwd, p)]
    columns += [(0, fwd.n - 1)] if empty_ok else []
    for good in seeds:
        columns += good
        tree.offer(good)
    master.add(columns, [tree.path_profit(p) for p in columns])
    root = _Node((-math.inf, 0, 0), total, 0, Restrictions())
    return _run(tree, root)


def _run(tree: Tree, root: _Node) -> Result[Routes]:
    deadline, t = tree.deadline, tree.tuning
    heap: list[_Node] = [root]
    counter = itertools.count(1)
    nodes = 0
    tree.stats["root_bound"] = tree.rounded(root.bound)  # until the root is solved
    tree.stats["root_s"] = deadline.elapsed()
    stuck: list[float] = []
    current: _Node | None = None
    while heap and not deadline.expired():
        current = heapq.heappop(heap)
        if tree.pruned(current.bound):
            current = None
            continue
        nodes += 1
        lp, proven = tree.column_generation(current)
        if nodes == 1:
            tree.stats["root_bound"] = tree.rounded(current.bound)
            tree.stats["root_s"] = deadline.elapsed()
        if lp is None and proven:
            current = None  # pruned
            continue
        if lp is None:
            if deadline.expired():
                break
            log.error("the master LP of node %d failed twice; the node stays open", nodes)
            stuck.append(current.bound)  # its bound still holds; the rest of the tree goes on
            current = None
            continue
        if nodes == 1 or nodes % t.primal_every == 0:
            tree.primal()
        if nodes == 1 and not tree.pruned(current.bound):
            tree.again()
        if (nodes == 1 and t.fix_arcs and current.duals is not None
                and not tree.pruned(current.bound)):
            fix_arcs(tree, current.duals)
        if tree.pruned(current.bound) or (
                current.duals is not None and close_node(tree, current.restr, current.duals)):
            current = None
            continue
        t0 = time.perf_counter()
        kids, probes = branch(tree.master, tree.fwd.prof, current.restr, lp,
                              most=t.strong, floor=tree.value, deadline=deadline)
        tree.stats["strong_lps"] = tree.stats.get("strong_lps", 0.0) + probes
        tree.tick("branching_s", t0)
        if kids is None:
            if lp.artificial <= 1e-6:
                chosen = np.flatnonzero(lp.values > 0.5).tolist()
                tree.offer([tree.master.paths[k] for k in chosen])
            if not proven and not tree.pruned(current.bound):
                stuck.append(current.bound)  # nothing left to branch on, bound not proven
            current = None
            continue
        for r in kids:
            b = current.bound
            heapq.heappush(heap, _Node((-tree.rounded(b), -(current.depth + 1), next(counter)),
                                       b, current.depth + 1, r))
        current = None
    open_bounds = [n.bound for n in heap] + stuck
    open_bounds += [] if current is None else [current.bound]
    return result(tree, nodes, open_bounds)
