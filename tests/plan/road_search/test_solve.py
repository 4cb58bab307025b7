"""The registry and ``solve``: the names, input checks, ``auto``'s stages, determinism, and
the catalogue: every backend that says OPTIMAL has the exhaustive objective."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.road_search import BACKENDS, RoadSearchProblem, RoadSearchSettings, solve

from .helpers import STATIC, edge, grid_roads, random_problem, random_roads

NAMES = ["auto", "exhaustive", "beam", "exact", "greedy", "random", "ideal"]


def catalogue() -> list[tuple[str, RoadSearchProblem]]:
    """Grid and random map, three seeds, L = 1..4, one and two UAVs, with true targets."""
    out = []
    for map_name in ("grid", "random"):
        for seed in range(3):
            roads = grid_roads() if map_name == "grid" else random_roads(seed)
            for lookahead in (1, 2, 3, 4):
                for uavs in (1, 2):
                    rng = np.random.default_rng(100 * seed + 10 * lookahead + uavs)
                    p = random_problem(roads, rng, uavs=uavs, lookahead=lookahead,
                                       targets=2, particles=60, per_length=seed == 2)
                    truth = p.roads.uniform(p.n_targets, rng)
                    p = RoadSearchProblem(p.roads, p.uav_nodes, p.particle_edge, p.particle_s,
                                          p.particle_weight, p.entropy, p.settings, *truth)
                    out.append((f"{map_name}-s{seed}-L{lookahead}-Q{uavs}", p))
    return out


CATALOGUE = catalogue()


def test_names() -> None:
    """The registered backends, auto first."""
    assert BACKENDS.names() == NAMES


@pytest.mark.parametrize(("name", "problem"), CATALOGUE, ids=[n for n, _ in CATALOGUE])
def test_optimal_answers_agree_with_exhaustive(name: str, problem: RoadSearchProblem) -> None:
    """Whenever a backend says OPTIMAL its objective is the exhaustive optimum; no backend's
    objective exceeds it, and every bound is at least it."""
    ref = solve(problem, backend="exhaustive", time_limit_s=60.0)
    assert ref.status is Status.OPTIMAL and ref.objective is not None
    for backend in [*NAMES[2:], "auto"]:
        res = solve(problem, backend=backend, time_limit_s=60.0)
        assert res.status in (Status.OPTIMAL, Status.FEASIBLE), (backend, res.message)
        assert res.objective is not None
        assert res.objective <= ref.objective * (1 + 1e-9) + 1e-15, backend
        assert res.bound is not None and res.bound >= ref.objective * (1 - 1e-9), backend
        if res.status is Status.OPTIMAL:
            assert res.objective == pytest.approx(ref.objective, rel=1e-7), backend


def test_auto_names_the_stage_that_answered() -> None:
    """auto: the beam's plan when nothing was pruned, CP-SAT's stage otherwise."""
    one = random_problem(grid_roads(), np.random.default_rng(0), lookahead=2)
    res = solve(one, backend="auto", time_limit_s=10.0)
    assert res.status is Status.OPTIMAL and res.backend == "beam"
    two = random_problem(grid_roads(), np.random.default_rng(1), uavs=2, lookahead=3)
    res = solve(two, backend="auto", time_limit_s=30.0)
    assert res.status is Status.OPTIMAL and res.backend in ("beam", "exact")
    assert "heuristic_objective" in res.stats and "auto:" in res.message


@pytest.mark.parametrize("backend", NAMES)
def test_deterministic_for_a_seed(backend: str) -> None:
    """The same problem and seed give the same plan and objective."""
    rng = np.random.default_rng(4)
    p = random_problem(random_roads(4), rng, uavs=2, lookahead=3)
    truth = p.roads.uniform(p.n_targets, rng)
    p = RoadSearchProblem(p.roads, p.uav_nodes, p.particle_edge, p.particle_s,
                          p.particle_weight, p.entropy, p.settings, *truth)
    a = solve(p, backend=backend, time_limit_s=30.0, seed=7)
    b = solve(p, backend=backend, time_limit_s=30.0, seed=7)
    assert a.plan == b.plan and a.objective == b.objective


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"backend": "anneal"}, "backend"),
    ({"time_limit_s": 0.0}, "time_limit_s"),
    ({"seed": -1}, "seed"),
])
def test_bad_arguments(kwargs: dict[str, object], field: str) -> None:
    """Unknown backend, bad limit or seed: InvalidInputError naming it."""
    p = random_problem(grid_roads(), np.random.default_rng(0), lookahead=1)
    with pytest.raises(InvalidInputError) as err:
        solve(p, **kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_nothing_to_see_is_optimal_at_zero() -> None:
    """With every particle out of reach each backend answers OPTIMAL with objective 0."""
    p = RoadSearchProblem(grid_roads(), (0,), np.full((1, 3), edge(7, 8)), np.full((1, 3), 50.0),
                          np.ones((1, 3)), np.ones(1),
                          RoadSearchSettings(lookahead=1, motion=STATIC),
                          np.array([edge(7, 8)]), np.array([50.0]))
    assert p.scenario.n_groups == 0 and p.scenario.upper_bound() == 0.0
    for backend in NAMES:
        res = solve(p, backend=backend)
        assert res.status is Status.OPTIMAL and res.objective == 0.0 and res.bound == 0.0


def test_a_limit_spent_loading_or_tools_keeps_the_beam_answer(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """While OR-Tools is still loading when the limit runs out, ``exact`` answers NO_SOLUTION
    and ``auto`` the beam's plan, unproved."""
    solve_module = importlib.import_module("searchtrack.plan.road_search.solve")

    monkeypatch.setattr(solve_module, "loaded_within", lambda name, deadline: False)
    two = random_problem(grid_roads(), np.random.default_rng(1), uavs=2, lookahead=3)
    exact = solve(two, backend="exact", time_limit_s=1.0)
    assert exact.status is Status.NO_SOLUTION and exact.plan is None
    assert "OR-Tools" in exact.message
    beam = solve(two, backend="beam", time_limit_s=1.0)
    auto = solve(two, backend="auto", time_limit_s=1.0)
    assert auto.status is Status.FEASIBLE and auto.backend == "beam"
    assert auto.objective == beam.objective and auto.bound == beam.bound


def test_the_limit_covers_the_scenario_build(monkeypatch: pytest.MonkeyPatch) -> None:
    """A scenario build that outlasts the limit answers NO_SOLUTION (nothing kept, so a later
    call with more time builds it and plans); a stop request during the build answers
    INTERRUPTED; the runtime of an answer counts the build."""
    import time

    from searchtrack.core.interrupt import clear_stop, request_stop

    scenario_module = importlib.import_module("searchtrack.plan.road_search.scenario")
    slow = scenario_module._lattice_arcs

    def lattice(*args: object) -> object:
        time.sleep(0.05)
        return slow(*args)

    monkeypatch.setattr(scenario_module, "_lattice_arcs", lattice)
    p = random_problem(grid_roads(), np.random.default_rng(2), uavs=2, lookahead=2)
    for backend in ("auto", "exhaustive", "beam"):
        res = solve(p, backend=backend, time_limit_s=0.02)
        assert res.status is Status.NO_SOLUTION and res.plan is None, backend
        assert "scenario" in res.message and "scenario" not in p.__dict__
    request_stop()
    try:
        res = solve(p, backend="beam", time_limit_s=10.0)
    finally:
        clear_stop()
    assert res.status is Status.INTERRUPTED and res.plan is None
    res = solve(p, backend="exhaustive", time_limit_s=10.0)
    assert res.status is Status.OPTIMAL and res.runtime_s >= 0.1   # two UAVs' graphs slept
    assert "scenario" in p.__dict__
