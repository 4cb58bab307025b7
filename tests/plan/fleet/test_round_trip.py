"""Lemma 1 of paper 000: S_node, the point-to-point check of Assumption 5, S_avg (Eq. 30) and
T_ave (Eq. 31), against the reproduction values of the paper's analysis."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork, grid_network
from searchtrack.plan.fleet import point_distance_mc, round_trip_ratio, s_avg, s_node, t_ave

from .conftest import grid_3x3


@pytest.mark.parametrize(("targets", "ratio"), [(2, 2.0), (3, 3.0), (4, 3.6095), (5, 4.0451),
                                                (10, 5.3047)])
def test_round_trip_ratio_matches_eq_30(targets: int, ratio: float) -> None:
    """S_avg/S_point is 2, 3, 3.6095, 4.0451 and 5.3047 for M = 2, 3, 4, 5, 10."""
    assert round_trip_ratio(targets) == pytest.approx(ratio, abs=1e-3)


def test_round_trip_ratio_is_the_mean_polygon_perimeter() -> None:
    """Eq. 30 averages the perimeters M·S·sin(π/M)/sin(πm/M) of the M − 1 polygons."""
    for m_targets in (2, 6, 17):
        per = [m_targets * math.sin(math.pi / m_targets) / math.sin(math.pi * m / m_targets)
               for m in range(1, m_targets)]
        assert round_trip_ratio(m_targets) == pytest.approx(np.mean(per))


@pytest.mark.parametrize(("rows", "cols", "with_diag", "without"),
                         [(2, 3, 138.89, 166.67), (3, 3, 177.78, 200.00)])
def test_s_node_on_grids(rows: int, cols: int, with_diag: float, without: float) -> None:
    """S_node for 100 m grids: 138.89/166.67 m (2 × 3) and 177.78/200.00 m (3 × 3)."""
    roads = grid_network(rows, cols, 100.0, 100.0)
    assert s_node(roads) == pytest.approx(with_diag, abs=5e-3)
    assert s_node(roads, include_diagonal=False) == pytest.approx(without, abs=5e-3)


def test_s_node_sampled_sources_estimate_the_mean() -> None:
    """Sampling sources is exact with every node and close with a third of them."""
    roads = grid_3x3(spacing_m=10.0)
    exact = s_node(roads)
    assert s_node(roads, sources=roads.n_nodes) == pytest.approx(exact)
    sampled = s_node(roads, sources=roads.n_nodes // 3, seed=4)
    assert sampled == pytest.approx(exact, rel=0.05)
    assert sampled == s_node(roads, sources=roads.n_nodes // 3, seed=4)


def test_point_distance_on_one_edge_is_a_third_of_it() -> None:
    """Two uniform points on one 90 m road are 30 m apart on average."""
    roads = RoadNetwork(np.array([[0.0, 0.0], [90.0, 0.0]]), np.array([[0, 1]]), np.array([90.0]))
    assert point_distance_mc(roads, 200_000, seed=1) == pytest.approx(30.0, rel=0.01)


def test_assumption_5_holds_on_the_paper_grid() -> None:
    """S_node (diagonal included) is within 2 % of the map length of the point-to-point mean,
    and S_node on finely resampled roads converges to it."""
    roads = grid_3x3()
    s_point = point_distance_mc(roads, 100_000, seed=0)
    assert abs(s_node(roads) - s_point) < 0.02 * roads.total_length_m
    fine = s_node(grid_3x3(spacing_m=5.0))
    assert fine == pytest.approx(s_point, rel=0.01)
    assert point_distance_mc(roads, 1000, seed=3) == point_distance_mc(roads, 1000, seed=3)


def test_point_distance_takes_the_way_round() -> None:
    """On a square loop two points on one long road may be closer around the other three."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]])
    edges = np.array([[0, 1], [1, 2], [2, 3], [0, 3]])
    roads = RoadNetwork(coords, edges, np.array([100.0, 10.0, 10.0, 10.0]))
    # the long road is 100 m but its ends are 30 m apart the other way
    assert point_distance_mc(roads, 20_000, seed=2) < 100.0 / 3


def test_s_avg_and_t_ave() -> None:
    """S_avg = ratio · S_point and T_ave = S_avg / V_a (M = 2 on the 3 × 3 grid: 8.89 s)."""
    s = s_node(grid_3x3())
    assert s_avg(2, s) == pytest.approx(2 * s)
    assert t_ave(2, s, 40.0) == pytest.approx(8.8889, abs=1e-4)


@pytest.mark.parametrize("targets", [0, 1, -3, 2.5, True, None, "4"])
def test_round_trip_refuses_bad_target_counts(targets: object) -> None:
    """Fewer than two targets or a non-integer count names the field ``targets``."""
    with pytest.raises(InvalidInputError, match="targets"):
        round_trip_ratio(targets)  # type: ignore[arg-type]


@pytest.mark.parametrize(("name", "call"), [
    ("s_point_m", lambda: s_avg(3, math.nan)),
    ("s_point_m", lambda: s_avg(3, -1.0)),
    ("uav_speed_mps", lambda: t_ave(3, 100.0, 0.0)),
    ("uav_speed_mps", lambda: t_ave(3, 100.0, math.inf)),
    ("samples", lambda: point_distance_mc(grid_3x3(), 0)),
    ("sources", lambda: s_node(grid_3x3(), sources=0)),
])
def test_bad_values_name_the_field(name: str, call: object) -> None:
    """NaN, negative, zero and infinite inputs raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError, match=name):
        call()  # type: ignore[operator]


def test_disconnected_network_is_refused() -> None:
    """Distances on a network in two pieces would be infinite: the network is refused."""
    roads = RoadNetwork(np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 0.0], [6.0, 0.0]]),
                        np.array([[0, 1], [2, 3]]), np.array([1.0, 1.0]))
    with pytest.raises(InvalidInputError, match="network"):
        s_node(roads)
    with pytest.raises(InvalidInputError, match="network"):
        point_distance_mc(roads)
