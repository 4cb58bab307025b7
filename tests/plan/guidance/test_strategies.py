"""The Ch. 5 guidance strategies (thesis 001 (5.12), (5.15), (5.16), (5.33)): the mode rules,
the force assembly, the covered probability and each backend's behaviour over steps."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models.dubins import DubinsLimits, UavState, step_force
from searchtrack.models.road_synthetic import grid_network
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import (
    BACKENDS,
    Guidance,
    GuidanceProblem,
    GuidanceView,
    Pairing,
    StrategyConfig,
    coverage_force,
    pauli_force,
    solve,
    spring_force,
    strategies,
)
from searchtrack.plan.guidance.strategies import (
    assemble,
    covered_probability,
    loiter_modes,
    search_and_loiter_modes,
    search_modes,
)

from .helpers import path_road, view_of


def _tracker(n: int, node: int, peak: float, track_id: int = 0) -> NodeTracker:
    p = np.full(n, (1.0 - peak) / (n - 1))
    p[node] = peak
    return NodeTracker(p, track_id)

def _guide(backend: str, view: GuidanceView, config: StrategyConfig, diff: GraphDiffusion,
           seed: int = 0, limit_s: float = 2.0) -> Guidance:
    result = solve(GuidanceProblem(view, config, diff), backend=backend, time_limit_s=limit_s,
                   seed=seed)
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert result.backend == backend and result.bound is None
    return result.plan

def test_search_and_loiter_switches_at_threshold() -> None:
    """A paired UAV loiters when its peak ≤ ϱ and searches above it."""
    net = path_road(20)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    cfg = StrategyConfig(sensor_range_m=30.0)
    for seed, (peak, mode) in enumerate([(0.5, "search"), (0.31, "search"), (0.3, "loiter"),
                                         (0.1, "loiter")]):
        view = view_of(net, [[50.0, 0.0], [190.0, 0.0]], (_tracker(20, 4, peak),))
        g = _guide("search_and_loiter", view, cfg, diff, seed)
        assert g.mode == (mode, "search")
        assert g.pairing.tracker == (0, -1)

def test_loiter_forces_follow_5_15_and_5_14() -> None:
    """Loitering UAV: ∇L + repulsion from loiterers only; searcher: ∇R + ∇P (all) + ∇Q."""
    net = path_road(30)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    cfg = StrategyConfig(sensor_range_m=20.0)
    xy = [[115.0, 0.0], [100.0, 5.0], [300.0, 0.0]]
    view = view_of(net, xy, (_tracker(30, 12, 0.6, 0), _tracker(30, 29, 0.6, 1)))
    result = solve(GuidanceProblem(view, cfg, diff), backend="loiter", seed=0)
    g = result.plan
    assert g is not None and g.mode == ("loiter", "search", "loiter")
    assert result.objective == pytest.approx(1.2)  # two loiterers over peaks of 0.6
    uav = np.array(xy)
    loiterers = [0, 2]
    pauli_l = pauli_force(uav[loiterers], cfg.sigma)
    pull = spring_force(uav[loiterers], net.coords[[12, 29]], cfg.k_loiter)
    np.testing.assert_allclose(g.force[loiterers], pull + pauli_l)
    # the searcher on a flat field: no gradient, spring to n_max, repelled by both others
    searcher = g.force[1] - pauli_force(uav, cfg.sigma)[1]
    assert np.hypot(*searcher) <= cfg.k_spring * cfg.sensor_range_m + 1e-9

def test_search_strategy_ignores_trackers() -> None:
    """`search` puts every UAV in search mode even when trackers exist."""
    net = path_road(10)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    result = solve(GuidanceProblem(view_of(net, [[0.0, 0.0]], (_tracker(10, 3, 0.1),)),
                                   StrategyConfig(), diff), backend="search", seed=0)
    g = result.plan
    assert g is not None and g.mode == ("search",) and g.route == ((),) and g.plan_ms == 0.0
    assert g.reacquisitions == () and result.objective == 0.0

def _reacquire_setup() -> tuple[RoadNetwork, GraphDiffusion, TrackerBank]:
    net = grid_network(5, 5, 100.0, 20.0)
    diff = GraphDiffusion.on_network(net, 0.05, 0.3)
    p = np.zeros(net.n_nodes)
    p[int(net.nearest_nodes([[300.0, 300.0]])[0])] = 1.0
    for _ in range(30):
        p = diff.propagate(p)
    assert p.max() < 0.3
    return net, diff, TrackerBank(net.n_nodes, (NodeTracker(p / p.sum(), 0),), 1)

def test_reacquire_strategy_follows_its_route() -> None:
    """A fading tracker's UAV plans a route and closes on the route's next node; the route
    passes from each answer to the next step's problem."""
    net, diff, bank = _reacquire_setup()
    cfg = StrategyConfig(sensor_range_m=30.0, speed_mps=20.0)
    limits = DubinsLimits(speed_max_mps=20.0, speed_min_mps=20.0)
    uavs = UavState(np.zeros(1), np.zeros(1), np.full(1, np.pi / 4), np.full(1, 20.0))
    field = LikelihoodField(np.zeros(net.n_nodes))
    guides, dists = [], []
    problem: GuidanceProblem | None = None
    for k in range(100):
        view = GuidanceView(net, uavs.xy_m, uavs.heading_rad, uavs.speed_mps, field, bank, 0.0)
        problem = (GuidanceProblem(view, cfg, diff) if problem is None
                   else problem.following(view, guides[-1]))
        result = solve(problem, backend="search_and_reacquire", time_limit_s=2.0, seed=k)
        assert result.plan is not None
        guides.append(result.plan)
        uavs = step_force(uavs, guides[-1].force, 0.3, limits)
        if guides[0].route[0]:
            dists.append(float(np.hypot(*(uavs.xy_m[0] - net.coords[guides[0].route[0][0]]))))
    first = guides[0]
    assert first.mode == ("reacquire",) and len(first.route[0]) > 0 and first.plan_ms > 0.0
    (kept,) = first.reacquisitions
    assert kept.track_id == 0 and kept.uav == 0 and kept.remaining() == first.route[0]
    assert dists[10] < dists[0] - 45.0  # closing on the first route node
    assert min(dists) <= cfg.sensor_range_m  # and it gets served
    served = [g for g in guides if g.route[0] and g.route[0][0] != first.route[0][0]]
    assert served and served[0].route[0] == first.route[0][1:]  # then on to the next one
    assert served[0].plan_ms == 0.0  # followed, not re-planned
    assert guides[1].reacquisitions[0].nodes == kept.nodes

def test_reacquire_route_dropped_when_reacquired() -> None:
    """A peak back above ϱ returns the UAV to search and forgets the route."""
    net, diff, bank = _reacquire_setup()
    cfg = StrategyConfig(sensor_range_m=30.0)
    xy = [[0.0, 0.0]]
    problem = GuidanceProblem(view_of(net, xy, bank.trackers), cfg, diff)
    first = solve(problem, backend="search_and_reacquire", seed=0).plan
    assert first is not None and first.mode == ("reacquire",) and first.reacquisitions
    again = problem.following(view_of(net, xy, (_tracker(net.n_nodes, 10, 0.9),)), first)
    g = solve(again, backend="search_and_reacquire", seed=1).plan
    assert g is not None and g.mode == ("search",) and g.route == ((),)
    assert g.reacquisitions == ()

def test_strategies_are_deterministic_for_a_seed() -> None:
    """Same problem and seed, same forces, modes and routes, over a chain of steps."""
    net, diff, bank = _reacquire_setup()
    llr = np.random.default_rng(2).normal(size=net.n_nodes)
    cfg = StrategyConfig(sensor_range_m=30.0)
    view = GuidanceView(net, np.array([[0.0, 0.0], [400.0, 0.0]]), np.zeros(2),
                        np.full(2, 35.0), LikelihoodField(llr), bank, 0.0)
    for name in BACKENDS.names():
        runs = []
        for _ in range(2):
            problem, answers = GuidanceProblem(view, cfg, diff), []
            for seed in (9, 10, 11):
                answer = solve(problem, backend=name, time_limit_s=2.0, seed=seed).plan
                assert answer is not None
                answers.append(answer)
                problem = problem.following(view, answer)
            runs.append(answers)
        for a, b in zip(*runs, strict=True):
            np.testing.assert_array_equal(a.force, b.force)
            assert a.mode == b.mode and a.route == b.route
            assert a.reacquisitions == b.reacquisitions

def test_seed_drives_the_gradient_tie_break() -> None:
    """On a field with tied edges the chosen edge follows the seed, as the generator it seeds."""
    net = grid_network(3, 3, 100.0, 50.0)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    centre = int(net.nearest_nodes([[100.0, 100.0]])[0])
    llr = np.zeros(net.n_nodes)
    llr[centre] = 5.0  # every edge at the centre ties
    view = view_of(net, [[100.0, 100.0]], llr=llr)
    forces = {tuple(np.round(_guide("search", view, StrategyConfig(), diff, seed).force[0], 9))
              for seed in range(12)}
    assert len(forces) > 1


def test_mode_rules() -> None:
    """(5.12) searches everywhere; (5.15) holds every paired UAV; (5.16) holds a paired UAV only
    while its peak is ≤ ϱ = 0.3."""
    net = path_road(10)
    problem = GuidanceProblem(view_of(net, [[0.0, 0.0]] * 4), StrategyConfig(),
                              GraphDiffusion.on_network(net, 0.447, 0.3))
    pairing = Pairing((0, -1, 1, 2), (0, -1, 1, 2), (3, -1, 5, 7), (0.2, 0.0, 0.5, 0.3))
    assert search_modes(problem, pairing) == ["search"] * 4
    assert loiter_modes(problem, pairing) == ["loiter", "search", "loiter", "loiter"]
    assert search_and_loiter_modes(problem, pairing) == ["loiter", "search", "search", "loiter"]


def test_held_uav_feels_only_its_spring_and_other_held_uavs() -> None:
    """(5.14): with one UAV held and one searching, the held UAV's force is its zero-rest spring
    to its anchor alone; two held UAVs also repel each other."""
    net = path_road(10)
    cfg = StrategyConfig(sensor_range_m=30.0)
    xy = [[20.0, 5.0], [60.0, 0.0]]
    problem = GuidanceProblem(view_of(net, xy), cfg, GraphDiffusion.on_network(net, 0.447, 0.3))
    anchors = np.array([[30.0, 0.0], [0.0, 0.0]])
    rng = np.random.default_rng(0)
    one = assemble(problem, rng, ["loiter", "search"], anchors)
    np.testing.assert_allclose(one[0], spring_force([xy[0]], anchors[:1], cfg.k_loiter)[0])
    both = assemble(problem, rng, ["loiter", "reacquire"], anchors)
    expected = spring_force(xy, anchors, cfg.k_loiter) + pauli_force(xy, cfg.sigma)
    np.testing.assert_allclose(both, expected, rtol=1e-12)


def test_covered_probability() -> None:
    """Per loitering UAV its peak probability, per reacquiring UAV its tracker's mass on the
    route left, nothing for a searcher: 0.4 + (0.1 + 0.2)."""
    net = path_road(5)
    p0 = np.array([0.4, 0.15, 0.15, 0.15, 0.15])
    p1 = np.array([0.1, 0.2, 0.3, 0.3, 0.1])
    trackers = (NodeTracker(p0, 0), NodeTracker(p1, 1))
    problem = GuidanceProblem(view_of(net, [[0.0, 0.0]] * 3, trackers), StrategyConfig(),
                              GraphDiffusion.on_network(net, 0.447, 0.3))
    pairing = Pairing((0, 1, -1), (0, 1, -1), (0, 2, -1), (0.4, 0.3, 0.0))
    answer = Guidance(np.zeros((3, 2)), pairing, ("loiter", "reacquire", "search"),
                      ((), (0, 1), ()))
    assert covered_probability(problem, answer) == pytest.approx(0.7)


def test_potential_backends_are_named_for_their_rule() -> None:
    """Each force-law backend carries its name and its rule's equation in its docstring."""
    for name, eq in (("search", "(5.12)"), ("loiter", "(5.15)"),
                     ("search_and_loiter", "(5.16)")):
        solver = getattr(strategies, f"solve_{name}")
        assert solver.__name__ == f"solve_{name}" and eq in (solver.__doc__ or "")


def _covered_west_view(net: RoadNetwork, xy: list[list[float]], trackers: tuple[NodeTracker, ...],
                       coverage: np.ndarray | None) -> GuidanceView:
    base = view_of(net, xy, trackers)
    return GuidanceView(net, base.uav_xy_m, base.uav_heading_rad, base.uav_speed_mps,
                        base.field, base.bank, 0.0, coverage)


@pytest.mark.parametrize("backend", ["search_and_loiter", "search_and_reacquire"])
def test_coverage_pushes_free_searchers_toward_uncovered_road(backend: str) -> None:
    """On a grid whose western half was just covered, a free searching UAV in the middle is
    pushed east by exactly ``w`` times the coverage force; the UAV paired with a tracker (and
    searching, its peak above ϱ) feels nothing new. Weight 0, or a view without coverage,
    reproduces the thesis's force bit for bit."""
    net = grid_network(5, 5, 100.0, 20.0)  # 400 m square
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    west = (net.coords[:, 0] < 200.0).astype(float)
    xy = [[200.0, 200.0], [400.0, 0.0]]
    tracker = (_tracker(net.n_nodes, int(net.nearest_nodes([[400.0, 20.0]])[0]), 0.6),)
    forces = {}
    for weight, coverage in [(0.0, None), (0.0, west), (3.0, None), (3.0, west)]:
        cfg = StrategyConfig(sensor_range_m=60.0, coverage_weight=weight)
        g = _guide(backend, _covered_west_view(net, xy, tracker, coverage), cfg, diff, seed=5)
        assert g.mode == ("search", "search") and g.pairing.tracker == (-1, 0)
        forces[weight, coverage is not None] = g.force
    old = forces[0.0, False]
    np.testing.assert_array_equal(forces[0.0, True], old)
    np.testing.assert_array_equal(forces[3.0, False], old)
    push = forces[3.0, True] - old
    expected = 3.0 * coverage_force(net, [xy[0]], west, 60.0, 120.0)[0]
    np.testing.assert_allclose(push[0], expected, atol=1e-9)
    assert push[0, 0] > 0.5 and abs(push[0, 1]) < 1e-9  # east, toward uncovered road
    np.testing.assert_array_equal(push[1], [0.0, 0.0])  # the paired UAV
