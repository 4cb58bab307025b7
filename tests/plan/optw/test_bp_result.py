"""The answer of a branch-and-price run: status, bound and plan from the tree's state."""

from __future__ import annotations

import pytest

from searchtrack.core.result import Status
from searchtrack.plan.optw.bp import Tuning, solve_bp
from tests.plan.optw.catalogue import brute_force, catalogue


def test_a_closed_tree_is_optimal_or_infeasible() -> None:
    """Every catalogue instance closes (OPTIMAL at the brute-force value, or INFEASIBLE);
    the statistics carry the node, column and pricing counts."""
    for name, inst in catalogue().items():
        res = solve_bp(inst, time_limit_s=20, tuning=Tuning(ils_max_s=0.02))
        best = brute_force(inst)
        if best == float("-inf"):
            assert res.status is Status.INFEASIBLE, name
            continue
        assert res.status is Status.OPTIMAL, name
        assert res.objective == pytest.approx(best) and res.bound == res.objective, name
        assert res.backend == "bp"
        assert {"nodes", "columns", "pricing_calls", "root_bound"} <= set(res.stats)
