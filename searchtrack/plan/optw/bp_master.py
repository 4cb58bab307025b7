"""Restricted master problem of the team-OPTW branch-and-price (Boussier, Feillet & Gendreau 2007).

Set packing over route columns, as a linear program solved by HiGHS's dual simplex (Huangfu &
Hall 2018)::

    max  Σ_r c_r λ_r
    s.t. Σ_r a_ir λ_r ≤ 1   (= 1 when customer i is required by a branch)   duals π_i
         Σ_r λ_r      ≤ m   (= m when the empty route is infeasible)       dual  μ
         Σ_r α_cr λ_r ≤ 1   for each subset-row cut c                      dual  σ_c
         λ ≥ 0

Customers are the vertices ``1 … n − 2`` of the labelling core graph
(:func:`searchtrack.plan.optw.labelling_core.build_cores`); a column is a feasible elementary
core path ``src → … → snk``. Every row also has an artificial variable of profit ``−M``
(bounded to 0 unless the row is an equality), so the RMP is always feasible; it only restricts
the duals (``π_i ≥ −M``), so every Lagrangian bound computed from them stays valid.

Branching restricts the master by bounds only: a column a node forbids gets upper bound 0, a
required customer's row gets lower bound 1. HiGHS keeps its basis across these changes and across
added columns and rows, so each solve starts from the last optimum (OR-Tools' GLOP, through
``pywraplp``, re-solves from scratch after a bound change). Subset-row cuts
(:mod:`searchtrack.plan.optw.bp_cuts`) are rows added by :meth:`Master.add_cuts`, valid at
every node.
"""

from __future__ import annotations

import itertools
import logging
import time
from collections.abc import Iterable
from dataclasses import dataclass, field

import highspy
import numpy as np
from highspy._core import _Highs
from numpy.typing import NDArray

from searchtrack.plan.optw.bp_cuts import SubsetRowCut

log = logging.getLogger("searchtrack.plan.optw.bp")

Path = tuple[int, ...]
Arc = tuple[int, int]


@dataclass(frozen=True)
class Restrictions:
    """The branching decisions of a node, on core vertices and arcs."""

    forbidden: frozenset[int] = frozenset()
    required: frozenset[int] = frozenset()
    no_arcs: frozenset[Arc] = frozenset()
    arcs: frozenset[Arc] = frozenset()  # forced: i → j is the only way out of i and into j

    def child(self, *, forbid: int | None = None, require: int | None = None,
              no_arc: Arc | None = None, arc: Arc | None = None) -> Restrictions:
        """These restrictions plus one more decision."""
        return Restrictions(
            self.forbidden | ({forbid} if forbid is not None else set()),
            self.required | ({require} if require is not None else set()),
            self.no_arcs | ({no_arc} if no_arc is not None else set()),
            self.arcs | ({arc} if arc is not None else set()),
        )

    def allows(self, path: Path, src: int, snk: int) -> bool:
        """True when the core path ``path`` (``src`` … ``snk``) obeys every decision."""
        if any(v in self.forbidden for v in path[1:-1]):
            return False
        steps = set(itertools.pairwise(path))
        if steps & self.no_arcs:
            return False
        for i, j in self.arcs:
            out = [b for a, b in steps if a == i]
            inn = [a for a, b in steps if b == j]
            if i != src and out and out[0] != j:
                return False
            if j != snk and inn and inn[0] != i:
                return False
        return True


@dataclass
class LPSolution:
    """One RMP optimum: objective, column values and the duals."""

    objective: float
    values: NDArray[np.float64]
    pi: NDArray[np.float64]  # by core vertex (0 at src and snk)
    mu: float
    sigma: NDArray[np.float64]  # by cut, ≥ 0
    artificial: float  # total artificial activity (> 0: the node looks infeasible)


_INF = highspy.kHighsInf
_NONE = np.zeros(0, dtype=np.int32)


@dataclass
class Master:
    """The RMP over a growing pool of columns, shared by every node of the tree.

    Rows ``0 … n − 1`` are the core vertices (those of the source and the sink stay empty), row
    ``n`` the fleet, then one row per cut; the LP's first ``n − 1`` columns are the artificial
    variables (customers ``1 … n − 2``, then the fleet), then the pooled routes in pool order.

    Parameters
    ----------
    n
        Core vertices (source 0, customers ``1 … n − 2``, sink ``n − 1``).
    vehicles
        Routes ``m``.
    empty_ok
        Whether the empty route is feasible (then ``Σ λ ≤ m``, else ``= m``).
    penalty
        Profit ``M`` lost per unit of artificial variable.
    """

    n: int
    vehicles: int
    empty_ok: bool
    penalty: float
    paths: list[Path] = field(default_factory=list)
    profits: list[float] = field(default_factory=list)
    _known: dict[Path, int] = field(default_factory=dict)
    cuts: list[SubsetRowCut] = field(default_factory=list)
    failures: int = field(default=0, init=False)
    """Solves HiGHS did not finish at an optimum (each repeated from a fresh factorisation)."""

    def __post_init__(self) -> None:
        h = _Highs()  # the bare solver: highspy's wrapper logs a banner before any option is set
        h.setOptionValue("output_flag", False)
        h.setOptionValue("threads", 1)
        h.changeObjectiveSense(highspy.ObjSense.kMaximize)
        self.highs = h
        for _ in range(self.n):
            h.addRow(-_INF, 1.0, 0, _NONE, np.zeros(0))
        m = float(self.vehicles)
        h.addRow(-_INF if self.empty_ok else m, m, 0, _NONE, np.zeros(0))
        k = self.n - 1  # customer artificials, then the fleet's
        rows = np.append(np.arange(1, self.n - 1), self.n).astype(np.int32)
        upper = np.zeros(k)
        upper[-1] = 0.0 if self.empty_ok else m
        h.addCols(k, np.full(k, -self.penalty), np.zeros(k), upper, k,
                  np.arange(k, dtype=np.int32), rows, np.ones(k))
        self.upper = np.zeros(0)
        """Upper bound of each pooled column (0: the node forbids it)."""
        self.required: set[int] = set()
        """Customers whose row is an equality."""

    @property
    def size(self) -> int:
        """Columns in the pool."""
        return len(self.paths)

    def index(self, path: Path) -> int:
        """Position of the pooled column ``path`` in :attr:`paths`."""
        return self._known[path]

    def add(self, paths: Iterable[Path], profits: Iterable[float], allowed: bool = True) -> int:
        """Add the new ones of ``paths`` (core paths with their profit); return how many."""
        starts: list[int] = []
        index: list[int] = []
        value: list[float] = []
        cost: list[float] = []
        fleet = self.n
        for path, c in zip(paths, profits, strict=True):
            if path in self._known:
                continue
            starts.append(len(index))
            index.extend(path[1:-1])
            value.extend([1.0] * (len(path) - 2))
            index.append(fleet)
            value.append(1.0)
            for r, cut in enumerate(self.cuts):
                a = cut.coefficient(path)
                if a:
                    index.append(fleet + 1 + r)
                    value.append(float(a))
            self._known[path] = len(self.paths)
            self.paths.append(path)
            self.profits.append(float(c))
            cost.append(float(c))
        added = len(cost)
        if added:
            up = _INF if allowed else 0.0
            self.highs.addCols(added, np.array(cost), np.zeros(added), np.full(added, up),
                               len(index), np.array(starts, dtype=np.int32),
                               np.array(index, dtype=np.int32), np.array(value))
            self.upper = np.append(self.upper, np.full(added, up))
        return added

    def add_cuts(self, cuts: Iterable[SubsetRowCut]) -> int:
        """Add the cuts (rows ``≤ 1`` over the pooled columns); return how many."""
        added = 0
        first = self.n - 1
        for cut in cuts:
            cols: list[int] = []
            coef: list[float] = []
            for k, path in enumerate(self.paths):
                a = cut.coefficient(path)
                if a:
                    cols.append(first + k)
                    coef.append(float(a))
            self.highs.addRow(-_INF, 1.0, len(cols), np.array(cols, dtype=np.int32),
                              np.array(coef))
            self.cuts.append(cut)
            added += 1
        return added

    def cut_cost(self, path: Path, sigma: NDArray[np.float64]) -> float:
        """``Σ_c σ_c α_c(path)``: what the cuts take from the reduced profit of ``path``."""
        return float(sum(sigma[c] * cut.coefficient(path)
                         for c, cut in enumerate(self.cuts) if sigma[c] > 0.0))

    def set_upper(self, columns: NDArray[np.int64], upper: float) -> None:
        """Give the pooled ``columns`` the upper bound ``upper`` (0 or infinity)."""
        if columns.size:
            up = np.full(columns.size, upper)
            self.highs.changeColsBounds(columns.size, (columns + self.n - 1).astype(np.int32),
                                        np.zeros(columns.size), up)
            self.upper[columns] = upper

    def require(self, customer: int, on: bool) -> None:
        """Make the row of ``customer`` an equality (``on``) or ``≤ 1`` again."""
        if on == (customer in self.required):
            return
        self.highs.changeRowBounds(customer, 1.0 if on else -_INF, 1.0)
        self.highs.changeColBounds(customer - 1, 0.0, 1.0 if on else 0.0)
        if on:
            self.required.add(customer)
        else:
            self.required.discard(customer)

    def ruled_out(self, node: Restrictions) -> NDArray[np.bool_]:
        """For each pooled column, whether the decisions ``node`` forbid it."""
        if node.no_arcs or node.arcs:
            return np.array([not node.allows(path, 0, self.n - 1) for path in self.paths],
                            dtype=bool)
        if node.forbidden:  # a customer decision only: no need to look at the arcs
            return np.array([not node.forbidden.isdisjoint(path) for path in self.paths],
                            dtype=bool)
        return np.zeros(len(self.paths), dtype=bool)  # a required row rules no column out

    def restrict(self, node: Restrictions) -> None:
        """Bounds of the node ``node``: its forbidden columns at 0, its required rows at 1."""
        ok = ~self.ruled_out(node)
        up = np.where(ok, _INF, 0.0)
        changed = np.flatnonzero(up != self.upper)
        self.set_upper(changed[ok[changed]], _INF)
        self.set_upper(changed[~ok[changed]], 0.0)
        for i in self.required - node.required:
            self.require(i, False)
        for i in node.required:
            self.require(i, True)

    def solve(self, time_limit_s: float) -> LPSolution | None:
        """Solve the RMP; ``None`` when HiGHS stops before its optimum.

        HiGHS starts from the previous basis; a solve that ends without an optimum for any
        reason but the time limit is repeated once from a fresh factorisation of the same LP.
        """
        started = time.perf_counter()
        status = self._run(time_limit_s)
        if status not in (highspy.HighsModelStatus.kOptimal,
                          highspy.HighsModelStatus.kTimeLimit):
            log.warning("HiGHS: %s on the master (%d columns); solving it again from a fresh "
                        "factorisation", status, len(self.paths))
            self.failures += 1
            self.highs.clearSolver()
            status = self._run(time_limit_s - (time.perf_counter() - started))
        if status != highspy.HighsModelStatus.kOptimal:
            return None
        sol = self.highs.getSolution()
        col = np.asarray(sol.col_value, dtype=np.float64)
        dual = np.asarray(sol.row_dual, dtype=np.float64)
        k = self.n - 1
        pi = np.zeros(self.n)
        pi[1:-1] = dual[1:self.n - 1]
        # the Lagrangian bound needs π ≥ 0 on the "≤ 1" rows, μ ≥ 0 on a "≤ m" fleet row and
        # σ ≥ 0: clip what the solver's tolerances leave below 0 (equality rows keep their sign)
        free = pi < 0.0
        free[list(self.required)] = False
        pi[free] = 0.0
        mu = float(dual[self.n])
        mu = max(mu, 0.0) if self.empty_ok else mu
        sigma = np.maximum(dual[self.n + 1:], 0.0)
        objective = float(self.highs.getInfo().objective_function_value)
        return LPSolution(objective, col[k:].copy(), pi, mu, sigma, float(col[:k].sum()))

    def _run(self, seconds: float) -> highspy.HighsModelStatus:
        """One HiGHS run within ``seconds`` (its clock counts every run of the object)."""
        h = self.highs
        h.setOptionValue("time_limit", h.getRunTime() + max(seconds, 1e-3))
        h.run()
        return h.getModelStatus()

    def visits(self, values: NDArray[np.float64]) -> NDArray[np.float64]:
        """``Σ_r a_ir λ_r`` for every core vertex."""
        y = np.zeros(self.n)
        for k in np.flatnonzero(values > 1e-9).tolist():
            for i in self.paths[k][1:-1]:
                y[i] += values[k]
        return y

    def arc_flows(self, values: NDArray[np.float64]) -> dict[Arc, float]:
        """``x_ij = Σ_r λ_r`` over the columns using arc ``i → j``."""
        x: dict[Arc, float] = {}
        for k in np.flatnonzero(values > 1e-9).tolist():
            path = self.paths[k]
            for a in itertools.pairwise(path):
                x[a] = x.get(a, 0.0) + float(values[k])
        return x
