"""solve(): every backend on the catalogue, validator-backed results, and auto's hand-over."""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw import OPTWInstance, Routes, read_optw, validate
from searchtrack.plan.optw.solve import BACKENDS, checked, heuristic_share, solve
from tests.plan.optw.catalogue import brute_force

DATA = Path(__file__).parents[2] / "data" / "optw"


def _random(seed: int, n: int, vehicles: int, end: int | None) -> OPTWInstance:
    rng = np.random.default_rng(seed)
    xy = np.round(rng.uniform(0, 20, size=(n, 2)), 2)
    opn = rng.integers(0, 30, size=n).astype(float)
    opn[0] = 0
    close = opn + rng.integers(5, 40, size=n)
    close[0] = 80
    return OPTWInstance.from_coordinates(
        xy, profit=rng.integers(1, 10, size=n).astype(float), service=rng.integers(0, 4, size=n),
        open=opn, close=close, decimals=1, vehicles=vehicles, end=end, tmax=60,
        name=f"rand{seed}",
    )


CASES = [(s, n, m, end) for s, n, m, end in
         [(1, 7, 1, 0), (2, 8, 1, 0), (3, 7, 2, 0), (4, 8, 1, None), (5, 7, 2, 3), (6, 6, 3, 0)]]


@pytest.mark.parametrize("backend", BACKENDS.names())
@pytest.mark.parametrize("case", CASES, ids=[f"s{c[0]}n{c[1]}m{c[2]}e{c[3]}" for c in CASES])
def test_every_backend_on_the_catalogue(backend: str, case: tuple[int, int, int, int | None]
                                        ) -> None:
    """Each backend returns a validated plan; exact ones prove the brute-force optimum."""
    inst = _random(*case)
    if BACKENDS.get(backend).supports(inst) is not None:
        with pytest.raises(InvalidInputError, match="backend"):
            solve(inst, backend=backend, time_limit_s=1.0)
        return
    exact = BACKENDS.get(backend).exact
    # the exact backends get time to prove; the heuristic stops at its limit when it cannot
    res = solve(inst, backend=backend, time_limit_s=5.0 if exact else 0.5, seed=1)
    best = brute_force(inst)
    assert res.plan is not None and validate(inst, res.plan).feasible
    assert res.objective is not None and res.objective <= best + 1e-9
    if exact:
        assert res.status is Status.OPTIMAL and res.objective == pytest.approx(best)
    if res.bound is not None:
        assert res.bound >= best - 1e-9


def test_auto_says_who_answered() -> None:
    """auto proves c101's optimum and names the backend whose plan it returns."""
    inst = read_optw(DATA / "c101.txt")
    res = solve(inst, backend="auto", time_limit_s=30.0)
    assert res.status is Status.OPTIMAL and res.objective == 320
    assert res.backend in {"ils", "labelling"} and res.message.startswith("auto:")


@pytest.mark.parametrize("limit_s", [0.002, 0.01, 0.03])
def test_auto_heuristic_share_leaves_time_for_the_exact_solver(limit_s: float) -> None:
    """auto's heuristic share never exceeds half of a short limit, so the ILS alone cannot
    overrun it (a 10 ms limit used to give the ILS 20 ms)."""
    assert heuristic_share(limit_s) <= 0.5 * limit_s
    assert heuristic_share(100.0) == pytest.approx(1.0)
    assert heuristic_share(1.0) == pytest.approx(0.1)


def test_checked_turns_a_bad_plan_into_error() -> None:
    """A plan the validator rejects (or a misreported profit) becomes an ERROR result."""
    inst = _random(1, 7, 1, 0)
    bad: Result[Routes] = Result(Status.FEASIBLE, 1.0, None, 0.1, "fake", plan=((0, 1, 1, 0),))
    out = checked(inst, bad)
    assert out.status is Status.ERROR and "already visited" in out.message
    lie: Result[Routes] = Result(Status.FEASIBLE, 99.0, None, 0.1, "fake", plan=((0, 0),))
    assert checked(inst, lie).status is Status.ERROR


def test_unreachable_instance_has_empty_optimal_plan() -> None:
    """When nothing is reachable every backend returns profit 0 with empty routes, no error."""
    inst = OPTWInstance.from_coordinates(
        [[0, 0], [50, 0], [0, 60]], profit=[0, 5, 6], service=[0, 1, 1], open=[0, 0, 0],
        close=[10, 100, 100], decimals=1,
    )
    for backend in BACKENDS.names():
        res = solve(inst, backend=backend, time_limit_s=2.0)
        assert res.objective == 0 and res.plan is not None
        assert all(len(r) == 2 for r in res.plan)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"backend": "nope"}, "backend"), ({"time_limit_s": -1.0}, "time_limit_s"),
    ({"seed": -3}, "seed")])
def test_bad_arguments(kwargs: dict[str, object], field: str) -> None:
    """Unknown backends, bad limits and bad seeds raise InvalidInputError naming the argument."""
    with pytest.raises(InvalidInputError) as info:
        solve(_random(1, 5, 1, 0), **kwargs)  # type: ignore[arg-type]
    assert info.value.field == field


def test_a_limit_spent_loading_or_tools_keeps_the_ils_answer(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """While OR-Tools is still loading when the limit runs out, its backends answer NO_SOLUTION
    and ``auto`` with two vehicles the ILS's plan, unproved; one vehicle needs no OR-Tools."""
    solve_module = importlib.import_module("searchtrack.plan.optw.solve")

    monkeypatch.setattr(solve_module, "loaded_within", lambda name, deadline: False)
    team = _random(8, 12, 2, 0)   # the ILS does not prove it
    for backend in ("cpsat", "bp", "mip"):
        res = solve(team, backend=backend, time_limit_s=1.0)
        assert res.status is Status.NO_SOLUTION and "OR-Tools" in res.message, backend
    auto = solve(team, backend="auto", time_limit_s=1.0, seed=1)
    assert auto.status is Status.FEASIBLE and auto.backend == "ils"
    one = _random(1, 7, 1, 0)
    assert solve(one, backend="auto", time_limit_s=5.0).status is Status.OPTIMAL
