"""Tests of the reacquisition OPTW and the Ch. 5 guidance strategies solved by name."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from searchtrack.core.errors import InvalidInputError
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
    Reacquisition,
    StrategyConfig,
    pauli_force,
    reacquire_time,
    reacquisition_instance,
    solve,
    spring_force,
)
from searchtrack.plan.guidance.reacquire import plan_reacquisition
from searchtrack.plan.optw import validate


def _path(n: int, step: float = 10.0) -> RoadNetwork:
    xy = np.column_stack([np.arange(n) * step, np.zeros(n)])
    e = np.column_stack([np.arange(n - 1), np.arange(1, n)]).astype(np.int64)
    return RoadNetwork(xy, e, np.full(n - 1, step))


def _tracker(n: int, node: int, peak: float, track_id: int = 0) -> NodeTracker:
    p = np.full(n, (1.0 - peak) / (n - 1))
    p[node] = peak
    return NodeTracker(p, track_id)


def _view(net: RoadNetwork, xy: list[list[float]], trackers: tuple[NodeTracker, ...] = (),
          llr: np.ndarray | None = None) -> GuidanceView:
    o = len(xy)
    bank = TrackerBank(net.n_nodes, trackers, 1 + max((t.track_id for t in trackers), default=0))
    field = LikelihoodField(np.zeros(net.n_nodes) if llr is None else llr)
    return GuidanceView(net, np.array(xy, dtype=float), np.zeros(o), np.full(o, 35.0), field,
                        bank, 0.0)


def _guide(backend: str, view: GuidanceView, config: StrategyConfig, diff: GraphDiffusion,
           seed: int = 0, limit_s: float = 2.0) -> Guidance:
    result = solve(GuidanceProblem(view, config, diff), backend=backend, time_limit_s=limit_s,
                   seed=seed)
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert result.backend == backend and result.bound is None
    return result.plan


def test_reacquire_time_matches_direct_simulation() -> None:
    """T_r on a path graph equals stepping e^{−αLΔt} until the peak is below P_min."""
    net = _path(15)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    p0 = np.zeros(15)
    p0[7] = 1.0
    op = expm(-0.447 * 0.3 * net.laplacian.toarray())
    p, steps = p0, 0
    while p.max() >= 0.07:
        p, steps = op @ p, steps + 1
    assert reacquire_time(diff, p0, p_min=0.07) == pytest.approx(steps * 0.3)
    assert reacquire_time(diff, np.full(15, 1 / 15), p_min=0.07) == 0.0
    assert reacquire_time(diff, p0, p_min=0.07, max_steps=3) == pytest.approx(0.9)


def test_reacquire_time_local_support_matches_full_propagation() -> None:
    """The cached operator's support-only propagation gives the same T_r as full steps."""
    net = grid_network(6, 6, 100.0, 10.0)
    p0 = np.zeros(net.n_nodes)
    p0[[40, 41, 90]] = [0.5, 0.3, 0.2]
    cached = GraphDiffusion.on_network(net, 0.447, 0.3)
    full = GraphDiffusion.on_network(net, 0.447, 0.3, method="expm_multiply")
    assert cached.operator is not None and full.operator is None
    for p_min in (0.3, 0.07, 0.02):
        assert reacquire_time(cached, p0, p_min=p_min) == pytest.approx(
            reacquire_time(full, p0, p_min=p_min))


def test_reacquisition_instance_layout() -> None:
    """Start = UAV with zero score, open end, windows [0, T_r], scores = probabilities."""
    net = grid_network(3, 3, 100.0, 20.0)
    p = np.random.default_rng(1).random(net.n_nodes)
    p /= p.sum()
    inst, ids = reacquisition_instance(net, p, np.array([5.0, -5.0]), 20.0, 12.5, max_nodes=10)
    assert inst.start == 0 and inst.end is None and ids[0] == -1
    assert inst.n == 11 and inst.profit[0] == 0.0
    np.testing.assert_allclose(inst.profit[1:], p[ids[1:]])
    assert np.all(np.diff(inst.profit[1:]) <= 0.0)  # most probable first
    assert np.all(inst.open == 0) and np.all(inst.close == round(12.5 * inst.time_scale))
    assert np.all(inst.service == 0)
    d = np.hypot(*(net.coords[ids[1]] - [5.0, -5.0]))
    assert inst.to_time(inst.travel[0, 1]) == pytest.approx(d / 20.0, abs=0.011)


def test_reacquisition_support_mass_truncates() -> None:
    """Candidates stop once the kept mass reaches support_mass."""
    net = _path(6)
    p = np.array([0.5, 0.3, 0.1, 0.05, 0.05, 0.0])
    _, ids = reacquisition_instance(net, p, np.zeros(2), 10.0, 5.0, support_mass=0.8)
    assert ids.tolist() == [-1, 0, 1]


def _greedy_score(inst_profit: np.ndarray, travel: np.ndarray, close: int) -> float:
    here, t, score, todo = 0, 0, 0.0, set(range(1, travel.shape[0]))
    while True:
        ok = [g for g in todo if t + travel[here, g] <= close]
        if not ok:
            return score
        g = min(ok, key=lambda v: (travel[here, v], v))
        t, here, score = t + travel[here, g], g, score + inst_profit[g]
        todo.remove(g)


@pytest.mark.parametrize("seed", range(4))
def test_solved_route_is_valid_and_beats_greedy(seed: int) -> None:
    """The OPTW route is feasible and collects at least the nearest-first greedy route's score."""
    rng = np.random.default_rng(seed)
    net = grid_network(4, 4, 100.0, 25.0)
    p = rng.random(net.n_nodes) ** 4
    p /= p.sum()
    inst, ids = reacquisition_instance(net, p, rng.uniform(0, 300, 2), 35.0, 20.0, max_nodes=25)
    route, result = plan_reacquisition(inst, ids, backend="auto", time_limit_s=5.0)
    vertices = [0] + [int(np.flatnonzero(ids == n)[0]) for n in route]
    check = validate(inst, [vertices])
    assert check.feasible
    assert check.profit >= _greedy_score(inst.profit, inst.travel, int(inst.close[0])) - 1e-12
    assert check.profit == pytest.approx(result.objective)


def test_search_and_loiter_switches_at_threshold() -> None:
    """A paired UAV loiters when its peak ≤ ϱ and searches above it."""
    net = _path(20)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    cfg = StrategyConfig(sensor_range_m=30.0)
    for seed, (peak, mode) in enumerate([(0.5, "search"), (0.31, "search"), (0.3, "loiter"),
                                         (0.1, "loiter")]):
        view = _view(net, [[50.0, 0.0], [190.0, 0.0]], (_tracker(20, 4, peak),))
        g = _guide("search_and_loiter", view, cfg, diff, seed)
        assert g.mode == (mode, "search")
        assert g.pairing.tracker == (0, -1)


def test_loiter_forces_follow_5_15_and_5_14() -> None:
    """Loitering UAV: ∇L + repulsion from loiterers only; searcher: ∇R + ∇P (all) + ∇Q."""
    net = _path(30)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    cfg = StrategyConfig(sensor_range_m=20.0)
    xy = [[115.0, 0.0], [100.0, 5.0], [300.0, 0.0]]
    view = _view(net, xy, (_tracker(30, 12, 0.6, 0), _tracker(30, 29, 0.6, 1)))
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
    net = _path(10)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    result = solve(GuidanceProblem(_view(net, [[0.0, 0.0]], (_tracker(10, 3, 0.1),)),
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
    problem = GuidanceProblem(_view(net, xy, bank.trackers), cfg, diff)
    first = solve(problem, backend="search_and_reacquire", seed=0).plan
    assert first is not None and first.mode == ("reacquire",) and first.reacquisitions
    again = problem.following(_view(net, xy, (_tracker(net.n_nodes, 10, 0.9),)), first)
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
    view = _view(net, [[100.0, 100.0]], llr=llr)
    forces = {tuple(np.round(_guide("search", view, StrategyConfig(), diff, seed).force[0], 9))
              for seed in range(12)}
    assert len(forces) > 1


def test_bad_inputs() -> None:
    """Bad configs, views, problems and instance arguments raise InvalidInputError naming the
    field."""
    net = _path(5)
    diff = GraphDiffusion.on_network(net, 1.0, 0.3)
    with pytest.raises(InvalidInputError, match="p_min"):
        StrategyConfig(p_min=0.5, revisit_threshold=0.3)
    with pytest.raises(InvalidInputError, match="optw_backend"):
        StrategyConfig(optw_backend="nope")
    with pytest.raises(InvalidInputError, match="sensor_range_m"):
        StrategyConfig(sensor_range_m=0.0)
    with pytest.raises(InvalidInputError, match="field"):
        GuidanceView(net, np.zeros((1, 2)), np.zeros(1), np.ones(1),
                     LikelihoodField(np.zeros(4)), TrackerBank(5), 0.0)
    with pytest.raises(InvalidInputError, match="field"):
        GuidanceView(net, np.zeros((1, 2)), np.zeros(1), np.ones(1),
                     np.zeros(5), TrackerBank(5), 0.0)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="bank"):
        GuidanceView(net, np.zeros((1, 2)), np.zeros(1), np.ones(1),
                     LikelihoodField(np.zeros(5)), TrackerBank(4), 0.0)
    with pytest.raises(InvalidInputError, match="uav_heading_rad"):
        GuidanceView(net, np.zeros((2, 2)), np.zeros(1), np.ones(2),
                     LikelihoodField(np.zeros(5)), TrackerBank(5), 0.0)
    view = _view(net, [[0.0, 0.0]])
    with pytest.raises(InvalidInputError, match="predictor"):
        GuidanceProblem(view, StrategyConfig(), "not a diffusion")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="predictor"):
        GuidanceProblem(view, StrategyConfig(), GraphDiffusion.on_network(_path(6), 1.0, 0.3))
    with pytest.raises(InvalidInputError, match="reacquisitions"):
        GuidanceProblem(view, StrategyConfig(), diff, (Reacquisition.planned(0, 1, (2,)),))
    with pytest.raises(InvalidInputError, match="reacquisitions"):
        GuidanceProblem(view, StrategyConfig(), diff, (Reacquisition.planned(0, 0, (2,)),
                                                       Reacquisition.planned(0, 0, (3,))))
    with pytest.raises(InvalidInputError, match="served"):
        Reacquisition(0, 0, (1, 2), (False,))
    problem = GuidanceProblem(view, StrategyConfig(), diff)
    with pytest.raises(InvalidInputError, match="backend"):
        solve(problem, backend="chase")
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(problem, backend="search", time_limit_s=0.0)
    with pytest.raises(InvalidInputError, match="seed"):
        solve(problem, backend="search", seed=-1)
    with pytest.raises(InvalidInputError, match="horizon_s"):
        reacquisition_instance(net, np.full(5, 0.2), np.zeros(2), 10.0, -1.0)
    with pytest.raises(InvalidInputError, match="probability"):
        reacquire_time(diff, np.ones(4))
    with pytest.raises(InvalidInputError, match="predictor"):
        reacquire_time("not a diffusion", np.ones(5))  # type: ignore[arg-type]
