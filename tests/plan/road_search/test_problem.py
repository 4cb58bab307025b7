"""The problem's validation (errors name the field), its constructor from a belief (also on a
merged network), its derived quantities and the plan type."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.road_builder import network_from_polylines
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.models.road_synthetic import grid_network
from searchtrack.plan.road_search import (
    ChainGraph,
    RoadPlan,
    RoadSearchProblem,
    RoadSearchSettings,
    target_weights,
)
from searchtrack.plan.road_search.problem import MAX_TICKS_PER_EDGE

from .helpers import FakeBelief, edge, grid_roads, uniform_belief


def base_problem(**changes: object) -> RoadSearchProblem:
    """Two targets of three particles on the grid, one UAV at the centre."""
    fields: dict[str, object] = {
        "roads": grid_roads(), "uav_nodes": (4,),
        "particle_edge": np.array([[0, 1, 2], [3, 4, 5]]),
        "particle_s": np.full((2, 3), 10.0), "particle_weight": np.ones((2, 3)),
        "entropy": np.array([1.0, 2.0]),
    }
    fields.update(changes)
    return RoadSearchProblem(**fields)  # type: ignore[arg-type]


def test_valid_problem_normalises_weights_and_derives_gamma_and_ticks() -> None:
    """Weights sum to 1 per target, γ is Eq. 20, every grid edge is one tick of 2.5 s."""
    p = base_problem(particle_weight=np.array([[1.0, 1.0, 2.0], [0.0, 0.0, 5.0]]))
    assert p.particle_weight.sum(axis=1) == pytest.approx([1.0, 1.0])
    assert p.particle_weight[0] == pytest.approx([0.25, 0.25, 0.5])
    assert p.gamma == pytest.approx(target_weights(np.array([1.0, 2.0])))
    assert p.tick_s == pytest.approx(100.0 / 40.0)
    assert np.all(p.edge_ticks == 1)
    assert (p.n_uavs, p.n_targets, p.lookahead) == (1, 2, 3)
    assert not p.particle_edge.flags.writeable and not p.particle_weight.flags.writeable


@pytest.mark.parametrize(("changes", "field"), [
    ({"uav_nodes": (9,)}, "uav_nodes"),
    ({"uav_nodes": ()}, "uav_nodes"),
    ({"uav_nodes": (1.5,)}, "uav_nodes"),
    ({"particle_edge": np.array([0, 1, 2])}, "particle_edge"),
    ({"particle_edge": np.array([[0, 1, 24], [3, 4, 5]])}, "particle_edge"),
    ({"particle_s": np.full((2, 3), 150.0)}, "particle_s"),
    ({"particle_s": np.full((2, 2), 1.0)}, "particle_s"),
    ({"particle_weight": -np.ones((2, 3))}, "particle_weight"),
    ({"particle_weight": np.array([[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]])}, "particle_weight"),
    ({"entropy": np.array([1.0])}, "entropy"),
    ({"entropy": np.array([1.0, -2.0])}, "entropy"),
    ({"truth_edge": np.array([0, 1])}, "truth_s"),
    ({"truth_edge": np.array([0, 99]), "truth_s": np.zeros(2)}, "truth_edge"),
    ({"truth_edge": np.array([0]), "truth_s": np.zeros(1)}, "truth_edge"),
    ({"roads": grid_network(3, 3, 100.0, spacing_m=100.0)}, "roads"),
    ({"settings": {"lookahead": 2}}, "settings"),
    ({"uav_delay_s": (1.0, 2.0)}, "uav_delay_s"),
    ({"uav_delay_s": (-1.0,)}, "uav_delay_s"),
    ({"uav_delay_s": (float("nan"),)}, "uav_delay_s"),
    ({"uav_delay_s": ("soon",)}, "uav_delay_s"),
])
def test_bad_problem_names_the_field(changes: dict[str, object], field: str) -> None:
    """Each bad field raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError) as err:
        base_problem(**changes)
    assert err.value.field == field


@pytest.mark.parametrize(("changes", "field"), [
    ({"lookahead": 0}, "lookahead"),
    ({"uav_speed_mps": 0.0}, "uav_speed_mps"),
    ({"discount": 0.0}, "discount"),
    ({"discount": 1.5}, "discount"),
    ({"gain": -1.0}, "gain"),
    ({"normalization": "mean"}, "normalization"),
    ({"weighting": "naive"}, "weighting"),
    ({"per_length": 1}, "per_length"),
    ({"draw_seed": -1}, "draw_seed"),
    ({"tick_s": 0.0}, "tick_s"),
    ({"horizon_s": 0.0}, "horizon_s"),
    ({"horizon_s": -3.0}, "horizon_s"),
    ({"motion": "cv"}, "motion"),
])
def test_bad_settings_name_the_field(changes: dict[str, object], field: str) -> None:
    """Each bad setting raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError) as err:
        RoadSearchSettings(**changes)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize("delay", [["soon"], [1.0, 2.0, 3.0], [-0.5], [float("inf")]])
def test_from_belief_names_a_bad_delay(delay: list[object]) -> None:
    """Delays given through ``from_belief`` are checked as the problem's own field."""
    belief = uniform_belief(grid_roads(), 2, 10, np.random.default_rng(0))
    with pytest.raises(InvalidInputError) as err:
        RoadSearchProblem.from_belief(belief, [4], uav_delay_s=delay)  # type: ignore[arg-type]
    assert err.value.field == "uav_delay_s"


def test_delays_default_to_zero_and_round_to_ticks() -> None:
    """No delays: every UAV at its node now; 3.9 s at 2.5 s ticks starts at tick 2."""
    p = base_problem(uav_nodes=(4, 0))
    assert p.uav_delay_s == (0.0, 0.0) and list(p.start_ticks) == [0, 0]
    q = base_problem(uav_nodes=(4, 0), uav_delay_s=[0.0, 3.9])
    assert q.uav_delay_s == (0.0, 3.9) and list(q.start_ticks) == [0, 2]
    assert [int(lat.state_tick[0]) for lat in q.scenario.lattices] == [0, 2]


def test_a_path_ends_at_the_look_ahead_or_past_the_horizon() -> None:
    """Without a horizon: at L edges. With 6 s (2.4 ticks of 2.5 s, so tick 2): after one edge
    at least, at the first arrival at tick 2 or later, never past L."""
    p = base_problem()
    assert p.horizon_tick is None
    assert not p.path_ends(99, 2) and p.path_ends(0, 3)
    q = base_problem(settings=RoadSearchSettings(horizon_s=6.0))
    assert q.horizon_tick == 2
    assert not q.path_ends(5, 0) and not q.path_ends(1, 1)
    assert q.path_ends(2, 1) and q.path_ends(0, 3)


def test_tick_rounds_edge_times() -> None:
    """With a 1 s tick a 100 m edge at 40 m/s takes round(2.5) = 2 ticks; at 30 m/s 3."""
    p = base_problem(settings=RoadSearchSettings(tick_s=1.0))
    assert np.all(p.edge_ticks == 2)
    q = base_problem(settings=RoadSearchSettings(tick_s=1.0, uav_speed_mps=30.0))
    assert np.all(q.edge_ticks == 3)


def test_from_belief_copies_the_belief() -> None:
    """from_belief takes the particles, weights and entropies of any RoadParticleBelief."""
    roads = grid_roads()
    belief = uniform_belief(roads, 3, 20, np.random.default_rng(1))
    p = RoadSearchProblem.from_belief(belief, [0, 8], settings=RoadSearchSettings(lookahead=2))
    assert p.uav_nodes == (0, 8) and p.n_targets == 3 and p.lookahead == 2
    assert np.array_equal(p.particle_edge, belief.edge)
    assert np.array_equal(p.entropy, belief.entropy)
    with pytest.raises(InvalidInputError) as err:
        RoadSearchProblem.from_belief("belief", [0])  # type: ignore[arg-type]
    assert err.value.field == "belief"


def test_from_belief_on_merged_chains() -> None:
    """On a 10 m grid merged into intersections (corners kept), particles map to the 100 m
    roads and a plan maps back to every 10 m node; a UAV between intersections is refused."""
    fine_net = grid_network(3, 3, 100.0, spacing_m=10.0)
    fine = DirectedRoads(fine_net)
    corners = [int(np.flatnonzero(np.all(fine_net.coords == xy, axis=1))[0])
               for xy in ([0.0, 0.0], [0.0, 200.0], [200.0, 0.0], [200.0, 200.0])]
    chains = ChainGraph(fine_net, keep=tuple(corners))
    e, s = fine.uniform((2, 50), np.random.default_rng(2))
    belief = FakeBelief(fine, e, s, np.ones((2, 50)), np.array([1.0, 2.0]))
    centre = int(np.flatnonzero(np.all(fine_net.coords == [100.0, 100.0], axis=1))[0])
    p = RoadSearchProblem.from_belief(belief, [centre], chains=chains,
                                      truth=(e[:, 0], s[:, 0]))
    assert p.roads.n_edges == 24 and p.chains is chains
    assert np.allclose(fine.point(e, s), p.roads.point(p.particle_edge, p.particle_s))
    assert p.truth_edge is not None and np.array_equal(p.truth_edge, p.particle_edge[:, 0])
    assert np.allclose(p.roads.network.coords[p.uav_nodes[0]], [100.0, 100.0])
    first = int(np.flatnonzero(p.roads.tail == p.uav_nodes[0])[0])
    nodes = p.network_nodes(RoadPlan.from_edges(p.roads, [[first]]))[0]
    assert nodes.size == 11 and nodes[0] == centre
    assert np.allclose(np.abs(np.diff(fine_net.coords[nodes], axis=0)).sum(axis=1), 10.0)
    middle = int(np.flatnonzero(np.all(fine_net.coords == [50.0, 100.0], axis=1))[0])
    with pytest.raises(InvalidInputError) as err:
        RoadSearchProblem.from_belief(belief, [middle], chains=chains)
    assert err.value.field == "uav_nodes"
    with pytest.raises(InvalidInputError) as err:
        RoadSearchProblem.from_belief(belief, [centre], chains=ChainGraph(grid_network(2, 2)))
    assert err.value.field == "chains"


def test_plan_from_edges() -> None:
    """A plan lists nodes and edges; the first edge is the one flown."""
    roads = grid_roads()
    plan = RoadPlan.from_edges(roads, [[edge(4, 3), edge(3, 0)], [edge(8, 5), edge(5, 4)]])
    assert plan.nodes == ((4, 3, 0), (8, 5, 4))
    assert plan.next_nodes == (3, 5)
    assert plan.first_edges == (edge(4, 3), edge(8, 5))


def test_problem_is_frozen() -> None:
    """The problem cannot be changed after construction."""
    p = base_problem()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.uav_nodes = (0,)  # type: ignore[misc]


def test_default_tick_is_capped_for_very_short_edges() -> None:
    """A 1 m road next to 100 m ones: the default tick is 100 m / 64 of flight, not 1 m."""
    net = network_from_polylines([np.array([(0.0, 0.0), (100.0, 0.0)]),
                                  np.array([(100.0, 0.0), (101.0, 0.0)])], 1000.0)
    roads = DirectedRoads(net)
    p = RoadSearchProblem(roads, (0,), np.zeros((1, 1), dtype=np.int64), np.zeros((1, 1)),
                          np.ones((1, 1)), np.ones(1))
    assert p.tick_s == pytest.approx(100.0 / MAX_TICKS_PER_EDGE / 40.0)
    assert sorted(p.edge_ticks.tolist()) == [1, 1, MAX_TICKS_PER_EDGE, MAX_TICKS_PER_EDGE]
