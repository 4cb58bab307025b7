"""Courier-like targets: they stay on roads, never exceed V_max, stop, turn and are seeded."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork, grid_network, random_network
from searchtrack.models.dubins import MPS_PER_MPH
from searchtrack.models.targets import CourierModel, CourierMotion, TargetState

V_MAX = 50 * MPS_PER_MPH  # 22.352 m/s (Tables 6.2, 6.4)
DT = 0.3  # s (Tables 6.2, 6.4)


@pytest.fixture(scope="module")
def roads() -> RoadNetwork:
    """Random planar roads, 40 junctions in 1 km², nodes every 10 m."""
    return random_network(40, 1000.0, 10.0, seed=2)


def _plus() -> RoadNetwork:
    """A crossroads: centre node 0 and four 10 m arms to nodes 1–4 (edges 0–3)."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [-10.0, 0.0], [0.0, -10.0]])
    return RoadNetwork(coords=coords, edges=np.array([[0, 1], [0, 2], [0, 3], [0, 4]]),
                       lengths_m=np.full(4, 10.0))


def _state(k: int, edge: int, offset: float, forward: bool, speed: float) -> TargetState:
    return TargetState(edge=np.full(k, edge), offset_m=np.full(k, offset),
                       forward=np.full(k, forward), speed_mps=np.full(k, speed),
                       drive_left_s=np.full(k, 1e6), dwell_left_s=np.zeros(k),
                       odometer_m=np.zeros(k))


def _road_gap_m(net: RoadNetwork, a: TargetState, b: TargetState) -> np.ndarray:
    """Road distance (m) from each target in ``a`` to the same target in ``b``."""
    ea, eb = net.edges[a.edge], net.edges[b.edge]
    la, lb = net.lengths_m[a.edge], net.lengths_m[b.edge]
    to_a = np.column_stack([a.offset_m, la - a.offset_m])  # to edges[., 0] and edges[., 1]
    to_b = np.column_stack([b.offset_m, lb - b.offset_m])
    gap = np.where(a.edge == b.edge, np.abs(a.offset_m - b.offset_m), np.inf)
    dist = net.shortest_paths(np.unique(ea))
    row = {int(n): i for i, n in enumerate(np.unique(ea))}
    for i in range(a.n):
        for p in (0, 1):
            for q in (0, 1):
                d = to_a[i, p] + dist[row[int(ea[i, p])], eb[i, q]] + to_b[i, q]
                gap[i] = min(gap[i], d)
    return gap


def test_targets_stay_on_roads_and_move_continuously(roads: RoadNetwork) -> None:
    """Over 300 steps every target is on an edge, and moves along roads by its odometer."""
    motion = CourierMotion(roads)
    rng = np.random.default_rng(1)
    state = motion.spawn(30, rng)
    for k in range(300):
        new = motion.step(state, DT, rng)
        assert np.all(new.offset_m <= roads.lengths_m[new.edge])
        driven = new.odometer_m - state.odometer_m
        if k % 30 == 0:  # the road distance moved is at most the distance driven
            assert np.all(_road_gap_m(roads, state, new) <= driven + 1e-9)
        state = new
    u, v = roads.edges[state.edge].T
    xy = state.xy_m(roads)
    seg = roads.coords[v] - roads.coords[u]
    cross = seg[:, 0] * (xy - roads.coords[u])[:, 1] - seg[:, 1] * (xy - roads.coords[u])[:, 0]
    np.testing.assert_allclose(cross, 0.0, atol=1e-6)  # on the edge's segment


def test_targets_never_exceed_v_max(roads: RoadNetwork) -> None:
    """Per step, road and straight-line distances stay within V_max·Δt, and speeds reach it."""
    motion = CourierMotion(roads, CourierModel(mean_drive_s=20.0, dwell_min_s=0.0,
                                               dwell_max_s=2.0))
    rng = np.random.default_rng(2)
    state = motion.spawn(50, rng)
    top = 0.0
    for _ in range(400):
        new = motion.step(state, DT, rng)
        driven = new.odometer_m - state.odometer_m
        assert np.all(driven <= V_MAX * DT + 1e-9)
        jump = np.linalg.norm(new.xy_m(roads) - state.xy_m(roads), axis=1)
        assert np.all(jump <= V_MAX * DT + 1e-9)
        assert np.all(new.speed_mps <= V_MAX)
        top = max(top, float(driven.max()))
        state = new
    assert top > 0.95 * V_MAX * DT


def test_same_seed_same_trajectories(roads: RoadNetwork) -> None:
    """Two runs from the same seed agree exactly; another seed differs."""
    motion = CourierMotion(roads)

    def run(seed: int) -> TargetState:
        rng = np.random.default_rng(seed)
        state = motion.spawn(8, rng)
        for _ in range(100):
            state = motion.step(state, DT, rng)
        return state

    a, b, c = run(5), run(5), run(6)
    np.testing.assert_array_equal(a.edge, b.edge)
    np.testing.assert_array_equal(a.offset_m, b.offset_m)
    np.testing.assert_array_equal(a.dwell_left_s, b.dwell_left_s)
    assert not np.array_equal(a.offset_m, c.offset_m)


def test_targets_stop_and_start() -> None:
    """Targets stand still while stopped; the stopped fraction is E[dwell]/(E[dwell]+E[drive])."""
    net = grid_network(4, 4, 100.0, 10.0)
    model = CourierModel(mean_drive_s=10.0, dwell_min_s=2.0, dwell_max_s=8.0)
    motion = CourierMotion(net, model)
    rng = np.random.default_rng(3)
    state = motion.spawn(200, rng)
    stopped_steps, steps = 0, 0
    for k in range(600):
        new = motion.step(state, DT, rng)
        still = state.dwell_left_s >= DT  # stopped through the whole step
        np.testing.assert_allclose(new.dwell_left_s[still], state.dwell_left_s[still] - DT)
        np.testing.assert_array_equal(new.offset_m[still], state.offset_m[still])
        np.testing.assert_array_equal(new.odometer_m[still], state.odometer_m[still])
        if k >= 100:
            stopped_steps += int(new.stopped.sum())
            steps += new.n
        state = new
    assert stopped_steps / steps == pytest.approx(5.0 / 15.0, abs=0.03)


def test_random_turns_at_an_intersection() -> None:
    """Crossing a 4-way node, targets take each of the other three roads about equally, never
    turning back; at a dead end they turn back."""
    net = _plus()
    motion = CourierMotion(net)
    # 3000 targets 5 m from the centre on arm 0, heading in: 10 m later they are 5 m up an arm
    out = motion.step(_state(3000, 0, 5.0, False, 10.0), 1.0, np.random.default_rng(4))
    assert np.all(out.edge != 0)
    np.testing.assert_allclose(np.bincount(out.edge, minlength=4)[1:] / 3000, 1 / 3, atol=0.03)
    np.testing.assert_allclose(out.offset_m, 5.0)
    assert np.all(out.forward)  # heading away from the centre, edges[., 0]
    back = motion.step(_state(10, 0, 5.0, True, 10.0), 1.0, np.random.default_rng(4))
    assert np.all(back.edge == 0) and not np.any(back.forward)
    np.testing.assert_allclose(back.offset_m, 5.0)  # 5 m out to node 1, 5 m back


def test_along_a_road_targets_go_straight_on() -> None:
    """On a road's degree-2 nodes a target keeps going: 25 m along a straight road is 25 m away."""
    net = grid_network(1, 2, 100.0, 10.0)  # one 100 m road along x, nodes every 10 m
    end = int(np.argmin(net.coords[:, 0]))
    edge = int(np.flatnonzero(np.any(net.edges == end, axis=1))[0])
    forward = bool(net.edges[edge, 0] == end)
    state = _state(1, edge, 0.0 if forward else float(net.lengths_m[edge]), forward, 25.0)
    out = CourierMotion(net).step(state, 1.0, np.random.default_rng(0))
    np.testing.assert_allclose(out.xy_m(net), net.coords[[end]] + [[25.0, 0.0]], atol=1e-9)


def test_positions_and_nearest_nodes() -> None:
    """xy interpolates along the edge and nodes() gives the nearer end."""
    net = _plus()
    state = TargetState(edge=[0, 1, 3], offset_m=[2.5, 7.5, 10.0], forward=[True, True, False],
                        speed_mps=[1, 1, 1], drive_left_s=[1, 1, 1], dwell_left_s=[0, 0, 0],
                        odometer_m=[0, 0, 0])
    np.testing.assert_allclose(state.xy_m(net), [[2.5, 0.0], [0.0, 7.5], [0.0, -10.0]])
    np.testing.assert_array_equal(state.nodes(net), [0, 2, 4])


def test_spawn_is_uniform_over_road_length() -> None:
    """Spawned targets fall on the arms of a plus in proportion to their lengths."""
    coords = np.array([[0.0, 0.0], [30.0, 0.0], [0.0, 10.0]])
    net = RoadNetwork(coords=coords, edges=np.array([[0, 1], [0, 2]]),
                      lengths_m=np.array([30.0, 10.0]))
    state = CourierMotion(net).spawn(4000, np.random.default_rng(8))
    assert np.mean(state.edge == 0) == pytest.approx(0.75, abs=0.03)
    assert state.offset_m[state.edge == 0].mean() == pytest.approx(15.0, abs=0.6)
    assert np.all(state.speed_mps <= V_MAX) and np.all(state.speed_mps >= V_MAX / 2)


@pytest.mark.parametrize(
    ("build", "field"),
    [
        (lambda: CourierModel(max_speed_mps=-1.0), "max_speed_mps"),
        (lambda: CourierModel(max_speed_mps=math.nan), "max_speed_mps"),
        (lambda: CourierModel(min_speed_fraction=1.5), "min_speed_fraction"),
        (lambda: CourierModel(mean_drive_s=0.0), "mean_drive_s"),
        (lambda: CourierModel(dwell_min_s=10.0, dwell_max_s=5.0), "dwell_max_s"),
        (lambda: TargetState(edge=[0], offset_m=[0], forward=[True], speed_mps=[-2.0],
                             drive_left_s=[1], dwell_left_s=[0], odometer_m=[0]), "speed_mps"),
        (lambda: TargetState(edge=[0], offset_m=[math.nan], forward=[True], speed_mps=[2.0],
                             drive_left_s=[1], dwell_left_s=[0], odometer_m=[0]), "offset_m"),
        (lambda: TargetState(edge=[-1], offset_m=[0], forward=[True], speed_mps=[2.0],
                             drive_left_s=[1], dwell_left_s=[0], odometer_m=[0]), "edge"),
        (lambda: CourierMotion(_plus()).step(_state(1, 7, 0.0, True, 1.0), DT,
                                             np.random.default_rng(0)), "edge"),
        (lambda: CourierMotion(_plus()).step(_state(1, 0, 11.0, True, 1.0), DT,
                                             np.random.default_rng(0)), "offset_m"),
        (lambda: CourierMotion(_plus()).step(_state(1, 0, 1.0, True, 1.0), -DT,
                                             np.random.default_rng(0)), "dt_s"),
        (lambda: CourierMotion(_plus()).spawn(-1, np.random.default_rng(0)), "count"),
        (lambda: CourierMotion(_plus()).spawn(2, 42), "rng"),  # type: ignore[arg-type]
    ],
)
def test_bad_input_names_the_field(build: object, field: str) -> None:
    """Negative or NaN speeds and offsets, bad edges, Δt ≤ 0 and a non-Generator name the field."""
    with pytest.raises(InvalidInputError) as err:
        build()  # type: ignore[operator]
    assert err.value.field == field
