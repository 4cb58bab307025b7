"""The experiments a campaign can run: each a pure function ``(params, seed) -> metrics`` with
declared, typed parameters and metrics.

Heavy shared inputs (a road network and its diffusion operators) are built once per process and
cached by their map name (and, for missions, the trackers' diffusivity), so a Dask worker builds
each map once however many runs it takes.
"""

from __future__ import annotations

import functools
import json
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from importlib import resources

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan
from searchtrack.estimate.phd.filter import step
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.optw import BACKENDS as OPTW_BACKENDS
from searchtrack.plan.optw import read_optw, solve
from searchtrack.plan.search import CentreProbability, EmptyHorizonMI, lawnmower_3d
from searchtrack.sim.campaigns import series
from searchtrack.sim.particles.scenario import STANDARD_AREA, standard_scenario
from searchtrack.sim.particles.search import PLANNERS, SearchConfig, run_search_episode
from searchtrack.sim.particles.tracking import (
    TRACK_PLANNERS,
    TrackConfig,
    run_track_episode,
    taxi_world,
)
from searchtrack.sim.radio import experiment as radio_tracking
from searchtrack.sim.road_particles.episode import RoadTrackingConfig
from searchtrack.sim.road_particles.planners import PLANNERS as ROAD_PLANNERS
from searchtrack.sim.roads import experiment as road_missions
from searchtrack.sim.roads import scenario as sc

ParamValue = bool | int | float | str
"""A parameter value: what TOML gives and a DuckDB column holds."""

MetricValue = float | int | str | None
"""A metric value (``None``: not defined for this run, e.g. no target to count)."""

Params = Mapping[str, ParamValue]
Metrics = dict[str, MetricValue]

#: Column names every run row has; parameters and metrics may not take them.
RESERVED = ("key", "experiment", "seed", "status", "runtime_s", "error", "host", "version",
            "started_utc", "ended_utc")


@dataclass(frozen=True)
class Param:
    """A parameter of an experiment: its name, type (``bool``, ``int``, ``float``, ``str``),
    default and, optionally, the values it may take or the least value of a number."""

    name: str
    kind: type[bool] | type[int] | type[float] | type[str]
    default: ParamValue
    choices: tuple[ParamValue, ...] = ()
    minimum: float | None = None

    def check(self, value: object) -> ParamValue:
        """``value`` as this parameter's type (an integer is accepted for a float).

        Raises
        ------
        InvalidInputError
            Naming the parameter: wrong type, not one of the choices, or below the minimum.
        """
        ok = isinstance(value, self.kind) and (self.kind is bool or not isinstance(value, bool))
        if self.kind is float and isinstance(value, int) and not isinstance(value, bool):
            value, ok = float(value), True
        if not ok:
            raise InvalidInputError(self.name, value, f"must be {self.kind.__name__}")
        if self.kind is float and not math.isfinite(float(value)):  # type: ignore[arg-type]
            raise InvalidInputError(self.name, value, "must be finite")
        if self.choices and value not in self.choices:
            raise InvalidInputError(self.name, value, f"must be one of {list(self.choices)}")
        if self.minimum is not None and value < self.minimum:  # type: ignore[operator]
            raise InvalidInputError(self.name, value, f"must be ≥ {self.minimum:g}")
        return value  # type: ignore[return-value]


@dataclass(frozen=True)
class Experiment:
    """A registered experiment.

    Parameters
    ----------
    name
        Its name in campaign files.
    params
        Its parameters, in column order.
    metrics
        Metric name -> type (``float``, ``int`` or ``str``) of the row a run returns.
    run
        ``(params, seed) -> metrics``; ``params`` has every parameter, checked.
    """

    name: str
    params: tuple[Param, ...]
    metrics: Mapping[str, type[float] | type[int] | type[str]]
    run: Callable[[Params, int], Metrics]
    description: str = ""

    def __post_init__(self) -> None:
        names = [p.name for p in self.params] + list(self.metrics)
        clash = sorted({n for n in names if n in RESERVED or names.count(n) > 1})
        if clash:
            raise InvalidInputError("params", clash, "reserved or repeated column names")
        for p in self.params:
            p.check(p.default)

    def param(self, name: str) -> Param:
        """The parameter ``name``.

        Raises
        ------
        InvalidInputError
            Unknown name, listing the known ones.
        """
        for p in self.params:
            if p.name == name:
                return p
        raise InvalidInputError(name, name, f"not a parameter of {self.name!r} "
                                f"(parameters: {[p.name for p in self.params]})")

    def resolve(self, given: Mapping[str, object]) -> dict[str, ParamValue]:
        """Every parameter: ``given`` (checked) over the defaults."""
        for name in given:
            self.param(name)
        return {p.name: p.check(given[p.name]) if p.name in given else p.default
                for p in self.params}


def _toy(params: Params, seed: int) -> Metrics:
    """Sleep ``sleep_s``, then return ``value`` (or raise when ``fail``)."""
    time.sleep(float(params["sleep_s"]))
    if params["fail"]:
        raise RuntimeError(f"toy run failed on purpose (seed {seed})")
    return {"result": float(params["value"]), "seed_echo": seed}


#: Maps of the ``mission`` experiment: the thesis's maps and a small grid for quick runs.
MISSION_MAPS = road_missions.MISSION_MAPS


def _phd(params: Params, seed: int) -> Metrics:
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


OPTW_INSTANCES = ("c101", "r101", "rc101", "pr01")
"""The OPTW instances bundled in ``searchtrack/data/optw``."""


def _optw(params: Params, seed: int) -> Metrics:
    """One bundled OPTW instance solved by one backend."""
    path = resources.files("searchtrack") / "data" / "optw" / f"{params['instance']}.txt"
    inst = read_optw(str(path), vehicles=int(params["vehicles"]))
    result = solve(inst, backend=str(params["backend"]),
                   time_limit_s=float(params["time_limit_s"]), seed=seed)
    return {"objective": result.objective, "bound": result.bound,
            "solve_status": result.status.name, "solve_s": result.runtime_s}


def _finite(value: float) -> float | None:
    """``value``, or ``None`` when it is not finite (no value for this run)."""
    return value if math.isfinite(value) else None


SEARCH_REFINEMENTS = ("centre", "mi")
"""Refinement terms of ``phd_search_episode``: centre probabilities (004 eq. 11) or MI."""

SEARCH_FOUND_BY_STEP = 250
"""The step at which ``phd_search_episode`` reports targets found (004 E1's 250 steps)."""


def _search(params: Params, seed: int) -> Metrics:
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
        cap = len(lawnmower_3d(SearchConfig().bounds, 48.0, 48.0, 12.0))
    refinement = CentreProbability() if params["refinement"] == "centre" else EmptyHorizonMI()
    base = SearchConfig()
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
            "false_found": ep.false_found, "rmse_m": _finite(ep.rmse_m),
            "planner_ms": ep.planner_ms, "filter_ms": ep.filter_ms}


TRACK_METRICS = ("count_ratio", "entropy", "in_view", "ospa_m", "altitude_m")
"""Per-step series of a tracking episode reported (as means over its second half)."""


def _track(params: Params, seed: int) -> Metrics:
    """One closed-loop paper-003 tracking episode, configured as
    ``benchmarks/phd_tracking_experiments.py track`` does; the tail means of its series."""
    config = TrackConfig(planner=str(params["planner"]),  # type: ignore[arg-type]
                         motion=str(params["motion"]),  # type: ignore[arg-type]
                         robots=int(params["robots"]), horizon=int(params["horizon"]),
                         steps=int(params["steps"]))
    ep = run_track_episode(config, taxi_world(config, seed), seed)
    out: Metrics = {name: _finite(ep.tail_mean(name)) for name in TRACK_METRICS}
    out.update(planner_ms=ep.planner_ms, filter_ms=ep.filter_ms)
    return out


ROAD_MAPS: dict[str, sc.MapSpec] = {
    "grid-3x3": sc.MapSpec("grid", rows=3, cols=3, block_m=100.0, spacing_m=100.0),
    **{name: sc.MapSpec("osm", sc.bundled_map(name), spacing_m=1e6)
       for name in sc.BUNDLED_MAPS},
}
"""Maps of ``road_tracking_episode``: the paper's 3 × 3 grid of 100 m roads, and the bundled
OSM extracts with one edge per road segment between junctions (not resampled)."""


@functools.cache
def road_entropy_bound(map_name: str, targets: int, uavs: int) -> float:
    """Theorem 1's lower bound for the combined entropy an episode records: ``B_L`` per target
    on the same 5 m road bins (bin masses), plus ``ln M`` for pooling ``M`` targets of mass
    ``1/M`` each (exact when their supports do not overlap); paper defaults otherwise (V_a 40,
    v 10, σ_v 4, R 5 m², δt 0.1 s)."""
    from searchtrack.plan.fleet import BoundConfig, BoundMap, entropy_bound

    config = BoundConfig(targets=targets, bin_m=5.0, binning="mass")
    bound_map = BoundMap.from_network(ROAD_MAPS[map_name].build(), config)
    return entropy_bound(bound_map, config, uavs).bound + math.log(targets)


def _bound_line(params: Mapping[str, object]) -> dict[str, float]:
    """The Fig. 11 reference line of a group of ``road_tracking_episode`` runs."""
    name = str(params.get("map", "grid-3x3"))
    if name != "grid-3x3":  # Lemma 5 on a whole OSM map takes seconds: drawn on the grid only
        return {}
    bound = road_entropy_bound(name, int(str(params.get("targets", 2))),
                               int(str(params.get("uavs", 1))))
    return {f"lower bound (Theorem 1) {bound:.2f}": bound}


series.REFERENCES["road_tracking_episode"] = _bound_line


@functools.cache
def _roads(map_name: str) -> DirectedRoads:
    """The directed roads of ``map_name``, built once per process."""
    return DirectedRoads(ROAD_MAPS[map_name].build())


def _road_tracking(params: Params, seed: int) -> Metrics:
    """One closed-loop paper-000 episode: the entropy over time (JSON, one value per scan) and
    its means over the whole run, its first and last thirds."""
    from searchtrack.sim.road_particles.episode import run_road_tracking

    map_name = str(params["map"])
    config = RoadTrackingConfig(
        map=ROAD_MAPS[map_name], planner=str(params["planner"]),
        targets=int(params["targets"]), uavs=int(params["uavs"]),
        duration_s=float(params["duration_s"]), histories=int(params["histories"]),
        particles=int(params["particles"]), lookahead=int(params["lookahead"]),
        normalization="max" if params["normalization"] == "max" else "sum")
    log = run_road_tracking(config, seed, _roads(map_name))
    third = max(1, log.entropy.size // 3)
    found = log.detected
    return {"mean_entropy": log.mean_entropy,
            "early_entropy": float(log.entropy[:third].mean()),
            "late_entropy": float(log.entropy[-third:].mean()),
            "error_m": float(log.error_m.mean()),
            "all_detected_s": None if np.isnan(found).any() else float(found.max()),
            "planner_ms": log.planner_ms, "filter_ms": log.filter_ms,
            "entropy_series": json.dumps([round(float(v), 4) for v in log.entropy])}


_EXPERIMENTS = (
    Experiment("toy", (Param("sleep_s", float, 0.0), Param("fail", bool, False),
                       Param("value", float, 1.0)),
               {"result": float, "seed_echo": int}, _toy,
               "sleeps, returns its value as result (or raises): for tests and benchmarks"),
    Experiment("mission", (
        Param("map", str, "grid-small", tuple(MISSION_MAPS)), Param("mode", str, "track", sc.MODES),
        Param("uavs", int, 3), Param("targets", int, 4),
        Param("strategy", str, sc.GuidanceSpec.strategy, sc.STRATEGIES),
        Param("altitude_m", float, 457.2), Param("duration_s", float, 60.0),
        Param("tracker_alpha", float, 0.0, minimum=0.0),
        Param("handover", bool, sc.FilterSpec.handover),
        Param("coverage_weight", float, 0.0, minimum=0.0)),
        {"detected": int, "time_to_detect_all_s": float, "moc_mean": float,
         "moc_after_detection": float, "pvt": float, "pva": float}, road_missions.mission_run,
        "a road mission (thesis §6.1 detect / §6.2 track; tracker_alpha 0 = the LRT's α)"),
    Experiment("phd_tracking_scenario", (
        Param("n_targets", int, 10), Param("n_scans", int, 100), Param("burn_in", int, 20),
        Param("particles_per_target", int, 400), Param("clutter_rate", float, 10.0)),
        {"ospa_mean": float, "estimates_mean": float}, _phd,
        "the standard SMC-PHD scenario: mean OSPA after burn-in"),
    Experiment("optw_instance", (
        Param("instance", str, "c101", OPTW_INSTANCES),
        Param("backend", str, "ils", tuple(OPTW_BACKENDS.names())),
        Param("time_limit_s", float, 1.0), Param("vehicles", int, 1)),
        {"objective": float, "bound": float, "solve_status": str, "solve_s": float}, _optw,
        "a bundled OPTW instance solved by one backend"),
    Experiment("phd_search_episode", (
        Param("planner", str, "proposed", PLANNERS), Param("horizon", int, 1, (1, 2, 3, 4, 5)),
        Param("refinement", str, "centre", SEARCH_REFINEMENTS), Param("alpha", float, 1.0),
        Param("max_steps", int, 0), Param("adaptive_birth", bool, False),
        Param("found_gate_sigmas", float, 4.0, minimum=0.0),
        Param("fov", str, "printed", ("printed", "squared"))),
        {"steps_to_find_all": int, "steps_capped": int, "targets_found": int,
         "found_by_step_250": int, "false_found": int, "rmse_m": float, "planner_ms": float,
         "filter_ms": float}, _search,
        "paper 004's closed-loop 3-D search with the SMC-PHD filter: steps to find all 12"),
    Experiment("phd_tracking_episode", (
        Param("planner", str, "end", TRACK_PLANNERS),
        Param("motion", str, "gp", ("gp", "random_walk")), Param("robots", int, 2),
        Param("horizon", int, 2), Param("steps", int, 60)),
        {**dict.fromkeys(TRACK_METRICS, float), "planner_ms": float, "filter_ms": float},
        _track, "paper 003's closed-loop multi-UAV PHD tracking: tail means of its series"),
    Experiment("road_tracking_episode", (
        Param("planner", str, RoadTrackingConfig.planner, ROAD_PLANNERS),
        Param("map", str, "grid-3x3", tuple(ROAD_MAPS)),
        Param("targets", int, 2), Param("uavs", int, 1), Param("duration_s", float, 120.0),
        Param("histories", int, 10), Param("particles", int, 500),
        Param("lookahead", int, 3), Param("normalization", str, "sum", ("sum", "max"))),
        {"mean_entropy": float, "early_entropy": float, "late_entropy": float,
         "error_m": float, "all_detected_s": float, "planner_ms": float, "filter_ms": float,
         "entropy_series": str},
        _road_tracking, "paper 000's closed-loop road tracking (RBPF + planner): entropy"),
    Experiment("radio_tracking_episode",
               tuple(Param(name, kind, default, choices)  # type: ignore[arg-type]
                     for name, (kind, default, choices) in radio_tracking.PARAMS.items()),
               radio_tracking.METRICS, radio_tracking.radio_episode,
               "paper 002's closed loop (TBD/DTT filter + Rényi/CS/straight path): OSPA"),
)

EXPERIMENTS: dict[str, Experiment] = {e.name: e for e in _EXPERIMENTS}
"""Every registered experiment by name."""


def get(name: str) -> Experiment:
    """The experiment ``name``.

    Raises
    ------
    InvalidInputError
        Unknown name, listing the registered ones.
    """
    if name not in EXPERIMENTS:
        raise InvalidInputError("experiment", name, f"must be one of {sorted(EXPERIMENTS)}")
    return EXPERIMENTS[name]
