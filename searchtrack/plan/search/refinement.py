"""Refinement terms ``T(q)`` of the search score ``α E(q) + T(q)`` (paper 004 eq. 8).

Each term is a small frozen object: :class:`CentreProbability` (eq. 11, the estimated centres),
:class:`EmptyHorizonMI` (the MI of the belief with an empty horizon of measurements) and
:class:`NoRefinement` (exploration only). A term checks that the problem carries what it reads and
scores every candidate sequence.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.plan.search.exploration import centre_probability, empty_horizon_mi

if TYPE_CHECKING:
    from searchtrack.plan.search.problem import SearchProblem


@runtime_checkable
class Refinement(Protocol):
    """A refinement term: what it needs from the problem and its score of each sequence."""

    @property
    def name(self) -> str:
        """Short label (``"centre"``, ``"mi"``, ``"none"``)."""
        ...

    def check(self, problem: SearchProblem) -> None:
        """Raise :class:`InvalidInputError` naming the field the term needs and ``problem``
        lacks."""
        ...

    def scores(self, problem: SearchProblem, sequences: FloatArray) -> FloatArray:
        """``(S,)`` values of the term for ``(S, τ, 3)`` position sequences."""
        ...


@dataclass(frozen=True)
class CentreProbability:
    """Eq. (11): ``Σ_j Σ_i π(x̂_i, q_{k+j})`` over the estimated centres ``x̂_i``."""

    @property
    def name(self) -> str:
        """``"centre"``."""
        return "centre"

    def check(self, problem: SearchProblem) -> None:
        """The problem needs its ``centres`` (possibly none)."""
        if problem.centres is None:
            raise InvalidInputError("centres", None, "centre-probability refinement needs "
                                    "the estimated centres (an empty (0, 3) array for none)")

    def scores(self, problem: SearchProblem, sequences: FloatArray) -> FloatArray:
        """Sum of the detection probabilities of the centres along each sequence."""
        centres = problem.centres
        if centres is None or centres.shape[0] == 0:
            return np.zeros(sequences.shape[0])
        return np.array([centre_probability(problem.sensor, centres, s) for s in sequences])


@dataclass(frozen=True)
class EmptyHorizonMI:
    """The MI between the targets and "every measurement along the horizon is empty"."""

    @property
    def name(self) -> str:
        """``"mi"``."""
        return "mi"

    def check(self, problem: SearchProblem) -> None:
        """The problem needs its ``belief``."""
        if problem.belief is None:
            raise InvalidInputError("belief", None, "MI refinement needs the particle belief")

    def scores(self, problem: SearchProblem, sequences: FloatArray) -> FloatArray:
        """Binary MI of each sequence's empty-horizon event on the belief."""
        belief = problem.belief
        if belief is None:
            return np.zeros(sequences.shape[0])
        positions, weights = belief.positions, belief.weights
        return np.array([empty_horizon_mi(problem.sensor, positions, weights, s)
                         for s in sequences])


@dataclass(frozen=True)
class NoRefinement:
    """No refinement: the score is the exploration term alone."""

    @property
    def name(self) -> str:
        """``"none"``."""
        return "none"

    def check(self, problem: SearchProblem) -> None:
        """Needs nothing."""

    def scores(self, problem: SearchProblem, sequences: FloatArray) -> FloatArray:
        """Zeros."""
        return np.zeros(sequences.shape[0])
