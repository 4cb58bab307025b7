"""The search family's independent validator (paper 004 §4.1): what a returned step must
satisfy, recomputed from the problem's raw arrays without the planners' scoring code.

* the sequence is finite, inside the box, and for the lattice planner each position is one axis
  move of ``step_m`` from the one before (planar moves only when ``dims`` is 2);
* the exploration part ``E = Σ_j ι(q_j)`` (eq. 10), with the multilinear interpolation of the
  bonus grid written out here; the centre refinement ``T = Σ_j Σ_i π(x̂_i, q_j)`` (eq. 11) from
  the sensor; the MI refinement is a mutual information, so non-negative;
* the score ``α E + T`` (eq. 8) is the reported objective, never above a claimed bound.
"""

from __future__ import annotations

import itertools

import numpy as np

from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.plan.search.problem import SearchPlan, SearchProblem

#: Absolute and relative tolerance of every check.
TOL = 1e-9


def interpolated(axes: tuple[FloatArray, ...], values: FloatArray,
                 points: FloatArray) -> FloatArray:
    """Multilinear interpolation of the grid ``values`` at ``(K, ≥d)`` points clamped to it."""
    d = len(axes)
    lo_idx = []
    frac = []
    for k, ax in enumerate(axes):
        x = np.clip(points[:, k], ax[0], ax[-1])
        i = np.clip(np.searchsorted(ax, x, side="right") - 1, 0, ax.size - 2)
        lo_idx.append(i)
        frac.append((x - ax[i]) / (ax[i + 1] - ax[i]))
    out = np.zeros(points.shape[0])
    for corner in itertools.product((0, 1), repeat=d):
        weight = np.ones(points.shape[0])
        index = []
        for k, bit in enumerate(corner):
            weight = weight * (frac[k] if bit else 1.0 - frac[k])
            index.append(lo_idx[k] + bit)
        out += weight * values[tuple(index)]
    return out


def _moves(problem: SearchProblem, sequence: FloatArray) -> list[str]:
    steps = np.diff(np.vstack([problem.position[None, :3], sequence]), axis=0)
    step = problem.settings.step_m
    dims = problem.settings.dims
    out = []
    for j, s in enumerate(steps):
        moved = np.flatnonzero(np.abs(s) > TOL * (1.0 + step))
        if moved.size != 1 or moved[0] >= dims or abs(abs(s[moved[0]]) - step) > TOL * step:
            out.append(f"step {j} moves by {s.tolist()}, not one lattice move of {step:g} m")
    return out


def answer_problems(problem: SearchProblem, result: Result[SearchPlan],
                    seed: int = 0) -> list[str]:
    """What is wrong with ``result``'s sequence, score and bound (empty when they hold)."""
    del seed  # the check draws nothing
    plan = result.plan
    assert plan is not None
    seq = np.asarray(plan.sequence, dtype=np.float64)
    if seq.ndim != 2 or seq.shape[0] < 1 or seq.shape[1] < 3 or not np.all(np.isfinite(seq)):
        return [f"sequence of shape {seq.shape}: want (τ ≥ 1, 3) finite positions"]
    seq = seq[:, :3]
    box = problem.bounds
    slack = TOL * (1.0 + np.abs(box))
    if np.any(seq < box[:, 0] - slack[:, 0]) or np.any(seq > box[:, 1] + slack[:, 1]):
        return ["the sequence leaves the search box"]
    problems = _moves(problem, seq) if result.backend == "receding" else []
    bonus = problem.bonus
    explore = float(np.sum(interpolated(bonus.axes, bonus.values, seq)))
    name = problem.settings.refinement.name
    refine = plan.refinement
    if name == "centre":
        centres = problem.centres if problem.centres is not None else np.empty((0, 3))
        refine = float(sum(np.sum(np.clip(problem.sensor.detection_probability(q, centres),
                                          0.0, 1.0)) for q in seq)) if centres.size else 0.0
    elif name == "none":
        refine = 0.0
    elif plan.refinement < -TOL:
        problems.append(f"MI refinement {plan.refinement} is negative")
    total = problem.settings.alpha * explore + refine

    def off(a: float, b: float) -> bool:
        return abs(a - b) > TOL * (1.0 + abs(b))

    for label, got, want in (("exploration", plan.exploration, explore),
                             ("refinement", plan.refinement, refine),
                             ("score", plan.score, total)):
        if off(got, want):
            problems.append(f"reported {label} {got} but the sequence scores {want}")
    if result.objective is not None and off(result.objective, total):
        problems.append(f"objective {result.objective} is not the score {total}")
    if result.objective is not None and result.bound is not None and \
            result.objective > result.bound + TOL * (1.0 + abs(result.bound)):
        problems.append(f"objective {result.objective} exceeds the claimed bound {result.bound}")
    return problems
