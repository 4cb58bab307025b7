"""Monotone submodular set objectives over (UAV, action) pairs on a particle belief.

A selection is a tuple of ``(robot, action)`` pairs, at most one per UAV. Every objective is zero
on the empty selection, so greedy's ½ guarantee applies (paper 003 Theorem 1).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from searchtrack.core.types import FloatArray
from searchtrack.plan.assign.mutual_info import binary_mi, conditional_entropy
from searchtrack.plan.assign.problem import AssignmentProblem, detection_matrix

Selection = Sequence[tuple[int, int]]


class Objective(Protocol):
    """A set function with marginal gains for one UAV's whole candidate set."""

    def value(self, selection: Selection) -> float:
        """``f(selection)``."""
        ...

    def gains(self, selection: Selection, robot: int) -> FloatArray:
        """``(A_robot,)`` marginal gains ``f(S ∪ {(robot, a)}) − f(S)`` of every action."""
        ...

    def gain(self, selection: Selection, robot: int, action: int) -> float:
        """The marginal gain of one action."""
        ...


class ExpectedDetections:
    """END, paper 003 eq. (13) on particles: ``Σ_j w_j (1 − Π_{q∈Q} (1 − p_d(x_j | q)))``.

    The per-particle miss product ``m`` of a selection is formed from the selected actions; the
    gain of action ``a`` of UAV ``r`` is ``Σ_j w_j m_j hit_{r,a,j}`` (Lemma 2), one
    matrix–vector product for all of a UAV's actions.
    """

    def __init__(self, problem: AssignmentProblem) -> None:
        self.problem = problem

    def miss_product(self, selection: Selection) -> FloatArray:
        """``(N,)`` probabilities that every selected pose misses each particle."""
        m = np.ones(self.problem.positions.shape[0])
        for r, a in selection:
            m = m * (1.0 - self.problem.hit[r][a])
        return m

    def value(self, selection: Selection) -> float:
        """Expected number of targets detected at least once."""
        return float(self.problem.weights @ (1.0 - self.miss_product(selection)))

    def gains(self, selection: Selection, robot: int) -> FloatArray:
        """Marginal gains of every action of ``robot``."""
        wm = self.problem.weights * self.miss_product(selection)
        out: FloatArray = np.maximum(self.problem.hit[robot] @ wm, 0.0)
        return out

    def gain(self, selection: Selection, robot: int, action: int) -> float:
        """Marginal gain of one action."""
        wm = self.problem.weights * self.miss_product(selection)
        return max(0.0, float(wm @ self.problem.hit[robot][action]))


class BinaryMutualInformation:
    """Binary MI ``I[X; Y]`` between the belief and the ``y = 1(Z ≠ ∅)`` detections of every
    selected pose (paper 003 eq. 12 and §2.5; see :mod:`.mutual_info`)."""

    def __init__(self, problem: AssignmentProblem) -> None:
        self.problem = problem
        self._cache: dict[tuple[tuple[int, int], ...], float] = {}
        self._h_cond: dict[tuple[int, int], float] = {}

    def _conditional(self, r: int, a: int) -> float:
        """``H[Y | X]`` of one action's measurements (modular, so cached per action)."""
        if (r, a) not in self._h_cond:
            self._h_cond[(r, a)] = conditional_entropy(self.problem.detection[r][a],
                                                       self.problem.weights,
                                                       self.problem.mi.clutter_rate)
        return self._h_cond[(r, a)]

    def _pd(self, selection: Selection) -> FloatArray:
        rows = [self.problem.detection[r][a] for r, a in selection]
        if not rows:
            return np.zeros((0, self.problem.positions.shape[0]))
        return np.concatenate(rows)

    def value(self, selection: Selection) -> float:
        """MI in nats (exact up to ``mi.exact_max`` measurements, Monte Carlo above)."""
        key = tuple(sorted((int(r), int(a)) for r, a in selection))
        if key not in self._cache:
            s = self.problem.mi
            self._cache[key] = binary_mi(self._pd(key), self.problem.weights, s.clutter_rate,
                                         exact_max=s.exact_max, samples=s.samples, seed=s.seed,
                                         h_cond=sum(self._conditional(r, a) for r, a in key))
        return self._cache[key]

    def gains(self, selection: Selection, robot: int) -> FloatArray:
        """Marginal gains of every action of ``robot`` (clipped at 0 against round-off)."""
        base = self.value(selection)
        out: FloatArray = np.array([self.value([*selection, (robot, a)]) - base
                        for a in range(self.problem.n_actions(robot))])
        out = np.maximum(out, 0.0)
        return out

    def gain(self, selection: Selection, robot: int, action: int) -> float:
        """Marginal gain of one action."""
        return max(0.0, self.value([*selection, (robot, action)]) - self.value(selection))


def objective_for(problem: AssignmentProblem) -> Objective:
    """The objective ``problem.objective`` names."""
    if problem.objective == "mi":
        return BinaryMutualInformation(problem)
    return ExpectedDetections(problem)


def expected_detections_of_poses(problem: AssignmentProblem, poses: FloatArray) -> float:
    """END (003 eq. 13) of arbitrary ``(..., pose_dim)`` poses with the problem's sensor."""
    flat = poses.reshape(-1, poses.shape[-1])
    pd = detection_matrix(problem.sensor, flat, problem.positions)
    return float(problem.weights @ (1.0 - np.prod(1.0 - pd, axis=0)))
