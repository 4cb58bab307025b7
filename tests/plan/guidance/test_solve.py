"""The catalogue of guidance backends: every backend of ``BACKENDS`` solves small problems with
known modes, forces and objectives."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import (
    BACKENDS,
    GuidanceProblem,
    GuidanceView,
    StrategyConfig,
    solve,
    spring_force,
)

NAMES = BACKENDS.names()
SEARCHING = {name: "route" if name.startswith("route_") else "search" for name in NAMES}
CONFIG = StrategyConfig(sensor_range_m=30.0, speed_mps=20.0)


def _path(n: int, step: float = 10.0) -> RoadNetwork:
    xy = np.column_stack([np.arange(n) * step, np.zeros(n)])
    e = np.column_stack([np.arange(n - 1), np.arange(1, n)]).astype(np.int64)
    return RoadNetwork(xy, e, np.full(n - 1, step))


def _problem(net: RoadNetwork, xy: list[list[float]], peaks: list[tuple[int, float]]
             ) -> GuidanceProblem:
    trackers = []
    for k, (node, peak) in enumerate(peaks):
        p = np.full(net.n_nodes, (1.0 - peak) / (net.n_nodes - 1))
        p[node] = peak
        trackers.append(NodeTracker(p, k))
    bank = TrackerBank(net.n_nodes, tuple(trackers), len(trackers))
    o = len(xy)
    view = GuidanceView(net, np.array(xy, dtype=float), np.zeros(o), np.full(o, 20.0),
                        LikelihoodField(np.zeros(net.n_nodes)), bank, 0.0)
    return GuidanceProblem(view, CONFIG, GraphDiffusion.on_network(net, 0.447, 0.3))


def test_catalogue_lists_the_strategies() -> None:
    """The registry holds the four Ch. 5 strategies, the four route strategies and the two
    partitioned route strategies, none of them exact."""
    assert NAMES == ["search", "loiter", "search_and_loiter", "search_and_reacquire",
                     "route_search", "route_loiter", "route_search_and_loiter",
                     "route_search_and_reacquire", "route_partition_search",
                     "route_partition_loiter"]
    assert all(not BACKENDS.get(n).exact and BACKENDS.get(n).description for n in NAMES)


@pytest.mark.parametrize("backend", NAMES)
def test_out_of_range_uav_springs_back_to_the_road(backend: str) -> None:
    """No tracker and no node within ρ: only ∇Q, toward the nearest node, past rest ρ; a
    route strategy flies ∇W toward the first node of its search route over the neutral field."""
    net = _path(10)
    problem = _problem(net, [[0.0, 200.0]], [])
    result = solve(problem, backend=backend, time_limit_s=1.0, seed=0)
    assert result.status is Status.FEASIBLE and result.backend == backend
    assert result.objective == 0.0 and result.bound is None and result.runtime_s >= 0.0
    g = result.plan
    assert g is not None and g.mode == (SEARCHING[backend],)
    if SEARCHING[backend] == "route":
        (route,) = g.search_routes
        assert g.route == (route.nodes,)
        np.testing.assert_allclose(g.force, spring_force([[0.0, 200.0]],
                                                         net.coords[[route.nodes[0]]],
                                                         CONFIG.k_loiter))
    else:
        assert g.route == ((),) and g.search_routes == ()
        np.testing.assert_allclose(g.force, [[0.0, -CONFIG.k_spring * (200.0 - 30.0)]])
    assert g.reacquisitions == () and g.pairing.tracker == (-1,)


STRONG = {"search": "search", "loiter": "loiter", "search_and_loiter": "search",
          "search_and_reacquire": "search", "route_search": "route", "route_loiter": "loiter",
          "route_search_and_loiter": "route", "route_search_and_reacquire": "route",
          "route_partition_search": "route", "route_partition_loiter": "loiter"}
FADING = {"search": "search", "loiter": "loiter", "search_and_loiter": "loiter",
          "search_and_reacquire": "reacquire", "route_search": "route", "route_loiter": "loiter",
          "route_search_and_loiter": "loiter", "route_search_and_reacquire": "reacquire",
          "route_partition_search": "route", "route_partition_loiter": "loiter"}



@pytest.mark.parametrize("backend", NAMES)
def test_strong_tracker(backend: str) -> None:
    """Peak 0.6 > ϱ: only ``loiter`` holds over it, with ∇L to the peak; objective 𝒫 = 0.6."""
    net = _path(30)
    result = solve(_problem(net, [[100.0, 20.0]], [(20, 0.6)]), backend=backend, seed=1)
    g = result.plan
    assert g is not None and g.mode == (STRONG[backend],) and g.pairing.tracker == (0,)
    if STRONG[backend] == "loiter":
        np.testing.assert_allclose(g.force, spring_force([[100.0, 20.0]], net.coords[[20]],
                                                         CONFIG.k_loiter))
        assert result.objective == pytest.approx(0.6)
    else:
        assert result.objective == 0.0


@pytest.mark.parametrize("backend", NAMES)
def test_fading_tracker(backend: str) -> None:
    """Peak 0.2 ≤ ϱ: loiter and search-and-loiter hold over the peak, search-and-reacquire flies
    a route whose remaining probability is the objective."""
    net = _path(30)
    problem = _problem(net, [[100.0, 20.0]], [(20, 0.2)])
    result = solve(problem, backend=backend, time_limit_s=2.0, seed=2)
    g = result.plan
    assert g is not None and g.mode == (FADING[backend],)
    if FADING[backend] == "loiter":
        assert result.objective == pytest.approx(0.2)
    elif FADING[backend] == "reacquire":
        route = g.route[0]
        assert route and g.plan_ms > 0.0 and result.objective is not None
        p = problem.view.bank[0].node_probability()
        assert 0.0 < result.objective == pytest.approx(float(p[list(route)].sum()))
        (kept,) = g.reacquisitions
        assert kept.track_id == 0 and kept.remaining() == route
        anchor = net.coords[route[0]]
        np.testing.assert_allclose(g.force, spring_force([[100.0, 20.0]], anchor[None, :],
                                                         CONFIG.k_loiter))
    else:
        assert result.objective == 0.0
    assert problem.reacquisitions == ()  # the input is left as it was


@pytest.mark.parametrize("backend", NAMES)
def test_two_uavs_one_tracker(backend: str) -> None:
    """The nearer UAV is paired; the other searches whatever the backend."""
    net = _path(30)
    result = solve(_problem(net, [[100.0, 20.0], [280.0, 0.0]], [(10, 0.2)]), backend=backend,
                   time_limit_s=2.0, seed=3)
    g = result.plan
    assert g is not None and g.pairing.tracker == (0, -1)
    # under route_search the paired UAV's route already takes the short road's every cell;
    # under route_partition_search the partition leaves the other UAV its own cells
    assert g.mode == (FADING[backend],
                      "search" if backend == "route_search" else SEARCHING[backend])


def test_default_backend_is_search_and_reacquire() -> None:
    """Without a backend name a fading tracker's UAV flies a reacquisition route."""
    net = _path(30)
    result = solve(_problem(net, [[100.0, 20.0]], [(20, 0.2)]), time_limit_s=2.0)
    assert result.backend == "search_and_reacquire" and result.plan is not None
    assert result.plan.mode == ("reacquire",)

