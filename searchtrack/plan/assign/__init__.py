"""Multi-UAV action assignment on particle beliefs (papers 003 and 004).

One candidate action per UAV, chosen to maximise a monotone submodular objective of the belief:
expected number of detections (:class:`ExpectedDetections`) or binary mutual information
(:class:`MutualInformation`). Backends: greedy and lazy greedy (½-approximation), exact END by
branch and bound or by an integer program (SCIP, CP-SAT), brute force, and a CasADi NLP that moves
the waypoints continuously; :func:`solve` picks one by name (``BACKENDS.names()``); ``auto``
answers greedily, then proves the answer with the branch and bound (END) or by enumeration (mutual
information, small problems) within the time limit.
"""

from __future__ import annotations

from searchtrack.plan.assign.actions import FixedWingPrimitives, fixed_wing_actions
from searchtrack.plan.assign.nlp import NLPLimits
from searchtrack.plan.assign.objectives import (
    ExpectedDetections,
    ExpectedDetectionsFunction,
    MutualInformation,
    MutualInformationFunction,
    Objective,
    SetFunction,
)
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem
from searchtrack.plan.assign.solve import BACKENDS, solve

__all__ = ["BACKENDS", "Assignment", "AssignmentProblem", "ExpectedDetections",
           "ExpectedDetectionsFunction", "FixedWingPrimitives", "MutualInformation",
           "MutualInformationFunction", "NLPLimits", "Objective", "SetFunction",
           "fixed_wing_actions", "solve"]
