"""Constrained information-driven path planning for radio-tag tracking (Nguyen et al., §III-D).

The UAV chooses ``H`` action primitives to maximise the Rényi or Cauchy–Schwarz divergence
between the posterior after predicted ideal measurements and the prediction (eqs. 32–43),
subject to the void-probability constraint (eqs. 44–45). :class:`RadioPlanProblem` holds the
belief, pose, scenario and :class:`RadioPlanSettings`; :func:`solve` picks a backend of
:data:`BACKENDS` (``auto``, ``exhaustive``, ``beam``, ``greedy``, ``straight``) and returns a
:class:`~searchtrack.core.result.Result` of :class:`RadioPlan`; :func:`check_plan` verifies a
plan independently. :mod:`.divergences` holds the factorised divergences and void probability.
"""

from __future__ import annotations

from searchtrack.plan.radio.divergences import cauchy_schwarz, renyi, void_probability
from searchtrack.plan.radio.problem import RadioPlan, RadioPlanProblem, RadioPlanSettings
from searchtrack.plan.radio.solve import BACKENDS, solve
from searchtrack.plan.radio.validator import PlanCheck, check_plan

__all__ = ["BACKENDS", "PlanCheck", "RadioPlan", "RadioPlanProblem", "RadioPlanSettings",
           "cauchy_schwarz", "check_plan", "renyi", "solve", "void_probability"]
