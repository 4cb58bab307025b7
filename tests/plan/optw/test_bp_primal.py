"""The primal side of the branch-and-price: the ILS's plans as columns, the pool IP."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.plan.optw import validate
from searchtrack.plan.optw.bp_primal import ils_paths, packing, plan_paths, pool_ip
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


def test_packing_against_brute_force() -> None:
    """Random pools of columns over eight customers, required customers, fractional profits in
    cents: the packing's optimum and its proof agree with trying every subset of columns."""
    rng = np.random.default_rng(7)
    for trial in range(40):
        paths = [(0, *sorted({int(v) for v in rng.integers(1, 9, rng.integers(1, 4))}), 9)
                 for _ in range(10)]
        profits = (rng.integers(1, 2000, len(paths)) / 100.0).tolist()
        vehicles, empty_ok = int(rng.integers(1, 4)), bool(trial % 2)
        required = {int(v) for v in rng.choice(np.arange(1, 9), int(rng.integers(0, 3)),
                                               replace=False)}
        best = -np.inf
        for k in range(vehicles + 1):
            if k < vehicles and not empty_ok:
                continue
            for combo in itertools.combinations(range(len(paths)), k):
                seen = [v for c in combo for v in paths[c][1:-1]]
                if len(seen) == len(set(seen)) and required <= set(seen):
                    best = max(best, sum(profits[c] for c in combo))
        chosen, proven = packing(paths, profits, vehicles, empty_ok, -1.0, 10.0, 0,
                                 required=required)
        assert proven
        if best == -np.inf:
            assert chosen is None
            continue
        assert chosen is not None and sum(profits[c] for c in chosen) == pytest.approx(best)
        assert required <= {v for c in chosen for v in paths[c][1:-1]}
        assert packing(paths, profits, vehicles, empty_ok, best, 10.0, 0,
                       required=required) == (None, True)


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
