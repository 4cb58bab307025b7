"""The paper's two reference planners (Moore et al. 2021, §6): random and ideal.

``random``: at each node a UAV takes one of the edges leaving it, uniformly (turning back
allowed, as in the authors' code).

``ideal``: knows where the targets truly are. The paper says only "perfect knowledge"; the
authors' code alternates between the targets, flying the shortest path to the current one. Here,
so that the planner needs no memory between decisions, each UAV heads for a target chosen by
entropy: UAV ``q`` takes the ``q``-th most uncertain target (cycling when ``Q > M``). After a
sighting that target's entropy drops and the next decision turns to another, which alternates in
closed loop. A UAV flies the shortest road path to the nearer end of the target's road, then
along that road towards the target; a path shorter than ``L`` edges continues straight on
(the first successor at each node).

Both plans are scored on the shared objective and are ``FEASIBLE`` with the scenario's upper
bound (``OPTIMAL`` only when they happen to meet it).
"""

from __future__ import annotations

import itertools

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem, meets_bound


def _answer(problem: RoadSearchProblem, paths: list[list[int]], deadline: Deadline,
            name: str, note: str) -> Result[RoadPlan]:
    sc = problem.scenario
    plan = RoadPlan.from_edges(problem.roads, paths)
    value = sc.score(plan)
    bound = sc.upper_bound()
    optimal = meets_bound(value, bound)
    return Result(Status.OPTIMAL if optimal else Status.FEASIBLE, value,
                  value if optimal else bound, deadline.elapsed(), name, plan, message=note)


def solve_random(problem: RoadSearchProblem, *, time_limit_s: float = 10.0,
                 seed: int = 0) -> Result[RoadPlan]:
    """Uniformly random paths (all edges leaving a node are candidates), from ``seed``."""
    deadline = Deadline(time_limit_s)
    rng = np.random.default_rng(seed)
    roads = problem.roads
    paths = []
    for node, tick in zip(problem.uav_nodes, problem.start_ticks, strict=True):
        path, here, when = list[int](), node, int(tick)
        while not problem.path_ends(when, len(path)):
            outs = roads.leaving(here)
            e = int(outs[int(rng.integers(outs.size))])
            path.append(e)
            here, when = int(roads.head[e]), when + int(problem.edge_ticks[e])
        paths.append(path)
    return _answer(problem, paths, deadline, "random", "random: uniform edge at each node")


def supports_ideal(problem: RoadSearchProblem) -> str | None:
    """``None`` when the problem carries the true target positions."""
    return None if problem.truth_edge is not None else "needs truth_edge and truth_s"


def _edge_between(roads: DirectedRoads, a: int, b: int) -> int:
    outs = roads.leaving(a)
    return int(outs[roads.head[outs] == b][0])


def ideal_path(problem: RoadSearchProblem, start: int, target: int) -> list[int]:
    """``L`` directed edges from ``start`` towards the true position of ``target``."""
    assert problem.truth_edge is not None and problem.truth_s is not None
    roads = problem.roads
    d, s = int(problem.truth_edge[target]), float(problem.truth_s[target])
    dist = roads.network.shortest_paths(start)[0]
    via_tail = dist[roads.tail[d]] + s
    via_head = dist[roads.head[d]] + roads.length[d] - s
    road = d if via_tail <= via_head else d ^ 1  # fly along the road towards the target
    nodes, _ = roads.network.shortest_path(start, int(roads.tail[road]))
    if nodes.size == 0:  # the target is out of reach: fly straight on
        path = [int(roads.leaving(start)[0])]
    else:
        path = [_edge_between(roads, int(a), int(b))
                for a, b in itertools.pairwise(nodes.tolist())] + [road]
    while len(path) < problem.lookahead:
        last = path[-1]
        path.append(int(roads.successors[roads.successor_ptr[last]]))
    return path[:problem.lookahead]


def _to_horizon(problem: RoadSearchProblem, uav: int, path: list[int]) -> list[int]:
    """``path`` cut where it reaches the problem's time horizon (unchanged without one)."""
    when = int(problem.start_ticks[uav])
    for i, e in enumerate(path):
        when += int(problem.edge_ticks[e])
        if problem.path_ends(when, i + 1):
            return path[:i + 1]
    return path


def solve_ideal(problem: RoadSearchProblem, *, time_limit_s: float = 10.0,
                seed: int = 0) -> Result[RoadPlan]:
    """Shortest paths towards the true targets, the most uncertain first (module docstring);
    ``seed`` is unused."""
    del seed
    deadline = Deadline(time_limit_s)
    if supports_ideal(problem) is not None:
        return Result(Status.ERROR, None, None, deadline.elapsed(), "ideal", None,
                      message="ideal: the problem has no true target positions")
    order = np.argsort(-problem.entropy, kind="stable")
    paths = [_to_horizon(problem, q, ideal_path(problem, node, int(order[q % order.size])))
             for q, node in enumerate(problem.uav_nodes)]
    return _answer(problem, paths, deadline, "ideal",
                   "ideal: shortest path to the true targets, most uncertain first")
