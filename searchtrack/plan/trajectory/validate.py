"""The trajectory family's independent validator: what a controller's answer must satisfy,
checked from the problem's model limits without the controllers' code.

* ``N`` = the problem's horizon inputs of the model's ``nu`` and ``N + 1`` states of its ``nx``,
  the plan's stage length the problem's ``dt_s``, the first state the problem's state;
* every input inside the model's box (up to a solver tolerance relative to the box's width);
* a cost (the objective, minimised) that is finite and not below a claimed bound.
"""

from __future__ import annotations

import math

import numpy as np

from searchtrack.core.result import Result
from searchtrack.plan.trajectory.problem import ControlPlan, TrackingProblem

#: Relative tolerance on the input box (interior-point and QP solvers stop within it).
BOX_TOL = 1e-6
#: Tolerance on the first state and the stage length.
TOL = 1e-9


def answer_problems(problem: TrackingProblem, result: Result[ControlPlan],
                    seed: int = 0) -> list[str]:
    """What is wrong with ``result``'s control plan and cost (empty when they hold)."""
    del seed  # the check draws nothing
    plan = result.plan
    assert plan is not None
    m = problem.model
    u, x = plan.inputs, plan.states
    want = ((problem.horizon, m.nu), (problem.horizon + 1, m.nx))
    if (u.shape, x.shape) != want:
        return [f"inputs {u.shape} and states {x.shape}, want {want[0]} and {want[1]}"]
    problems: list[str] = []
    if abs(plan.dt_s - problem.dt_s) > TOL * problem.dt_s:
        problems.append(f"stages of {plan.dt_s} s, the problem's are {problem.dt_s} s")
    if not np.allclose(x[0], problem.state, rtol=TOL, atol=TOL):
        problems.append("the predicted states do not start at the problem's state")
    lower = np.asarray(m.input_lower, dtype=np.float64)
    upper = np.asarray(m.input_upper, dtype=np.float64)
    slack = BOX_TOL * problem.input_range()
    low = np.flatnonzero(np.any(u < lower - slack, axis=0))
    high = np.flatnonzero(np.any(u > upper + slack, axis=0))
    for i in sorted({*low.tolist(), *high.tolist()}):
        problems.append(f"input {i} leaves [{lower[i]:g}, {upper[i]:g}]: "
                        f"{float(u[:, i].min()):g} … {float(u[:, i].max()):g}")
    obj = result.objective
    if obj is not None and not math.isfinite(obj):
        problems.append(f"cost {obj} is not finite")
    if obj is not None and result.bound is not None and obj < result.bound - TOL * (
            1.0 + abs(result.bound)):
        problems.append(f"cost {obj} is below the claimed bound {result.bound}")
    return problems
