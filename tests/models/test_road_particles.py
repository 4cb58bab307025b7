"""Directed roads and the road motion model: successors, uniform init, advance, G(x), nearest."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork, grid_network
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads, RoadMotion


def _path(n: int, spacing_m: float = 10.0) -> DirectedRoads:
    """A straight road of ``n`` nodes along x (dead ends at both ends)."""
    coords = np.column_stack([np.arange(n) * spacing_m, np.zeros(n)])
    edges = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    return DirectedRoads(RoadNetwork(coords, edges, np.full(n - 1, spacing_m)))


@pytest.fixture(scope="module")
def grid3() -> DirectedRoads:
    """The paper's 3×3 map: 12 two-way roads of 100 m."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def _succ(roads: DirectedRoads, d: int) -> set[int]:
    return set(roads.successors[roads.successor_ptr[d]:roads.successor_ptr[d + 1]].tolist())


def test_directed_edges_pair_up(grid3: DirectedRoads) -> None:
    """Edge 2k runs along road k, 2k + 1 back: reverse is d ^ 1, same length."""
    assert grid3.n_edges == 24
    d = np.arange(24)
    np.testing.assert_array_equal(grid3.tail[d], grid3.head[d ^ 1])
    np.testing.assert_array_equal(grid3.length[d], grid3.length[d ^ 1])
    assert grid3.total_length_m == pytest.approx(2400.0)


def test_successors_leave_the_head_without_u_turns(grid3: DirectedRoads) -> None:
    """Successors start at the head, exclude the reverse edge, and are all other out-edges."""
    deg = np.bincount(grid3.tail, minlength=9)
    for d in range(grid3.n_edges):
        succ = _succ(grid3, d)
        assert all(grid3.tail[e] == grid3.head[d] for e in succ)
        assert d ^ 1 not in succ
        assert len(succ) == deg[grid3.head[d]] - 1


def test_dead_end_allows_the_u_turn_only() -> None:
    """At a dead end the reverse edge is the only successor; mid-road it is excluded."""
    roads = _path(3)
    assert _succ(roads, 0) == {2}   # 0→1 continues 1→2
    assert _succ(roads, 2) == {3}   # 1→2 ends at a dead end: U-turn 2→1
    assert _succ(roads, 3) == {1}   # 2→1 continues 1→0
    np.testing.assert_array_equal(roads.successor_count, [1, 1, 1, 1])


def test_turns_are_uniform_and_never_u_turns(grid3: DirectedRoads) -> None:
    """Particles crossing the centre node pick each of its 3 onward edges about equally often."""
    d = next(d for d in range(24) if grid3.head[d] == 4)
    n = 30_000
    edge = np.full(n, d)
    s = np.full(n, 99.0)
    out, pos = grid3.advance(edge, s, np.full(n, 2.0), np.random.default_rng(0))
    assert not np.any(out == d ^ 1)
    np.testing.assert_allclose(pos, 1.0)
    counts = np.array([np.sum(out == e) for e in sorted(_succ(grid3, d))])
    assert counts.sum() == n
    np.testing.assert_allclose(counts / n, 1 / 3, atol=0.015)


def test_uniform_init_is_uniform_by_length() -> None:
    """Edges are drawn in proportion to length and s is uniform along the edge (Eq. 1)."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [40.0, 0.0]])
    roads = DirectedRoads(RoadNetwork(coords, np.array([[0, 1], [1, 2]]), np.array([10.0, 30.0])))
    edge, s = roads.uniform(40_000, np.random.default_rng(1))
    assert edge.dtype == np.int64 and edge.shape == (40_000,)
    np.testing.assert_allclose(np.isin(edge, [2, 3]).mean(), 0.75, atol=0.01)
    np.testing.assert_allclose(np.bincount(edge, minlength=4) / 40_000, [0.125, 0.125, 0.375,
                                                                          0.375], atol=0.01)
    frac = s / roads.length[edge]
    assert frac.min() >= 0.0 and frac.max() <= 1.0
    np.testing.assert_allclose(np.quantile(frac, [0.1, 0.5, 0.9]), [0.1, 0.5, 0.9], atol=0.01)


def test_uniform_init_keeps_the_shape(grid3: DirectedRoads) -> None:
    """A tuple shape gives arrays of that shape."""
    edge, s = grid3.uniform((3, 4, 5), np.random.default_rng(0))
    assert edge.shape == s.shape == (3, 4, 5)
    grid3.check_positions(edge, s)


def test_advance_carries_leftover_over_several_nodes() -> None:
    """25 m from 2 m along the first 10 m edge ends 7 m along the third edge."""
    roads = _path(5)
    edge, s = roads.advance(np.array([0]), np.array([2.0]), np.array([25.0]),
                            np.random.default_rng(0))
    assert edge[0] == 4 and s[0] == pytest.approx(7.0)
    np.testing.assert_allclose(roads.point(edge, s), [[27.0, 0.0]])


def test_advance_turns_back_at_a_dead_end() -> None:
    """On a 20 m road, 30 m from 5 m goes to the end and 15 m back: x = 5 on edge 1→0."""
    roads = _path(3)
    edge, s = roads.advance(np.array([0]), np.array([5.0]), np.array([30.0]),
                            np.random.default_rng(0))
    assert edge[0] == 1 and s[0] == pytest.approx(5.0)
    np.testing.assert_allclose(roads.point(edge, s), [[5.0, 0.0]])


def test_point_is_linear_along_the_edge(grid3: DirectedRoads) -> None:
    """G(d, 0) is the tail, G(d, len) the head, G(d, len/2) the midpoint."""
    coords = grid3.network.coords
    d = np.arange(24)
    np.testing.assert_allclose(grid3.point(d, np.zeros(24)), coords[grid3.tail])
    np.testing.assert_allclose(grid3.point(d, grid3.length), coords[grid3.head])
    np.testing.assert_allclose(grid3.point(d, grid3.length / 2),
                               (coords[grid3.tail] + coords[grid3.head]) / 2)
    np.testing.assert_allclose(grid3.tail_xy + 30.0 * grid3.step_xy,
                               grid3.point(d, np.full(24, 30.0)))


def test_nearest_projects_onto_the_closest_road(grid3: DirectedRoads) -> None:
    """A point 3 m off the road y = 0 at x = 42 maps to 42 m along the even edge of that road."""
    edge, s = grid3.nearest(np.array([[42.0, 3.0], [200.0, 170.0]]))
    assert np.all(edge % 2 == 0)
    np.testing.assert_allclose(grid3.point(edge, s), [[42.0, 0.0], [200.0, 170.0]], atol=1e-9)


def test_disc_intervals_measure_the_road_in_a_disc(grid3: DirectedRoads) -> None:
    """A 30 m disc at the centre node holds 4 arms of 30 m, twice (both directions)."""
    s0, s1 = grid3.disc_intervals(np.array([100.0, 100.0]), 30.0)
    assert (s1 - s0).sum() == pytest.approx(240.0)
    assert np.all(s1 >= s0)
    s0, s1 = grid3.disc_intervals(np.array([50.0, 10.0]), 26.0)  # chord of half-length 24 m
    assert (s1 - s0).sum() == pytest.approx(96.0)
    inside = grid3.point(np.arange(24), (s0 + s1) / 2)
    hit = s1 > s0
    assert np.all(np.hypot(*(inside[hit] - [50.0, 10.0]).T) <= 26.0)


def test_motion_mean_and_variance_follow_eq_9() -> None:
    """On a long road the step is v·δt on average with variance σ²·δt² (Lemma 2)."""
    roads = _path(3, 1000.0)
    n = 20_000
    edge, s = RoadMotion(10.0, 4.0).step(roads, np.zeros(n, dtype=np.int64),
                                         np.full(n, 100.0), 0.5, np.random.default_rng(2))
    assert np.all(edge == 0)
    np.testing.assert_allclose((s - 100.0).mean(), 5.0, atol=0.05)
    np.testing.assert_allclose((s - 100.0).var(), 4.0, rtol=0.05)


def test_motion_never_reverses() -> None:
    """Negative noisy speeds are clipped: a particle never moves backwards."""
    roads = _path(3, 1000.0)
    edge, s = RoadMotion(0.0, 5.0).step(roads, np.zeros(1000, dtype=np.int64),
                                        np.full(1000, 10.0), 1.0, np.random.default_rng(3))
    assert np.all(s >= 10.0) and np.all(edge == 0)


def test_bad_input_names_the_field(grid3: DirectedRoads) -> None:
    """Out-of-range edges and arc lengths, bad motion parameters and NaN points are refused."""
    ok_e, ok_s = np.array([0, 1]), np.array([0.0, 50.0])
    with pytest.raises(InvalidInputError, match="edge"):
        grid3.check_positions(np.array([0, 24]), ok_s)
    with pytest.raises(InvalidInputError, match=r"^s="):
        grid3.check_positions(ok_e, np.array([0.0, 101.0]))
    with pytest.raises(InvalidInputError, match=r"^s="):
        grid3.check_positions(ok_e, np.array([-1.0, 1.0]))
    with pytest.raises(InvalidInputError, match=r"^s="):
        grid3.check_positions(ok_e, np.array([0.0]))
    with pytest.raises(InvalidInputError, match="speed_mps"):
        RoadMotion(speed_mps=-1.0)
    with pytest.raises(InvalidInputError, match="sigma_mps"):
        RoadMotion(sigma_mps=float("nan"))
    with pytest.raises(InvalidInputError, match="dt_s"):
        RoadMotion().step(grid3, ok_e, ok_s, -0.1, np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="points"):
        grid3.nearest(np.array([[np.nan, 0.0]]))
    with pytest.raises(InvalidInputError, match="radius_m"):
        grid3.disc_intervals(np.zeros(2), -1.0)


def test_leaving_lists_every_road_out_of_a_node_including_the_way_back() -> None:
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    centre = 4  # the middle of the 3 × 3 grid: four roads
    out = roads.leaving(centre)
    assert out.size == 4 and np.all(np.diff(out) > 0)
    assert np.all(roads.tail[out] == centre)
    for node in range(roads.network.n_nodes):
        assert set(roads.leaving(node).tolist()) == set(np.flatnonzero(roads.tail == node).tolist())


@pytest.mark.parametrize("kwargs,field", [
    ({"min_speed_mps": -1.0}, "min_speed_mps"),
    ({"min_speed_mps": 12.0, "max_speed_mps": 10.0}, "max_speed_mps"),
    ({"max_speed_mps": 0.0, "min_speed_mps": 0.0}, "max_speed_mps"),
    ({"mean_drive_s": 0.0}, "mean_drive_s"),
    ({"mean_stop_s": float("nan")}, "mean_stop_s"),
])
def test_courier_motion_bad_settings_name_the_field(kwargs: dict[str, float],
                                                    field: str) -> None:
    """A drive-and-stop motion with a bad speed range or mean refuses it by name."""
    with pytest.raises(InvalidInputError, match=field):
        CourierRoadMotion(**kwargs)
    with pytest.raises(InvalidInputError, match="dt_s"):
        CourierRoadMotion().switch_chances(-0.1)


def test_courier_motion_drives_and_stops_at_its_rates() -> None:
    """The stationary law drives a share T_d / (T_d + T_s) of the particles at speeds in the
    range; stopped particles do not move; drives and stops end at the rates 1/T_d and 1/T_s."""
    roads = DirectedRoads(grid_network(4, 4, 100.0, spacing_m=100.0))
    motion = CourierRoadMotion(min_speed_mps=6.0, max_speed_mps=12.0, mean_drive_s=20.0,
                               mean_stop_s=5.0)
    rng = np.random.default_rng(0)
    v = motion.initial_speeds(200_000, rng)
    assert np.mean(v > 0.0) == pytest.approx(0.8, abs=0.005)
    assert v[v > 0.0].min() >= 6.0 and v.max() <= 12.0
    edge, s = roads.uniform(200_000, rng)
    edge2, s2, v2 = motion.step(roads, edge, s, v, 0.5, rng)
    still = (v == 0.0) & (v2 == 0.0)
    assert np.all(s2[still] == s[still]) and np.all(edge2[still] == edge[still])
    stop, go = motion.switch_chances(0.5)
    assert np.mean(v2[v > 0.0] == 0.0) == pytest.approx(stop, abs=0.002)
    assert np.mean(v2[v == 0.0] > 0.0) == pytest.approx(go, abs=0.005)
    np.testing.assert_array_equal(v2[(v > 0.0) & (v2 > 0.0)], v[(v > 0.0) & (v2 > 0.0)])
