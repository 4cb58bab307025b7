"""Multi-UAV action assignment on particle beliefs (papers 003 and 004).

One candidate action per UAV, chosen to maximise a monotone submodular objective of the belief:
expected number of detections (END) or binary mutual information. Backends: greedy and lazy
greedy (½-approximation), exact END by branch and bound or by an integer program (SCIP, CP-SAT),
brute force, and a CasADi NLP that moves the waypoints continuously; :func:`solve` picks one by
name (``BACKENDS.names()``); ``auto`` answers greedily, then proves the answer with the branch and
bound (END) or by enumeration (mutual information, small problems) within the time limit.
"""

from __future__ import annotations

from searchtrack.plan.assign.actions import (
    FixedWingPrimitives,
    fixed_wing_actions,
    lattice_moves,
    lattice_sequences,
)
from searchtrack.plan.assign.exploration import (
    ExplorationBonus,
    centre_probability,
    empty_horizon_mi,
    exploration_value,
)
from searchtrack.plan.assign.footprint import GaussianFieldOfView
from searchtrack.plan.assign.nlp import NLPLimits
from searchtrack.plan.assign.objectives import (
    BinaryMutualInformation,
    ExpectedDetections,
    Objective,
    objective_for,
)
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem, MISettings
from searchtrack.plan.assign.solve import BACKENDS, solve

__all__ = ["BACKENDS", "Assignment", "AssignmentProblem", "BinaryMutualInformation",
           "ExpectedDetections", "ExplorationBonus", "FixedWingPrimitives",
           "GaussianFieldOfView", "MISettings", "NLPLimits", "Objective", "centre_probability",
           "empty_horizon_mi", "exploration_value", "fixed_wing_actions", "lattice_moves",
           "lattice_sequences", "objective_for", "solve"]
