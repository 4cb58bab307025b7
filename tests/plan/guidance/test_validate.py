"""The guidance family's validator: every strategy's answer passes it; a loitering UAV with no
tracker, a route node off the network and an answer for too few UAVs come back as ERROR."""

from __future__ import annotations

import dataclasses

from searchtrack.core.result import Status
from searchtrack.plan.guidance import BACKENDS, solve
from searchtrack.plan.guidance.validate import answer_problems
from searchtrack.plan.guidance.view import Guidance
from tests.plan.guidance.test_solve import NAMES, _path, _problem


def test_validator_rejects_wrong_guidance() -> None:
    """Each backend's answer passes; a loitering UAV with no tracker, a route node off the
    network and too few forces are named, and the registry turns them into ERROR."""
    net = _path(10)
    problem = _problem(net, [[20.0, 5.0], [70.0, 5.0]], [(2, 0.9)])
    for backend in NAMES:
        result = solve(problem, backend=backend, time_limit_s=1.0, seed=0)
        assert result.plan is not None and answer_problems(problem, result) == [], backend
    good = solve(problem, backend="search", time_limit_s=1.0, seed=0)
    plan = good.plan
    assert plan is not None
    loiter = dataclasses.replace(good, plan=dataclasses.replace(
        plan, mode=("loiter", "search"), pairing=plan.pairing.none(2)))
    assert any("paired with no tracker" in p for p in answer_problems(problem, loiter))
    assert BACKENDS.validated(problem, loiter).status is Status.ERROR
    off = dataclasses.replace(good, plan=dataclasses.replace(plan, route=((99,), ())))
    assert any("outside the network" in p for p in answer_problems(problem, off))
    few = dataclasses.replace(good, plan=Guidance(plan.force[:1], plan.pairing.none(1),
                                                  plan.mode[:1], plan.route[:1]))
    assert any("the view has 2" in p for p in answer_problems(problem, few))
