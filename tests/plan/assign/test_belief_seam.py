"""The belief seam: the planners read a ParticleBelief, whichever implementation holds it."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.types import FloatArray
from searchtrack.estimate.particle_belief import ParticleBelief, WeightedParticles
from searchtrack.estimate.phd import PHDState
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan import assign, search

from .helpers import DiscSensor, random_problem


class ListBelief:
    """A test-local belief that keeps its particles as Python lists."""

    def __init__(self, positions: FloatArray, weights: FloatArray) -> None:
        self._positions = positions.tolist()
        self._weights = weights.tolist()

    @property
    def positions(self) -> FloatArray:
        return np.array(self._positions)

    @property
    def weights(self) -> FloatArray:
        return np.array(self._weights)

    def expected_count(self) -> float:
        return float(sum(self._weights))


def beliefs(positions: FloatArray, weights: FloatArray) -> list[ParticleBelief]:
    """The same particles as the PHD filter's state (positions a view of wider states), as
    :class:`WeightedParticles` and as a test-local class."""
    n, p = positions.shape
    velocities = np.random.default_rng(9).normal(size=(n, p))
    state = PHDState.from_particles(np.hstack([positions, velocities]), weights, position_dim=p)
    out: list[ParticleBelief] = [state, WeightedParticles(positions, weights),
                                 ListBelief(positions, weights)]
    assert all(isinstance(b, ParticleBelief) for b in out)
    return out


@pytest.mark.parametrize("objective", [assign.ExpectedDetections(), assign.MutualInformation()])
def test_assignment_answers_do_not_depend_on_the_belief_class(
        objective: assign.Objective) -> None:
    """Every assignment backend gives the same status, value and plan on the three beliefs."""
    base = random_problem(np.random.default_rng(21), robots=3, actions=4, steps=2, particles=50,
                          separation=5.0)
    sensor = GaussianFieldOfView(0.9, 8.0, 40.0) if objective.coverage else DiscSensor()
    problems = [assign.AssignmentProblem(base.actions, b, sensor, objective=objective)
                for b in beliefs(base.positions, base.weights)]
    for backend in assign.BACKENDS.names():
        if assign.BACKENDS.get(backend).supports(problems[0]) is not None:
            continue
        results = [assign.solve(p, backend=backend, time_limit_s=20.0) for p in problems]
        first = results[0]
        assert first.plan is not None, backend
        for r in results[1:]:
            assert r.status is first.status, backend
            assert r.objective == first.objective, backend
            assert r.plan is not None and r.plan.actions == first.plan.actions, backend
            np.testing.assert_array_equal(r.plan.poses, first.plan.poses)


@pytest.mark.parametrize("refinement", [search.EmptyHorizonMI(), search.CentreProbability()])
def test_search_answers_do_not_depend_on_the_belief_class(
        refinement: search.Refinement) -> None:
    """Every search backend gives the same plan and score on the three beliefs."""
    rng = np.random.default_rng(5)
    pos = rng.normal([60.0, 40.0, 20.0], 4.0, size=(80, 3))
    w = rng.uniform(0.0, 0.05, size=80)
    box = np.array([[0.0, 96.0]] * 3)
    bonus = search.ExplorationBonus(box, 12.0).updated(GaussianFieldOfView(), np.zeros(3))
    settings = search.SearchSettings(horizon=2, alpha=0.3, refinement=refinement)
    centres = np.array([[60.0, 40.0, 20.0]])
    problems = [search.SearchProblem(np.array([48.0, 48.0, 24.0]), box, bonus,
                                     GaussianFieldOfView(0.98, 25.0, 25.0), settings, belief=b,
                                     centres=centres) for b in beliefs(pos, w)]
    for backend in search.BACKENDS.names():
        results = [search.solve(p, backend=backend) for p in problems]
        first = results[0]
        assert first.plan is not None, backend
        for r in results[1:]:
            assert r.status is first.status and r.objective == first.objective, backend
            assert r.plan is not None
            np.testing.assert_array_equal(r.plan.sequence, first.plan.sequence)


def test_radio_tag_filter_is_a_belief_the_assignment_scores() -> None:
    """Paper 002's TBD-LMB filter is a ParticleBelief (masses r_λ w_i): paper 003's END scores
    actions on it, preferring the action over the tag it has found."""
    import dataclasses

    from searchtrack.estimate.radio import TbdLmbFilter
    from searchtrack.estimate.radio.filter import FilterConfig
    from searchtrack.models.radio import RadioScenario, simulate_stft

    scenario = RadioScenario.paper(noise_var_v2=0.01**2)
    tag = np.array([[850.0, 320.0]])
    filt = TbdLmbFilter(scenario, FilterConfig(particles_per_label=400), seed=1)
    rng = np.random.default_rng(2)
    for k in range(12):
        pose = np.array([700.0 + 10.0 * k, 250.0, 0.0])
        filt.step(simulate_stft(scenario.signal, tag, np.array([0]), np.array([0.1]), pose, rng),
                  pose)
    assert isinstance(filt, ParticleBelief) and filt.state.r[0] > 0.9
    over, away = [850.0, 320.0, 30.0], [200.0, 1300.0, 30.0]
    actions = (np.array([[away], [over]]),)
    problem = assign.AssignmentProblem(actions, filt, GaussianFieldOfView(0.9, 60.0, 30.0))
    result = assign.solve(problem, backend="greedy")
    assert result.plan is not None and result.plan.actions == (1,)
    copy = dataclasses.replace(problem, belief=WeightedParticles(filt.positions, filt.weights))
    assert assign.solve(copy, backend="greedy").objective == pytest.approx(result.objective)
