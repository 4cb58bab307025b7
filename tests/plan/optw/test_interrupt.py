"""A stop request (what Ctrl-C sends) ends every OPTW backend early with INTERRUPTED and the best
plan and bound found so far."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core import Status
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.plan.optw import OPTWInstance, read_optw, validate
from searchtrack.plan.optw.solve import solve, warm_up

DATA = Path(__file__).parents[3] / "searchtrack" / "data" / "optw"


def _wide(n: int = 200) -> OPTWInstance:
    """A wide-window instance the labelling DP cannot prove within a second."""
    rng = np.random.default_rng(0)
    xy = rng.uniform(0.0, 100.0, (n, 2))
    profit = np.concatenate([[0.0], rng.integers(1, 10, n - 1)])
    return OPTWInstance.from_coordinates(xy, profit, np.zeros(n), np.zeros(n), np.full(n, 400.0),
                                         decimals=1, start=0, end=0, tmax=400.0, name="wide")


CASES = [("ils", "r101", 1), ("labelling", "wide", 1), ("cpsat", "c101", 3),
         ("mip", "c101", 1), ("auto", "rc101", 2)]


@pytest.fixture(autouse=True)
def _clean_flag() -> Iterator[None]:
    clear_stop()
    yield
    clear_stop()


@pytest.mark.parametrize(("backend", "name", "vehicles"), CASES,
                         ids=[f"{b}-{n}-m{m}" for b, n, m in CASES])
def test_stop_request_ends_the_solve(backend: str, name: str, vehicles: int) -> None:
    """Stopped 0.5 s into a 60 s solve, the backend returns within seconds: INTERRUPTED (or a
    proof found just in time) with a plan that validates, if any, under its bound."""
    inst = _wide() if name == "wide" else read_optw(DATA / f"{name}.txt")
    inst = replace(inst, vehicles=vehicles)
    warm_up(backend)
    timer = threading.Timer(0.5, request_stop)
    timer.start()
    started = time.perf_counter()
    result = solve(inst, backend=backend, time_limit_s=60.0, seed=0)
    waited = time.perf_counter() - started
    timer.join()
    assert result.status in (Status.INTERRUPTED, Status.OPTIMAL), result.message
    assert waited < 20.0, f"{backend} took {waited:.1f} s to stop"
    if result.plan is not None:
        check = validate(inst, result.plan)
        assert check.feasible and check.profit == pytest.approx(result.objective)
        assert result.bound is None or result.bound >= check.profit - 1e-9
