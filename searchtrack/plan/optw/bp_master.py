"""Restricted master problem of the team-OPTW branch-and-price (Boussier, Feillet & Gendreau 2007).

Set packing over route columns, as a linear program solved by OR-Tools GLOP::

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
required customer's row gets lower bound 1. GLOP keeps its basis across these changes and across
added columns. Subset-row cuts (:mod:`searchtrack.plan.optw.bp_cuts`) are rows added by
:meth:`Master.add_cuts`, valid at every node.
"""

from __future__ import annotations

import itertools
import logging
import time
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from ortools.linear_solver import linear_solver_pb2, pywraplp

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


@dataclass
class Master:
    """The RMP over a growing pool of columns, shared by every node of the tree.

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
    """Solves GLOP reported numerically troubled (each repeated in a fresh solver)."""

    def __post_init__(self) -> None:
        s = pywraplp.Solver.CreateSolver("GLOP")
        if s is None:  # pragma: no cover - GLOP ships with OR-Tools
            raise RuntimeError("OR-Tools GLOP is not available")
        self.solver = s
        inf = s.infinity()
        self.rows = [s.Constraint(-inf, 1.0) for _ in range(self.n)]
        m = float(self.vehicles)
        self.fleet = s.Constraint(-inf if self.empty_ok else m, m)
        self.objective = s.Objective()
        self.objective.SetMaximization()
        self.slack = []
        for i in range(1, self.n - 1):
            a = s.NumVar(0.0, 0.0, "")
            self.rows[i].SetCoefficient(a, 1.0)
            self.objective.SetCoefficient(a, -self.penalty)
            self.slack.append(a)
        self.fleet_slack = s.NumVar(0.0, 0.0 if self.empty_ok else m, "")
        self.fleet.SetCoefficient(self.fleet_slack, 1.0)
        self.objective.SetCoefficient(self.fleet_slack, -self.penalty)
        self.vars: list[pywraplp.Variable] = []
        self.cut_rows: list[pywraplp.Constraint] = []

    @property
    def size(self) -> int:
        """Columns in the pool."""
        return len(self.paths)

    def index(self, path: Path) -> int:
        """Position of the pooled column ``path`` in :attr:`paths`."""
        return self._known[path]

    def add(self, paths: Iterable[Path], profits: Iterable[float], allowed: bool = True) -> int:
        """Add the new ones of ``paths`` (core paths with their profit); return how many."""
        added = 0
        s = self.solver
        for path, c in zip(paths, profits, strict=True):
            if path in self._known:
                continue
            v = s.NumVar(0.0, s.infinity() if allowed else 0.0, "")
            for i in path[1:-1]:
                self.rows[i].SetCoefficient(v, 1.0)
            self.fleet.SetCoefficient(v, 1.0)
            for row, cut in zip(self.cut_rows, self.cuts, strict=True):
                a = cut.coefficient(path)
                if a:
                    row.SetCoefficient(v, float(a))
            self.objective.SetCoefficient(v, float(c))
            self._known[path] = len(self.paths)
            self.paths.append(path)
            self.profits.append(float(c))
            self.vars.append(v)
            added += 1
        return added

    def add_cuts(self, cuts: Iterable[SubsetRowCut]) -> int:
        """Add the cuts (rows ``≤ 1`` over the pooled columns); return how many."""
        s = self.solver
        added = 0
        for cut in cuts:
            row = s.Constraint(-s.infinity(), 1.0)
            for v, path in zip(self.vars, self.paths, strict=True):
                a = cut.coefficient(path)
                if a:
                    row.SetCoefficient(v, float(a))
            self.cuts.append(cut)
            self.cut_rows.append(row)
            added += 1
        return added

    def cut_cost(self, path: Path, sigma: NDArray[np.float64]) -> float:
        """``Σ_c σ_c α_c(path)``: what the cuts take from the reduced profit of ``path``."""
        return float(sum(sigma[c] * cut.coefficient(path)
                         for c, cut in enumerate(self.cuts) if sigma[c] > 0.0))

    def restrict(self, node: Restrictions) -> None:
        """Bounds of the node ``node``: its forbidden columns at 0, its required rows at 1."""
        inf = self.solver.infinity()
        src, snk = 0, self.n - 1
        simple = not node.no_arcs and not node.arcs
        for v, path in zip(self.vars, self.paths, strict=True):
            if simple:
                ok = not any(i in node.forbidden for i in path[1:-1])
            else:
                ok = node.allows(path, src, snk)
            v.SetUb(inf if ok else 0.0)
        for i in range(1, self.n - 1):
            req = i in node.required
            self.rows[i].SetLb(1.0 if req else -inf)
            self.slack[i - 1].SetUb(1.0 if req else 0.0)

    def solve(self, time_limit_s: float) -> LPSolution | None:
        """Solve the RMP; ``None`` when GLOP stops before its optimum.

        GLOP warm-starts from the previous basis; when it reports numerical trouble
        (``ABNORMAL``, seen after thousands of columns and many bound changes, on an RMP that a
        fresh GLOP solves at once) the RMP is rebuilt in a new solver and solved again.
        """
        s = self.solver
        started = time.perf_counter()
        s.SetTimeLimit(max(1, int(1000 * time_limit_s)))
        status = s.Solve()
        if status == pywraplp.Solver.ABNORMAL:
            log.warning("GLOP: numerical trouble on the master (%d columns); solving it again "
                        "in a fresh solver", len(self.vars))
            self.failures += 1
            s = self._rebuild()
            left = time_limit_s - (time.perf_counter() - started)
            s.SetTimeLimit(max(1, int(1000 * left)))
            status = s.Solve()
        if status != pywraplp.Solver.OPTIMAL:
            return None
        values = np.array([v.solution_value() for v in self.vars], dtype=np.float64)
        pi = np.zeros(self.n)
        pi[1:-1] = [self.rows[i].dual_value() for i in range(1, self.n - 1)]
        art = sum(a.solution_value() for a in self.slack) + self.fleet_slack.solution_value()
        sigma = np.maximum(np.array([r.dual_value() for r in self.cut_rows], dtype=np.float64),
                           0.0)
        return LPSolution(self.objective.Value(), values, pi, self.fleet.dual_value(), sigma,
                          art)

    def _rebuild(self) -> pywraplp.Solver:
        """Move the RMP into a fresh GLOP (same rows, columns, bounds and objective) and
        rebind the handles; return the new solver."""
        proto = linear_solver_pb2.MPModelProto()
        self.solver.ExportModelToProto(proto)
        s = pywraplp.Solver.CreateSolver("GLOP")
        error = s.LoadModelFromProto(proto)
        if error:  # pragma: no cover - a model GLOP itself exported
            raise RuntimeError(f"GLOP could not reload the master: {error}")
        rows, columns = s.constraints(), s.variables()
        k = self.n - 2  # customer slacks, then the fleet slack, then the route columns
        self.rows, self.fleet = rows[:self.n], rows[self.n]
        self.cut_rows = rows[self.n + 1:]
        self.slack, self.fleet_slack, self.vars = columns[:k], columns[k], columns[k + 1:]
        self.solver, self.objective = s, s.Objective()
        return s

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
