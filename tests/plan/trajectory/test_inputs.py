"""Obstacles, references and tracking problems: geometry and bad-input errors."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import fixed_wing, unicycle
from searchtrack.plan.trajectory import Obstacles, SampledPath, TrackingProblem, waypoint_path
from searchtrack.plan.trajectory.solve import solve


def test_sphere_and_cylinder_distances() -> None:
    """A sphere measures 3-D distance, a vertical cylinder only the horizontal one."""
    obs = Obstacles(centers_m=[[0, 0, 0], [0, 0, 0]], radii_m=[1, 1],
                    cylinder=np.array([False, True]))
    d = obs.distance_m([[0, 0, 5]])
    np.testing.assert_allclose(d, [[4.0, -1.0]])
    np.testing.assert_allclose(obs.distance_m([[3, 4]]), [[4.0, 4.0]])
    assert Obstacles().clearance_m([[1, 2]])[0] == math.inf
    assert obs.parameters(2, 0.5)[:, 4].tolist() == [0.0, 0.0]  # planar: all cylinders


def test_obstacle_bad_input() -> None:
    """Non-positive radii, ragged centres and wrong flag counts are rejected."""
    with pytest.raises(InvalidInputError, match="radii_m"):
        Obstacles(centers_m=[[0, 0, 0]], radii_m=[0.0])
    with pytest.raises(InvalidInputError, match="centers_m"):
        Obstacles(centers_m=[[0, 0, 0, 0]], radii_m=[1.0])
    with pytest.raises(InvalidInputError, match="cylinder"):
        Obstacles(centers_m=[[0, 0, 0]], radii_m=[1.0], cylinder=np.array([True, False]))


def test_waypoint_path_is_flown_at_constant_speed_and_held() -> None:
    """waypoint_path reaches each corner at arc length / speed and holds the last point."""
    ref = waypoint_path([[0, 0], [10, 0], [10, 10]], 5.0)
    assert ref.duration_s == pytest.approx(4.0)
    np.testing.assert_allclose(ref.positions([1.0, 2.0, 3.0, 9.0]),
                               [[5, 0], [10, 0], [10, 5], [10, 10]])
    with pytest.raises(InvalidInputError, match="speed_mps"):
        waypoint_path([[0, 0], [1, 1]], 0.0)
    with pytest.raises(InvalidInputError, match="times_s"):
        SampledPath(times_s=np.array([0.0, 0.0]), positions_m=np.zeros((2, 2)))


def _problem(**changes: object) -> TrackingProblem:
    base = TrackingProblem(unicycle(), np.array([0.0, 0.0, 0.0]),
                           waypoint_path([[0, 0], [50, 0]], 10.0),
                           obstacles=Obstacles(centers_m=[[20, 0]], radii_m=[3.0]))
    return replace(base, **changes)  # type: ignore[arg-type]


def test_infeasible_starts_and_bad_fields_are_rejected() -> None:
    """A start inside an obstacle, NaN, bad horizon, rates and reference sizes name the field."""
    with pytest.raises(InvalidInputError, match="inside obstacle 0"):
        _problem(state=np.array([21.0, 0.0, 0.0]))
    with pytest.raises(InvalidInputError, match="state"):
        _problem(state=np.array([math.nan, 0.0, 0.0]))
    with pytest.raises(InvalidInputError, match="horizon"):
        _problem(horizon=-3)
    with pytest.raises(InvalidInputError, match="dt_s"):
        _problem(dt_s=0.0)
    with pytest.raises(InvalidInputError, match="previous_input"):
        _problem(previous_input=np.array([100.0, 0.0]))
    with pytest.raises(InvalidInputError, match="reference"):
        _problem(reference=waypoint_path([[0, 0, 0], [1, 0, 0]], 1.0))
    with pytest.raises(InvalidInputError, match="pitch_rad"):
        TrackingProblem(fixed_wing(), np.array([0, 0, 10, 0, 1.2]),
                        waypoint_path([[0, 0, 10], [1, 0, 10]], 1.0))
    with pytest.raises(InvalidInputError, match="z_m"):
        TrackingProblem(fixed_wing(), np.array([0, 0, 80, 0, 0.0]),
                        waypoint_path([[0, 0, 10], [1, 0, 10]], 1.0))


def test_solve_rejects_bad_backend_and_time_limit() -> None:
    """Unknown backends and non-positive time limits raise InvalidInputError."""
    problem = _problem()
    with pytest.raises(InvalidInputError, match="backend"):
        solve(problem, backend="simplex")
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(problem, backend="nmpc", time_limit_s=-1.0)
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(problem, backend="auto", time_limit_s=math.nan)


def test_option_and_weight_objects_validate() -> None:
    """NmpcOptions, TrackingWeights and ClosedFormGains reject out-of-domain values by name."""
    from searchtrack.plan.trajectory import ClosedFormGains, NmpcOptions, TrackingWeights

    with pytest.raises(InvalidInputError, match="solver"):
        NmpcOptions(solver="fatrop")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="max_iter"):
        NmpcOptions(max_iter=0)
    with pytest.raises(InvalidInputError, match="tol"):
        NmpcOptions(tol=-1.0)
    with pytest.raises(InvalidInputError, match="effort"):
        TrackingWeights(effort=-0.1)
    with pytest.raises(InvalidInputError, match="backstepping"):
        ClosedFormGains(backstepping=(1.0, 0.0, 1.0))
    with pytest.raises(InvalidInputError, match="obstacle_turn"):
        ClosedFormGains(obstacle_turn="left")  # type: ignore[arg-type]


def test_unloadable_linear_solver_is_refused_when_the_solver_is_built() -> None:
    """A linear solver Ipopt cannot load (here: not a solver at all) is an InvalidInputError
    naming ``linear_solver`` at build time, not an Ipopt failure on every step."""
    from searchtrack.models.vehicles import unicycle
    from searchtrack.plan.trajectory import NmpcOptions, TrackingProblem, solve_nmpc, waypoint_path

    problem = TrackingProblem(unicycle(), np.array([0.0, -3.0, 0.0]),
                              waypoint_path([[0, 0], [50, 0]], 10.0), horizon=5)
    with pytest.raises(InvalidInputError, match="linear_solver"):
        solve_nmpc(problem, time_limit_s=1.0, options=NmpcOptions(linear_solver="no_such"))
