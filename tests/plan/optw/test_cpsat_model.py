"""The CP-SAT model: profit scaling, the constraints each formulation adds, hints and read-back."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ortools.sat.python import cp_model

from searchtrack.plan.optw import OPTWInstance, validate
from searchtrack.plan.optw.arcs import arc_graph
from searchtrack.plan.optw.cpsat_model import (
    CpModel,
    Formulation,
    add_hint,
    build_model,
    profit_scale,
    read_routes,
    scaled_bound,
    scaled_profit,
)
from tests.plan.optw.catalogue import brute_force, catalogue
from tests.plan.optw.feasible_routes import feasible_routes

KINDS = ("routes", "circuit", "no_overlap", "cumulative", "at_most_one", "interval", "linear")
SOLVED = ["euclid-m1", "euclid-m2", "euclid-open-m2", "euclid-fraction-m1", "asym-m1",
          "asym-start-end-m2", "detour-m2", "euclid-tmax-m1"]


def _kinds(mdl: CpModel) -> dict[str, int]:
    """How many constraints of each kind the model holds."""
    counts = dict.fromkeys(KINDS, 0)
    for ct in mdl.model.proto.constraints:
        for kind in KINDS:
            counts[kind] += bool(getattr(ct, f"has_{kind}")())
    return counts


def _solve(mdl: CpModel, *, fix_hint: bool = False
           ) -> tuple[cp_model.CpSolver, cp_model.CpSolverStatus]:
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = 1
    solver.parameters.max_time_in_seconds = 10.0
    solver.parameters.fix_variables_to_their_hinted_value = fix_hint
    return solver, solver.solve(mdl.model)


def _clash(vehicles: int) -> OPTWInstance:
    """Customers 1 and 2 are both served exactly at time 5 and lie 3 apart: no route serves
    both, in either order."""
    return OPTWInstance(travel=[[0, 5, 5], [5, 0, 3], [5, 3, 0]], service=[0, 0, 0],
                        profit=[0, 2, 3], open=[0, 5, 5], close=[20, 5, 5], vehicles=vehicles)


@pytest.mark.parametrize(("profit", "ints", "scale", "slack"), [
    ([1.0, 2.0, 3.0], [1, 2, 3], 1, 0.0),
    ([1.5, 2.25], [150, 225], 100, 0.0),
    ([0.1, 0.7], [1, 7], 10, 0.0),
    ([1 / 3, 2 / 3], [333_333, 666_667], 10**6, 1 / 3 * 10**6 - 333_333),
    ([2.0**49, 0.5], [2**49, 0], 1, 0.5)])
def test_profit_scale_by_hand(profit: list[float], ints: list[int], scale: int, slack: float
                              ) -> None:
    """The least power of ten that makes profits whole; else 10⁶ rounded with the rounding-down
    as slack; and never a scale that pushes the total past 2⁵⁰."""
    got_ints, got_scale, got_slack = profit_scale(np.array(profit))
    assert got_ints.tolist() == ints and got_scale == scale
    assert got_slack == pytest.approx(slack, abs=1e-9)


def test_scaled_profits_bound_every_subset() -> None:
    """For random fractional profits and any subset S, Σ_S p ≤ scaled_bound(Σ_S P)."""
    rng = np.random.default_rng(11)
    for _ in range(50):
        p = rng.uniform(0, 100, size=8) * rng.choice([1.0, 1e-3, 1e9])
        ints, scale, slack = profit_scale(p)
        for _ in range(20):
            subset = rng.random(8) < 0.5
            assert p[subset].sum() <= scaled_bound(int(ints[subset].sum()), scale, slack)


def test_scaled_bound_is_exact_for_whole_profits_and_rounds_up_otherwise() -> None:
    """Integral profits give the bound as is; otherwise (whole + slack) / scale rounded up."""
    assert scaled_bound(7, 1, 0.0) == 7.0
    assert scaled_bound(375, 100, 0.0) == math.nextafter(3.75, math.inf)
    third = scaled_bound(1_000_000, 10**6, 1 / 3)
    assert 1.0 + 1 / 3 * 1e-6 < third < 1.0 + 1e-6


@pytest.mark.parametrize("name", SOLVED)
def test_model_optimum_is_the_brute_force_optimum(name: str) -> None:
    """Solved as built, the model's optimum is the brute-force profit (scaled) and the routes
    read back validate, one per vehicle, with the same scaled profit."""
    inst = catalogue()[name]
    mdl = build_model(inst, arc_graph(inst), Formulation())
    solver, status = _solve(mdl)
    assert status == cp_model.OPTIMAL
    assert solver.objective_value == pytest.approx(brute_force(inst) * mdl.scale)
    routes = read_routes(mdl, solver, inst)
    assert len(routes) == inst.vehicles
    check = validate(inst, routes)
    assert check.feasible, check.violations
    assert check.profit == pytest.approx(brute_force(inst))
    assert scaled_profit(mdl, routes) == round(solver.objective_value)


@pytest.mark.parametrize("name", ["euclid-m1", "asym-open-m1", "euclid-start-end-m2"])
def test_a_hinted_route_is_a_complete_feasible_assignment(name: str) -> None:
    """Every feasible route, hinted and fixed, is accepted by the model, read back unchanged,
    and worth what add_hint says."""
    inst = catalogue()[name]
    g = arc_graph(inst)
    idle = (inst.start,) if inst.end is None else (inst.start, inst.end)
    for route, _ in feasible_routes(inst)[::3]:
        mdl = build_model(inst, g, Formulation())
        value = add_hint(mdl, inst, (route,))
        solver, status = _solve(mdl, fix_hint=True)
        assert status in (cp_model.OPTIMAL, cp_model.FEASIBLE), route
        assert round(solver.objective_value) == value
        expected = route if len(route) > len(idle) else idle
        assert read_routes(mdl, solver, inst) == (expected,) + (idle,) * (inst.vehicles - 1)
        assert value == scaled_profit(mdl, (route,))


def test_default_single_vehicle_model_has_routes_intervals_and_budget() -> None:
    """m = 1 by default: the routes constraint (not a circuit), a no-overlap over the optional
    service intervals, and the budget row among the linear ones."""
    inst = catalogue()["euclid-m1"]
    g = arc_graph(inst)
    full = _kinds(build_model(inst, g, Formulation()))
    assert full["routes"] == 1 and full["circuit"] == 0
    assert full["no_overlap"] == 1 and full["cumulative"] == 0
    assert full["interval"] == g.size - 1
    bare = _kinds(build_model(inst, g, Formulation(budget=False)))
    assert full["linear"] - bare["linear"] == 1


def test_switches_remove_their_constraints() -> None:
    """Without routes_for_single, intervals and incompatibility the m = 1 model is a circuit with
    only linear side constraints; ordering adds conditional linear rows."""
    inst = catalogue()["euclid-fraction-m1"]
    g = arc_graph(inst)
    bare = _kinds(build_model(inst, g, Formulation(routes_for_single=False, intervals=False,
                                                    incompatibility=False)))
    assert bare["circuit"] == 1 and bare["routes"] == 0
    assert bare["interval"] == bare["no_overlap"] == bare["at_most_one"] == 0
    plain = _kinds(build_model(inst, g, Formulation()))
    ordered = _kinds(build_model(inst, g, Formulation(ordering=True)))
    assert plain["at_most_one"] > 0
    assert ordered["linear"] > plain["linear"]


def test_team_model_uses_a_cumulative_of_capacity_m() -> None:
    """With m vehicles the intervals share a cumulative of capacity m instead of a no-overlap."""
    inst = catalogue()["euclid-m2"]
    mdl = build_model(inst, arc_graph(inst), Formulation())
    kinds = _kinds(mdl)
    assert kinds["cumulative"] == 1 and kinds["no_overlap"] == 0
    cumulative = next(ct.cumulative for ct in mdl.model.proto.constraints if ct.has_cumulative())
    assert cumulative.capacity.offset == 2


@pytest.mark.parametrize(("vehicles", "cuts", "best"), [(1, 1, 3.0), (2, 0, 5.0)])
def test_clashing_customers_get_a_clique_cut_for_one_vehicle(vehicles: int, cuts: int,
                                                            best: float) -> None:
    """Two customers no route can share form a clique: at most one of them with one vehicle
    (optimum 3); with two vehicles a clique of two is no cut and both are served (optimum 5)."""
    inst = _clash(vehicles)
    mdl = build_model(inst, arc_graph(inst), Formulation())
    kinds = _kinds(mdl)
    assert kinds["at_most_one"] == cuts
    if cuts:
        amo = next(ct.at_most_one for ct in mdl.model.proto.constraints if ct.has_at_most_one())
        assert sorted(amo.literals) == sorted([mdl.visit[1].index, mdl.visit[2].index])
    solver, status = _solve(mdl)
    assert status == cp_model.OPTIMAL and solver.objective_value == best
