"""Earth Mover's Distance (thesis §4.3): exact transport between signatures or on a road graph.

``emd(p, q, cost)`` solves the transportation LP (4.3)–(4.7) with a cost matrix;
``emd_on_graph(adjacency, p, q)`` gives the same distance under the graph's shortest-path
metric as a min-cost flow on the graph's arcs. Both return a :class:`~searchtrack.plan.Result`
whose objective is the EMD, from an exact network simplex (``backend="network"``, the default
through ``"auto"``) or the cvxpy/HiGHS reference LP (``backend="lp"``).
"""

from __future__ import annotations

from searchtrack.estimate.transport.plan import GraphFlow, TransportPlan
from searchtrack.estimate.transport.problem import (
    MASS_MODES,
    GraphProblem,
    MassMode,
    TransportProblem,
)
from searchtrack.estimate.transport.solve import EMD_BACKENDS, GRAPH_EMD_BACKENDS, emd, emd_on_graph

__all__ = [
    "EMD_BACKENDS",
    "GRAPH_EMD_BACKENDS",
    "MASS_MODES",
    "GraphFlow",
    "GraphProblem",
    "MassMode",
    "TransportPlan",
    "TransportProblem",
    "emd",
    "emd_on_graph",
]
