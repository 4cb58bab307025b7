"""An independent check of a road-search plan: it follows the roads, and its objective
recomputed from scratch by propagating the particles with the problem's fixed draws.

Nothing here uses the scenario the solvers share (no time-expanded graph, no particle groups):
the particles are stepped with the motion model (Eq. 9) tick by tick from ``draw_seed``, a UAV
in flight starts its path at its delay in whole ticks, a path with a horizon ends at the first
node it reaches at or past the horizon tick, each particle's best sighting ``β(ℓ, e) =
discount**ℓ`` (over ``len(e)`` when ``per_length``) is taken over every UAV and level whose edge
it lies on (either direction when ``both_directions``) at the tick the edge is started, and the
objective is the sum of ``γ_m w_{mn}`` times that
(:mod:`~searchtrack.plan.road_search.scenario`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem
from searchtrack.plan.road_search.weights import target_weights


@dataclass(frozen=True)
class PlanCheck:
    """The verdict on a plan.

    Parameters
    ----------
    feasible
        Every path leaves its UAV's node and follows consecutive directed edges: ``L`` of them,
        or with a horizon up to the first node reached at or past it.
    objective
        The plan's objective recomputed from scratch (``nan`` when not feasible).
    reasons
        What is wrong, one line per fault.
    """

    feasible: bool
    objective: float
    reasons: tuple[str, ...] = ()


def _flight_ticks(problem: RoadSearchProblem) -> FloatArray:
    """``(E,)`` ticks to fly each directed edge, from the lengths and the UAV speed."""
    st = problem.settings
    return np.maximum(1, np.rint(problem.roads.length / (st.uav_speed_mps * problem.tick_s)))


def _edges_allowed(problem: RoadSearchProblem, ticks: FloatArray, uav: int,
                   edges: tuple[int, ...]) -> int:
    """How many edges the path must have: ``L``, or with a horizon the first count after
    which its arrival (delay plus flight ``ticks``) is at or past the horizon."""
    st = problem.settings
    if st.horizon_s is None:
        return st.lookahead
    when = round(problem.uav_delay_s[uav] / problem.tick_s)
    horizon = round(st.horizon_s / problem.tick_s)
    for i, e in enumerate(edges[:st.lookahead]):
        if not 0 <= e < problem.roads.n_edges:
            return len(edges)  # a missing edge is reported on its own
        when += int(ticks[e])
        if when >= horizon:
            return i + 1
    return st.lookahead


def _path_faults(problem: RoadSearchProblem, plan: RoadPlan, ticks: FloatArray) -> list[str]:
    roads = problem.roads
    faults = []
    if not isinstance(plan, RoadPlan):
        return [f"the plan is a {type(plan).__name__}, not a RoadPlan"]
    if len(plan.edges) != problem.n_uavs or len(plan.nodes) != problem.n_uavs:
        return [f"{len(plan.edges)} paths for {problem.n_uavs} UAVs"]
    for q, (nodes, edges) in enumerate(zip(plan.nodes, plan.edges, strict=True)):
        want = _edges_allowed(problem, ticks, q, edges)
        if len(edges) != want or len(nodes) != want + 1:
            faults.append(f"UAV {q}: {len(edges)} edges and {len(nodes)} nodes, the look-ahead "
                          f"{problem.lookahead} and the horizon allow {want} edges")
            continue
        if nodes[0] != problem.uav_nodes[q]:
            faults.append(f"UAV {q}: starts at {nodes[0]}, not its node {problem.uav_nodes[q]}")
        for i, e in enumerate(edges):
            if not 0 <= e < roads.n_edges:
                faults.append(f"UAV {q}: edge {e} does not exist")
            elif roads.tail[e] != nodes[i] or roads.head[e] != nodes[i + 1]:
                faults.append(f"UAV {q}: edge {e} does not go from {nodes[i]} to {nodes[i + 1]}")
    return faults


def check_plan(problem: RoadSearchProblem, plan: RoadPlan) -> PlanCheck:
    """Check ``plan`` against ``problem`` and recompute its objective from scratch."""
    ticks = _flight_ticks(problem)
    faults = _path_faults(problem, plan, ticks)
    if faults:
        return PlanCheck(False, math.nan, tuple(faults))
    st = problem.settings
    roads = problem.roads
    sightings = []  # (tick, edge, beta)
    for edges, delay in zip(plan.edges, problem.uav_delay_s, strict=True):
        tick = round(delay / problem.tick_s)  # a UAV in flight starts its path that late
        for level, e in enumerate(edges):
            beta = st.discount**level / (float(roads.length[e]) if st.per_length else 1.0)
            sightings.append((tick, e, beta))
            tick += int(ticks[e])
    rng = np.random.default_rng(st.draw_seed)
    edge, s = problem.particle_edge.copy(), problem.particle_s.copy()
    best = np.zeros(edge.shape)
    for t in range(max(t for t, _, _ in sightings) + 1):
        if t > 0:
            edge, s = st.motion.step(roads, edge, s, problem.tick_s, rng)
        for when, e, beta in sightings:
            if when == t:
                on = (edge == e) | ((edge == (e ^ 1)) & st.both_directions)
                best[on] = np.maximum(best[on], beta)
    gamma = target_weights(problem.entropy, gain=st.gain, normalization=st.normalization,
                           weighting=st.weighting)
    value = float(np.sum(gamma[:, None] * problem.particle_weight * best))
    return PlanCheck(True, value)


def answer_problems(problem: RoadSearchProblem, result: Result[RoadPlan],
                    seed: int = 0) -> list[str]:
    """What :func:`check_plan` finds wrong with ``result``: path faults, an objective that is
    not the plan's recomputed value, an objective above a claimed bound."""
    del seed  # the check draws nothing
    assert result.plan is not None
    check = check_plan(problem, result.plan)
    if not check.feasible:
        return list(check.reasons)
    problems = []
    obj = result.objective
    tol = 1e-7 * (1.0 + abs(check.objective))
    if obj is not None and abs(obj - check.objective) > tol:
        problems.append(f"reported value {obj} but the paths score {check.objective}")
    if obj is not None and result.bound is not None and obj > result.bound + tol:
        problems.append(f"value {obj} exceeds the claimed bound {result.bound}")
    return problems
