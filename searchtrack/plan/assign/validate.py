"""The assignment family's independent validator: what a returned plan must satisfy, checked from
the problem's raw arrays with none of the solvers' code (no cached hit matrices, no set-function
evaluators, no conflict tables).

* one action index per UAV, within its candidate list, and the poses that action flies (the NLP
  may move its poses off the candidates; they must stay finite and of the plan's shape);
* no two UAVs closer than ``min_separation_m`` at a common step;
* the objective: END recomputed as ``Σ_n w_n (1 − Π_{q} (1 − p_d(q, x_n)))`` over every pose
  flown (paper 003 eq. 13); the binary MI (paper 003 §2.5) of ``M`` binary measurements lies in
  ``[0, M log 2]``;
* the objective never above a claimed bound.
"""

from __future__ import annotations

import math

import numpy as np

from searchtrack.core.result import Result
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem

#: Absolute and relative tolerance of the objective check.
TOL = 1e-9
#: Metres by which a moved pose may come inside the separation (the NLP's constraint tolerance).
SEPARATION_TOL_M = 1e-6


def _structure(problem: AssignmentProblem, plan: Assignment) -> list[str]:
    problems: list[str] = []
    if len(plan.actions) != problem.robots:
        return [f"{len(plan.actions)} actions for {problem.robots} UAVs"]
    for r, a in enumerate(plan.actions):
        if not 0 <= a < problem.actions[r].shape[0]:
            problems.append(f"UAV {r}: action {a} of {problem.actions[r].shape[0]}")
    if problems:
        return problems
    want = (problem.robots, *problem.actions[0].shape[1:])
    if plan.poses.shape != want or not np.all(np.isfinite(plan.poses)):
        return [f"poses of shape {plan.poses.shape}, want {want} and finite"]
    return []


def _too_close(problem: AssignmentProblem, poses: np.ndarray) -> list[str]:
    sep = problem.min_separation_m
    if sep <= 0.0:
        return []
    out = []
    for r in range(problem.robots):
        for s in range(r + 1, problem.robots):
            gap = float(np.min(np.linalg.norm(poses[r, :, :3] - poses[s, :, :3], axis=1)))
            if gap < sep - SEPARATION_TOL_M:
                out.append(f"UAVs {r} and {s} come {gap:.6g} m apart (< {sep:g} m)")
    return out


def expected_detections(problem: AssignmentProblem, poses: np.ndarray) -> float:
    """END of the flown ``(R, T, pose_dim)`` poses on the problem's particles."""
    miss = np.ones(problem.positions.shape[0])
    for pose in poses.reshape(-1, poses.shape[-1]):
        pd = np.clip(problem.sensor.detection_probability(pose, problem.positions), 0.0, 1.0)
        miss = miss * (1.0 - pd)
    return float(np.dot(problem.weights, 1.0 - miss))


def answer_problems(problem: AssignmentProblem, result: Result[Assignment],
                    seed: int = 0) -> list[str]:
    """What is wrong with ``result``'s plan, objective and bound (empty when they hold)."""
    del seed  # the check draws nothing
    plan = result.plan
    assert plan is not None
    problems = _structure(problem, plan)
    if problems:
        return problems
    moved = not np.array_equal(plan.poses, Assignment.of(problem, plan.actions).poses)
    if moved and not problem.objective.coverage:
        problems.append("poses off the candidate actions for a non-coverage objective")
    problems += _too_close(problem, plan.poses)
    obj = result.objective
    if obj is not None:
        if problem.objective.coverage:
            true = expected_detections(problem, plan.poses)
            if abs(obj - true) > TOL * (1.0 + abs(true)):
                problems.append(f"reported END {obj} but the poses score {true}")
        else:
            most = plan.poses.shape[0] * plan.poses.shape[1] * math.log(2.0)
            if not -TOL <= obj <= most + TOL:
                problems.append(f"reported MI {obj} outside [0, M log 2 = {most:.6g}]")
    if obj is not None and result.bound is not None and obj > result.bound + TOL * (
            1.0 + abs(result.bound)):
        problems.append(f"objective {obj} exceeds the claimed bound {result.bound}")
    return problems
