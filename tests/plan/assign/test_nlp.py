"""The NLP backend (CasADi + Ipopt): limits kept, END not lost, limits inferred from the
candidates, and the problems and limits it refuses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.assign import (
    AssignmentProblem,
    FixedWingPrimitives,
    MutualInformation,
    fixed_wing_actions,
    solve,
)
from searchtrack.plan.assign.nlp import NLPLimits, nlp_supports, solve_nlp

from .helpers import random_problem


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


def test_nlp_supports() -> None:
    """END with a CasADi sensor is accepted; MI or a sensor without ``casadi_detection`` is
    refused with the reason."""
    p = _nlp_problem()
    assert nlp_supports(p) is None
    mi = AssignmentProblem(p.actions, p.belief, p.sensor, objective=MutualInformation())
    assert "END" in (nlp_supports(mi) or "")
    assert "casadi_detection" in (nlp_supports(random_problem(np.random.default_rng(0))) or "")
    with pytest.raises(InvalidInputError, match="problem"):
        solve_nlp(mi)


def test_nlp_limits_bad_input() -> None:
    """Non-finite, non-positive or negative limits raise naming the field; an inverted altitude
    band is refused once resolved against the problem."""
    with pytest.raises(InvalidInputError, match="max_step_m"):
        NLPLimits(max_step_m=0.0)
    with pytest.raises(InvalidInputError, match="separation_m"):
        NLPLimits(separation_m=-1.0)
    with pytest.raises(InvalidInputError, match="z_min_m"):
        NLPLimits(z_min_m=math.nan)
    with pytest.raises(InvalidInputError, match="z_max_m"):
        NLPLimits(z_max_m="high")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="z_max_m"):
        solve_nlp(_nlp_problem(), NLPLimits(z_min_m=30.0, z_max_m=10.0))


def test_nlp_with_one_candidate_keeps_the_greedy_end_or_better() -> None:
    """One candidate per UAV at 20 m over a cluster 5 m aside: the NLP may move the waypoint
    within a 5 m step of the origin and never reports less than the candidate's END."""
    origins = np.array([[0.0, 0.0, 20.0]])
    acts = (np.array([[[0.0, 0.0, 20.0, 0.0, 0.0]]]),)
    pos = np.array([[5.0, 0.0], [5.0, 1.0]])
    sensor = GaussianFieldOfView(0.9, 8.0, 60.0)
    p = AssignmentProblem(acts, WeightedParticles(pos, np.ones(2)), sensor, origins=origins)
    res = solve_nlp(p, NLPLimits(max_step_m=5.0), time_limit_s=10.0)
    assert res.status is Status.FEASIBLE and res.plan is not None and res.objective is not None
    assert res.objective >= res.stats["greedy_objective"] - 1e-12
    q = res.plan.poses[0, 0, :3]
    assert np.linalg.norm(q - origins[0]) <= 5.0 + 1e-4
    assert q[2] == pytest.approx(20.0, abs=1e-6)  # band inferred from the one candidate
    assert res.objective > res.stats["greedy_objective"]  # it moved towards the cluster
