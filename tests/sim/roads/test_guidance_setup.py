"""Guidance set-up of a mission: the strategy's parameters from the scenario, the view the
guidance sees, and the step's problem."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.estimate import GraphDiffusion, LikelihoodField, TrackerBank
from searchtrack.models import DubinsLimits, RoadNetwork, SensorModel, UavState, grid_network
from searchtrack.plan.guidance import GuidanceProblem, StrategyConfig, solve
from searchtrack.sim.roads.guidance_setup import next_problem, strategy_config, view
from searchtrack.sim.roads.scenario import FilterSpec, GuidanceSpec, MapSpec, Scenario

UAVS = UavState(x_m=[50.0, 150.0], y_m=[0.0, 200.0], heading_rad=[0.0, math.pi / 2],
                speed_mps=[30.0, 25.0])


@pytest.fixture(scope="module")
def network() -> RoadNetwork:
    """A 3 × 3 grid of 100 m blocks with nodes every 20 m."""
    return grid_network(3, 3, 100.0, 20.0)


def test_spring_constants_reach_the_strategy() -> None:
    """``spring_k`` and ``loiter_k`` from the scenario configure the strategy's force laws."""
    from searchtrack.sim.roads.guidance_setup import strategy_config

    grid = MapSpec("grid", rows=3, cols=3)
    sc = Scenario("x", grid, guidance=GuidanceSpec(spring_k=5.0, loiter_k=7.0))
    config = strategy_config(sc)
    assert config.spring_k == 5.0
    assert config.loiter_k == 7.0


def test_strategy_config_takes_every_field_from_the_scenario() -> None:
    """ρ from the sensor, S_max from the UAV limits, P_min from the filter, the rest from the
    guidance spec; what the scenario does not set keeps the StrategyConfig default."""
    sc = Scenario("x", MapSpec("grid", rows=3, cols=3),
                  sensor=SensorModel(pd=0.9, pf=0.1, footprint_radius_m=140.0,
                                     position_noise_m=5.0),
                  limits=DubinsLimits(speed_max_mps=40.0, speed_min_mps=40.0),
                  filter=FilterSpec(p_min=0.12),
                  guidance=GuidanceSpec(revisit_threshold=0.45, optw_backend="labelling"))
    config = strategy_config(sc)
    assert config == StrategyConfig(sensor_range_m=140.0, spring_k=None, loiter_k=None,
                                    revisit_threshold=0.45, p_min=0.12, speed_mps=40.0,
                                    optw_backend="labelling")


def test_view_shows_the_uavs_field_and_bank(network: RoadNetwork) -> None:
    """The view holds the UAVs' positions, headings and speeds and the very field and bank."""
    field = LikelihoodField.neutral(network.n_nodes)
    bank = TrackerBank(network.n_nodes)
    seen = view(network, UAVS, field, bank, 4.2)
    assert seen.network is network and seen.field is field and seen.bank is bank
    np.testing.assert_array_equal(seen.uav_xy_m, [[50.0, 0.0], [150.0, 200.0]])
    np.testing.assert_array_equal(seen.uav_heading_rad, [0.0, math.pi / 2])
    np.testing.assert_array_equal(seen.uav_speed_mps, [30.0, 25.0])
    assert seen.time_s == 4.2


def test_next_problem_starts_from_the_config_then_follows(network: RoadNetwork) -> None:
    """The first problem takes the given config and tracker diffusion; later ones keep the
    previous problem's config, predictor and gradient structures, with the new view."""
    field = LikelihoodField.neutral(network.n_nodes)
    bank = TrackerBank(network.n_nodes)
    diffusion = GraphDiffusion.on_network(network, 0.447, 0.3)
    config = StrategyConfig(sensor_range_m=150.0)
    first = next_problem(None, view(network, UAVS, field, bank, 0.3), config, diffusion)
    assert isinstance(first, GuidanceProblem)
    assert first.config is config and first.predictor is diffusion and first.reacquisitions == ()
    answer = solve(first, backend="search")
    assert answer.plan is not None
    later_view = view(network, UAVS, field, bank, 0.6)
    other = GraphDiffusion.on_network(network, 1.0, 0.3)
    later = next_problem((first, answer.plan), later_view, StrategyConfig(), other)
    assert later.view is later_view and later.config is config
    assert later.predictor is diffusion and later.gradient is first.gradient
