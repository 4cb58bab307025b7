"""Iterated local search for the (team) OPTW: optimality on tiny instances, validity, limits."""

from __future__ import annotations

import itertools
import math
import time
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.optw import OPTWInstance, read_optw, validate
from searchtrack.plan.optw.ils import solve_ils, warm_up

DATA = Path(__file__).parents[2] / "data" / "optw"


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    """Compile (or load) the Numba kernels once, outside the timed tests."""
    warm_up()


def random_instance(
    seed: int, n: int, *, vehicles: int = 1, end: int | None = 0, start: int = 0,
    horizon: float = 30.0,
) -> OPTWInstance:
    """``n`` random vertices in a 10×10 square with windows and profits, times in 0.1 units."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 10, (n, 2)).round(1)
    opn = rng.uniform(0, 0.7 * horizon, n).round(1)
    close = np.minimum(opn + rng.uniform(2, horizon / 2, n).round(1), horizon)
    opn[start] = 0.0
    close[start] = horizon
    if end is not None:
        opn[end], close[end] = 0.0, horizon
    profit = rng.integers(1, 10, n).astype(float)
    service = rng.uniform(0, 2, n).round(1)
    return OPTWInstance.from_coordinates(
        xy, profit, service, opn, close, decimals=1, start=start, end=end, tmax=horizon,
        vehicles=vehicles,
    )


def _windows_ok(inst: OPTWInstance, route: list[int]) -> bool:
    """True if every vertex of ``route`` (a prefix, no end vertex) is served inside its window."""
    t = int(inst.open[route[0]])
    for u, v in itertools.pairwise(route):
        t = max(t + int(inst.service[u]) + int(inst.travel[u, v]), int(inst.open[v]))
        if t > int(inst.close[v]):
            return False
    return True


def brute_force(inst: OPTWInstance) -> float:
    """Optimum by enumerating every ordered subset of customers (pruned on missed windows),
    each complete route checked by the validator; routes of several vehicles are combined from
    the best feasible route per customer set."""
    customers = [int(v) for v in inst.customers]
    tail = () if inst.end is None else (inst.end,)
    feasible_sets: set[int] = set()

    def extend(route: list[int], mask: int) -> None:
        if validate(inst, [(*route, *tail)]).feasible:
            feasible_sets.add(mask)
        for k, v in enumerate(customers):
            if not mask >> k & 1 and _windows_ok(inst, [*route, v]):
                extend([*route, v], mask | 1 << k)

    extend([inst.start], 0)
    value = {s: sum(float(inst.profit[customers[k]]) for k in range(len(customers)) if s >> k & 1)
             for s in feasible_sets}
    if inst.vehicles == 1:
        return max(value.values(), default=0.0)
    assert inst.vehicles == 2
    sets = sorted(value, key=value.__getitem__, reverse=True)
    return max((value[a] + value[b] for a in sets for b in sets if not a & b), default=0.0)


def check(inst: OPTWInstance, plan: tuple[tuple[int, ...], ...] | None, objective: float) -> None:
    """The plan has one route per vehicle, passes the validator and collects ``objective``."""
    assert plan is not None
    assert len(plan) == inst.vehicles
    report = validate(inst, plan)
    assert report.feasible, report.violations
    assert report.profit == pytest.approx(objective)


@pytest.mark.parametrize("seed", range(12))
def test_reaches_brute_force_optimum_one_vehicle(seed: int) -> None:
    """On random 9-vertex instances the single-vehicle ILS finds the enumerated optimum."""
    inst = random_instance(seed, 9)
    res = solve_ils(inst, time_limit_s=5.0, seed=seed, max_iterations=300)
    check(inst, res.plan, res.objective or 0.0)
    assert res.objective == pytest.approx(brute_force(inst))


@pytest.mark.parametrize("seed", range(12))
def test_reaches_brute_force_optimum_two_vehicles(seed: int) -> None:
    """With two vehicles the ILS finds the optimum combined from disjoint feasible routes."""
    inst = random_instance(seed, 9, vehicles=2, horizon=20.0)
    res = solve_ils(inst, time_limit_s=5.0, seed=seed, max_iterations=300)
    check(inst, res.plan, res.objective or 0.0)
    assert res.objective == pytest.approx(brute_force(inst))


def test_search_improves_on_the_construction() -> None:
    """The brute-force instances are not trivial: search beats the first greedy pass on several."""
    improved = 0
    for seed in range(12):
        for inst in (random_instance(seed, 9), random_instance(seed, 9, vehicles=2, horizon=20.0)):
            first = solve_ils(inst, time_limit_s=5.0, seed=seed, max_iterations=0)
            final = solve_ils(inst, time_limit_s=5.0, seed=seed, max_iterations=300)
            improved += (final.objective or 0.0) > (first.objective or 0.0)
    assert improved >= 6


@pytest.mark.parametrize("seed", range(6))
def test_open_end_and_distinct_start_end(seed: int) -> None:
    """Open-end routes and routes from start to a different end vertex are optimal and valid."""
    for inst in (random_instance(200 + seed, 9, end=None),
                 random_instance(300 + seed, 9, start=1, end=4),
                 random_instance(400 + seed, 9, end=None, vehicles=2, horizon=20.0)):
        res = solve_ils(inst, time_limit_s=5.0, seed=seed, max_iterations=300)
        check(inst, res.plan, res.objective or 0.0)
        assert res.objective == pytest.approx(brute_force(inst))
        if inst.end is None:  # open end: a route stops at its last visit
            assert all(len(route) == 1 or route[-1] != inst.start for route in res.plan or ())


def test_benchmark_plan_is_valid_and_deterministic() -> None:
    """Two runs with the same seed and iteration budget on c101 return the same valid plan."""
    inst = read_optw(DATA / "c101.txt")
    first = solve_ils(inst, time_limit_s=60.0, seed=3, max_iterations=400)
    second = solve_ils(inst, time_limit_s=60.0, seed=3, max_iterations=400)
    check(inst, first.plan, first.objective or 0.0)
    assert first.plan == second.plan and first.objective == second.objective
    assert first.status is Status.FEASIBLE and first.backend == "ils"
    assert first.stats["iterations"] == 400


def test_team_plan_on_benchmark_is_valid() -> None:
    """Three vehicles on c101 give three valid, disjoint routes collecting more than one."""
    inst = read_optw(DATA / "c101.txt")
    one = solve_ils(inst, time_limit_s=60.0, seed=0, max_iterations=200)
    three = solve_ils(inst.with_vehicles(3), time_limit_s=60.0, seed=0, max_iterations=200)
    check(inst.with_vehicles(3), three.plan, three.objective or 0.0)
    assert (three.objective or 0.0) > (one.objective or 0.0)


def test_time_limit_is_honoured() -> None:
    """A 0.2 s limit on a 100-customer benchmark returns well within a second."""
    inst = read_optw(DATA / "c101.txt")
    started = time.perf_counter()
    res = solve_ils(inst, time_limit_s=0.2, seed=1)
    assert time.perf_counter() - started < 1.0
    assert res.runtime_s < 1.0
    check(inst, res.plan, res.objective or 0.0)


def test_starts_from_initial_plan() -> None:
    """Given a valid initial plan, the answer is valid and at least as good."""
    inst = random_instance(7, 9)
    seed_plan = solve_ils(inst, time_limit_s=5.0, seed=0, max_iterations=50).plan
    assert seed_plan is not None
    start_profit = validate(inst, seed_plan).profit
    res = solve_ils(inst, time_limit_s=5.0, seed=1, initial=seed_plan, max_iterations=0)
    check(inst, res.plan, res.objective or 0.0)
    assert (res.objective or 0.0) >= start_profit


def test_rejects_invalid_initial_plan() -> None:
    """An initial plan that breaks a window or repeats a vertex is refused with its field name."""
    inst = random_instance(7, 9)
    with pytest.raises(InvalidInputError, match="initial"):
        solve_ils(inst, initial=((0, 1, 1, 0),))


def test_nothing_reachable_gives_empty_routes() -> None:
    """When no customer can be reached in time the plan is empty routes with profit 0."""
    xy = np.array([[0.0, 0.0], [50.0, 0.0], [0.0, 60.0]])
    inst = OPTWInstance.from_coordinates(
        xy, [0, 5, 7], np.zeros(3), np.zeros(3), np.full(3, 10.0), decimals=1, vehicles=2
    )
    res = solve_ils(inst, time_limit_s=1.0)
    assert res.objective == 0.0
    assert res.plan == ((0, 0), (0, 0))
    assert res.status is Status.OPTIMAL


def test_unreachable_end_is_infeasible() -> None:
    """When even the direct trip to a distinct end vertex misses its deadline, no plan exists."""
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [30.0, 0.0]])
    inst = OPTWInstance.from_coordinates(
        xy, [0, 5, 0], np.zeros(3), np.zeros(3), np.full(3, 10.0), decimals=1, end=2
    )
    res = solve_ils(inst, time_limit_s=1.0)
    assert res.status is Status.INFEASIBLE and res.plan is None


def test_collecting_everything_is_optimal() -> None:
    """A plan that collects every reachable profit is reported OPTIMAL with that bound."""
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    inst = OPTWInstance.from_coordinates(
        xy, [0, 1, 2, 3], np.zeros(4), np.zeros(4), np.full(4, 100.0), decimals=1
    )
    res = solve_ils(inst, time_limit_s=1.0)
    assert res.status is Status.OPTIMAL
    assert res.objective == 6.0 and res.bound == 6.0


@pytest.mark.parametrize("limit", [0.0, -1.0, math.nan])
def test_bad_time_limit_is_rejected(limit: float) -> None:
    """A non-positive or NaN time limit raises InvalidInputError naming time_limit_s."""
    inst = random_instance(0, 5)
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve_ils(inst, time_limit_s=limit)


@pytest.mark.parametrize(("field", "kwargs"), [("seed", {"seed": -1}),
                                                ("max_iterations", {"max_iterations": -5})])
def test_bad_arguments_are_rejected(field: str, kwargs: dict[str, int]) -> None:
    """A negative seed or iteration budget raises InvalidInputError naming the field."""
    inst = random_instance(0, 5)
    with pytest.raises(InvalidInputError, match=field):
        solve_ils(inst, time_limit_s=1.0, **kwargs)  # type: ignore[arg-type]
