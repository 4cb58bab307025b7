"""PyVRP as a prize-collecting VRPTW: the reference point the OPTW benchmarks are compared with.

Every client is optional with its profit, scaled by a factor larger than any route's length, as
prize; travel costs one per tick. So PyVRP maximises collected prize first and uses distance only to
break ties (with zero travel cost its search has large plateaus and does much worse). Its routes are
re-checked with searchtrack's validator.
"""

from __future__ import annotations

import time

from pyvrp import Model
from pyvrp.stop import MaxRuntime

from searchtrack.plan.optw import OPTWInstance, validate

# Prize per unit of profit, in ticks of travel. Larger scales make PyVRP's time-warp penalties
# (capped by its PenaltyParams.max_penalty) cheaper than prizes, and it returns infeasible routes.
PRIZE_SCALE = 1000


def solve_pyvrp(inst: OPTWInstance, time_limit_s: float, seed: int = 0) -> tuple[float, float]:
    """Return (validated profit, seconds) of PyVRP on ``inst`` (start = end depot, m vehicles)."""
    assert inst.end == inst.start, "PyVRP anchor needs start == end"
    m = Model()
    locs = [m.add_location(0.0, 0.0) for _ in range(inst.n)]
    depot = m.add_depot(locs[inst.start], tw_early=int(inst.open[inst.start]),
                        tw_late=int(inst.latest_finish))
    m.add_vehicle_type(num_available=inst.vehicles, start_depot=depot, end_depot=depot,
                       tw_early=inst.departure, tw_late=int(inst.latest_finish),
                       unit_distance_cost=1)
    scale = PRIZE_SCALE
    clients = [v for v in range(inst.n) if v != inst.start]
    for v in clients:
        m.add_client(locs[v], service_duration=int(inst.service[v]), tw_early=int(inst.open[v]),
                     tw_late=int(inst.close[v]), prize=scale * round(float(inst.profit[v])),
                     required=False)
    for i in range(inst.n):
        for j in range(inst.n):
            if i != j:
                t = int(inst.travel[i, j])
                m.add_edge(locs[i], locs[j], distance=t, duration=t)
    started = time.perf_counter()
    res = m.solve(stop=MaxRuntime(time_limit_s), seed=seed, display=False)
    elapsed = time.perf_counter() - started
    routes = [
        (inst.start, *(clients[a.idx] for a in r.schedule() if a.is_client()), inst.start)
        for r in res.best.routes()
    ]
    check = validate(inst, routes)
    return (check.profit if check.feasible else float("nan")), elapsed
