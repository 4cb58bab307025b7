"""The exact labelling solver: brute-force optima, benchmark proof, deadline, input checks."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.optw import OPTWInstance, read_optw, validate
from searchtrack.plan.optw.labelling import solve_labelling, warm_up

DATA = Path(__file__).parents[2] / "data" / "optw"


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    """Compile (or load) the kernel once, outside the timed tests."""
    warm_up()


def brute_force(inst: OPTWInstance) -> float:
    """Best profit over every ordered subset of customers, each route judged by ``validate``.

    Prefixes whose own visits already miss a window are not extended (later visits cannot make
    them feasible again); every other candidate route goes to the validator.
    """
    best = -np.inf
    tail = () if inst.end is None else (inst.end,)
    customers = [int(c) for c in inst.customers]

    def extend(prefix: tuple[int, ...], begin: int) -> None:
        nonlocal best
        check = validate(inst, [prefix + tail])
        if check.feasible:
            best = max(best, check.profit)
        last = prefix[-1]
        for c in customers:
            if c in prefix:
                continue
            arrival = begin + int(inst.service[last]) + int(inst.travel[last, c])
            start = max(arrival, int(inst.open[c]))
            if start <= int(inst.close[c]):
                extend((*prefix, c), start)

    extend((inst.start,), inst.departure)
    return float(best)


def random_instance(seed: int) -> OPTWInstance:
    """A small random instance: symmetric or asymmetric travel, closed, shifted or open end."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 10))
    layout = seed % 4  # 0: start = end, 1: open end, 2: start ≠ end, 3: asymmetric matrix
    end: int | None = {0: 0, 1: None, 2: n - 1, 3: int(rng.integers(0, n))}[layout]
    start = 0 if layout < 3 else int(rng.integers(0, n))
    integral = seed % 3 != 0
    profit = rng.integers(0, 10, size=n) if integral else np.round(rng.uniform(0, 10, n), 3)
    service = rng.integers(0, 4, size=n).astype(float)
    opn = np.round(rng.uniform(0, 50, size=n), 1)
    close = np.round(np.minimum(opn + rng.uniform(5, 60, size=n), 90.0), 1)
    for v in (start, end):
        if v is not None:
            opn[v], close[v] = 0.0, 90.0
    tmax = None if seed % 2 else float(rng.integers(30, 80))
    if layout == 3:
        travel = np.round(rng.uniform(0, 25, size=(n, n)), 1)
        np.fill_diagonal(travel, 0.0)
        return OPTWInstance.from_travel_times(
            travel, profit, service=service, open=opn, close=close, start=start, end=end,
            tmax=tmax, time_scale=10, name=f"rand{seed}",
        )
    xy = np.round(rng.uniform(0, 20, size=(n, 2)), 2)
    return OPTWInstance.from_coordinates(
        xy, profit, service, opn, close, decimals=1, start=start, end=end, tmax=tmax,
        name=f"rand{seed}",
    )


@pytest.mark.parametrize("ng_size", [None, 0, 2])
@pytest.mark.parametrize("seed", range(16))
def test_matches_brute_force(seed: int, ng_size: int | None) -> None:
    """On small random instances the proven optimum equals brute force and the route validates
    (``ng_size`` 0 and 2 start from weak relaxations, so several passes and bounds are used)."""
    inst = random_instance(seed)
    best = brute_force(inst)
    res = solve_labelling(inst, time_limit_s=20.0, ng_size=ng_size)
    assert res.status is Status.OPTIMAL
    assert res.plan is not None and res.objective is not None
    check = validate(inst, res.plan)
    assert check.feasible, check.violations
    assert check.profit == pytest.approx(best, abs=1e-9)
    assert res.objective == pytest.approx(best, abs=1e-9)
    assert res.bound == pytest.approx(best, abs=1e-9)


def test_fine_time_scale() -> None:
    """With 10**7 ticks per unit (a coarse label queue) the optimum still matches brute force."""
    rng = np.random.default_rng(3)
    n = 8
    travel = np.round(rng.uniform(1, 25, size=(n, n)), 3)
    opn = np.round(rng.uniform(0, 40, size=n), 2)
    opn[0] = 0.0
    inst = OPTWInstance.from_travel_times(
        travel, rng.integers(1, 10, size=n), service=np.ones(n), open=opn, close=opn + 40.0,
        tmax=90.0, time_scale=10**7,
    )
    res = solve_labelling(inst, time_limit_s=20.0, ng_size=0)
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(brute_force(inst))


def test_zero_duration_cycles() -> None:
    """Customers at the same place with no service (free cycles) still give the optimum."""
    xy = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 1.0], [1.0, 1.0], [3.0, 0.0], [0.0, 3.0]])
    inst = OPTWInstance.from_coordinates(
        xy, [0, 2, 3, 4, 5, 6], np.zeros(6), np.zeros(6), np.full(6, 9.0), decimals=1
    )
    res = solve_labelling(inst, time_limit_s=20.0)
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(brute_force(inst))


def test_initial_route_is_a_lower_bound() -> None:
    """A given optimal route is accepted as the lower bound and the optimum is still proven."""
    inst = random_instance(5)
    first = solve_labelling(inst, time_limit_s=20.0)
    assert first.plan is not None
    again = solve_labelling(inst, time_limit_s=20.0, initial=first.plan)
    assert again.status is Status.OPTIMAL
    assert again.objective == pytest.approx(first.objective)


def test_infeasible_initial_rejected() -> None:
    """An initial plan that breaks the instance's constraints is refused, naming the field."""
    inst = random_instance(2)
    with pytest.raises(InvalidInputError, match="initial"):
        solve_labelling(inst, initial=((inst.start, 99),))


def test_no_feasible_route_is_infeasible() -> None:
    """When even the empty route misses the deadline, the answer is INFEASIBLE with no plan."""
    xy = np.array([[0.0, 0.0], [5.0, 0.0], [9.0, 0.0]])
    inst = OPTWInstance.from_coordinates(
        xy, [0, 1, 1], np.zeros(3), np.zeros(3), np.full(3, 100.0), decimals=1, end=2, tmax=3.0
    )
    res = solve_labelling(inst, time_limit_s=5.0)
    assert res.status is Status.INFEASIBLE and res.plan is None


def test_c101_proven_fast() -> None:
    """Solomon c101 (m = 1) is proven optimal at 320 within a few seconds."""
    inst = read_optw(DATA / "c101.txt")
    started = time.perf_counter()
    res = solve_labelling(inst, time_limit_s=60.0)
    assert time.perf_counter() - started < 10.0
    assert res.status is Status.OPTIMAL and res.objective == 320.0 and res.bound == 320.0
    assert res.plan is not None and validate(inst, res.plan).feasible


def test_time_limit_honoured() -> None:
    """On a hard instance a 0.5 s limit returns within 2 s with a route and a valid bound."""
    rng = np.random.default_rng(7)
    n = 160
    xy = np.round(rng.uniform(0, 100, size=(n, 2)), 1)
    xy[0] = (50.0, 50.0)
    inst = OPTWInstance.from_coordinates(
        xy, rng.integers(1, 20, size=n), np.full(n, 2.0), np.zeros(n), np.full(n, 400.0),
        decimals=1, name="hard",
    )
    started = time.perf_counter()
    res = solve_labelling(inst, time_limit_s=0.5)
    assert time.perf_counter() - started < 2.0
    assert res.status in (Status.FEASIBLE, Status.NO_SOLUTION)
    if res.plan is not None:
        assert validate(inst, res.plan).feasible
        assert res.bound is not None and res.objective is not None
        assert res.bound >= res.objective


def test_two_vehicles_rejected() -> None:
    """Team instances (vehicles = 2) are refused with an error naming ``vehicles``."""
    inst = random_instance(1).with_vehicles(2)
    with pytest.raises(InvalidInputError, match="vehicles"):
        solve_labelling(inst)


def test_full_label_store_keeps_a_valid_bound(monkeypatch: pytest.MonkeyPatch) -> None:
    """When the label store fills up, the best route so far comes back with a proven bound."""
    import searchtrack.plan.optw.labelling as labelling

    monkeypatch.setattr(labelling, "CAP_MAX", 300)
    inst = read_optw(DATA / "c101.txt")
    res = solve_labelling(inst, time_limit_s=20.0)
    assert res.status in (Status.FEASIBLE, Status.NO_SOLUTION)
    assert "full" in res.message
    if res.plan is not None:
        assert validate(inst, res.plan).feasible
        assert res.bound is not None and res.objective is not None
        assert res.bound >= 320.0 and res.objective <= 320.0
