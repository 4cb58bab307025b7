"""Planner routes flown closed loop: OPTW and potential-field routes on the road map with the
Dubins unicycle, 3-D waypoints made flyable, and the adapters' input checks."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import SensorModel
from searchtrack.models.dubins import DubinsLimits
from searchtrack.models.road_synthetic import grid_network
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.trajectory import Obstacles
from searchtrack.sim.flight.loop import FlightConfig
from searchtrack.sim.flight.routes import (
    dubins_model,
    fixed_wing_path,
    fly_optw_route,
    fly_xy_path,
    path_waypoints,
    plan_optw_route,
    road_obstacles,
    route_deviation_m,
    route_waypoints,
)
from searchtrack.sim.roads.mission import Mission
from searchtrack.sim.roads.scenario import GuidanceSpec, MapSpec, Scenario

LIMITS = DubinsLimits()
SPEED_MPS = LIMITS.speed_max_mps
TURN_RADIUS_M = float(LIMITS.turn_radius_m(SPEED_MPS))


@pytest.fixture(scope="module")
def network() -> RoadNetwork:
    """A 5 × 5 grid of 100 m blocks."""
    return grid_network(5, 5, 100.0, 10.0)


@pytest.fixture(scope="module")
def buildings(network: RoadNetwork) -> Obstacles:
    """Five 15 m cylinders in the blocks, 10 m clear of every road."""
    return road_obstacles(network, 5, radius_m=15.0, clearance_m=10.0,
                          rng=np.random.default_rng(1))


@pytest.fixture(scope="module")
def route(network: RoadNetwork) -> tuple[int, ...]:
    """An OPTW route over random node scores from node 0 with a 30 s budget."""
    scores = np.random.default_rng(0).random(network.n_nodes) ** 4
    return plan_optw_route(network, scores, 0, speed_mps=SPEED_MPS, horizon_s=30.0,
                           max_nodes=20, time_limit_s=0.3)


def test_road_obstacles_stand_clear_of_the_roads(network: RoadNetwork,
                                                 buildings: Obstacles) -> None:
    """Every building is at least its clearance from every road node."""
    gaps = buildings.clearance_m(network.coords)
    assert buildings.k == 5 and gaps.min() >= 10.0 - 1e-9


def test_optw_route_flight_stays_near_route_without_collision(
        network: RoadNetwork, buildings: Obstacles, route: tuple[int, ...]) -> None:
    """NMPC flies the OPTW route's straight legs at constant speed: close, never inside."""
    assert len(route) >= 3 and route[0] == 0
    log = fly_optw_route(network, route, obstacles=buildings,
                         config=FlightConfig(backend="nmpc", time_limit_s=5.0),  # generous: busy CI
                         rng=np.random.default_rng(0))
    assert log.collisions == 0 and log.min_clearance_m > 0.0
    deviation = route_deviation_m(log, route_waypoints(network, route))
    assert np.sqrt(np.mean(deviation**2)) < TURN_RADIUS_M  # 10 m node hops: corners cut
    assert log.rms_error_m < 30.0
    np.testing.assert_allclose(log.inputs[:, 0], SPEED_MPS)  # Dubins: constant speed
    assert log.count("nmpc") == len(log.controllers)


def test_optw_route_along_roads_under_auto(network: RoadNetwork, buildings: Obstacles,
                                           route: tuple[int, ...]) -> None:
    """Following the roads between the route's nodes, ``auto`` tracks closely and keeps clear."""
    pts = route_waypoints(network, route[:4], along_roads=True)
    assert pts.shape[0] > 4
    log = fly_optw_route(network, route[:4], obstacles=buildings, along_roads=True,
                         config=FlightConfig(backend="auto", time_limit_s=0.2),
                         rng=np.random.default_rng(0))
    assert log.collisions == 0
    assert np.sqrt(np.mean(route_deviation_m(log, pts) ** 2)) < TURN_RADIUS_M


def test_potential_field_path_is_flown_around_a_building(network: RoadNetwork,
                                                         buildings: Obstacles) -> None:
    """The UAV track of a short potential-field road mission, flown by NMPC: a building put on
    the track is skirted, the rest is followed to about a metre."""
    sensor = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)
    scenario = Scenario("pf", MapSpec("grid", rows=5, cols=5, block_m=100.0), uav_count=1,
                        target_count=2, sensor=sensor, altitude_m=None, duration_s=20.0,
                        seed=5, guidance=GuidanceSpec(strategy="search_and_loiter"))
    xy = Mission(scenario).run().uav_xy_m[:, 0]
    on_track = Obstacles(centers_m=np.vstack([buildings.centers_m[:, :2], xy[len(xy) // 2]]),
                         radii_m=np.append(buildings.radii_m, 8.0))
    assert on_track.clearance_m(xy).min() < 0.0
    log = fly_xy_path(xy, limits=scenario.limits, obstacles=on_track,
                      config=FlightConfig(backend="nmpc", time_limit_s=5.0),  # generous: busy CI
                      rng=np.random.default_rng(0))
    assert log.collisions == 0 and log.min_clearance_m > 0.0
    assert np.median(route_deviation_m(log, xy)) < 2.0
    assert log.rms_error_m < 10.0
    assert dubins_model(scenario.limits).input_lower[0] == pytest.approx(SPEED_MPS)


def test_fixed_wing_path_spreads_vertical_moves_into_climbs() -> None:
    """Vertical lattice moves become climbs no steeper than the slope limit along the legs."""
    wps = np.array([[0, 0, 0], [0, 0, -12], [0, 0, -24], [12, 0, -24], [24, 0, -24],
                    [36, 0, -24], [48, 0, -24], [60, 0, -24], [72, 0, -24], [84, 0, -24],
                    [96, 0, -24], [108, 0, -24]], dtype=float)
    ref = fixed_wing_path(wps, 12.0, 0.25)
    pos = ref.positions_m
    run = np.linalg.norm(np.diff(pos[:, :2], axis=0), axis=1)
    assert np.all(np.abs(np.diff(pos[:, 2])) <= 0.25 * run + 1e-9)
    assert pos[-1, 2] == pytest.approx(-24.0)
    assert ref.duration_s == pytest.approx(108.0 / 12.0)


def test_bad_route_inputs_name_the_field(network: RoadNetwork) -> None:
    """Empty routes, out-of-range or NaN nodes and NaN paths raise InvalidInputError."""
    rng = np.random.default_rng(0)
    with pytest.raises(InvalidInputError, match="route_nodes"):
        fly_optw_route(network, [], rng=rng)
    with pytest.raises(InvalidInputError, match="route_nodes"):
        fly_optw_route(network, [0, network.n_nodes], rng=rng)
    with pytest.raises(InvalidInputError, match="route_nodes"):
        route_waypoints(network, [0.0, float("nan")])
    with pytest.raises(InvalidInputError, match="route_nodes"):
        fly_optw_route(network, [3], rng=rng)
    with pytest.raises(InvalidInputError, match="xy_m"):
        fly_xy_path([[0.0, 0.0], [float("nan"), 5.0]], rng=rng)
    with pytest.raises(InvalidInputError, match="xy_m"):
        path_waypoints([[1.0, 0.0], [1.0, 0.0]], min_spacing_m=5.0)
    with pytest.raises(InvalidInputError, match="start_node"):
        plan_optw_route(network, np.ones(network.n_nodes), network.n_nodes, speed_mps=10.0,
                        horizon_s=10.0)
