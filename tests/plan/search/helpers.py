"""The search box, sensor and start shared by the search tests, and a solve that must succeed."""

from __future__ import annotations

import numpy as np

from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.search import SearchPlan, SearchProblem, solve

BOX = np.array([[0.0, 120.0], [0.0, 120.0], [0.0, 120.0]])
SENSOR = GaussianFieldOfView(0.98, 25.0, 25.0)
CENTRE = np.array([60.0, 60.0, 60.0])


def plan(problem: SearchProblem, backend: str = "receding") -> SearchPlan:
    """The plan of a solve that must succeed."""
    result = solve(problem, backend=backend)
    assert result.plan is not None, result.message
    return result.plan
