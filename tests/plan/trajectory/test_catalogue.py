"""Every registered controller on the known-answer problem: a unicycle on a free line at its own
speed, whose best input is to keep cruising; and every controller keeps its limits near an
obstacle and on the 3-D fixed-wing model."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core import Status
from searchtrack.models.vehicles import fixed_wing
from searchtrack.plan.trajectory import BACKENDS, Obstacles, TrackingProblem, solve, waypoint_path
from tests.plan.trajectory.plans import check_limits, small_problem


@pytest.mark.parametrize("backend", BACKENDS.names())
def test_every_controller_cruises_on_the_reference(backend: str) -> None:
    """On the line at 10 m/s every controller answers with u = (10 m/s, 0) first and keeps the
    limits; its result names the controller that answered."""
    problem = small_problem(obstacles=Obstacles(), horizon=8)
    result = solve(problem, backend=backend, time_limit_s=5.0)
    assert result.status in (Status.OPTIMAL, Status.FEASIBLE) and result.plan is not None
    np.testing.assert_allclose(result.plan.inputs[0], [10.0, 0.0], atol=1e-3)
    check_limits(problem, result.plan)
    assert result.backend in BACKENDS.names() and result.backend != "auto"
    if backend != "auto":
        assert result.backend == backend


@pytest.mark.parametrize("backend", BACKENDS.names())
def test_every_controller_keeps_its_limits_near_an_obstacle(backend: str) -> None:
    """With a cylinder on the line every controller still returns a plan within its input box
    and rate limits, starting at the state."""
    problem = small_problem(horizon=10)
    result = solve(problem, backend=backend, time_limit_s=5.0)
    assert result.plan is not None, result.message
    check_limits(problem, result.plan)


@pytest.mark.parametrize("backend", BACKENDS.names())
def test_every_controller_flies_the_fixed_wing(backend: str) -> None:
    """On the 3-D fixed-wing model level on a straight climb-free line every controller returns
    a plan within the model's limits."""
    problem = TrackingProblem(fixed_wing(), np.array([0.0, 0.0, 50.0, 0.0, 0.0]),
                              waypoint_path([[0, 0, 50], [300, 0, 50]], 15.0), horizon=8)
    result = solve(problem, backend=backend, time_limit_s=5.0)
    assert result.plan is not None, result.message
    check_limits(problem, result.plan)
