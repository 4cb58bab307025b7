"""Exact single-vehicle OPTW by bounded labelling with ng/DSSR relaxation (Righini & Salani 2009).

The search runs *passes*. A pass is one labelling dynamic program
(:func:`searchtrack.plan.optw.labelling_core.run_pass`, shared with the branch-and-price pricing)
over a relaxation of the elementary path problem: a path may revisit a customer unless the
customer is in the label's ng-memory (Baldacci, Mingozzi & Roberti 2011: each customer remembers
its 8 nearest customers; with at most 16 customers, all).

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
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw import labelling_kernels as K
from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes
from searchtrack.plan.optw.labelling_core import (
    BIG,
    CAP_MAX,
    FULL_MEMORY,
    NG_SIZE,
    PATHS_PER_PASS,
    Core,
    base_ng,
    build_cores,
    forbid_cycles,
    initial_ng,
    instance_route,
    run_pass,
)

log = logging.getLogger("searchtrack.plan.optw.labelling")


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

    def step(self, direction: int) -> int | None:
        """Run one pass (0 forward, 1 backward); the kernel's stop code, or None if proven."""
        core = self.fwd if direction == 0 else self.rev
        out = run_pass(core, self.ng, self.tables[1 - direction], lb=self.lb, ub=self.upper,
                       gap=self.gap, cap=CAP_MAX, deadline=self.deadline)
        for key, value in zip(("passes", "labels", "expanded", "checks"),
                              (1, out.labels, out.pops, out.work), strict=True):
            self.stats[key] += float(value)
        if out.best >= 0 and out.lb > self.lb:
            path = out.path(out.best)
            self.lb = out.lb
            self.route = instance_route(self.inst, self.orig,
                                        path if direction == 0 else path[::-1])
        if out.code != K.DONE:
            return out.code
        # the non-elementary paths that beat the best route: their cycles are forbidden next
        lp = out.lp
        better = out.sinks[lp[out.sinks] >= self.lb + self.gap]
        relaxed = float(lp[better].max()) if better.size else -np.inf
        self.upper = min(self.upper, max(self.lb, relaxed))
        log.debug("pass %d (%s): %d labels, %d expanded, lb %g, relaxed %g, %.2f s",
                  int(self.stats["passes"]), "fwd" if direction == 0 else "bwd", out.labels,
                  out.pops, self.lb, relaxed, self.deadline.elapsed())
        if not better.size:
            return None
        added = 0
        for s in better[np.argsort(-lp[better], kind="stable")[:PATHS_PER_PASS]]:
            added += forbid_cycles(self.ng, out.path(int(s)))
        if not added:  # cannot happen (a forbidden cycle is gone); full memory is exact anyway
            log.warning("no cycle to forbid after pass %d: remembering every visit",
                        int(self.stats["passes"]))
            self.ng |= initial_ng(self.fwd, self.fwd.n)
        self.tables[direction] = out.table()
        return out.code


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
        ng_size = fwd.n if fwd.n - 2 <= FULL_MEMORY else NG_SIZE
    search = _Search(
        inst, fwd, rev, orig, ng=np.bitwise_or(base_ng(fwd), initial_ng(fwd, ng_size)),
        gap=_profit_gap(inst), lb=-np.inf, route=None, upper=float(fwd.prof.sum()),
        deadline=deadline,
    )
    if fwd.dur[fwd.src, fwd.snk] < BIG:
        search.lb, search.route = 0.0, instance_route(inst, orig, [fwd.src, fwd.snk])
    if start is not None and _collected(inst, start) > search.lb:
        search.lb, search.route = _collected(inst, start), start
    code = None
    direction = 0
    while search.lb + search.gap <= search.upper:
        code = search.step(direction)
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
