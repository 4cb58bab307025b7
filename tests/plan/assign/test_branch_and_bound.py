"""Branch and bound for END: agreement with the integer program and brute force, hand-computed
optima, plans mapped back through the reductions, and the objective it refuses."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import AssignmentProblem
from searchtrack.plan.assign.branch_and_bound import solve_branch_and_bound
from searchtrack.plan.assign.brute import solve_brute_force
from searchtrack.plan.assign.exact import solve_exact

from .helpers import DiscSensor, random_problem


@pytest.mark.parametrize("seed", range(4))
def test_bnb_and_ip_agree_with_collisions_on_larger_instances(seed: int) -> None:
    """Branch and bound and the IP find the same optimal END with collision constraints."""
    rng = np.random.default_rng(300 + seed)
    p = random_problem(rng, robots=4, actions=8, steps=2, particles=150, separation=12.0)
    a, b = solve_branch_and_bound(p, time_limit_s=30.0), solve_exact(p, time_limit_s=30.0)
    brute = solve_brute_force(p, time_limit_s=30.0)
    assert a.status is Status.OPTIMAL and b.status is Status.OPTIMAL
    assert a.objective == pytest.approx(brute.objective, rel=1e-9)
    assert b.objective == pytest.approx(brute.objective, rel=1e-9)


def test_escapes_the_greedy_trap() -> None:
    """Unit clusters at 0 and 8 m, 0.9 at 100 m; UAV 0 covers the pair or the far cluster, UAV 1
    only the pair: greedy's 1.92 is beaten by 0.72 + 1.6 = 2.32, proven optimal."""
    pos = np.array([[0.0, 0.0], [8.0, 0.0], [100.0, 0.0]])
    a0 = np.array([[[4.0, 0.0, 20.0]], [[100.0, 0.0, 20.0]]])
    a1 = np.array([[[4.0, 0.0, 20.0]], [[200.0, 0.0, 20.0]]])
    p = AssignmentProblem((a0, a1), WeightedParticles(pos, np.array([1.0, 1.0, 0.9])),
                          DiscSensor(radius_m=6.5))
    res = solve_branch_and_bound(p)
    assert res.status is Status.OPTIMAL and res.plan is not None
    assert res.plan.actions == (1, 0)
    assert res.objective == res.bound == pytest.approx(2.32, rel=1e-12)
    assert res.stats["nodes"] >= 1.0


def test_plan_names_the_original_actions() -> None:
    """Each UAV has actions that see nothing, dominated by one that sees a particle: one column
    per UAV is left, and the plan names the original actions (2, 1), not the columns (0, 0)."""
    acts0 = np.array([[[300.0, 0.0, 20.0]], [[400.0, 0.0, 20.0]], [[0.0, 0.0, 20.0]]])
    acts1 = np.array([[[60.0, 0.0, 20.0]], [[50.0, 0.0, 20.0]]])
    belief = WeightedParticles(np.array([[0.0, 0.0], [50.0, 0.0]]), np.array([1.0, 0.1]))
    p = AssignmentProblem((acts0, acts1), belief, DiscSensor(radius_m=5.0))
    res = solve_branch_and_bound(p)
    assert res.status is Status.OPTIMAL and res.plan is not None
    assert res.plan.actions == (2, 1)
    assert res.objective == pytest.approx(0.8 + 0.08, rel=1e-12)
    assert res.stats["columns"] == 2.0


def test_refuses_mutual_information() -> None:
    """Branch and bound is built on END's coverage structure: MI raises naming the objective."""
    mi = random_problem(np.random.default_rng(0), objective="mi")
    with pytest.raises(InvalidInputError, match="objective"):
        solve_branch_and_bound(mi)
