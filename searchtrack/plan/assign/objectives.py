"""The objectives of the assignment: monotone submodular set functions of the belief.

An objective is a small frozen spec (:class:`ExpectedDetections`, :class:`MutualInformation`)
that the problem carries; :meth:`Objective.evaluator` binds it to a problem as a
:class:`SetFunction` over selections. A selection is a tuple of ``(robot, action)`` pairs, at most
one per UAV. Every objective is zero on the empty selection, so greedy's ½ guarantee applies
(paper 003 Theorem 1).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

from searchtrack.core.checks import non_negative
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.footprint import detection_matrix
from searchtrack.plan.assign.binary_entropy import Bounded
from searchtrack.plan.assign.mutual_info import binary_mi, conditional_entropy_with_error

if TYPE_CHECKING:
    from searchtrack.plan.assign.problem import AssignmentProblem

Selection = Sequence[tuple[int, int]]


class SetFunction(Protocol):
    """An objective bound to one problem: values and marginal gains of selections."""

    def value(self, selection: Selection) -> float:
        """``f(selection)``."""
        ...

    def gains(self, selection: Selection, robot: int) -> FloatArray:
        """``(A_robot,)`` marginal gains ``f(S ∪ {(robot, a)}) − f(S)`` of every action."""
        ...

    def gain(self, selection: Selection, robot: int, action: int) -> float:
        """The marginal gain of one action."""
        ...


@runtime_checkable
class Objective(Protocol):
    """What the assignment maximises: a name, its capabilities and its set function."""

    @property
    def name(self) -> str:
        """Short label for messages (``"end"``, ``"mi"``)."""
        ...

    @property
    def coverage(self) -> bool:
        """True when the objective is the expected coverage ``Σ_j w_j (1 − Π (1 − p_d))``: the
        structure the integer programs, the branch and bound and the NLP are built on."""
        ...

    def evaluator(self, problem: AssignmentProblem) -> SetFunction:
        """The set function of this objective on ``problem``."""
        ...

    def estimated(self, problem: AssignmentProblem) -> str | None:
        """Why the values on ``problem`` are estimates (no enumeration of them proves a plan
        optimal), or ``None`` when they are exact."""
        ...


@dataclass(frozen=True)
class ExpectedDetections:
    """Expected number of detections (END), paper 003 eq. (13)."""

    @property
    def name(self) -> str:
        """``"end"``."""
        return "end"

    @property
    def coverage(self) -> bool:
        """END is the expected coverage of the particles."""
        return True

    def evaluator(self, problem: AssignmentProblem) -> ExpectedDetectionsFunction:
        """END on ``problem``'s cached hit probabilities."""
        return ExpectedDetectionsFunction(problem)

    def estimated(self, problem: AssignmentProblem) -> str | None:
        """END is exact."""
        return None


@dataclass(frozen=True)
class MutualInformation:
    """Binary mutual information ``I[X; Y]`` of the detections (paper 003 eq. 12 and §2.5).

    Parameters
    ----------
    exact_max
        Largest number ``M`` of binary measurements evaluated exactly over the ``2^M`` outcomes;
        above it a Monte Carlo estimate with common random numbers is used.
    samples
        Target sets drawn for the Monte Carlo estimate.
    clutter_rate
        Expected clutter detections per measurement ``λ_c`` (``y = 0`` needs no clutter either).
    seed
        Seed of the Monte Carlo draws (the same draws serve every evaluation).
    """

    exact_max: int = 12
    samples: int = 2000
    clutter_rate: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.exact_max, int) or not 0 <= self.exact_max <= 20:
            raise InvalidInputError("exact_max", self.exact_max, "must be an integer in [0, 20]")
        if not isinstance(self.samples, int) or self.samples < 10:
            raise InvalidInputError("samples", self.samples, "must be an integer >= 10")
        non_negative("clutter_rate", self.clutter_rate)
        if not isinstance(self.seed, int) or self.seed < 0:
            raise InvalidInputError("seed", self.seed, "must be a non-negative integer")

    @property
    def name(self) -> str:
        """``"mi"``."""
        return "mi"

    @property
    def coverage(self) -> bool:
        """Mutual information is not a coverage function."""
        return False

    def evaluator(self, problem: AssignmentProblem) -> MutualInformationFunction:
        """The binary MI on ``problem``'s cached detection tensor (values cached per call)."""
        return MutualInformationFunction(problem, self)

    def estimated(self, problem: AssignmentProblem) -> str | None:
        """A full selection has ``R·T`` measurements; above ``exact_max`` its MI is a Monte
        Carlo estimate."""
        m = problem.robots * problem.horizon
        if m <= self.exact_max:
            return None
        return (f"MI of {m} measurements is a Monte Carlo estimate (exact up to "
                f"exact_max={self.exact_max})")


class ExpectedDetectionsFunction:
    """END on particles: ``Σ_j w_j (1 − Π_{q∈Q} (1 − p_d(x_j | q)))``.

    The per-particle miss product ``m`` of a selection is formed from the selected actions; the
    gain of action ``a`` of UAV ``r`` is ``Σ_j w_j m_j hit_{r,a,j}`` (003 Lemma 2), one
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


class MutualInformationFunction:
    """Binary MI between the belief and the ``y = 1(Z ≠ ∅)`` detections of every selected pose
    (see :mod:`.mutual_info`); values are cached per selection, ``H[Y | X]`` per action."""

    def __init__(self, problem: AssignmentProblem, spec: MutualInformation) -> None:
        self.problem = problem
        self.spec = spec
        self._cache: dict[tuple[tuple[int, int], ...], float] = {}
        self._h_cond: dict[tuple[int, int], Bounded] = {}

    def _conditional(self, r: int, a: int) -> Bounded:
        """``H[Y | X]`` of one action's measurements and its error bound (modular, so cached
        per action)."""
        if (r, a) not in self._h_cond:
            self._h_cond[(r, a)] = conditional_entropy_with_error(
                self.problem.detection[r][a], self.problem.weights, self.spec.clutter_rate)
        return self._h_cond[(r, a)]

    def error(self, selection: Selection) -> float:
        """A bound on the absolute error of :meth:`value` from the series behind
        ``H[Y | X]`` (exact evaluations; the Monte Carlo estimate above ``exact_max`` has its
        own sampling error on top)."""
        return sum(self._conditional(int(r), int(a)).error for r, a in selection)

    def _pd(self, selection: Selection) -> FloatArray:
        rows = [self.problem.detection[r][a] for r, a in selection]
        if not rows:
            return np.zeros((0, self.problem.positions.shape[0]))
        return np.concatenate(rows)

    def value(self, selection: Selection) -> float:
        """MI in nats (exact up to ``exact_max`` measurements, Monte Carlo above)."""
        key = tuple(sorted((int(r), int(a)) for r, a in selection))
        if key not in self._cache:
            s = self.spec
            self._cache[key] = binary_mi(self._pd(key), self.problem.weights, s.clutter_rate,
                                         exact_max=s.exact_max, samples=s.samples, seed=s.seed,
                                         h_cond=sum(self._conditional(r, a).value for r, a in key))
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


def coverage_only(problem: AssignmentProblem) -> str | None:
    """``None`` when ``problem``'s objective is a coverage objective (END), else the reason a
    backend built on that structure cannot take it."""
    if problem.objective.coverage:
        return None
    return f"solves the END objective only (got {problem.objective.name!r})"


def expected_detections_of_poses(problem: AssignmentProblem, poses: FloatArray) -> float:
    """END (003 eq. 13) of arbitrary ``(..., pose_dim)`` poses with the problem's sensor."""
    flat = poses.reshape(-1, poses.shape[-1])
    pd = detection_matrix(problem.sensor, flat, problem.positions)
    return float(problem.weights @ (1.0 - np.prod(1.0 - pd, axis=0)))
