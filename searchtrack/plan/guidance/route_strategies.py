"""Strategies that plan the search as an orienteering problem (this library's, beside the thesis
001 Ch. 5 strategies of :mod:`~searchtrack.plan.guidance.strategies`).

Each is a thesis strategy whose searching UAVs fly OPTW routes over the search field's mass
(:mod:`~searchtrack.plan.guidance.search_routes`; within a footprint radius of a live tracker's
peak only its unexplained part, the positive evidence being the tracked target's) instead of
climbing its gradient (5.12):

- ``route_search``: every UAV searches so, as (5.12);
- ``route_loiter``: paired UAVs loiter over their tracker's peak (5.15);
- ``route_search_and_loiter``: paired UAVs loiter while their peak is ≤ ``ϱ`` (5.16);
- ``route_search_and_reacquire``: as ``route_search_and_loiter``, but a fading tracker's UAV
  flies its reacquisition route (5.33), exactly as search-and-reacquire;
- ``route_partition_search``, ``route_partition_loiter``: as ``route_search`` and
  ``route_loiter``, but the searching UAVs split the mass by a balanced partition and value
  time in their prizes (:mod:`~searchtrack.plan.guidance.search_partition`): a UAV that plans
  sees only the cells it owns, each worth its mass discounted by the earliest arrival, and
  when none lies within the look-ahead it doubles the look-ahead (a few times) to reach them.

The rule's paired UAVs are held exactly as in the thesis strategy. A UAV the rule leaves
searching keeps its :class:`~searchtrack.plan.guidance.search_routes.SearchRoute` (mode
``"route"``: ∇W toward the route's first node, ∇P from every UAV) until it comes within
``search_serve_m`` of that node or the route is ``search_replan_s`` old; then it plans again,
with the look-ahead ``search_horizon_s`` as the OPTW's time budget. The UAVs that plan in the
same step do so one after another, in index order, each leaving out the cells of the nodes of
the other UAVs' routes (those kept and those planned before it): the prizes of the earlier
routes are taken (the family's team OPTW sends every route from one start vertex, while each
UAV starts where it is). The OPTW is solved by the family's iterated local search
(:func:`~searchtrack.plan.optw.ils.solve_ils`) for ``search_iterations`` iterations, its answer
checked by the family's validator. A UAV whose plan is empty (nothing with mass within reach,
or no plan within the time limit) searches by the gradient (5.12) this step and plans again at
the next.

The plans of one step (reacquisition first, then search) share ``time_limit_s``: each OPTW
solve gets an equal share of what is left among the plans still to make (at least 1 ms).
Randomness comes from ``numpy.random.default_rng(seed)``: one OPTW seed per route planned, then
the gradient's tie-break. The answer is deterministic for a seed as long as each OPTW solve
finishes within its share (as for search-and-reacquire; the search solves run a fixed number
of iterations, well within it). The objective is the tracker probability the plan sets out to
cover, as for the thesis strategies (search routes add nothing to it).
"""

from __future__ import annotations

import logging

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.core.registry import MAX_SEED, SolveFn
from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.plan.guidance.pairing import pair_checked
from searchtrack.plan.guidance.problem import GuidanceProblem
from searchtrack.plan.guidance.search_partition import balanced_partition
from searchtrack.plan.guidance.search_routes import (
    SearchRoute,
    near_peaks,
    search_instance,
    search_mass,
)
from searchtrack.plan.guidance.strategies import (
    ModeRule,
    answer,
    assemble,
    loiter_modes,
    peak_anchors,
    reacquire_fading,
    search_and_loiter_modes,
    search_modes,
)
from searchtrack.plan.guidance.view import Guidance, Reacquisition
from searchtrack.plan.optw.solve import solve_ils_capped, warm_up

log = logging.getLogger("searchtrack.plan.guidance.route_strategies")

#: The partitioned strategies double a UAV's look-ahead at most this many times to reach its
#: part of the partition.
REACH_DOUBLINGS = 3
#: The least share of the heaviest cell's mass a cell holds to be partitioned (the search
#: OPTW's ``min_share``).
MIN_SHARE = 1e-3


def plan_search(problem: GuidanceProblem, uav: int, mass: FloatArray, claimed: list[int],
                rng: np.random.Generator, budget: Deadline, waiting: int,
                keep: NDArray[np.bool_] | None = None) -> tuple[int, ...]:
    """Plan ``uav``'s search route over the field's ``mass``, leaving out the cells of the
    ``claimed`` nodes; the OPTW gets an equal share of what is left of ``budget`` among the
    ``waiting`` plans still to make (this one included). Empty when nothing is planned.

    With ``keep`` (the cells of the UAV's part of the partition) the prizes are discounted by
    the earliest arrival (``search_discount_s``) and only the kept cells are candidates; when
    none lies within the look-ahead, the look-ahead is doubled (up to
    :data:`REACH_DOUBLINGS` times) until one does."""
    cfg, view = problem.config, problem.view
    horizon = cfg.search_horizon_s
    for _ in range(1 + (REACH_DOUBLINGS if keep is not None else 0)):
        inst, node_ids = search_instance(
            problem.search_cells, mass, view.uav_xy_m[uav], cfg.speed_mps, horizon,
            max_nodes=cfg.search_route_nodes, serve_m=cfg.serve_m, exclude=claimed, keep=keep,
            discount_s=None if keep is None else cfg.search_discount_s)
        if inst.n > 1:
            break
        horizon *= 2.0
    seed = int(rng.integers(0, MAX_SEED))
    if inst.n == 1:
        return ()
    warm_up("ils")  # before the share is taken: a first compile does not eat the budget
    result = solve_ils_capped(inst, time_limit_s=max(1e-3, budget.remaining() / waiting),
                              seed=seed, max_iterations=cfg.search_iterations)
    nodes = () if not result.plan else tuple(int(node_ids[v]) for v in result.plan[0]
                                             if v != inst.start)
    log.debug("uav %d: %d candidate cells, %s search route of %d nodes (%.3g)", uav, inst.n - 1,
              result.status.name, len(nodes), result.objective or 0.0)
    return nodes


def partition_cells(problem: GuidanceProblem, mass: FloatArray, searchers: list[int]
                    ) -> dict[int, NDArray[np.bool_]]:
    """Per searching UAV, the cells it owns: the cells holding at least the search OPTW's
    least share of the heaviest cell's mass, split by
    :func:`~searchtrack.plan.guidance.search_partition.balanced_partition` among the
    ``searchers`` where they are now."""
    cells = problem.search_cells
    total, vertex = cells.prizes(mass)
    massive = np.flatnonzero((total > 0.0) & (total >= MIN_SHARE * total.max()))
    owner = balanced_partition(problem.view.network.coords[vertex[massive]], total[massive],
                               problem.view.uav_xy_m[searchers])
    owned = {}
    for i, j in enumerate(searchers):
        keep = np.zeros(cells.n_cells, dtype=bool)
        keep[massive[owner == i]] = True
        owned[j] = keep
    return owned


def route_search(rule: ModeRule, name: str, *, reacquire: bool = False,
                 partitioned: bool = False) -> SolveFn[GuidanceProblem, Guidance]:
    """The backend that holds the UAVs ``rule`` pairs as the thesis strategy does (and, with
    ``reacquire``, flies fading trackers' reacquisition routes) while the others fly search
    routes (module docstring); with ``partitioned``, over their part of the partition with
    discounted prizes (:mod:`~searchtrack.plan.guidance.search_partition`)."""

    def solve(problem: GuidanceProblem, *, time_limit_s: float, seed: int) -> Result[Guidance]:
        clock = Deadline(time_limit_s)
        rng = np.random.default_rng(seed)
        view, cfg = problem.view, problem.config
        pairing = pair_checked(view.network, view.uav_xy_m, view.bank)
        modes = rule(problem, pairing)
        anchors = peak_anchors(view, pairing)
        routes: list[tuple[int, ...]] = [()] * view.n_uavs
        searching = [j for j, m in enumerate(modes) if m == "search"]
        kept = {r.uav: r for r in problem.search_routes if r.uav in searching}
        due = [j for j in searching
               if j not in kept or kept[j].due(view.network, view.uav_xy_m, view.time_s,
                                               cfg.serve_m, cfg.search_replan_s)]
        for j in due:
            kept.pop(j, None)
        budget = Deadline(time_limit_s)  # one budget per step, shared
        reacquisitions: tuple[Reacquisition, ...] = ()
        plans = 0
        if reacquire:
            reacquisitions, plans = reacquire_fading(problem, pairing, modes, anchors, routes,
                                                     rng, budget, later=len(due))
        mass = None
        if due:
            peaks = [view.bank[t].peak_node() for t in range(len(view.bank))]
            mass = search_mass(view.field, near_peaks(view.network, peaks, cfg.sensor_range_m))
        owned = partition_cells(problem, mass, searching) if partitioned and mass is not None \
            else {}
        for k, j in enumerate(due):
            assert mass is not None
            claimed = [v for r in kept.values() for v in r.nodes]
            nodes = plan_search(problem, j, mass, claimed, rng, budget, len(due) - k,
                                owned.get(j))
            if nodes:
                kept[j] = SearchRoute(j, nodes, view.time_s)
        plans += len(due)
        plan_s = budget.elapsed() if plans else 0.0
        for j, route in kept.items():
            modes[j] = "route"
            anchors[j] = view.network.coords[route.nodes[0]]
            routes[j] = route.nodes
        force = assemble(problem, rng, modes, anchors, pairing)
        guidance = Guidance(force, pairing, tuple(modes), tuple(routes), 1000.0 * plan_s,
                            reacquisitions, tuple(kept[j] for j in sorted(kept)))
        return answer(problem, guidance, name, clock, plans)

    solve.__name__ = f"solve_{name}"
    solve.__doc__ = (f"The ``{name}`` backend: searching UAVs fly OPTW search routes; "
                     f"{rule.__doc__}")
    return solve


solve_route_search = route_search(search_modes, "route_search")
solve_route_loiter = route_search(loiter_modes, "route_loiter")
solve_route_search_and_loiter = route_search(search_and_loiter_modes, "route_search_and_loiter")
solve_route_search_and_reacquire = route_search(search_and_loiter_modes,
                                                "route_search_and_reacquire", reacquire=True)
solve_route_partition_search = route_search(search_modes, "route_partition_search",
                                            partitioned=True)
solve_route_partition_loiter = route_search(loiter_modes, "route_partition_loiter",
                                            partitioned=True)
