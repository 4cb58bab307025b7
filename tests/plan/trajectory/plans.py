"""Shared by the controller tests: a small unicycle problem and checks of a plan's limits."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from searchtrack.models.vehicles import unicycle
from searchtrack.plan.trajectory import ControlPlan, Obstacles, TrackingProblem, waypoint_path

TOL = 1e-4


def check_limits(problem: TrackingProblem, plan: ControlPlan) -> None:
    """Assert that ``plan`` keeps the input box and rate limits and starts at the state."""
    m = problem.model
    assert np.all(plan.inputs >= np.asarray(m.input_lower) - TOL)
    assert np.all(plan.inputs <= np.asarray(m.input_upper) + TOL)
    steps = np.diff(np.vstack([problem.u_prev, plan.inputs]), axis=0)
    assert np.all(np.abs(steps) <= np.asarray(m.input_rate_max) * problem.dt_s + TOL)
    np.testing.assert_allclose(plan.states[0], problem.state)


def clearance(problem: TrackingProblem, plan: ControlPlan) -> float:
    """Least distance (m) from a predicted position to an obstacle surface."""
    pos = plan.states[1:, list(problem.model.position_indices)]
    return float(problem.obstacles.clearance_m(pos).min())


def small_problem(**changes: object) -> TrackingProblem:
    """A unicycle at the origin on a 50 m eastward line with one cylinder on it, with
    ``changes`` applied."""
    base = TrackingProblem(unicycle(), np.array([0.0, 0.0, 0.0]),
                           waypoint_path([[0, 0], [50, 0]], 10.0),
                           obstacles=Obstacles(centers_m=[[20, 0]], radii_m=[3.0]))
    return replace(base, **changes)  # type: ignore[arg-type]
