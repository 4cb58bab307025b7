"""NMPC and the LTV-MPC QP together on the 3-D vehicles: bounds and clearance of a sphere."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models.vehicles import fixed_wing, uav7
from searchtrack.plan.trajectory import (
    Obstacles,
    TrackingProblem,
    solve_ltv_mpc,
    solve_nmpc,
    waypoint_path,
)
from tests.plan.trajectory.plans import check_limits, clearance


@pytest.mark.parametrize("make", [fixed_wing, uav7])
def test_3d_models_get_feasible_plans(make: object) -> None:
    """Fixed-wing and 7-state UAV: NMPC and QP plans respect bounds and avoid a sphere."""
    model = make()  # type: ignore[operator]
    up = -1.0 if model.name == "uav7" else 1.0  # uav7 is NED
    state = np.zeros(model.nx)
    state[2] = 20.0 * up
    if model.name == "uav7":
        state[3] = 15.0
    ref = waypoint_path([[0, 0, 20 * up], [200, 0, 20 * up]], float(model.nominal_input[0])
                        if model.name != "uav7" else 15.0)
    problem = TrackingProblem(model, state, ref, obstacles=Obstacles(
        centers_m=[[15, 0.7, 20 * up]], radii_m=[3.0], cylinder=np.array([False])))
    for result in (solve_nmpc(problem, time_limit_s=5.0), solve_ltv_mpc(problem, time_limit_s=5.0)):
        assert result.plan is not None, result.message
        check_limits(problem, result.plan)
        assert clearance(problem, result.plan) >= problem.safety_margin_m - 1e-3
