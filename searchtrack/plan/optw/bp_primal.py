"""The primal side of the team-OPTW branch-and-price: plans, not bounds.

* :func:`ils_paths`: the iterated local search (:mod:`searchtrack.plan.optw.ils`) before the
  tree, and again from the incumbent once the root leaves a gap; its routes become columns and
  its plan an incumbent.
* :func:`pool_ip`: the restricted master's columns as an integer program, by CP-SAT;
  :func:`packing` the same with required customers and a proof flag, for the routes that
  :mod:`~searchtrack.plan.optw.bp_enumeration` lists.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence

import numpy as np
from numpy.typing import NDArray

from searchtrack.plan.optw.bp_master import Path
from searchtrack.plan.optw.instance import OPTWInstance, Routes
from searchtrack.plan.optw.labelling_core import Core, core_path, feasible_path


def ils_paths(inst: OPTWInstance, core: Core, orig: NDArray[np.int64], *, seconds: float,
              seed: int, start: Routes | None, iterations: int) -> list[Path] | None:
    """The ILS's plan (from ``start`` if given) as core paths, within ``seconds`` and
    ``iterations``; ``None`` when it found none. Routes of no customer are left out."""
    from searchtrack.plan.optw.ils import solve_ils

    res = solve_ils(inst, time_limit_s=seconds, seed=seed, initial=start,
                    max_iterations=iterations)
    if res.plan is None:
        return None
    return plan_paths(inst, core, orig, res.plan)


def plan_paths(inst: OPTWInstance, core: Core, orig: NDArray[np.int64],
               plan: Routes) -> list[Path]:
    """The routes of ``plan`` that visit a customer, as feasible core paths."""
    where = {int(v): c for c, v in enumerate(orig[1:-1].tolist(), start=1)}
    paths = [core_path(inst, where, r) for r in plan]
    return [p for p in paths if p is not None and feasible_path(core, p) and len(p) > 2]


def pool_ip(paths: Sequence[Path], profits: Sequence[float], vehicles: int, empty_ok: bool,
            floor: float, time_limit_s: float, seed: int,
            hint: Sequence[int] = ()) -> list[int] | None:
    """The best set of at most ``m`` disjoint pool columns (exactly ``m`` when the empty route is
    infeasible), by CP-SAT within ``time_limit_s``; ``None`` when none beats ``floor``.

    The restricted master's columns as an integer program: a cheap primal heuristic that often
    closes the gap of a branch-and-price on its own.
    """
    return packing(paths, profits, vehicles, empty_ok, floor, time_limit_s, seed, hint)[0]


def packing(paths: Sequence[Path], profits: Sequence[float], vehicles: int, empty_ok: bool,
            floor: float, time_limit_s: float, seed: int, hint: Sequence[int] = (),
            required: Collection[int] = ()) -> tuple[list[int] | None, bool]:
    """:func:`pool_ip` with the customers ``required`` served exactly once, and whether the
    answer is proven: the best packing (``None`` when none beats ``floor``) and True when
    CP-SAT proved it optimal, or proved that no packing beats ``floor``."""
    from ortools.sat.python import cp_model

    from searchtrack.core.interrupt import watch

    p = np.asarray(profits, dtype=np.float64)
    # the least power of ten that makes every profit whole keeps the weights exact (and a
    # proof a proof); otherwise six significant digits
    scale = next((10.0 ** k for k in range(7)
                  if np.allclose(p * 10.0 ** k, np.round(p * 10.0 ** k), rtol=0, atol=1e-6)),
                 None)
    exact = scale is not None
    scale = scale or 1e6 / max(1.0, float(p.max(initial=1.0)))
    weights = np.round(p * scale).astype(np.int64).tolist()
    model = cp_model.CpModel()
    x = [model.new_bool_var("") for _ in paths]
    cover: dict[int, list[cp_model.IntVar]] = {}
    for var, path in zip(x, paths, strict=True):
        for i in path[1:-1]:
            cover.setdefault(i, []).append(var)
    for i in required:
        if i not in cover:
            return None, True
    for i, vs in cover.items():
        if i in required:
            model.add_exactly_one(vs)
        elif len(vs) > 1:
            model.add_at_most_one(vs)
    if empty_ok:
        model.add(sum(x) <= vehicles)
    else:
        model.add(sum(x) == vehicles)
    model.maximize(cp_model.LinearExpr.weighted_sum(x, weights))
    for k in hint:
        model.add_hint(x[k], True)
    solver = cp_model.CpSolver()
    # deterministic time units (about seconds), so that a seed fixes the answer; the wall
    # clock only guards against a slow machine
    solver.parameters.max_deterministic_time = max(0.01, time_limit_s)
    solver.parameters.max_time_in_seconds = max(0.01, 2.0 * time_limit_s)
    solver.parameters.num_workers = 1
    solver.parameters.random_seed = seed
    solver.parameters.catch_sigint_signal = False
    with watch(solver.stop_search):
        status = solver.solve(model)
    if status == cp_model.INFEASIBLE:
        return None, True  # not even a plan
    if status not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None, False
    proven = status == cp_model.OPTIMAL and exact
    chosen = [k for k, var in enumerate(x) if solver.value(var)]
    if float(p[chosen].sum()) <= floor:
        return None, proven
    return chosen, proven
