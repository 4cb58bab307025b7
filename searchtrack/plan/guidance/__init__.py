"""UAV guidance for road search and track (thesis 001, Ch. 5): potential-field forces,
UAV-to-tracker pairing, reacquisition OPTW routes, and the strategies built from them as a
family of solver backends (:data:`BACKENDS`, :func:`solve`), beside this library's route
strategies, whose searching UAVs fly OPTW routes over the search field.

Guidance reads beliefs through the protocols of :mod:`searchtrack.estimate.belief`: a
:class:`~searchtrack.estimate.belief.SearchField` for the gradient, a
:class:`~searchtrack.estimate.belief.BeliefBank` of track beliefs for pairing and holding, a
:class:`~searchtrack.estimate.belief.NodePredictor` for the reacquisition horizon.
"""

from __future__ import annotations

from searchtrack.plan.guidance.forces import (
    GradientField,
    coverage_force,
    default_loiter_k,
    default_spring_k,
    pauli_force,
    spring_force,
)
from searchtrack.plan.guidance.pairing import Pairing, pair_uavs
from searchtrack.plan.guidance.problem import GuidanceProblem
from searchtrack.plan.guidance.reacquire import (
    candidate_nodes,
    plan_reacquisition,
    reacquire_time,
    reacquisition_instance,
)
from searchtrack.plan.guidance.search_routes import (
    SearchCells,
    SearchRoute,
    near_peaks,
    search_instance,
    search_mass,
)
from searchtrack.plan.guidance.solve import BACKENDS, solve
from searchtrack.plan.guidance.view import Guidance, GuidanceView, Reacquisition, StrategyConfig

__all__ = [
    "BACKENDS",
    "GradientField",
    "Guidance",
    "GuidanceProblem",
    "GuidanceView",
    "Pairing",
    "Reacquisition",
    "SearchCells",
    "SearchRoute",
    "StrategyConfig",
    "candidate_nodes",
    "coverage_force",
    "default_loiter_k",
    "default_spring_k",
    "near_peaks",
    "pair_uavs",
    "pauli_force",
    "plan_reacquisition",
    "reacquire_time",
    "reacquisition_instance",
    "search_instance",
    "search_mass",
    "solve",
    "spring_force",
]
