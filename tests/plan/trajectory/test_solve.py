"""The trajectory registry and ``auto``: who answers, and the fallbacks when NMPC cannot."""

from __future__ import annotations

import importlib
import math
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Sense, Status
from searchtrack.models.vehicles import VehicleModel, unicycle
from searchtrack.plan.trajectory import BACKENDS, ControlPlan, TrackingProblem, solve
from tests.plan.trajectory.plans import small_problem

solve_module = importlib.import_module("searchtrack.plan.trajectory.solve")


def test_registry_lists_the_controllers() -> None:
    """The registry offers auto, nmpc, ltv_mpc and closed_form."""
    assert BACKENDS.names() == ["auto", "nmpc", "ltv_mpc", "closed_form"]


def test_auto_answers_with_the_real_time_iteration(course: TrackingProblem) -> None:
    """auto's answer comes from the real-time iteration (the QP) and no fallback fires."""
    result = solve(course, backend="auto", time_limit_s=5.0)
    assert result.backend == "ltv_mpc" and result.plan is not None
    assert result.stats["fallbacks"] == 0.0


def _failing(problem: TrackingProblem, *, time_limit_s: float) -> Result[ControlPlan]:
    return Result(Status.NO_SOLUTION, None, None, 0.0, "x", None, Sense.MINIMIZE, "forced")


def test_auto_falls_back_to_nmpc_when_the_qp_fails(
        course: TrackingProblem, monkeypatch: pytest.MonkeyPatch) -> None:
    """When the real-time iteration has no plan (e.g. it would enter an obstacle), NMPC
    answers in the time left."""
    monkeypatch.setattr(solve_module, "solve_ltv_mpc", _failing)
    result = solve(course, backend="auto", time_limit_s=5.0)
    assert result.backend == "nmpc" and result.plan is not None and result.status.has_plan
    assert "ltv_mpc failed" in result.message and result.stats["fallbacks"] == 1.0


def test_auto_reaches_the_closed_form_when_the_qp_and_nmpc_fail(
        course: TrackingProblem, monkeypatch: pytest.MonkeyPatch) -> None:
    """If the QP and NMPC both fail, the closed form answers and the message says so."""
    monkeypatch.setattr(solve_module, "solve_nmpc", _failing)
    monkeypatch.setattr(solve_module, "solve_ltv_mpc", _failing)
    result = solve(course, backend="auto", time_limit_s=0.05)
    assert result.backend == "closed_form" and result.plan is not None
    assert "nmpc failed" in result.message and "ltv_mpc failed" in result.message
    assert result.stats["fallbacks"] == 2.0


def _glider(course: TrackingProblem) -> TrackingProblem:
    base = unicycle()
    other = VehicleModel("glider", base.state_names, base.input_names, base.dynamics,
                         base.state_lower, base.state_upper, base.input_lower, base.input_upper,
                         base.input_rate_max, base.nominal_input, base.position_indices)
    return replace(course, model=other)


def test_closed_form_needs_a_known_model(course: TrackingProblem) -> None:
    """A model without a closed-form law is refused by closed_form; auto still flies it with
    NMPC or the QP."""
    problem = _glider(course)
    with pytest.raises(InvalidInputError, match="closed-form"):
        solve(problem, backend="closed_form")
    assert solve(problem, backend="ltv_mpc", time_limit_s=5.0).plan is not None
    result = solve(problem, backend="auto", time_limit_s=5.0)
    assert result.backend == "ltv_mpc" and result.plan is not None
    assert np.isfinite(problem.state).all()


def test_auto_without_a_closed_form_reports_the_failure(
        course: TrackingProblem, monkeypatch: pytest.MonkeyPatch) -> None:
    """When NMPC and the QP fail on a model with no closed form, auto returns no plan and says
    why instead of raising."""
    monkeypatch.setattr(solve_module, "solve_nmpc", _failing)
    monkeypatch.setattr(solve_module, "solve_ltv_mpc", _failing)
    result = solve(_glider(course), backend="auto", time_limit_s=0.05)
    assert result.plan is None and not result.status.has_plan
    assert "no closed-form law" in result.message


def test_solve_rejects_bad_backend_and_time_limit() -> None:
    """Unknown backends and non-positive time limits raise InvalidInputError."""
    problem = small_problem()
    with pytest.raises(InvalidInputError, match="backend"):
        solve(problem, backend="simplex")
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(problem, backend="nmpc", time_limit_s=-1.0)
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(problem, backend="auto", time_limit_s=math.nan)


@pytest.mark.parametrize("backend", ["nmpc", "ltv_mpc", "closed_form"])
def test_a_named_backend_answers_itself(course: TrackingProblem, backend: str) -> None:
    """Asking for one controller gets that controller's plan, with no fallback."""
    result = solve(course, backend=backend, time_limit_s=5.0)
    assert result.backend == backend and result.plan is not None
    assert result.plan.controller == backend
