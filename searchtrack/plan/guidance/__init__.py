"""UAV guidance for road search and track (thesis 001, Ch. 5): potential-field forces,
UAV-to-tracker pairing, reacquisition OPTW routes and the strategies built from them."""

from __future__ import annotations

from searchtrack.plan.guidance.forces import (
    GradientField,
    default_loiter_k,
    default_spring_k,
    pauli_force,
    spring_force,
)
from searchtrack.plan.guidance.pairing import Pairing, pair_uavs
from searchtrack.plan.guidance.reacquire import (
    candidate_nodes,
    plan_reacquisition,
    reacquire_time,
    reacquisition_instance,
)
from searchtrack.plan.guidance.strategies import (
    STRATEGIES,
    Loiter,
    Search,
    SearchAndLoiter,
    SearchAndReacquire,
    Strategy,
)
from searchtrack.plan.guidance.view import Guidance, GuidanceView, StrategyConfig

__all__ = [
    "STRATEGIES",
    "GradientField",
    "Guidance",
    "GuidanceView",
    "Loiter",
    "Pairing",
    "Search",
    "SearchAndLoiter",
    "SearchAndReacquire",
    "Strategy",
    "StrategyConfig",
    "candidate_nodes",
    "default_loiter_k",
    "default_spring_k",
    "pair_uavs",
    "pauli_force",
    "plan_reacquisition",
    "reacquire_time",
    "reacquisition_instance",
    "spring_force",
]
