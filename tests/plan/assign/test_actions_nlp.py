"""Fixed-wing motion primitives, the Gaussian footprint and the NLP backend."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.assign import (
    AssignmentProblem,
    FixedWingPrimitives,
    fixed_wing_actions,
    solve,
)
from searchtrack.plan.assign.nlp import NLPLimits, solve_nlp


def test_straight_primitive_matches_kinematics() -> None:
    """Zero rates fly straight at v for steps × step_s seconds; turns keep the speed."""
    prim = FixedWingPrimitives(speeds_mps=(2.0,), yaw_rates_rps=(0.0, 0.2),
                               pitch_rates_rps=(0.0,), steps=2, step_s=5.0)
    acts = fixed_wing_actions(np.array([0.0, 0.0, 10.0, 0.0, 0.0]), prim)
    assert acts.shape == (2, 2, 5)
    np.testing.assert_allclose(acts[0, :, :3], [[10.0, 0.0, 10.0], [20.0, 0.0, 10.0]], atol=1e-9)
    chord = np.linalg.norm(acts[1, 0, :2])
    assert chord < 10.0 and chord > 9.0
    assert acts[1, 1, 3] == pytest.approx(2.0, abs=1e-6)


def test_altitude_limits_prune_primitives() -> None:
    """Climbing or diving out of the altitude band removes the primitive."""
    prim = FixedWingPrimitives(speeds_mps=(5.0,), yaw_rates_rps=(0.0,),
                               pitch_rates_rps=(-0.2, 0.0, 0.2), z_min_m=8.0, z_max_m=12.0)
    acts = fixed_wing_actions(np.array([0.0, 0.0, 10.0, 0.0, 0.0]), prim)
    assert acts.shape[0] == 1
    assert acts[0, 0, 2] == pytest.approx(10.0)


def test_primitives_fly_the_vehicle_model() -> None:
    """The primitives are Euler steps of 003's kinematics written out by hand, with the pitch
    clipped and the yaw wrapped; the vehicle model carries the band and the pitch limit."""
    prim = FixedWingPrimitives(speeds_mps=(3.0,), yaw_rates_rps=(0.25,), pitch_rates_rps=(0.05,),
                               steps=3, step_s=2.0, euler_dt_s=0.1, max_pitch_rad=0.15)
    state = np.array([5.0, -3.0, 20.0, 3.0, 0.1])
    acts = fixed_wing_actions(state, prim)
    x, y, z, yaw, pitch = state
    expected = []
    for _ in range(3):
        for _ in range(20):
            x += 0.1 * 3.0 * np.cos(pitch) * np.cos(yaw)
            y += 0.1 * 3.0 * np.cos(pitch) * np.sin(yaw)
            z += 0.1 * 3.0 * np.sin(pitch)
            yaw += 0.1 * 0.25
            pitch = min(pitch + 0.1 * 0.05, 0.15)
        expected.append([x, y, z, (yaw + np.pi) % (2 * np.pi) - np.pi, pitch])
    np.testing.assert_allclose(acts[0], expected, rtol=0.0, atol=1e-12)
    model = prim.vehicle
    assert (model.state_lower[2], model.state_upper[2]) == (2.0, 50.0)
    assert (model.state_lower[4], model.state_upper[4]) == (-0.15, 0.15)
    assert model.input_lower == model.input_upper == (3.0, 0.25, 0.05)


def test_primitives_bad_input() -> None:
    """Bad control grids and bands raise naming the field."""
    with pytest.raises(InvalidInputError, match="speeds_mps"):
        FixedWingPrimitives(speeds_mps=(0.0,))
    with pytest.raises(InvalidInputError, match="z_max_m"):
        FixedWingPrimitives(z_min_m=10.0, z_max_m=5.0)
    with pytest.raises(InvalidInputError, match="max_pitch_rad"):
        FixedWingPrimitives(max_pitch_rad=2.0)
    with pytest.raises(InvalidInputError, match="state"):
        fixed_wing_actions(np.zeros(3), FixedWingPrimitives())


def _nlp_problem(separation: float = 0.0) -> AssignmentProblem:
    rng = np.random.default_rng(4)
    origins = np.array([[0.0, 0.0, 20.0], [20.0, 0.0, 20.0]])
    prim = FixedWingPrimitives(speeds_mps=(2.0,), steps=2, step_s=5.0, euler_dt_s=0.1)
    acts = tuple(fixed_wing_actions(np.array([*o, 0.0, 0.0]), prim) for o in origins)
    pos = np.concatenate([rng.normal([25.0, 10.0], 3.0, size=(80, 2)),
                          rng.normal([5.0, -8.0], 3.0, size=(80, 2))])
    w = np.full(160, 4.0 / 160)
    return AssignmentProblem(acts, WeightedParticles(pos, w), GaussianFieldOfView(0.9, 8.0, 60.0),
                             min_separation_m=separation, origins=origins)


def test_nlp_improves_greedy_within_limits() -> None:
    """The NLP keeps the step, altitude and separation limits and does not lose END."""
    p = _nlp_problem(separation=6.0)
    greedy = solve(p, backend="greedy")
    res = solve_nlp(p, NLPLimits(max_step_m=10.0, z_min_m=10.0, z_max_m=30.0), time_limit_s=10.0)
    assert res.status is Status.FEASIBLE and res.plan is not None
    assert res.objective is not None and greedy.objective is not None
    assert res.objective >= greedy.objective - 1e-9
    q = res.plan.poses[:, :, :3]
    chain = np.concatenate([p.origins[:, None, :3], q], axis=1)  # type: ignore[index]
    assert np.all(np.linalg.norm(np.diff(chain, axis=1), axis=2) <= 10.0 + 1e-4)
    assert np.all((q[:, :, 2] >= 10.0 - 1e-6) & (q[:, :, 2] <= 30.0 + 1e-6))
    assert np.all(np.linalg.norm(q[0] - q[1], axis=1) >= 6.0 - 1e-4)


def test_nlp_needs_smooth_sensor() -> None:
    """The NLP backend refuses a sensor without a CasADi expression."""
    from .helpers import random_problem

    p = random_problem(np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="casadi"):
        solve(p, backend="nlp")


def test_nlp_through_registry_uses_inferred_limits() -> None:
    """solve(backend='nlp') infers the step and altitude limits from the candidate actions."""
    p = _nlp_problem()
    res = solve(p, backend="nlp", time_limit_s=10.0)
    assert res.status is Status.FEASIBLE and res.plan is not None
    zs = np.concatenate([a[:, :, 2].ravel() for a in p.actions])
    q = res.plan.poses[:, :, :3]
    assert np.all((q[:, :, 2] >= zs.min() - 1e-6) & (q[:, :, 2] <= zs.max() + 1e-6))
    assert res.plan.poses.shape == (2, 2, 5)
