"""The primal side of the branch-and-price: the ILS's plans as columns, the pool IP."""

from __future__ import annotations

import pytest

from searchtrack.plan.optw import validate
from searchtrack.plan.optw.bp_primal import ils_paths, plan_paths, pool_ip
from searchtrack.plan.optw.labelling_core import build_cores, instance_route
from tests.plan.optw.catalogue import catalogue

# core graph of two customers: source 0, customers 1 and 2, sink 3
PATHS = [(0, 1, 3), (0, 2, 3), (0, 1, 2, 3), (0, 3)]
PROFITS = [5.0, 3.0, 7.0, 0.0]


@pytest.mark.parametrize(("vehicles", "empty_ok", "best"), [(1, True, 7.0), (2, True, 8.0),
                                                            (3, False, None)])
def test_pool_ip_packs_disjoint_columns(vehicles: int, empty_ok: bool, best: float | None) -> None:
    """CP-SAT on the pool picks the best disjoint columns, or none when m cannot be met."""
    chosen = pool_ip(PATHS[:3], PROFITS[:3], vehicles, empty_ok, -1.0, 5.0, 0)
    if best is None:
        assert chosen is None
        return
    assert chosen is not None and sum(PROFITS[k] for k in chosen) == best
    assert pool_ip(PATHS[:3], PROFITS[:3], vehicles, empty_ok, best, 5.0, 0) is None


@pytest.mark.parametrize("name", sorted(catalogue()))
def test_ils_paths_are_the_plan_as_feasible_columns(name: str) -> None:
    """The ILS's plan comes back as core paths that map to its routes (customers only), each a
    feasible route; from a start plan, the same."""
    from searchtrack.plan.optw import ils

    ils.warm_up()
    inst = catalogue()[name]
    fwd, _, orig = build_cores(inst)
    paths = ils_paths(inst, fwd, orig, seconds=2.0, seed=0, start=None, iterations=2000)
    if paths is None:
        return
    routes = [instance_route(inst, orig, list(p)) for p in paths]
    assert len(routes) <= inst.vehicles
    assert all(validate(inst, [r]).feasible for r in routes)
    res = ils.solve_ils(inst, time_limit_s=2.0, seed=0, max_iterations=2000)
    assert res.plan is not None
    assert plan_paths(inst, fwd, orig, res.plan) == paths
    assert all(len(p) > 2 for p in paths)
