"""The one-step planner: at each node fly the edge of highest weighted value (Eq. 21) on the
particles propagated to that time, with the particles already seen removed (Moore et al. 2021,
§4.1; with ``weighting="uniform"`` the naive value of Eq. 17).

Each UAV flies its greedy edges in turn (``L``, or up to the horizon); later UAVs do not count
what earlier ones see. With ``L = 1`` and one UAV this is the best plan (the objective is then
the edge value itself): ``OPTIMAL``; otherwise ``FEASIBLE`` with the scenario's upper bound.
"""

from __future__ import annotations

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem, meets_bound
from searchtrack.plan.road_search.weights import edge_values


def greedy_paths(problem: RoadSearchProblem) -> list[list[int]]:
    """Each UAV's greedy edges (ties: the lowest edge index)."""
    st = problem.settings
    roads = problem.roads
    edge_at = problem.scenario.edge_at
    alive = np.ones(problem.particle_edge.size)
    shape = problem.particle_edge.shape
    paths: list[list[int]] = []
    for start, start_tick in zip(problem.uav_nodes, problem.start_ticks, strict=True):
        node, tick, path = start, int(start_tick), list[int]()
        while not problem.path_ends(tick, len(path)):
            here = edge_at[tick]
            values = edge_values(roads.length, here.reshape(shape),
                                 (problem.particle_weight.reshape(-1) * alive).reshape(shape),
                                 problem.gamma, per_length=st.per_length,
                                 both_directions=st.both_directions)
            outs = roads.leaving(node)
            e = int(outs[int(np.argmax(values[outs]))])
            seen = (here == e) | ((here == (e ^ 1)) & st.both_directions)
            alive[seen] = 0.0
            path.append(e)
            tick += int(problem.edge_ticks[e])
            node = int(roads.head[e])
        paths.append(path)
    return paths


def solve_greedy(problem: RoadSearchProblem, *, time_limit_s: float = 10.0,
                 seed: int = 0) -> Result[RoadPlan]:
    """The greedy plan; ``seed`` is unused (deterministic)."""
    del seed
    deadline = Deadline(time_limit_s)
    sc = problem.scenario
    plan = RoadPlan.from_edges(problem.roads, greedy_paths(problem))
    value = sc.score(plan)
    bound = sc.upper_bound()
    optimal = (problem.n_uavs == 1 and problem.lookahead == 1) or meets_bound(value, bound)
    return Result(Status.OPTIMAL if optimal else Status.FEASIBLE, value,
                  value if optimal else bound, deadline.elapsed(), "greedy", plan,
                  message="greedy: best weighted edge at each node (Eq. 21)")
