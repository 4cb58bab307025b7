"""The trajectory family's validator: every controller's answer passes it; an input outside the
model's box, states that start elsewhere and a horizon of the wrong length come back as ERROR."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.trajectory import BACKENDS, ControlPlan, TrackingProblem, solve
from searchtrack.plan.trajectory.validate import answer_problems


@pytest.mark.parametrize("backend", ["closed_form", "ltv_mpc", "nmpc", "auto"])
def test_every_controller_passes(course: TrackingProblem, backend: str) -> None:
    """The answer of each controller on the course holds."""
    result = solve(course, backend=backend, time_limit_s=5.0)
    assert result.status is not Status.ERROR, result.message
    assert result.plan is not None and answer_problems(course, result) == []


def test_wrong_plans_are_rejected(course: TrackingProblem) -> None:
    """Each corruption is named; the registry turns it into ERROR."""
    good = solve(course, backend="ltv_mpc", time_limit_s=5.0)
    assert good.plan is not None
    plan = good.plan
    upper = np.asarray(course.model.input_upper, dtype=float)
    i = int(np.flatnonzero(np.isfinite(upper))[0])
    inputs = plan.inputs.copy()
    inputs[0, i] = upper[i] + 1.0
    fast = dataclasses.replace(good, plan=ControlPlan(inputs, plan.states, plan.dt_s, "x"))
    assert any(f"input {i} leaves" in p for p in answer_problems(course, fast))
    assert BACKENDS.validated(course, fast).status is Status.ERROR
    states = plan.states.copy()
    states[0] += 1.0
    moved = dataclasses.replace(good, plan=ControlPlan(plan.inputs, states, plan.dt_s, "x"))
    assert any("start" in p for p in answer_problems(course, moved))
    short = dataclasses.replace(good, plan=ControlPlan(plan.inputs[:-1], plan.states[:-1],
                                                       plan.dt_s, "x"))
    assert any("want" in p for p in answer_problems(course, short))
