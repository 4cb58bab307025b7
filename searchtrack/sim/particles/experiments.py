"""The campaign experiments of particles in open space: the standard SMC-PHD scenario filtered
once (``phd_tracking_scenario``), paper 003's closed-loop multi-UAV tracking
(``phd_tracking_episode``) and paper 004's closed-loop 3-D search (``phd_search_episode``).

Each parameter that sets a field of :class:`~searchtrack.sim.particles.tracking.TrackConfig`,
:class:`~searchtrack.sim.particles.search.SearchConfig` or a keyword of
:func:`~searchtrack.sim.particles.scenario.standard_scenario` takes its default from there.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from searchtrack.core.checks import finite_or_none
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan
from searchtrack.estimate.phd.filter import step
from searchtrack.plan.search import CentreProbability, EmptyHorizonMI
from searchtrack.sim.campaigns.experiments import Experiment, Metric, Metrics, Param, Params
from searchtrack.sim.particles.scenario import STANDARD_AREA, standard_scenario
from searchtrack.sim.particles.search import PLANNERS, SearchConfig, run_search_episode
from searchtrack.sim.particles.tracking import (
    TRACK_PLANNERS,
    TrackConfig,
    run_track_episode,
    taxi_world,
)


def phd_scenario_run(params: Params, seed: int) -> Metrics:
    """The standard PHD scenario filtered once: mean OSPA (p = 1, c = 100 m) after burn-in."""
    n_scans, burn_in = int(params["n_scans"]), int(params["burn_in"])
    if burn_in >= n_scans:
        raise InvalidInputError("burn_in", burn_in, f"must be < n_scans={n_scans}")
    sc = standard_scenario(seed, n_targets=int(params["n_targets"]), n_scans=n_scans,
                           clutter_rate=float(params["clutter_rate"]))
    config = PHDConfig(particles_per_target=int(params["particles_per_target"]),
                       region=np.array(STANDARD_AREA))
    rng = np.random.default_rng(seed)
    state, pose = PHDState.empty(4, 2), np.zeros(3)
    distances, counts = [], []
    for k, z in enumerate(sc.scans):
        state, est = step(state, [SensorScan(sc.sensor, pose, z)], sc.motion, config, sc.dt_s,
                          rng)
        if k >= burn_in:
            distances.append(ospa(np.array(est.positions).reshape(-1, 2), sc.truth[k][:, :2],
                                  100.0, 1.0))
            counts.append(len(est))
    return {"ospa_mean": float(np.mean(distances)), "estimates_mean": float(np.mean(counts))}


SEARCH_REFINEMENTS = ("centre", "mi")
"""Refinement terms of ``phd_search_episode``: centre probabilities (004 eq. 11) or MI."""

SEARCH_FOVS = ("printed", "squared")
"""Fields of view of ``phd_search_episode``: 004's printed ``exp(−‖ζ‖/2)`` or the Gaussian."""

SEARCH_FOUND_BY_STEP = 250
"""The step at which ``phd_search_episode`` reports targets found (004 E1's 250 steps)."""

_LOOP = SearchConfig()
"""The search loop's defaults, which the parameters of ``phd_search_episode`` switch from."""


def search_run(params: Params, seed: int) -> Metrics:
    """One closed-loop paper-004 search episode, configured as
    ``benchmarks/phd_search_experiments.py search`` / ``horizon`` do (``max_steps = 0``: the
    3-D lawnmower's length, as the scripts' default cap).

    ``adaptive_birth = true`` switches the filter to
    ``PHDConfig(adaptive_birth=True, birth_mass=1)`` with the found-target mass ``T_m = 1``
    derived for that birth (see :mod:`searchtrack.sim.particles.search`);
    ``found_gate_sigmas`` is ``FoundConfig.gate_sigmas`` (4, the loop's innovation gate, by
    default; 0: 004's printed ball of ``T_z = 5`` m); ``fov = "squared"`` gives the sensor the
    Gaussian field of view ``exp(−‖ζ‖²/2)`` instead of 004's printed ``exp(−‖ζ‖/2)``
    (:class:`~searchtrack.models.range_sensor.RangeBearingElevationSensor`)."""
    cap = int(params["max_steps"])
    if cap == 0:
        cap = len(_LOOP.lawnmower_route())
    refinement = CentreProbability() if params["refinement"] == "centre" else EmptyHorizonMI()
    base = _LOOP
    phd, found = base.phd, replace(base.found, gate_sigmas=float(params["found_gate_sigmas"]))
    if params["adaptive_birth"]:
        phd = replace(phd, adaptive_birth=True, birth_mass=1.0)
        found = replace(found, mass=1.0)
    sensor = replace(base.sensor, squared=params["fov"] == "squared")
    config = SearchConfig(planner=str(params["planner"]),  # type: ignore[arg-type]
                          horizon=int(params["horizon"]), max_steps=cap,
                          alpha=float(params["alpha"]), refinement=refinement, phd=phd,
                          found=found, sensor=sensor)
    ep = run_search_episode(config, seed)
    counts = ep.found_per_step
    return {"steps_to_find_all": ep.steps_to_find_all if ep.finished else None,
            "steps_capped": ep.steps_to_find_all,
            "targets_found": int(counts[-1]),
            "found_by_step_250": int(counts[min(SEARCH_FOUND_BY_STEP, counts.size) - 1]),
            "false_found": ep.false_found, "rmse_m": finite_or_none(ep.rmse_m),
            "planner_ms": ep.planner_ms, "filter_ms": ep.filter_ms}


TRACK_METRICS = ("count_ratio", "entropy", "in_view", "ospa_m", "altitude_m")
"""Per-step series of a tracking episode reported (as means over its second half)."""

TRACK_MOTIONS = ("gp", "random_walk")
"""Filter motion models of ``phd_tracking_episode`` (:attr:`TrackConfig.motion`)."""


def track_run(params: Params, seed: int) -> Metrics:
    """One closed-loop paper-003 tracking episode, configured as
    ``benchmarks/phd_tracking_experiments.py track`` does; the tail means of its series."""
    config = TrackConfig(planner=str(params["planner"]),  # type: ignore[arg-type]
                         motion=str(params["motion"]),  # type: ignore[arg-type]
                         robots=int(params["robots"]), horizon=int(params["horizon"]),
                         steps=int(params["steps"]))
    ep = run_track_episode(config, taxi_world(config, seed), seed)
    out: Metrics = {name: finite_or_none(ep.tail_mean(name)) for name in TRACK_METRICS}
    out.update(planner_ms=ep.planner_ms, filter_ms=ep.filter_ms)
    return out


EXPERIMENTS = (
    Experiment("phd_tracking_scenario", (
        Param.of(standard_scenario, "n_targets"), Param.of(standard_scenario, "n_scans"),
        Param("burn_in", int, 20), Param.of(PHDConfig, "particles_per_target"),
        Param.of(standard_scenario, "clutter_rate")),
        {"ospa_mean": Metric(float), "estimates_mean": Metric(float, non_negative=True)},
        phd_scenario_run,
        "the standard SMC-PHD scenario: mean OSPA after burn-in",
        claim="SMC-PHD on the standard scenario: OSPA (p = 1, c = 100 m) well below the "
              "cut-off once the targets are born"),
    Experiment("phd_search_episode", (
        Param.of(SearchConfig, "planner", choices=PLANNERS),
        Param.of(SearchConfig, "horizon", choices=(1, 2, 3, 4, 5)),
        Param("refinement", str,
              "centre" if isinstance(_LOOP.refinement, CentreProbability) else "mi",
              SEARCH_REFINEMENTS),
        Param.of(SearchConfig, "alpha"),
        # 0 stands for the lawnmower's length on the run's box (SearchConfig's 812 on 004's).
        Param("max_steps", int, 0),
        Param("adaptive_birth", bool, _LOOP.phd.adaptive_birth),
        Param("found_gate_sigmas", float, _LOOP.found.gate_sigmas, minimum=0.0),
        Param("fov", str, "squared" if _LOOP.sensor.squared else "printed", SEARCH_FOVS)),
        {**dict.fromkeys(("steps_to_find_all", "steps_capped", "targets_found",
                          "found_by_step_250", "false_found"), Metric(int)),
         **dict.fromkeys(("rmse_m", "planner_ms", "filter_ms"),
                         Metric(float, non_negative=True))}, search_run,
        "paper 004's closed-loop 3-D search with the SMC-PHD filter: steps to find all 12",
        claim="paper 004: exploration + refinement finds every target sooner than the "
              "lawnmower; refinement alone does not find them all"),
    Experiment("phd_tracking_episode", (
        Param.of(TrackConfig, "planner", choices=TRACK_PLANNERS),
        Param.of(TrackConfig, "motion", choices=TRACK_MOTIONS),
        Param.of(TrackConfig, "robots"), Param.of(TrackConfig, "horizon"),
        Param.of(TrackConfig, "steps")),
        {**{name: Metric(float, non_negative=name in ("ospa_m", "altitude_m"))
            for name in TRACK_METRICS},
         **dict.fromkeys(("planner_ms", "filter_ms"), Metric(float, non_negative=True))},
        track_run, "paper 003's closed-loop multi-UAV PHD tracking: tail means of its series",
        claim="paper 003: greedy END tracks the most targets with the lowest entropy per "
              "target; MI the fewest; the lawnmower the highest entropy"),
)
"""``phd_tracking_scenario``, ``phd_search_episode`` and ``phd_tracking_episode``."""
