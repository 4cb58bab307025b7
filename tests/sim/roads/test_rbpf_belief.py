"""The RBPF of Moore et al. 2021 as a thesis mission's belief: the models mapped from the thesis's
couriers and sensor, the particle search field, and the bank and field the guidance reads."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import BeliefBank, TrackBelief
from searchtrack.estimate.stepping import RoadFilter, RoadScan, TrackBirth
from searchtrack.models import CourierModel, RoadNetwork, SensorModel, UavState, grid_network
from searchtrack.models.measurements import PositionScan
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.guidance import GuidanceView
from searchtrack.sim.roads.guidance_setup import view
from searchtrack.sim.roads.metrics import count_associations, credit_birth, match_tracks
from searchtrack.sim.roads.rbpf_belief import (
    MAX_P_FA,
    RBPFMissionBelief,
    courier_motion,
    rbpf_config,
    thesis_disc_sensor,
)
from searchtrack.sim.roads.scenario import FilterSpec, MapSpec, Scenario

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=120.0, position_noise_m=5.0)


@pytest.fixture(scope="module")
def network() -> RoadNetwork:
    """A 4 × 4 grid of 100 m blocks, nodes every 10 m."""
    return grid_network(4, 4, 100.0, 10.0)


def scenario(**changes: object) -> Scenario:
    """Two targets on the 4 × 4 grid, an RBPF of 3 histories × 200 particles."""
    base = Scenario("rbpf", MapSpec("grid", rows=4, cols=4, block_m=100.0), uav_count=1,
                    target_count=2, sensor=SENSOR, altitude_m=None, seed=5,
                    filter=FilterSpec(belief="rbpf", histories=3, particles=200))
    return dataclasses.replace(base, **changes)  # type: ignore[arg-type]


def test_courier_motion_is_the_couriers_drives_and_stops() -> None:
    """The particles drive at the couriers' speeds for their mean drive and stop for their mean
    dwell; couriers that never dwell give particles that stop for about a step."""
    c = CourierModel(max_speed_mps=20.0, min_speed_fraction=0.5, mean_drive_s=60.0,
                     dwell_min_s=10.0, dwell_max_s=30.0)
    m = courier_motion(c)
    assert (m.min_speed_mps, m.max_speed_mps, m.mean_drive_s, m.mean_stop_s) == (
        10.0, 20.0, 60.0, 20.0)
    assert m.driving_share == pytest.approx(0.75)
    steady = courier_motion(CourierModel(max_speed_mps=12.0, min_speed_fraction=1.0,
                                         dwell_min_s=0.0, dwell_max_s=0.0))
    assert steady.min_speed_mps == steady.max_speed_mps == 12.0
    assert steady.switch_chances(0.3)[1] == pytest.approx(1.0)


def test_disc_sensor_is_the_thesis_sensor() -> None:
    """View ρ, σ² = s², P_FN = 1 − P_d, P_FA = P(at least one Poisson false alarm), the negative
    update over the whole footprint; P_FA is capped below 1 and a noiseless sensor refused."""
    d = thesis_disc_sensor(SENSOR)
    assert (d.fov_radius_m, d.sigma2_m2) == (120.0, 25.0)
    assert d.p_fn == pytest.approx(0.05)
    assert d.p_fa == pytest.approx(1.0 - math.exp(-0.05))
    assert d.negative_radius_m == 120.0 and d.clutter == "view"
    noisy = thesis_disc_sensor(dataclasses.replace(SENSOR, false_alarms_per_scan=100.0))
    assert noisy.p_fa == MAX_P_FA
    with pytest.raises(InvalidInputError) as info:
        thesis_disc_sensor(dataclasses.replace(SENSOR, position_noise_m=0.0))
    assert info.value.field == "sensor.position_noise_m"


def test_config_takes_the_sizes_from_the_scenario() -> None:
    """M = the scenario's targets, H and N from its filter spec, one-to-one scans."""
    cfg = rbpf_config(scenario(target_count=3))
    assert (cfg.n_targets, cfg.n_histories, cfg.n_particles) == (3, 3, 200)
    assert cfg.association == "joint"


@pytest.mark.parametrize(("make", "name"), [
    (lambda net: RBPFMissionBelief(scenario(), net, np.random.default_rng(0),
                                   DirectedRoads(grid_network(2, 2))), "roads"),
    (lambda net: RBPFMissionBelief(scenario(), net, 5), "rng"),  # type: ignore[arg-type]
])
def test_bad_inputs_name_the_field(network: RoadNetwork, make: object, name: str) -> None:
    """A directed view of another map and a seed where the filter's generator belongs are
    refused by name."""
    with pytest.raises(InvalidInputError) as info:
        make(network)  # type: ignore[operator]
    assert info.value.field == name


def test_a_search_lrt_of_another_map_is_refused(network: RoadNetwork) -> None:
    """The LRT whose φ is the search field must be of the filter's own network."""
    from searchtrack.sim.roads.lrt_belief import LRTMissionBelief
    from searchtrack.sim.roads.world import World

    other = scenario(map=MapSpec("grid", rows=2, cols=2, block_m=100.0))
    lrt = LRTMissionBelief.for_mission(other, World.build(other), np.random.default_rng(0))
    with pytest.raises(InvalidInputError) as info:
        RBPFMissionBelief(scenario(), network, np.random.default_rng(0), search=lrt)
    assert info.value.field == "search"


UAV = UavState(np.array([150.0]), np.array([110.0]), np.zeros(1), np.full(1, 30.0))
TRUTH = np.array([[150.0, 100.0], [300.0, 300.0]])


def _scan(xy: list[list[float]], target: list[int], time_s: float) -> RoadScan:
    pts = np.array(xy, dtype=float).reshape(-1, 2)
    tgt = np.array(target, dtype=np.int64)
    return RoadScan(time_s, PositionScan(np.zeros(len(tgt), dtype=np.int64), pts, tgt))


def test_detections_localise_a_target_for_the_guidance(network: RoadNetwork) -> None:
    """Repeated fixes of a target under the UAV make one filter target a live track (a birth
    credited to the true target, its MAP peak on it, an association scored valid); the bank is
    a BeliefBank the guidance view accepts, and the searched footprint scores below the rest."""
    sc = scenario()
    belief = RBPFMissionBelief(sc, network, np.random.default_rng(5))
    assert isinstance(belief, RoadFilter)
    assert len(belief.bank) == 0 and isinstance(belief.bank, BeliefBank)
    np.testing.assert_allclose(belief.search_field.node_score(), 0.0)
    births: list[TrackBirth] = []
    valid = 0
    for k in range(6):
        scan = _scan([[151.0, 100.0 + k]], [0], 0.3 * (k + 1))
        matched = match_tracks([t.track_id for t in belief.bank], belief.estimates_xy(), TRUTH,
                               sc.valid_distance_m)
        found = belief.update(scan, UAV)
        pairs = [(j, track, int(scan.positions.target[q])) for j, track, q in found.pairs]
        n_valid, n_false = count_associations(pairs, matched)
        valid += n_valid
        assert len(pairs) == n_valid + n_false
        births += found.births
        belief.predict(0.3)
    assert len(belief.bank) == 1 and isinstance(belief.bank[0], TrackBelief)
    assert np.linalg.norm(belief.estimates_xy()[0] - TRUTH[0]) < sc.valid_distance_m
    assert valid >= 1
    assert [credit_birth(b.xy_m, TRUTH, sc.valid_distance_m)[0] for b in births] == [0]
    assert [b.track_id for b in births] == [belief.bank[0].track_id]
    score = belief.search_field.node_score()
    under = network.nodes_within(UAV.xy_m, 60.0)[1]
    assert score[under].max() < np.median(score)
    seen = view(network, UAV, belief.search_field, belief.bank, 1.8)
    assert isinstance(seen, GuidanceView) and len(seen.bank) == 1


def test_detect_mode_keeps_no_tracks_and_reports_the_birth(network: RoadNetwork) -> None:
    """In detect mode a localised target is reported as a birth (credited to the true target
    it is on, the other never) and the bank stays empty, as the thesis's detect-mode trackers
    are dropped at birth."""
    sc = scenario(mode="detect")
    belief = RBPFMissionBelief(sc, network, np.random.default_rng(5))
    found = np.zeros(2, dtype=bool)
    for k in range(4):
        births = belief.update(_scan([[150.0, 101.0]], [0], 0.3 * (k + 1)), UAV).births
        for b in births:
            target, _ = credit_birth(b.xy_m, TRUTH, sc.valid_distance_m, found)
            if target >= 0:
                found[target] = True
    assert found.tolist() == [True, False]
    assert len(belief.bank) == 0 and belief.estimates_xy().shape == (0, 2)


def test_the_filter_owns_its_draws(network: RoadNetwork) -> None:
    """Two filters given generators of one seed step identically (no call takes a generator);
    another seed starts from other clouds."""
    sc = scenario()
    runs = []
    for seed in (5, 5, 6):
        belief = RBPFMissionBelief(sc, network, np.random.default_rng(seed))
        for k in range(3):
            belief.update(_scan([[151.0, 100.0]], [0], 0.3 * (k + 1)), UAV)
            belief.predict(0.3)
        runs.append(belief.rbpf.target_particles())
    for a, b in zip(runs[0], runs[1], strict=True):
        np.testing.assert_array_equal(a, b)
    assert not np.array_equal(runs[0][1], runs[2][1])


def _tracked(belief: RBPFMissionBelief) -> None:
    """Six fixes of target 0 under the UAV, the last one not predicted on (target 0 is then in
    the bank, which the last update set)."""
    for k in range(6):
        if k:
            belief.predict(0.3)
        belief.update(_scan([[151.0, 100.0 + k]], [0], 0.3 * (k + 1)), UAV)
    assert len(belief.bank) == 1


@pytest.mark.parametrize("resolution", [None, 0.0, 12.0])
def test_the_bank_reads_the_cloud_at_the_sensor_resolution(network: RoadNetwork,
                                                           resolution: float | None) -> None:
    """The bank holds each localised target's own node belief blurred by the road kernel of
    ``filter.node_resolution_m`` (the sensor's ``s`` when unset; none at 0); the localisation
    and the estimates read the cloud itself."""
    sc = scenario(filter=FilterSpec(belief="rbpf", histories=3, particles=200,
                                    node_resolution_m=resolution))
    belief = RBPFMissionBelief(sc, network, np.random.default_rng(5))
    _tracked(belief)
    own = belief.rbpf.node_beliefs()[belief.bank[0].track_id].probability
    sigma = SENSOR.position_noise_m if resolution is None else resolution
    if sigma == 0.0:
        assert belief.kernel is None
        np.testing.assert_array_equal(belief.bank[0].probability, own)
        return
    assert belief.kernel is not None and belief.kernel.sigma_m == sigma
    np.testing.assert_allclose(belief.bank[0].probability, own @ belief.kernel.matrix.toarray(),
                               atol=1e-12)
    assert belief.bank[0].peak_probability < own.max()
    np.testing.assert_array_equal(belief.estimates_xy(), belief.rbpf.map_positions()[[0]])


def test_a_mission_filter_shares_its_worlds_kernel(network: RoadNetwork) -> None:
    """Filters built for missions on one world read through the kernel it keeps."""
    from searchtrack.sim.roads.world import World

    sc = scenario()
    world = World.build(sc, network)
    a = RBPFMissionBelief.for_mission(sc, world, np.random.default_rng(1))
    b = RBPFMissionBelief.for_mission(sc, world, np.random.default_rng(2))
    assert a.kernel is b.kernel is world.road_kernel(SENSOR.position_noise_m)


def test_a_kernel_of_another_map_or_resolution_is_refused(network: RoadNetwork) -> None:
    """A kernel of another network, or of another σ than the scenario's node resolution
    (with no kernel wanted at all, 0), is named as bad input."""
    from searchtrack.estimate.road_kernel import RoadKernel

    sc = scenario()
    for kernel, spec in ((RoadKernel(grid_network(2, 2), SENSOR.position_noise_m), sc),
                         (RoadKernel(network, 2.0 * SENSOR.position_noise_m), sc),
                         (RoadKernel(network, SENSOR.position_noise_m), dataclasses.replace(
                             sc, filter=dataclasses.replace(sc.filter, node_resolution_m=0.0)))):
        with pytest.raises(InvalidInputError) as info:
            RBPFMissionBelief(spec, network, np.random.default_rng(0), kernel=kernel)
        assert info.value.field == "kernel" and "node resolution" in str(info.value)
