"""Settings, problem and plan: defaults, validation naming the field, copies of the input."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.radio import RadioPlan, RadioPlanProblem, RadioPlanSettings

from .helpers import POSE, problem, scenario, spread_belief


def test_settings_defaults() -> None:
    """The paper's defaults: H = 3, Rényi α = 0.5, γ = 1, K = 1, r_min = 50 m, P_vmin = 0.9."""
    st = RadioPlanSettings()
    assert (st.horizon, st.reward, st.alpha, st.cs_k, st.discount) == (3, "renyi", 0.5, 1.0, 1.0)
    assert (st.r_min_m, st.p_void_min, st.plan_particles) == (50.0, 0.9, 1000)
    RadioPlanSettings(reward="cs", alpha=1.0, discount=1.0, r_min_m=0.0, p_void_min=0.0)


@pytest.mark.parametrize(("field", "value"), [
    ("horizon", 0), ("horizon", 1.5), ("reward", "kl"), ("alpha", 0.0), ("alpha", -1.0),
    ("cs_k", 0.0), ("discount", 0.0), ("discount", 1.01), ("r_min_m", -1.0),
    ("r_min_m", math.nan), ("p_void_min", 1.0), ("p_void_min", -0.1), ("plan_particles", 0),
    ("plan_particles", True)])
def test_bad_settings(field: str, value: Any) -> None:
    """Each out-of-domain setting is refused with an error naming it."""
    with pytest.raises(InvalidInputError, match=field):
        RadioPlanSettings(**{field: value})


def test_problem_copies_and_freezes_the_belief() -> None:
    """The problem keeps a read-only copy: changing the caller's belief changes nothing."""
    b = spread_belief()
    p = RadioPlanProblem(b, POSE, scenario())
    before = p.belief.x.copy()
    b.x[:] = 0.0
    assert np.array_equal(p.belief.x, before)
    with pytest.raises(ValueError, match="read-only"):
        p.belief.w[0, 0] = 1.0
    assert p.n_labels == 4 and p.steps_per_interval == 5 and p.n_poses == 15


def _bad_belief(change: str) -> Any:
    b = spread_belief()
    if change == "type":
        return "particles"
    if change == "labels":
        return dataclasses.replace(b, x=b.x[:3], mode=b.mode[:3], tau=b.tau[:3], w=b.w[:3],
                                   r=b.r[:3])
    if change == "nan":
        b.x[0, 0, 0] = math.nan
    elif change == "weights":
        b.w[0] *= 2.0
    elif change == "negative":
        b.w[0, 0] = -b.w[0, 0]
    elif change == "r":
        b.r[1] = 1.2
    elif change == "mode":
        b.mode[0, 0] = 2
    elif change == "tau":
        b.tau[0, 0] = 1.0
    return b


@pytest.mark.parametrize(("change", "field"), [
    ("type", "belief"), ("labels", "belief"), ("nan", "belief.x"), ("weights", "belief.w"),
    ("negative", "belief.w"), ("r", "belief.r"), ("mode", "belief.mode"),
    ("tau", "belief.tau")])
def test_bad_belief(change: str, field: str) -> None:
    """A belief of the wrong type, shape or content is refused, naming the field."""
    with pytest.raises(InvalidInputError, match=field.replace(".", r"\.")):
        RadioPlanProblem(_bad_belief(change), POSE, scenario())


@pytest.mark.parametrize("pose", [[600.0, 600.0], [600.0, math.nan, 0.0],
                                  [-1600.0, 600.0, 0.0], [600.0, 3000.5, 0.0]])
def test_bad_pose(pose: list[float]) -> None:
    """A pose that is not three finite numbers within the area's size of the area is refused
    (just outside is allowed: a UAV may have had to leave)."""
    with pytest.raises(InvalidInputError, match="uav_pose"):
        RadioPlanProblem(spread_belief(), np.array(pose), scenario())


def test_bad_scenario_and_settings() -> None:
    """A scenario or settings of the wrong type is refused."""
    with pytest.raises(InvalidInputError, match="scenario"):
        RadioPlanProblem(spread_belief(), POSE, "paper")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="settings"):
        RadioPlanProblem(spread_belief(), POSE, scenario(), {})  # type: ignore[arg-type]


def test_plan_checks_and_objective() -> None:
    """A plan is frozen and consistent; its objective discounts later rewards."""
    path = np.zeros((4, 3))
    plan = RadioPlan(np.array([0.1, 0.2]), path, np.array([1.0, 2.0]), np.full(4, 0.95), True)
    assert plan.objective(1.0) == 3.0 and plan.objective(0.5) == 2.0
    assert plan.min_void == 0.95
    with pytest.raises(ValueError, match="read-only"):
        plan.path[0, 0] = 1.0
    with pytest.raises(InvalidInputError, match="path"):
        RadioPlan(np.array([0.1, 0.2]), np.zeros((3, 3)), np.ones(2), np.ones(3), True)
    with pytest.raises(InvalidInputError, match="rewards"):
        RadioPlan(np.array([0.1]), path, np.ones(2), np.ones(4), True)
    with pytest.raises(InvalidInputError, match="void"):
        RadioPlan(np.array([0.1]), path, np.ones(1), np.ones(3), True)


def test_problem_helper_settings() -> None:
    """The shared helper builds small problems (a guard for the other tests' assumptions)."""
    p = problem(horizon=1, reward="cs")
    assert p.settings.horizon == 1 and p.settings.reward == "cs" and p.n_poses == 5
