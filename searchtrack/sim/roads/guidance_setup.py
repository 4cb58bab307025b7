"""Build a scenario's guidance configuration, the view the guidance sees each step, and the
step's guidance problem."""

from __future__ import annotations

import numpy as np

from searchtrack.core.types import FloatArray
from searchtrack.estimate import BeliefBank, GraphDiffusion, SearchField
from searchtrack.models import RoadNetwork, UavState
from searchtrack.plan.guidance import Guidance, GuidanceProblem, GuidanceView, StrategyConfig
from searchtrack.plan.guidance.view import SEARCH_SETTINGS
from searchtrack.sim.roads.scenario import Scenario


def strategy_config(scenario: Scenario) -> StrategyConfig:
    """The guidance parameters of ``scenario``: its sensor, UAVs, filter and guidance spec."""
    g = scenario.guidance
    return StrategyConfig(
        sensor_range_m=scenario.sensor.footprint_radius_m,
        spring_k=g.spring_k,
        loiter_k=g.loiter_k,
        revisit_threshold=g.revisit_threshold,
        p_min=scenario.filter.p_min,
        speed_mps=scenario.limits.speed_max_mps,
        optw_backend=g.optw_backend,
        optw_iterations=g.optw_iterations,
        coverage_weight=g.coverage_weight,
        **{name: getattr(g, name) for name in SEARCH_SETTINGS},
    )


def view(network: RoadNetwork, uavs: UavState, field: SearchField, bank: BeliefBank,
         time_s: float, coverage: FloatArray | None = None) -> GuidanceView:
    """What the guidance sees at ``time_s``: the search field to climb (the LRT field, or any
    :class:`~searchtrack.estimate.belief.SearchField`), the track beliefs (any
    :class:`~searchtrack.estimate.belief.BeliefBank`) and, when kept, the road coverage
    (:class:`~searchtrack.sim.roads.coverage.CoverageMemory`)."""
    return GuidanceView(network=network, uav_xy_m=uavs.xy_m,
                        uav_heading_rad=np.asarray(uavs.heading_rad),
                        uav_speed_mps=np.asarray(uavs.speed_mps), field=field, bank=bank,
                        time_s=time_s, coverage=coverage)


def next_problem(previous: tuple[GuidanceProblem, Guidance] | None, seen: GuidanceView,
                 config: StrategyConfig, tracker_diffusion: GraphDiffusion) -> GuidanceProblem:
    """The step's guidance problem: the first from ``config`` and ``tracker_diffusion``, later
    ones following the previous step's problem and answer (the routes being flown)."""
    if previous is None:
        return GuidanceProblem(seen, config, tracker_diffusion)
    return previous[0].following(seen, previous[1])
