"""The registered experiments: typed parameters, declared metrics, runs that return them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.sim.campaigns.experiments import EXPERIMENTS, Experiment, Param, get
from searchtrack.sim.campaigns.spec import read_spec


def _run(name: str, params: dict[str, object], seed: int = 1) -> dict[str, object]:
    exp = get(name)
    metrics = exp.run(exp.resolve(params), seed)
    assert set(metrics) == set(exp.metrics)
    return dict(metrics)


def test_get_lists_the_registered_names() -> None:
    """An unknown experiment's error lists every registered name."""
    with pytest.raises(InvalidInputError, match=r"experiment='nope'.*toy"):
        get("nope")
    assert {"toy", "mission", "phd_tracking_scenario", "optw_instance"} <= set(EXPERIMENTS)


def test_resolve_checks_names_and_types() -> None:
    """Unknown names and wrong types are refused naming the parameter; ints widen to floats."""
    toy = get("toy")
    assert toy.resolve({"value": 2}) == {"sleep_s": 0.0, "fail": False, "value": 2.0}
    with pytest.raises(InvalidInputError, match="colour"):
        toy.resolve({"colour": 1})
    with pytest.raises(InvalidInputError, match="fail=1: must be bool"):
        toy.resolve({"fail": 1})
    with pytest.raises(InvalidInputError, match="value=True: must be float"):
        toy.resolve({"value": True})
    with pytest.raises(InvalidInputError, match="map='moon'"):
        get("mission").resolve({"map": "moon"})


def test_reserved_column_names_are_refused() -> None:
    """A parameter or metric may not take a column every row has (``seed``, ``status``...)."""
    with pytest.raises(InvalidInputError, match="seed"):
        Experiment("bad", (Param("seed", int, 0),), {"x": float}, lambda p, s: {"x": 0.0})


def test_toy_returns_its_value_or_raises() -> None:
    """The toy run returns its value, or raises when asked to fail."""
    assert _run("toy", {"value": 3.5}, seed=4) == {"result": 3.5, "seed_echo": 4}
    with pytest.raises(RuntimeError, match="on purpose"):
        get("toy").run(get("toy").resolve({"fail": True}), 0)


@pytest.mark.parametrize("mode", ["track", "detect"])
def test_mission_runs_on_the_small_grid(mode: str) -> None:
    """A short mission on the small grid returns its detections and scores."""
    metrics = _run("mission", {"mode": mode, "duration_s": 5.0, "uavs": 2, "targets": 2})
    assert 0 <= int(metrics["detected"]) <= 2  # type: ignore[call-overload]
    assert 0.0 <= float(metrics["moc_mean"]) <= 1.0  # type: ignore[arg-type]


def test_phd_scenario_gives_a_finite_ospa() -> None:
    """A short PHD scenario gives a finite mean OSPA within the cut-off."""
    metrics = _run("phd_tracking_scenario", {"n_targets": 2, "n_scans": 12, "burn_in": 4,
                                             "particles_per_target": 100})
    assert 0.0 <= float(metrics["ospa_mean"]) <= 100.0  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="burn_in"):
        _run("phd_tracking_scenario", {"n_scans": 5, "burn_in": 5})


def test_optw_instance_reports_the_solve() -> None:
    """An OPTW run reports objective, status and solve time."""
    metrics = _run("optw_instance", {"instance": "c101", "backend": "ils",
                                     "time_limit_s": 0.1})
    assert float(metrics["objective"]) > 0  # type: ignore[arg-type]
    assert metrics["solve_status"] in ("FEASIBLE", "OPTIMAL")
    assert math.isfinite(float(metrics["solve_s"]))  # type: ignore[arg-type]


@pytest.mark.parametrize(("planner", "refinement"), [("proposed", "centre"),
                                                     ("refinement", "mi"), ("lawnmower", "centre")])
def test_search_episode_matches_the_direct_call(planner: str, refinement: str) -> None:
    """A few steps of 004's closed-loop search give what ``run_search_episode`` gives for the
    same configuration and seed (what the benchmark script builds)."""
    from searchtrack.plan.search import CentreProbability, EmptyHorizonMI
    from searchtrack.sim.particles.search import SearchConfig, run_search_episode

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

    from searchtrack.sim.campaigns import experiments
    from searchtrack.sim.particles.search import SearchConfig, run_search_episode

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
    from searchtrack.sim.particles.tracking import (
        TrackConfig,
        run_track_episode,
        taxi_world,
    )

    metrics = _run("phd_tracking_episode", {"planner": planner, "motion": motion, "robots": 2,
                                            "horizon": 1, "steps": 3}, seed=1)
    cfg = TrackConfig(planner=planner, motion=motion, robots=2,  # type: ignore[arg-type]
                      horizon=1, steps=3)
    direct = run_track_episode(cfg, taxi_world(cfg, 1), 1)
    for name in ("count_ratio", "entropy", "in_view", "ospa_m", "altitude_m"):
        assert metrics[name] == direct.tail_mean(name), name
    assert all(isinstance(metrics[k], float) for k in ("planner_ms", "filter_ms"))


def test_tracking_episode_defaults_are_the_benchmark_defaults() -> None:
    """Defaults: END, GP motion, 2 UAVs, T = 2, 60 steps (``phd_tracking_experiments.py``)."""
    assert get("phd_tracking_episode").resolve({}) == {
        "planner": "end", "motion": "gp", "robots": 2, "horizon": 2, "steps": 60}


def test_road_tracking_episode_matches_the_direct_call() -> None:
    """The campaign's paper-000 episode is :func:`run_road_tracking` with the same settings."""
    import json

    import numpy as np

    from searchtrack.sim.road_particles.episode import (
        PAPER_GRID,
        RoadTrackingConfig,
        run_road_tracking,
    )

    params = {"planner": "exhaustive", "duration_s": 20.0, "histories": 2, "particles": 100}
    out = _run("road_tracking_episode", params, seed=3)
    log = run_road_tracking(RoadTrackingConfig(map=PAPER_GRID, planner="exhaustive",
                                               duration_s=20.0, histories=2, particles=100), 3)
    assert np.allclose(json.loads(str(out["entropy_series"])), log.entropy, atol=1e-4)
    assert out["mean_entropy"] == pytest.approx(log.mean_entropy)
    assert out["error_m"] == pytest.approx(float(log.error_m.mean()))


def test_mission_options_defaults_and_checks(tmp_path: Path) -> None:
    """``tracker_alpha`` and ``coverage_weight`` default to off (0), ``handover`` to on;
    a negative value is refused naming the parameter, in Python and in a campaign file (the
    file and the dotted key)."""
    mission = get("mission")
    resolved = mission.resolve({})
    assert (resolved["tracker_alpha"], resolved["handover"], resolved["coverage_weight"]) == (
        0.0, True, 0.0)
    assert "moc_after_detection" in mission.metrics
    for name, bad in [("tracker_alpha", -0.5), ("coverage_weight", -1.0),
                      ("tracker_alpha", float("inf")), ("handover", 1)]:
        with pytest.raises(InvalidInputError) as info:
            mission.resolve({name: bad})
        assert info.value.field == name
    path = tmp_path / "bad.toml"
    path.write_text('name = "b"\nexperiment = "mission"\nseeds = [0]\n[grid]\n'
                    'cells = [{uavs = 1, tracker_alpha = -1.0}]\n', encoding="utf-8")
    with pytest.raises(ParseError) as err:
        read_spec(path)
    assert err.value.field == "grid.cells[0].tracker_alpha" and "bad.toml" in str(err.value)
    path.write_text('name = "b"\nexperiment = "mission"\nseeds = [0]\n[settings]\n'
                    'coverage_weight = -2.0\n[grid]\nuavs = [1]\n', encoding="utf-8")
    with pytest.raises(ParseError) as err:
        read_spec(path)
    assert err.value.field == "settings.coverage_weight"


def test_mission_options_reach_the_scenario() -> None:
    """Switched on, the options change a short grid mission's run; off, the run is the one the
    scenario without them flies; MOC after detection is reported."""
    common: dict[str, object] = {"duration_s": 20.0, "uavs": 2, "targets": 2}
    base = _run("mission", common, seed=6)
    assert base == _run("mission", {**common, "tracker_alpha": 0.0, "handover": False,
                                    "coverage_weight": 0.0}, seed=6)
    after = base["moc_after_detection"]
    assert after is None or 0.0 <= float(after) <= 1.0  # type: ignore[arg-type]
    for option in ({"tracker_alpha": 4.47}, {"coverage_weight": 2.0}):
        assert _run("mission", {**common, **option}, seed=6) != base, option
