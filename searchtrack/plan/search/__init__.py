"""Search planners of paper 004: the receding-horizon exploration + refinement planner and the
lawnmower, as one registry family (:func:`solve`, ``BACKENDS``) over a :class:`SearchProblem`;
the exploration bonus (eqs. 9–10), the refinement terms (eq. 11) and the move lattice (eq. 7)."""

from __future__ import annotations

from searchtrack.plan.search.exploration import (
    ExplorationBonus,
    centre_probability,
    empty_horizon_mi,
    exploration_value,
)
from searchtrack.plan.search.lattice import lattice_moves, lattice_sequences
from searchtrack.plan.search.lawnmower import lawnmower_2d, lawnmower_3d
from searchtrack.plan.search.problem import SearchPlan, SearchProblem, SearchSettings
from searchtrack.plan.search.refinement import (
    CentreProbability,
    EmptyHorizonMI,
    NoRefinement,
    Refinement,
)
from searchtrack.plan.search.solve import BACKENDS, solve

__all__ = ["BACKENDS", "CentreProbability", "EmptyHorizonMI", "ExplorationBonus",
           "NoRefinement", "Refinement", "SearchPlan", "SearchProblem", "SearchSettings",
           "centre_probability", "empty_horizon_mi", "exploration_value", "lattice_moves",
           "lattice_sequences", "lawnmower_2d", "lawnmower_3d", "solve"]
