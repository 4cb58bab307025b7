"""The route strategies: searching UAVs fly OPTW routes over the search field's mass toward
where it is, paired UAVs are held as in the thesis strategies, routes are kept until reached or
stale, answers are deterministic per seed and fall back to the gradient without a plan."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.result import Result, Status
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.node_tracker import NodeTracker
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import (
    BACKENDS,
    Guidance,
    GuidanceProblem,
    StrategyConfig,
    route_strategies,
    solve,
)
from searchtrack.plan.guidance.validate import answer_problems
from searchtrack.plan.optw import ils

from .helpers import road, view_of

ROUTED = [n for n in BACKENDS.names() if n.startswith("route_")]
CFG = StrategyConfig(sensor_range_m=30.0, speed_mps=20.0, search_horizon_s=80.0)


def _two_roads() -> RoadNetwork:
    """Two parallel 300 m roads 1 km apart (y = 0 and y = 1000), nodes every 20 m."""
    xs = [20.0 * i for i in range(16)]
    coords = [(x, 0.0) for x in xs] + [(x, 1000.0) for x in xs]
    edges = [(i, i + 1) for i in range(15)] + [(16 + i, 17 + i) for i in range(15)]
    return road(coords, edges)


def _far_mass_llr(net: RoadNetwork) -> np.ndarray:
    """Road y = 0 searched (φ = −20), road y = 1000 unexplored (φ = 0)."""
    return np.where(net.coords[:, 1] < 500.0, -20.0, 0.0)


def _problem(net: RoadNetwork, xy: list[list[float]], llr: np.ndarray,
             trackers: tuple[NodeTracker, ...] = (), config: StrategyConfig = CFG
             ) -> GuidanceProblem:
    view = view_of(net, xy, trackers, llr)
    return GuidanceProblem(view, config, GraphDiffusion.on_network(net, 0.447, 0.3))


def _plan(problem: GuidanceProblem, backend: str, seed: int = 0,
          limit_s: float = 2.0) -> tuple[Guidance, Result[Guidance]]:
    result = solve(problem, backend=backend, time_limit_s=limit_s, seed=seed)
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert answer_problems(problem, result) == []
    return result.plan, result


@pytest.mark.parametrize("backend", ROUTED)
def test_uav_heads_for_the_mass_on_a_distant_road(backend: str) -> None:
    """All the mass 1 km away: the UAV plans a route on that road and is pulled toward it,
    where the gradient search, on its flat searched road, is not."""
    net = _two_roads()
    problem = _problem(net, [[150.0, 0.0]], _far_mass_llr(net))
    g, result = _plan(problem, backend)
    assert g.mode == ("route",) and result.objective == 0.0
    (route,) = g.search_routes
    assert route.uav == 0 and route.nodes == g.route[0] and route.planned_s == 0.0
    assert all(net.coords[v, 1] == 1000.0 for v in route.nodes)
    assert g.force[0, 1] > abs(g.force[0, 0])  # within 45° of north
    gradient, _ = _plan(problem, "search")
    assert abs(gradient.force[0, 1]) < 1e-9


def test_routes_stay_within_the_look_ahead() -> None:
    """A look-ahead too short to reach the far road plans nothing: the UAV searches by the
    gradient; a longer one reaches it, and the route flies within the look-ahead."""
    net = _two_roads()
    llr = _far_mass_llr(net)
    short = dataclasses.replace(CFG, search_horizon_s=40.0)  # 800 m at 20 m/s
    g, _ = _plan(_problem(net, [[150.0, 0.0]], llr, config=short), "route_search")
    assert g.mode == ("search",) and g.search_routes == () and g.route == ((),)
    g, _ = _plan(_problem(net, [[150.0, 0.0]], llr), "route_search")
    points = np.vstack([[[150.0, 0.0]], net.coords[list(g.route[0])]])
    flown_s = np.hypot(*np.diff(points, axis=0).T).sum() / CFG.speed_mps
    assert 0.0 < flown_s <= CFG.search_horizon_s + 1e-6


def test_no_plan_falls_back_to_the_gradient(monkeypatch: pytest.MonkeyPatch) -> None:
    """When the OPTW returns no plan the UAV searches by the gradient force (5.12), the same
    force as the search strategy's, and plans again at the next step."""
    net = _two_roads()
    llr = _far_mass_llr(net)
    llr[:16] = -20.0 + 0.1 * np.arange(16) ** 2  # steepest edge unique: no tie to break
    problem = _problem(net, [[50.0, 0.0]], llr)

    def nothing(*args: object, **kwargs: object) -> Result[object]:
        return Result(Status.NO_SOLUTION, None, None, 0.0, "ils", None)

    monkeypatch.setattr(ils, "solve_ils", nothing)  # route_strategies imports it when used
    g, result = _plan(problem, "route_search")
    assert g.mode == ("search",) and g.search_routes == () and result.stats["plans"] == 1.0
    searched, _ = _plan(problem, "search")
    np.testing.assert_allclose(g.force, searched.force)
    g2, again = _plan(problem.following(problem.view, g), "route_search", seed=1)
    assert again.stats["plans"] == 1.0 and g2.mode == ("search",)


def test_route_is_kept_until_reached_or_stale() -> None:
    """The next step keeps the route (no plan); reaching its first node or letting it age
    past ``search_replan_s`` plans again."""
    net = _two_roads()
    llr = _far_mass_llr(net)
    problem = _problem(net, [[150.0, 0.0]], llr)
    g, _ = _plan(problem, "route_search")
    (route,) = g.search_routes
    moved = view_of(net, [[150.0, 10.0]], (), llr)
    kept, result = _plan(problem.following(moved, g), "route_search", seed=1)
    assert result.stats["plans"] == 0.0 and kept.search_routes == (route,)
    head = net.coords[route.nodes[0]]
    arrived = view_of(net, [[head[0], head[1] - 5.0]], (), llr)
    again, result = _plan(problem.following(arrived, g), "route_search", seed=1)
    assert result.stats["plans"] == 1.0 and again.search_routes[0].nodes[0] != route.nodes[0]
    late = dataclasses.replace(moved, time_s=CFG.search_replan_s)
    _, result = _plan(problem.following(late, g), "route_search", seed=1)
    assert result.stats["plans"] == 1.0


def test_searchers_claim_distinct_cells() -> None:
    """Two UAVs planning in one step leave each other's route cells out (the look-ahead lets
    each reach only part of the far road)."""
    net = _two_roads()
    config = dataclasses.replace(CFG, search_horizon_s=55.0)
    problem = _problem(net, [[100.0, 0.0], [200.0, 0.0]], _far_mass_llr(net), config=config)
    g, result = _plan(problem, "route_search")
    assert g.mode == ("route", "route") and result.stats["plans"] == 2.0
    cells = problem.search_cells.cell_of
    first, second = ({int(cells[v]) for v in r.nodes} for r in g.search_routes)
    assert first and second and not first & second


def _tracker(n: int, node: int, peak: float) -> NodeTracker:
    p = np.full(n, (1.0 - peak) / (n - 1))
    p[node] = peak
    return NodeTracker(p, 0)


def test_searchers_leave_the_evidence_of_a_tracked_target_alone(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Strong evidence (φ = 8) at the far road's east end weighs e⁸ unexplored nodes in the
    search mass while no tracker holds it; once a tracker's peak lies there (its loitering UAV
    keeps looking), the nodes within a footprint radius of the peak weigh as unexplored road."""
    net = _two_roads()
    llr = _far_mass_llr(net)
    hot = int(np.flatnonzero((net.coords[:, 1] == 1000.0) & (net.coords[:, 0] == 300.0))[0])
    llr[hot] = 8.0
    west = int(np.flatnonzero((net.coords[:, 1] == 1000.0) & (net.coords[:, 0] == 0.0))[0])
    seen: list[np.ndarray] = []
    planned = route_strategies.plan_search

    def spy(problem: GuidanceProblem, uav: int, mass: np.ndarray, *args: object) -> object:
        seen.append(mass)
        return planned(problem, uav, mass, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(route_strategies, "plan_search", spy)
    _plan(_problem(net, [[150.0, 0.0]], llr), "route_search")
    assert seen[-1][hot] / seen[-1][west] == pytest.approx(np.exp(8.0))
    tracked = _problem(net, [[150.0, 0.0], [300.0, 1000.0]], llr,
                       (_tracker(net.n_nodes, hot, 0.5),))
    g, _ = _plan(tracked, "route_loiter")
    assert g.mode == ("route", "loiter")
    assert seen[-1][hot] == pytest.approx(seen[-1][west])


@pytest.mark.parametrize(("backend", "thesis"), [
    ("route_loiter", "loiter"), ("route_search_and_loiter", "search_and_loiter"),
    ("route_search_and_reacquire", "search_and_reacquire")])
def test_paired_uav_is_held_as_in_the_thesis_strategy(backend: str, thesis: str) -> None:
    """A fading tracker's UAV loiters or reacquires exactly as in the thesis strategy (same
    force, route and objective); the unpaired UAV flies a search route."""
    net = _two_roads()
    trackers = (_tracker(net.n_nodes, 5, 0.2),)
    problem = _problem(net, [[100.0, 0.0], [250.0, 0.0]], _far_mass_llr(net), trackers)
    g, result = _plan(problem, backend, seed=4)
    h, expected = _plan(problem, thesis, seed=4)
    assert g.mode[0] == h.mode[0] != "search" and g.mode[1] == "route"
    np.testing.assert_allclose(g.force[0], h.force[0])
    assert g.route[0] == h.route[0] and g.reacquisitions == h.reacquisitions
    assert result.objective == pytest.approx(expected.objective)


@pytest.mark.parametrize("backend", ROUTED)
def test_route_strategies_are_deterministic_for_a_seed(backend: str) -> None:
    """Same problem and seeds, same forces, modes and routes over a chain of steps."""
    net = _two_roads()
    llr = np.random.default_rng(3).normal(size=net.n_nodes)
    trackers = (_tracker(net.n_nodes, 20, 0.2),)
    runs = []
    for _ in range(2):
        problem, answers = _problem(net, [[0.0, 0.0], [300.0, 500.0]], llr, trackers), []
        for seed in (5, 6, 7):
            g, _ = _plan(problem, backend, seed=seed)
            answers.append(g)
            problem = problem.following(problem.view, g)
        runs.append(answers)
    for a, b in zip(*runs, strict=True):
        np.testing.assert_array_equal(a.force, b.force)
        assert a.mode == b.mode and a.route == b.route
        assert a.search_routes == b.search_routes and a.reacquisitions == b.reacquisitions


def test_time_limit_is_honoured() -> None:
    """A step with three UAVs to plan for stays within a short time limit (plus overhead)."""
    net = _two_roads()
    problem = _problem(net, [[0.0, 0.0], [150.0, 0.0], [300.0, 0.0]], _far_mass_llr(net))
    solve(problem, backend="route_search", time_limit_s=1.0)  # compile the kernels first
    _, result = _plan(problem, "route_search", limit_s=0.02)
    assert result.runtime_s < 0.02 + 0.05


def test_validator_checks_route_mode() -> None:
    """A UAV in route mode must fly the search route it keeps; search routes are per UAV."""
    net = _two_roads()
    problem = _problem(net, [[150.0, 0.0]], _far_mass_llr(net))
    result = solve(problem, backend="route_search", time_limit_s=2.0)
    assert result.plan is not None
    lost = dataclasses.replace(result, plan=dataclasses.replace(result.plan, search_routes=()))
    assert any("route mode" in p for p in answer_problems(problem, lost))
