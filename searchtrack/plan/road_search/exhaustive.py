"""The paper's exhaustive receding-horizon controller (Moore et al. 2021, §4.2): every path of
``L`` edges, the best one for the fixed draws.

One UAV: the whole tree of ``d^L`` paths (:func:`~searchtrack.plan.road_search.tree.search`),
``OPTIMAL``. Several UAVs: every joint choice of paths, ``OPTIMAL``, when ``Π_q n_q · G`` (paths
per UAV times particle groups) is at most :data:`MAX_JOINT_WORK` and one UAV's leaves fit in
:data:`MAX_LEAF_FLOATS`; otherwise each UAV in turn takes its best path given the particles the
earlier ones see (sequential, with consumption), then each re-plans against all the others
until nothing improves; that is ``FEASIBLE`` with the upper bound of
:meth:`~searchtrack.plan.road_search.scenario.Scenario.upper_bound`.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem, meets_bound
from searchtrack.plan.road_search.scenario import Scenario
from searchtrack.plan.road_search.tree import all_leaves, path_count, search

#: Largest ``Π_q n_q · G`` the joint enumeration of several UAVs takes on.
MAX_JOINT_WORK = 50_000_000

#: Largest ``n_q · G`` (floats) one UAV's leaves may hold in the joint enumeration.
MAX_LEAF_FLOATS = 1 << 23

#: Largest number of paths per UAV the exhaustive backend accepts (``supports``).
MAX_PATHS = 20_000_000


def supports_exhaustive(problem: RoadSearchProblem) -> str | None:
    """``None`` when every UAV has at most :data:`MAX_PATHS` paths, else the reason."""
    counts = [path_count(lat) for lat in problem.scenario.lattices]
    if max(counts) > MAX_PATHS:
        return f"{max(counts)} paths per UAV exceed {MAX_PATHS}; use beam or exact"
    return None


def sequential(scenario: Scenario, deadline: Deadline, width: int | None,
               passes: int) -> tuple[list[IntArray] | None, bool, bool]:
    """Each UAV's best path (beam of ``width``, or exhaustive) given the earlier UAVs' elements,
    then up to ``passes − 1`` rounds in which each re-plans against all the others. Returns the
    arcs per UAV (``None`` if the time ran out first), whether every search completed, whether
    any pruned."""
    n = len(scenario.lattices)
    arcs: list[IntArray] = []
    covs: list[FloatArray] = []
    complete, pruned = True, False
    zero = np.zeros(scenario.n_groups)
    for q in range(n):
        base = np.max(np.stack([zero, *covs]), axis=0)
        found = search(scenario, q, base, deadline, width=width)
        if found.arcs is None:
            return None, False, True
        complete &= found.complete
        pruned |= found.pruned
        arcs.append(found.arcs)
        covs.append(scenario.coverage(scenario.lattices[q].arc_element[found.arcs]))
    total = float(scenario.value_of(np.max(np.stack(covs), axis=0)))
    for _ in range(passes - 1 if n > 1 else 0):
        improved = False
        for q in range(n):
            base = np.max(np.stack([zero, *covs[:q], *covs[q + 1:]]), axis=0)
            found = search(scenario, q, base, deadline, width=width)
            if found.arcs is None or deadline.expired():
                return arcs, False, pruned
            if found.value > total + 1e-12 * max(1.0, total):
                arcs[q] = found.arcs
                covs[q] = scenario.coverage(scenario.lattices[q].arc_element[found.arcs])
                total = float(scenario.value_of(np.max(np.stack(covs), axis=0)))
                improved = True
        if not improved:
            break
    return arcs, complete, pruned


def _joint(scenario: Scenario, deadline: Deadline) -> tuple[list[IntArray] | None, bool]:
    """Every joint choice of paths; the best (first in enumeration order) and whether done."""
    leaves = [all_leaves(scenario, q, deadline) for q in range(len(scenario.lattices))]
    if any(arcs.shape[0] == 0 for arcs, _ in leaves):
        return None, False
    *heads, (_, last_cov) = leaves
    best_value, best_pick = -math.inf, None
    done = True
    for count, pick in enumerate(itertools.product(*(range(a.shape[0]) for a, _ in heads))):
        if count % 16 == 0 and deadline.expired():
            done = False
            break
        cov = np.max(np.stack([c[i] for (_, c), i in zip(heads, pick, strict=True)]), axis=0)
        values = scenario.value_of(np.maximum(last_cov, cov[None, :]))
        j = int(np.argmax(values))
        if values[j] > best_value:
            best_value, best_pick = float(values[j]), (*pick, j)
    if best_pick is None:
        return None, False
    return [a[i] for (a, _), i in zip(leaves, best_pick, strict=True)], done


def joint_work(scenario: Scenario) -> int:
    """``Π_q n_q · G``: the work of the joint enumeration."""
    return math.prod(path_count(lat) for lat in scenario.lattices) * max(1, scenario.n_groups)


def solve_exhaustive(problem: RoadSearchProblem, *, time_limit_s: float = 10.0,
                     seed: int = 0) -> Result[RoadPlan]:
    """Score every path (every joint choice for several UAVs when small enough, else
    sequential); ``OPTIMAL`` for the fixed draws when the enumeration is complete. ``seed`` is
    unused (the search is deterministic)."""
    del seed
    deadline = Deadline(time_limit_s)
    sc = problem.scenario
    bound = sc.upper_bound()
    n = problem.n_uavs
    if n == 1:
        found = search(sc, 0, np.zeros(sc.n_groups), deadline)
        arcs = None if found.arcs is None else [found.arcs]
        proven, how = found.complete, "enumerated every path"
    elif joint_work(sc) <= MAX_JOINT_WORK and max(
            path_count(lat) for lat in sc.lattices) * sc.n_groups <= MAX_LEAF_FLOATS:
        arcs, proven = _joint(sc, deadline)
        how = "enumerated every joint choice"
    else:
        arcs, _, _ = sequential(sc, deadline, None, passes=3)
        proven, how = False, "sequential: each UAV's best path given the others"
    if arcs is None:
        return Result(Status.NO_SOLUTION, None, bound, deadline.elapsed(), "exhaustive", None,
                      message="exhaustive: time limit before any complete path")
    plan = sc.plan_of(arcs)
    value = sc.score(plan)
    optimal = proven or meets_bound(value, bound)
    if not proven and deadline.expired():
        how = "stopped at the time limit"
    return Result(Status.OPTIMAL if optimal else Status.FEASIBLE, value,
                  value if optimal else bound, deadline.elapsed(), "exhaustive", plan,
                  message=f"exhaustive: {how}")
