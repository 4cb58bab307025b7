"""Receding-horizon road search on particle beliefs (Moore et al. 2021, §4).

``Q`` UAVs at road nodes each choose a path of ``L`` directed edges to see the most
entropy-weighted particle mass (Eq. 20–21), particles propagated during the look-ahead with
fixed draws and counted once (a maximum coverage problem on a time-expanded graph,
:mod:`~searchtrack.plan.road_search.scenario`). :func:`solve` picks a backend of
:data:`BACKENDS` by name: ``exhaustive`` (the paper's RHC), ``beam``, ``exact`` (CP-SAT),
``auto`` (beam, then CP-SAT), ``greedy`` (Eq. 21), and the baselines ``random`` and ``ideal``;
:func:`check_plan` verifies any plan independently. :class:`ChainGraph` merges degree-2 chains
so that a look-ahead step is a road segment between intersections.
"""

from __future__ import annotations

from searchtrack.plan.road_search.chains import ChainGraph
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem, RoadSearchSettings
from searchtrack.plan.road_search.solve import BACKENDS, solve
from searchtrack.plan.road_search.validator import PlanCheck, check_plan
from searchtrack.plan.road_search.weights import edge_values, target_weights

__all__ = ["BACKENDS", "ChainGraph", "PlanCheck", "RoadPlan", "RoadSearchProblem",
           "RoadSearchSettings", "check_plan", "edge_values", "solve", "target_weights"]
