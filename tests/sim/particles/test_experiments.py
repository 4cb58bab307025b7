"""The campaign experiments of particles in open space: the standard PHD scenario, 003's
tracking and 004's search episodes, each as the direct call and the benchmark scripts give it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.sim.campaigns.experiments import get
from searchtrack.sim.campaigns.spec import read_spec
from searchtrack.sim.particles.experiments import EXPERIMENTS
from searchtrack.sim.particles.search import SearchConfig
from searchtrack.sim.particles.tracking import TrackConfig


def _run(name: str, params: dict[str, object], seed: int = 1) -> dict[str, object]:
    exp = get(name)
    metrics = exp.run(exp.resolve(params), seed)
    assert set(metrics) == set(exp.metrics)
    return dict(metrics)


def test_declares_the_three_experiments_with_their_claims() -> None:
    assert [e.name for e in EXPERIMENTS] == ["phd_tracking_scenario", "phd_search_episode",
                                             "phd_tracking_episode"]
    assert all(get(e.name) is e for e in EXPERIMENTS)
    assert get("phd_tracking_episode").claims()[0].startswith("paper 003:")
    assert get("phd_search_episode").claims()[0].startswith("paper 004:")
    assert get("phd_tracking_scenario").claims()[0].startswith("SMC-PHD on the standard")


def test_phd_scenario_gives_a_finite_ospa() -> None:
    """A short PHD scenario gives a finite mean OSPA within the cut-off."""
    metrics = _run("phd_tracking_scenario", {"n_targets": 2, "n_scans": 12, "burn_in": 4,
                                             "particles_per_target": 100})
    assert 0.0 <= float(metrics["ospa_mean"]) <= 100.0  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="burn_in"):
        _run("phd_tracking_scenario", {"n_scans": 5, "burn_in": 5})


@pytest.mark.parametrize(("planner", "refinement"), [("proposed", "centre"),
                                                     ("refinement", "mi"), ("lawnmower", "centre")])
def test_search_episode_matches_the_direct_call(planner: str, refinement: str) -> None:
    """A few steps of 004's closed-loop search give what ``run_search_episode`` gives for the
    same configuration and seed (what the benchmark script builds)."""
    from searchtrack.plan.search import CentreProbability, EmptyHorizonMI
    from searchtrack.sim.particles.search import run_search_episode

    metrics = _run("phd_search_episode", {"planner": planner, "refinement": refinement,
                                          "horizon": 2, "max_steps": 3}, seed=2)
    direct = run_search_episode(SearchConfig(
        planner=planner, horizon=2, max_steps=3, alpha=1.0,  # type: ignore[arg-type]
        refinement=CentreProbability() if refinement == "centre" else EmptyHorizonMI()), 2)
    assert metrics["steps_to_find_all"] is None  # 12 targets are not found in 3 steps
    assert metrics["steps_capped"] == direct.steps_to_find_all == 4
    assert metrics["targets_found"] == int(direct.found_per_step[-1])
    assert metrics["found_by_step_250"] == int(direct.found_per_step[-1])
    assert metrics["false_found"] == direct.false_found
    rmse = metrics["rmse_m"]
    assert (rmse is None and math.isnan(direct.rmse_m)) or rmse == direct.rmse_m
    assert all(float(metrics[k]) >= 0.0 for k in ("planner_ms", "filter_ms"))  # type: ignore[arg-type]


def test_search_episode_defaults_are_the_benchmark_defaults() -> None:
    """Defaults: proposed planner, τ = 1, centre refinement, α = 1, cap = the lawnmower's
    length (``max_steps = 0``, as ``benchmarks/phd_search_experiments.py``)."""
    exp = get("phd_search_episode")
    assert exp.resolve({}) == {"planner": "proposed", "horizon": 1, "refinement": "centre",
                               "alpha": 1.0, "max_steps": 0, "adaptive_birth": False,
                               "found_gate_sigmas": 4.0, "fov": "printed"}
    with pytest.raises(InvalidInputError, match="horizon=6"):
        exp.resolve({"horizon": 6})


def test_search_defaults_are_the_loops() -> None:
    """The parameters that set a :class:`SearchConfig` field take its default; the switches
    default to the loop's own settings."""
    exp, loop = get("phd_search_episode"), SearchConfig()
    for name in ("planner", "horizon", "alpha"):
        assert exp.param(name).default == getattr(SearchConfig, name), name
    assert exp.param("found_gate_sigmas").default == loop.found.gate_sigmas
    assert exp.param("adaptive_birth").default == loop.phd.adaptive_birth
    assert (exp.param("fov").default == "squared") == loop.sensor.squared


def test_search_birth_and_gate_options_are_checked(tmp_path: Path) -> None:
    """``adaptive_birth`` must be a bool and ``found_gate_sigmas`` a number ≥ 0: bad values are
    refused naming the parameter, in Python and in a campaign file (the dotted key)."""
    exp = get("phd_search_episode")
    for name, bad in [("adaptive_birth", 1), ("adaptive_birth", "yes"),
                      ("found_gate_sigmas", -1.0), ("found_gate_sigmas", float("nan")),
                      ("found_gate_sigmas", True), ("fov", "gaussian"), ("fov", 1)]:
        with pytest.raises(InvalidInputError) as info:
            exp.resolve({name: bad})
        assert info.value.field == name
    path = tmp_path / "bad.toml"
    path.write_text('name = "b"\nexperiment = "phd_search_episode"\nseeds = [0]\n'
                    '[settings]\nadaptive_birth = 1\n[grid]\nplanner = ["lawnmower"]\n',
                    encoding="utf-8")
    with pytest.raises(ParseError) as err:
        read_spec(path)
    assert err.value.field == "settings.adaptive_birth"
    path.write_text('name = "b"\nexperiment = "phd_search_episode"\nseeds = [0]\n[grid]\n'
                    'found_gate_sigmas = [4.0, -2.0]\n', encoding="utf-8")
    with pytest.raises(ParseError) as err:
        read_spec(path)
    assert str(err.value.field).startswith("grid") and "found_gate_sigmas" in str(err.value.field)


def test_search_birth_and_gate_options_reach_the_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    """``adaptive_birth`` switches the filter to adaptive birth of mass 1 with ``T_m = 1``;
    ``found_gate_sigmas`` is the found-target gate; ``fov = "squared"`` the Gaussian field of
    view; the defaults are the loop's defaults."""
    from dataclasses import replace

    from searchtrack.sim.particles import experiments
    from searchtrack.sim.particles.search import run_search_episode

    seen: list[SearchConfig] = []
    real = run_search_episode

    def spy(config: SearchConfig, seed: int):  # type: ignore[no-untyped-def]
        seen.append(config)
        return real(replace(config, max_steps=1), seed)

    monkeypatch.setattr(experiments, "run_search_episode", spy)
    common: dict[str, object] = {"planner": "lawnmower", "max_steps": 2}
    _run("phd_search_episode", common)
    _run("phd_search_episode", {**common, "adaptive_birth": True, "found_gate_sigmas": 0,
                                "fov": "squared"})
    default, switched = seen
    loop = SearchConfig()
    assert (default.phd, default.found) == (loop.phd, loop.found)
    assert not default.sensor.squared and switched.sensor.squared
    for sensor in (default.sensor, switched.sensor):  # only the norm changes
        np.testing.assert_array_equal(sensor.fov_m, loop.sensor.fov_m)
        assert sensor.gain == loop.sensor.gain
    assert switched.phd == replace(loop.phd, adaptive_birth=True, birth_mass=1.0)
    assert switched.found == replace(loop.found, mass=1.0, gate_sigmas=0.0)


@pytest.mark.parametrize(("planner", "motion"), [("end", "random_walk"), ("mi", "gp"),
                                                 ("lawnmower", "random_walk")])
def test_tracking_episode_matches_the_direct_call(planner: str, motion: str) -> None:
    """A few steps of 003's closed loop give the tail means ``run_track_episode`` gives on
    ``taxi_world`` for the same configuration and seed."""
    from searchtrack.sim.particles.tracking import run_track_episode, taxi_world

    metrics = _run("phd_tracking_episode", {"planner": planner, "motion": motion, "robots": 2,
                                            "horizon": 1, "steps": 3}, seed=1)
    cfg = TrackConfig(planner=planner, motion=motion, robots=2,  # type: ignore[arg-type]
                      horizon=1, steps=3)
    direct = run_track_episode(cfg, taxi_world(cfg, 1), 1)
    for name in ("count_ratio", "entropy", "in_view", "ospa_m", "altitude_m"):
        assert metrics[name] == direct.tail_mean(name), name
    assert all(isinstance(metrics[k], float) for k in ("planner_ms", "filter_ms"))


def test_tracking_episode_defaults_are_the_benchmark_defaults() -> None:
    """Defaults: END, GP motion, 2 UAVs, T = 2, 60 steps (``phd_tracking_experiments.py``),
    each :class:`TrackConfig`'s."""
    exp = get("phd_tracking_episode")
    assert exp.resolve({}) == {
        "planner": "end", "motion": "gp", "robots": 2, "horizon": 2, "steps": 60}
    for name in ("planner", "motion", "robots", "horizon", "steps"):
        assert exp.param(name).default == getattr(TrackConfig, name), name
