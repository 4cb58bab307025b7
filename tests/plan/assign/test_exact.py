"""The END integer program: agreement with brute force on both MIP solvers, the exact
reductions, the first tangents, the initial plan and bad arguments."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import Assignment, AssignmentProblem
from searchtrack.plan.assign.branch_and_bound import solve_branch_and_bound
from searchtrack.plan.assign.brute import solve_brute_force
from searchtrack.plan.assign.exact import (
    MipSolver,
    formulate,
    initial_breakpoints,
    solve_exact,
)
from searchtrack.plan.assign.objectives import ExpectedDetectionsFunction

from .helpers import DiscSensor, random_problem


@pytest.mark.parametrize("solver", ["scip", "cpsat", "bnb", "scip-unreduced"])
@pytest.mark.parametrize("seed", range(6))
def test_exact_matches_brute_force(solver: str, seed: int) -> None:
    """The IP's and branch and bound's plans have the brute-force optimal END, valid bounds."""
    rng = np.random.default_rng(100 + seed)
    p = random_problem(rng, robots=3, actions=5, steps=2, particles=60, gaussian=seed % 2 == 0)
    best = solve_brute_force(p)
    if solver == "bnb":
        res = solve_branch_and_bound(p, time_limit_s=120.0)
    elif solver == "scip-unreduced":
        res = solve_exact(p, pieces=4, reduce=False, time_limit_s=120.0)
    else:
        res = solve_exact(p, solver=solver, time_limit_s=120.0)  # type: ignore[arg-type]
    assert best.objective is not None and res.objective is not None and res.bound is not None
    assert res.objective == pytest.approx(best.objective, rel=1e-6)
    assert res.bound >= best.objective - 1e-9
    if solver != "cpsat":
        assert res.status is Status.OPTIMAL
    assert res.plan is not None
    assert ExpectedDetectionsFunction(p).value(res.plan.selection) == pytest.approx(res.objective)

@pytest.mark.parametrize(("solver", "name"), [("scip", "exact"), ("cpsat", "exact_cpsat")])
def test_result_names_the_registry_backend(solver: str, name: str) -> None:
    """Each solver's result, with a plan or without one, is named as the registry names it."""
    solved = solve_exact(random_problem(np.random.default_rng(1), robots=2, actions=3),
                         solver=solver)  # type: ignore[arg-type]
    assert solved.plan is not None and solved.backend == name
    assert solved.message.startswith(f"{name}: ")
    acts = np.array([[[0.0, 0.0, 20.0]]])
    collide = AssignmentProblem((acts, acts), WeightedParticles(np.zeros((2, 2)), np.ones(2)),
                                DiscSensor(), min_separation_m=1.0)
    stuck = solve_exact(collide, solver=solver)  # type: ignore[arg-type]
    assert stuck.status is Status.INFEASIBLE and stuck.backend == name


def test_dominated_actions_are_reduced_exactly() -> None:
    """A copy of an action and an action covering a subset are dropped from the program."""
    from searchtrack.plan.assign.exact import undominated

    ell = np.array([[1.0, 1.0, 0.5, 0.0], [0.0, 0.0, 0.0, 2.0], [1.0, 1.0, 1.0, 0.0]])
    kept, column_of = undominated(ell, np.ones(4, dtype=bool))
    assert kept.tolist() == [0, 3]
    assert column_of.tolist() == [0, 0, 0, 1]
    kept, _ = undominated(ell, np.array([False, True, True, True]))
    assert kept.tolist() == [0, 1, 3]


def merged_problem() -> AssignmentProblem:
    """Two UAVs over particles A and A' (same spot, weights 1 and 0.5); C far from both and D
    under them with zero weight."""
    over = np.array([[[0.0, 0.0, 20.0]]])
    pos = np.array([[0.0, 0.0], [0.0, 0.0], [500.0, 0.0], [1.0, 0.0]])
    w = np.array([1.0, 0.5, 2.0, 0.0])
    return AssignmentProblem((over, over), WeightedParticles(pos, w), DiscSensor())


def test_formulate_merges_and_drops_particles() -> None:
    """Identical ℓ rows merge (weight 1.5), the unseen and the zero-weight particles go; each
    column holds ℓ = −log(1 − 0.8)."""
    form = formulate(merged_problem())
    np.testing.assert_allclose(form.ell, [[-math.log(0.2)] * 2], rtol=1e-12)
    np.testing.assert_allclose(form.weights, [1.5])
    assert form.offsets == (0, 1, 2) and form.conflicts == ()
    assert [k.tolist() for k in form.kept] == [[0], [0]]


def test_formulate_keeps_conflicting_pairs_and_every_action_unreduced() -> None:
    """Without reduction every action is a column, and colliding actions become column pairs
    offset by the earlier UAVs' columns."""
    acts = np.array([[[0.0, 0.0, 20.0]], [[0.0, 0.0, 20.0]], [[40.0, 0.0, 20.0]]])
    belief = WeightedParticles(np.array([[0.0, 0.0], [40.0, 0.0]]), np.ones(2))
    p = AssignmentProblem((acts, acts), belief, DiscSensor(), min_separation_m=5.0)
    form = formulate(p, reduce=False)
    assert form.offsets == (0, 3, 6)
    assert sorted(form.conflicts) == [(0, 3), (0, 4), (1, 3), (1, 4), (2, 5)]
    assert [k.tolist() for k in form.kept] == [[0, 1, 2], [0, 1, 2]]


def test_initial_breakpoints() -> None:
    """Tangent points b with 1 − e^{−b} evenly spaced up to the best coverage: with two looks
    of p_d = 0.8, f_max = 0.96, so two pieces give b = 0 and −log(1 − 0.48)."""
    form = formulate(merged_problem())
    assert initial_breakpoints(form, 1) == [[0.0]]
    (cuts,) = initial_breakpoints(form, 2)
    assert cuts[0] == 0.0
    assert cuts[1] == pytest.approx(-math.log(0.52), rel=1e-12)


def test_expired_limit_returns_the_initial_plan() -> None:
    """With no time to run the program the initial plan comes back FEASIBLE, with its true END
    and no bound."""
    p = random_problem(np.random.default_rng(5), robots=3, actions=4)
    start = Assignment.of(p, [1, 2, 3])
    res = solve_exact(p, time_limit_s=1e-9, initial=start)
    assert res.status is Status.FEASIBLE and res.plan is not None and res.bound is None
    assert res.plan.actions == (1, 2, 3)
    assert res.objective == pytest.approx(ExpectedDetectionsFunction(p).value(start.selection))


def test_initial_plan_does_not_change_the_optimum() -> None:
    """A poor initial plan is only a hint: both solvers still prove the brute-force optimum."""
    p = random_problem(np.random.default_rng(6), robots=3, actions=5, steps=2)
    best = solve_brute_force(p)
    solvers: tuple[MipSolver, ...] = ("scip", "cpsat")
    for solver in solvers:
        res = solve_exact(p, solver=solver, initial=Assignment.of(p, [0, 0, 0]))
        assert res.objective == pytest.approx(best.objective, rel=1e-6)


def test_exact_bad_arguments() -> None:
    """An unknown solver, no pieces or a mutual-information objective raise naming the field."""
    p = random_problem(np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="solver"):
        solve_exact(p, solver="gurobi")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="pieces"):
        solve_exact(p, pieces=0)
    mi = random_problem(np.random.default_rng(0), objective="mi")
    with pytest.raises(InvalidInputError, match="objective"):
        solve_exact(mi)
