"""The fixed-draw scenario: time-expanded graphs, propagation, particle groups and their
cover matrix checked against a per-particle computation, the objective by hand, the bound."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from searchtrack.plan.road_search import RoadPlan, RoadSearchProblem, RoadSearchSettings
from searchtrack.plan.road_search.scenario import propagate

from .helpers import STATIC, edge, grid_roads, random_problem, random_roads


def static_problem(**settings: object) -> RoadSearchProblem:
    """Target 0: one particle on road 3–4 (driving 3→4); target 1: one on road 0–1."""
    return RoadSearchProblem(
        grid_roads(), (4,), np.array([[edge(3, 4)], [edge(0, 1)]]), np.array([[50.0], [30.0]]),
        np.ones((2, 1)), np.array([1.0, 3.0]),
        RoadSearchSettings(motion=STATIC, **settings))  # type: ignore[arg-type]


def every_plan(problem: RoadSearchProblem) -> list[RoadPlan]:
    """Every joint plan, by brute force over node sequences; with a horizon a path stops at the
    first node it reaches at or past it (arrival times summed here from the edge lengths)."""
    roads = problem.roads
    st = problem.settings
    step = st.uav_speed_mps * problem.tick_s
    horizon = math.inf if st.horizon_s is None else round(st.horizon_s / problem.tick_s)

    def arrival(start_tick: int, path: list[int]) -> int:
        return start_tick + sum(max(1, round(float(roads.length[e]) / step)) for e in path)

    per_uav = []
    for start, delay in zip(problem.uav_nodes, problem.uav_delay_s, strict=True):
        t0 = round(delay / problem.tick_s)
        done: list[list[int]] = []
        paths: list[list[int]] = [[]]
        for _ in range(problem.lookahead):
            paths = [[*p, int(e)] for p in paths
                     for e in np.flatnonzero(roads.tail == (roads.head[p[-1]] if p else start))]
            done += [p for p in paths if arrival(t0, p) >= horizon]
            paths = [p for p in paths if arrival(t0, p) < horizon]
        per_uav.append(done + paths)
    return [RoadPlan.from_edges(roads, list(c)) for c in itertools.product(*per_uav)]


def test_objective_by_hand() -> None:
    """Path 4→3→0→1 sees target 0 at level 0 (β 1) and target 1 at level 2 (β 0.64)."""
    p = static_problem()
    plan = RoadPlan.from_edges(p.roads, [[edge(4, 3), edge(3, 0), edge(0, 1)]])
    g = p.gamma
    assert p.scenario.score(plan) == pytest.approx(g[0] + 0.64 * g[1], rel=1e-12)
    one_way = static_problem(both_directions=False)
    assert one_way.scenario.score(plan) == pytest.approx(0.64 * g[1], rel=1e-12)
    per_m = static_problem(per_length=True, discount=0.5)
    assert per_m.scenario.score(plan) == pytest.approx((g[0] + 0.25 * g[1]) / 100.0, rel=1e-12)
    twice = RoadPlan.from_edges(p.roads, [[edge(4, 3), edge(3, 4), edge(4, 3)]])
    assert p.scenario.score(twice) == pytest.approx(g[0], rel=1e-12)  # counted once


def test_lattice_of_the_grid() -> None:
    """From the centre, L = 2: 4 arcs to the 4 neighbours at tick 1, then 12 arcs to 5 nodes."""
    p = random_problem(grid_roads(), np.random.default_rng(0), lookahead=2)
    p = RoadSearchProblem(p.roads, (4,), p.particle_edge, p.particle_s, p.particle_weight,
                          p.entropy, RoadSearchSettings(lookahead=2))
    lat = p.scenario.lattices[0]
    assert lat.n_arcs == 16 and lat.n_states == 1 + 4 + 5
    assert sorted(lat.state_node[lat.state_level == 1].tolist()) == [1, 3, 5, 7]
    assert sorted(lat.state_node[lat.state_level == 2].tolist()) == [0, 2, 4, 6, 8]
    assert np.array_equal(lat.state_tick, lat.state_level)
    assert np.all(lat.arc_tick == lat.arc_level)


@pytest.mark.parametrize("seed", range(4))
def test_lattice_ticks_add_up_on_unequal_roads(seed: int) -> None:
    """On a random map an arc's head tick is its tail tick plus the edge's ticks."""
    p = random_problem(random_roads(seed), np.random.default_rng(seed), uavs=2, lookahead=3)
    for lat in p.scenario.lattices:
        heads = lat.state_tick[lat.arc_head]
        assert np.array_equal(heads, lat.arc_tick + p.edge_ticks[lat.arc_edge])
        assert np.array_equal(lat.state_node[lat.arc_tail], p.roads.tail[lat.arc_edge])
        assert np.array_equal(lat.state_node[lat.arc_head], p.roads.head[lat.arc_edge])
        assert np.all(np.diff(lat.out_ptr) >= 0)


@pytest.mark.parametrize(("seed", "per_length", "both"),
                         [(0, False, True), (1, True, True), (2, False, False), (3, True, False)])
def test_groups_and_cover_match_each_particle(seed: int, per_length: bool, both: bool) -> None:
    """cover[k, group(p)] is β_k exactly when element k sees particle p at its tick."""
    p = random_problem(random_roads(seed), np.random.default_rng(seed), uavs=2,
                       per_length=per_length, both_directions=both)
    sc = p.scenario
    road_at = sc.edge_at >> 1 if both else sc.edge_at
    sees = road_at[sc.element_tick] == sc.element_road[:, None]  # (K, P)
    live = sc.group_of_particle >= 0
    assert not np.any(sees[:, ~live] & (p.gamma[:, None] * p.particle_weight).reshape(-1)[~live]
                      .astype(bool))
    expected = np.where(sees[:, live], sc.element_beta[:, None], 0.0)
    assert np.array_equal(sc.cover[:, sc.group_of_particle[live]], expected)
    value = (p.gamma[:, None] * p.particle_weight).reshape(-1)
    assert sc.group_value.sum() == pytest.approx(value[live].sum(), rel=1e-12)
    assert sc.n_groups <= live.sum()


def test_propagation_is_fixed_by_the_draw_seed() -> None:
    """Same seed, same trajectories; another seed, others; tick 0 is the belief."""
    p = random_problem(grid_roads(), np.random.default_rng(5))
    a, b = propagate(p, 6), propagate(p, 6)
    assert np.array_equal(a, b) and np.array_equal(a[0], p.particle_edge.reshape(-1))
    other = RoadSearchProblem(p.roads, p.uav_nodes, p.particle_edge, p.particle_s,
                              p.particle_weight, p.entropy, RoadSearchSettings(draw_seed=7))
    assert not np.array_equal(propagate(other, 6), a)


@pytest.mark.parametrize("seed", range(3))
def test_upper_bound_holds_for_every_plan(seed: int) -> None:
    """No plan scores above the bound; scores are never negative."""
    rng = np.random.default_rng(seed)
    p = random_problem(grid_roads(), rng, uavs=2, lookahead=2)
    scores = [p.scenario.score(plan) for plan in every_plan(p)]
    assert min(scores) >= 0.0
    assert max(scores) <= p.scenario.upper_bound() * (1 + 1e-12)


def test_plans_off_the_lattice_are_refused() -> None:
    """A path that skips a node, starts elsewhere or has the wrong length raises ValueError."""
    p = static_problem(lookahead=2)
    with pytest.raises(ValueError, match="does not leave"):
        p.scenario.score(RoadPlan.from_edges(p.roads, [[edge(4, 3), edge(0, 1)]]))
    with pytest.raises(ValueError, match="look-ahead"):
        p.scenario.score(RoadPlan.from_edges(p.roads, [[edge(4, 3)]]))
    with pytest.raises(ValueError, match="UAVs"):
        p.scenario.score(RoadPlan((), ()))
