"""Reacquisition as an OPTW (thesis 001 §5.5): the horizon T_r, the candidate nodes, the
instance and the planned route."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.models.road_synthetic import grid_network
from searchtrack.plan.guidance import (
    candidate_nodes,
    reacquire_time,
    reacquisition_instance,
)
from searchtrack.plan.guidance.reacquire import plan_reacquisition
from searchtrack.plan.optw import validate

from .helpers import path_road


def test_reacquire_time_matches_direct_simulation() -> None:
    """T_r on a path graph equals stepping e^{−αLΔt} until the peak is below P_min."""
    net = path_road(15)
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
    net = path_road(6)
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


def test_candidate_nodes_by_hand() -> None:
    """Decreasing probability, lower index first on ties, until the mass is covered; never a
    zero-probability node; at most ``max_nodes``."""
    p = np.array([0.1, 0.3, 0.3, 0.0, 0.3])
    assert candidate_nodes(p).tolist() == [1, 2, 4, 0]
    assert candidate_nodes(p, support_mass=0.9).tolist() == [1, 2, 4]
    assert candidate_nodes(p, support_mass=1.0).tolist() == [1, 2, 4, 0]
    assert candidate_nodes(p, max_nodes=2).tolist() == [1, 2]
    assert candidate_nodes(np.zeros(4)).size == 0


def test_route_reaches_only_what_the_horizon_allows() -> None:
    """A node 20 m away at 10 m/s takes 2 s: a 1 s horizon gives an empty route, a 3 s one
    the node; with no candidate at all the route is empty too."""
    net = path_road(5)
    p = np.array([0.0, 0.0, 1.0, 0.0, 0.0])
    for horizon_s, route in ((1.0, ()), (3.0, (2,))):
        inst, ids = reacquisition_instance(net, p, np.zeros(2), 10.0, horizon_s)
        assert ids.tolist() == [-1, 2]
        assert inst.to_time(inst.travel[0, 1]) == pytest.approx(2.0)
        assert plan_reacquisition(inst, ids)[0] == route
    inst, ids = reacquisition_instance(net, np.zeros(5), np.zeros(2), 10.0, 3.0)
    assert inst.n == 1 and plan_reacquisition(inst, ids)[0] == ()


def test_reacquire_bad_arguments() -> None:
    """Bad thresholds, step caps, candidate limits, UAV positions, speeds, node ids and time
    limits raise naming the field."""
    net = path_road(5)
    diff = GraphDiffusion.on_network(net, 1.0, 0.3)
    p = np.full(5, 0.2)
    with pytest.raises(InvalidInputError, match="p_min"):
        reacquire_time(diff, p, p_min=1.0)
    with pytest.raises(InvalidInputError, match="max_steps"):
        reacquire_time(diff, p, max_steps=0)
    with pytest.raises(InvalidInputError, match="max_nodes"):
        candidate_nodes(p, max_nodes=True)
    with pytest.raises(InvalidInputError, match="support_mass"):
        candidate_nodes(p, support_mass=0.0)
    with pytest.raises(InvalidInputError, match="probability"):
        candidate_nodes(-p)
    with pytest.raises(InvalidInputError, match="uav_xy_m"):
        reacquisition_instance(net, p, np.zeros(3), 10.0, 5.0)
    with pytest.raises(InvalidInputError, match="speed_mps"):
        reacquisition_instance(net, p, np.zeros(2), 0.0, 5.0)
    inst, ids = reacquisition_instance(net, p, np.zeros(2), 10.0, 5.0)
    with pytest.raises(InvalidInputError, match="node_ids"):
        plan_reacquisition(inst, ids[:-1])
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        plan_reacquisition(inst, ids, time_limit_s=0.0)
    for backend, cap in (("auto", 10), ("ils", 0), ("ils", True)):
        with pytest.raises(InvalidInputError, match="optw_iterations"):
            plan_reacquisition(inst, ids, backend=backend, max_iterations=cap)


@pytest.mark.parametrize("seed", range(3))
def test_an_iteration_cap_repeats_the_route(seed: int) -> None:
    """With the ILS's iterations capped, a route is valid and the same on every call with one
    seed, whatever the time left over."""
    rng = np.random.default_rng(seed)
    net = grid_network(5, 5, 100.0, 25.0)
    p = rng.random(net.n_nodes) ** 4
    p /= p.sum()
    inst, ids = reacquisition_instance(net, p, rng.uniform(0, 400, 2), 35.0, 25.0, max_nodes=30)
    first = plan_reacquisition(inst, ids, backend="ils", time_limit_s=10.0, seed=seed,
                               max_iterations=200)
    assert first[1].plan is not None
    vertices = [0] + [int(np.flatnonzero(ids == n)[0]) for n in first[0]]
    assert validate(inst, [vertices]).feasible
    for limit in (5.0, 20.0):
        again = plan_reacquisition(inst, ids, backend="ils", time_limit_s=limit, seed=seed,
                                   max_iterations=200)
        assert again[0] == first[0] and again[1].objective == first[1].objective
