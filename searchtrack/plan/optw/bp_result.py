"""The answer of a team-OPTW branch-and-price run (:mod:`searchtrack.plan.optw.bp`) as the one
:class:`~searchtrack.core.result.Result`: status, plan, bound and the run's statistics."""

from __future__ import annotations

from typing import TYPE_CHECKING

from searchtrack.core.interrupt import stop_requested
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw.instance import Routes

if TYPE_CHECKING:
    from searchtrack.plan.optw.bp import Tree

BACKEND = "bp"


def result(tree: Tree, nodes: int, open_bounds: list[float]) -> Result[Routes]:
    """The run's answer: ``OPTIMAL`` when no open node can beat the incumbent, else the best
    plan with the largest rounded bound of the open nodes, and the run's statistics."""
    inst, deadline, m = tree.inst, tree.deadline, tree.master
    pricing_s = tree.stats.get("pricing_s", 0.0)
    calls = tree.pricer.stats["pricing_calls"]
    stats = {**tree.stats, **{f"pricing_{k}": v for k, v in tree.pricer.stats.items()
                              if k != "pricing_calls"},
             "nodes": float(nodes), "columns": float(m.size), "lp_failures": float(m.failures),
             "pricing_calls": calls, "pricing_per_s": calls / pricing_s if pricing_s else 0.0}
    open_bounds = [b for b in open_bounds if not tree.pruned(b)]
    plan = tree.plan()
    elapsed = deadline.elapsed()
    if not open_bounds:
        if plan is None:
            return Result(Status.INFEASIBLE, None, None, elapsed, BACKEND, None,
                          message=f"no {inst.vehicles} routes exist", stats=stats)
        settled = int(stats.get("enum_settled", 0.0))
        by_enum = f", {settled} settled by route enumeration" if settled else ""
        return Result(Status.OPTIMAL, tree.value, tree.value, elapsed, BACKEND, plan,
                      message=f"proven optimal; {nodes} nodes{by_enum}", stats=stats)
    bound = max(tree.rounded(b) for b in open_bounds)
    why = ("stopped on request" if stop_requested() else "time limit" if deadline.expired()
           else "nodes left open by failed master LPs")
    if plan is None:
        return Result(Status.NO_SOLUTION, None, float(bound), elapsed, BACKEND, None,
                      message=why, stats=stats)
    return Result(Status.FEASIBLE, tree.value, float(max(bound, tree.value)), elapsed, BACKEND,
                  plan, message=f"{why}; {nodes} nodes", stats=stats)
