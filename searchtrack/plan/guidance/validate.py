"""The guidance family's independent validator: what one step's answer must satisfy, checked
against the problem's view without the strategies' code (thesis Ch. 5).

* one force, mode and route per UAV of the view; forces finite;
* paired trackers exist in the view's bank (each at most once) and a UAV that loiters or
  reacquires is paired; a ``search`` backend answer leaves every UAV searching;
* every route, reacquisition and search-route node is a node of the network, reacquisitions fly
  distinct tracks by UAVs of the view, search routes distinct UAVs of the view, and a UAV in
  ``route`` mode flies the search route it keeps;
* the objective (a tracker probability mass) is finite and non-negative.
"""

from __future__ import annotations

import math

import numpy as np

from searchtrack.core.result import Result
from searchtrack.plan.guidance.problem import GuidanceProblem
from searchtrack.plan.guidance.view import Guidance


def answer_problems(problem: GuidanceProblem, result: Result[Guidance],
                    seed: int = 0) -> list[str]:
    """What is wrong with ``result``'s guidance (empty when it holds)."""
    del seed  # the check draws nothing
    plan = result.plan
    assert plan is not None
    view = problem.view
    o, n = view.n_uavs, view.network.n_nodes
    if plan.force.shape != (o, 2) or len(plan.mode) != o or len(plan.route) != o:
        return [f"an answer for {plan.force.shape[0]} UAVs, the view has {o}"]
    problems: list[str] = []
    if not np.all(np.isfinite(plan.force)):
        problems.append("a force is not finite")
    trackers = len(view.bank)
    for u, (t, mode) in enumerate(zip(plan.pairing.tracker, plan.mode, strict=True)):
        if t >= trackers:
            problems.append(f"UAV {u} paired with tracker {t} of {trackers}")
        if mode in ("loiter", "reacquire") and t < 0:
            problems.append(f"UAV {u} is in {mode} mode but paired with no tracker")
        if result.backend == "search" and mode != "search":
            problems.append(f"UAV {u} is in {mode} mode under the search strategy")
    nodes = [v for route in plan.route for v in route]
    nodes += [v for r in plan.reacquisitions for v in r.nodes]
    nodes += [v for r in plan.search_routes for v in r.nodes]
    if any(not 0 <= v < n for v in nodes):
        problems.append(f"a route node outside the network's {n} nodes")
    tracks = [r.track_id for r in plan.reacquisitions]
    if len(set(tracks)) != len(tracks) or any(not 0 <= r.uav < o for r in plan.reacquisitions):
        problems.append("reacquisitions must fly distinct tracks by UAVs of the view")
    searched = {r.uav: r.nodes for r in plan.search_routes}
    if len(searched) != len(plan.search_routes) or any(not 0 <= u < o for u in searched):
        problems.append("search routes must be flown by distinct UAVs of the view")
    for u, mode in enumerate(plan.mode):
        if mode == "route" and searched.get(u) != plan.route[u]:
            problems.append(f"UAV {u} is in route mode without the search route it flies")
    obj = result.objective
    if obj is not None and not (math.isfinite(obj) and obj >= 0.0):
        problems.append(f"objective {obj} is not a probability mass")
    return problems
