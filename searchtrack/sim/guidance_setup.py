"""Build a scenario's guidance strategy and the view it sees each step."""

from __future__ import annotations

import numpy as np

from searchtrack.estimate import GraphDiffusion, LikelihoodField, TrackerBank
from searchtrack.models import RoadNetwork, UavState
from searchtrack.plan.guidance import STRATEGIES, GuidanceView, Strategy, StrategyConfig
from searchtrack.sim.scenario import Scenario


def make_strategy(scenario: Scenario, tracker_diffusion: GraphDiffusion) -> Strategy:
    """The scenario's strategy, configured from its sensor, UAVs, filter and guidance spec."""
    g = scenario.guidance
    rho = scenario.sensor.footprint_radius_m
    config = StrategyConfig(
        sensor_range_m=rho,
        spring_k=g.spring_k,
        loiter_k=g.loiter_k,
        revisit_threshold=g.revisit_threshold,
        p_min=scenario.filter.p_min,
        speed_mps=scenario.limits.speed_max_mps,
        optw_backend=g.optw_backend,
        optw_budget_s=g.optw_budget_s,
    )
    return STRATEGIES[g.strategy](config, tracker_diffusion)


def view(network: RoadNetwork, uavs: UavState, field: LikelihoodField, bank: TrackerBank,
         time_s: float) -> GuidanceView:
    """What the strategy sees at ``time_s``."""
    return GuidanceView(network=network, uav_xy_m=uavs.xy_m,
                        uav_heading_rad=np.asarray(uavs.heading_rad),
                        uav_speed_mps=np.asarray(uavs.speed_mps), llr=field.llr, bank=bank,
                        time_s=time_s)
