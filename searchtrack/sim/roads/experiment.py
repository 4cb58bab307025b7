"""The thesis's road experiments (001 §6): the scenarios per map, fleet, altitude and strategy, and
what each run is scored by.

Experiment 1 (§6.1, Table 6.2): likelihood-gradient search, detection only: the time to detect
all 8 targets against the number of UAVs, on the two bundled OSM maps and a dense synthetic grid.
Experiment 2 (§6.2): loiter, search-and-loiter and search-and-reacquire at the four altitudes of
Table 6.3 for 1 UAV / 4 targets and 3 UAVs / 2 targets, scored by MOC, PVT and PVA (6.8)–(6.9).
The step budget: the filter-and-plan time of one closed-loop step on Aguascalientes with 3 UAVs.
The campaign experiment ``mission`` flies either on any map; its parameters that set a
:class:`Scenario`, :class:`FilterSpec` or :class:`GuidanceSpec` field take their defaults.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.dubins import DubinsLimits
from searchtrack.models.lrt_sensor import AltitudeModel, SensorModel
from searchtrack.plan.guidance.view import STEERINGS
from searchtrack.sim.campaigns.experiments import ClaimsBy, Experiment, Metric, Param
from searchtrack.sim.roads.mission import Mission, World
from searchtrack.sim.roads.record import MissionLog
from searchtrack.sim.roads.scenario import (
    MODES,
    STRATEGIES,
    FilterSpec,
    GuidanceSpec,
    MapSpec,
    Scenario,
    bundled_map,
)

MAPS: dict[str, MapSpec] = {
    "aguascalientes": MapSpec("osm", bundled_map("aguascalientes")),
    "West-Oakland": MapSpec("osm", bundled_map("West-Oakland")),
    "grid-dense": MapSpec("grid", rows=16, cols=16, block_m=65.0),
}
"""The maps of the experiments, by name: the two bundled OSM extracts and a dense 16 × 16 grid."""

TRACKING_STRATEGIES: tuple[str, ...] = ("loiter", "search_and_loiter", "search_and_reacquire")
"""Experiment 2's strategies (search-and-reacquire is the thesis's unsimulated one)."""

TRACKING_FLEETS: tuple[tuple[int, int], ...] = ((1, 4), (3, 2))
"""Experiment 2's (UAVs, targets): UAV-to-target ratios 0.25 and 1.5."""

DETECTION_TARGETS = 8
"""Targets to detect in experiment 1."""

DETECTION_SENSOR = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=120.0, position_noise_m=5.0)
"""Experiment 1's sensor (Table 6.2)."""

STEP_ALTITUDE_M = 1828.8
"""Altitude of the step-budget runs (the highest of Table 6.3)."""


def detection_scenario(map_name: str, *, max_duration_s: float = 1800.0,
                       llr_floor: float = -20.0) -> Scenario:
    """Experiment 1 on ``map_name`` (a key of :data:`MAPS`): 8 targets, likelihood-gradient
    search with a 50 °/s turn rate, random UAV starts, the run ending once every target is
    detected or at ``max_duration_s``. Set the fleet with :func:`with_fleet`.

    ``llr_floor`` bounds the negative evidence (``-inf``: none, as in the thesis).
    """
    return Scenario(map_name, MAPS[map_name], target_count=DETECTION_TARGETS,
                    sensor=DETECTION_SENSOR, altitude_m=None,
                    limits=DubinsLimits(turn_rate_max_rps=math.radians(50.0)),
                    guidance=GuidanceSpec(strategy="search"), mode="detect",
                    duration_s=max_duration_s, uav_start="random",
                    filter=FilterSpec(llr_floor=llr_floor))


def with_fleet(base: Scenario, uavs: int) -> Scenario:
    """``base`` flown by ``uavs`` UAVs."""
    return dataclasses.replace(base, uav_count=uavs)


def detection_time_s(log: MissionLog) -> float | None:
    """Experiment 1's score of a run: the time (s) by which every target was detected, ``None``
    when one was missed."""
    return log.score.time_to_detect_all_s


def tracking_base(map_name: str, *, duration_s: float = 300.0) -> Scenario:
    """The scenario experiment 2 varies, on ``map_name`` (a key of :data:`MAPS`); build the
    shared :class:`~searchtrack.sim.roads.mission.World` from it."""
    return Scenario("exp2", MAPS[map_name], duration_s=duration_s, mode="track")


def tracking_scenario(base: Scenario, *, uavs: int, targets: int, altitude_m: float,
                      strategy: str, altitude: AltitudeModel | None = None) -> Scenario:
    """One cell of experiment 2: ``base`` with the fleet, the sensor of the altitude model
    (6.4)–(6.7) at ``altitude_m`` and the guidance ``strategy``."""
    model = AltitudeModel() if altitude is None else altitude
    return dataclasses.replace(base, uav_count=uavs, target_count=targets,
                               sensor=model.sensor(altitude_m), altitude_m=altitude_m,
                               guidance=GuidanceSpec(strategy=strategy))


@dataclass(frozen=True)
class TrackingRun:
    """Experiment 2's scores of one run.

    Parameters
    ----------
    moc_mean
        MOC averaged over the run.
    moc_last_third
        MOC averaged over the last third of the steps (after the search phase).
    moc_after_detection
        Of the steps from each target's first valid track on, the fraction in which it was
        validly tracked (:func:`searchtrack.sim.roads.metrics.moc_after_detection`); ``None``
        when no target was ever tracked.
    pvt_pct, pva_pct
        PVT and PVA (6.8)–(6.9) in percent; ``None`` when there was nothing to count.
    first_detection_s
        Time of the first detection (s), ``None`` when no target was detected.
    plan_ms_p95
        95th percentile of the guidance's planning time per step (ms).
    """

    moc_mean: float
    moc_last_third: float
    moc_after_detection: float | None
    pvt_pct: float | None
    pva_pct: float | None
    first_detection_s: float | None
    plan_ms_p95: float


def tracking_run(log: MissionLog) -> TrackingRun:
    """The scores of one experiment-2 run."""
    score = log.score
    return TrackingRun(
        moc_mean=score.moc_mean,
        moc_last_third=float(log.moc[2 * len(log.moc) // 3:].mean()),
        moc_after_detection=score.moc_after_detection,
        pvt_pct=None if score.pvt is None else 100 * score.pvt,
        pva_pct=None if score.pva is None else 100 * score.pva,
        first_detection_s=score.time_to_first_detection_s,
        plan_ms_p95=float(np.percentile(log.plan_ms, 95)),
    )


def with_strategy(base: Scenario, strategy: str) -> Scenario:
    """``base`` guided by ``strategy`` (a guidance backend name, default settings)."""
    return dataclasses.replace(base, guidance=GuidanceSpec(strategy=strategy))


def step_scenario(*, duration_s: float = 120.0) -> Scenario:
    """The step-budget scenario: Aguascalientes, 3 UAVs, 4 targets at 1828.8 m; set the
    strategy with :func:`with_strategy`."""
    return Scenario("step", MAPS["aguascalientes"], uav_count=3, target_count=4,
                    sensor=AltitudeModel().sensor(STEP_ALTITUDE_M), altitude_m=STEP_ALTITUDE_M,
                    duration_s=duration_s, mode="track")


def step_samples(logs: Sequence[MissionLog]) -> tuple[IntArray, FloatArray, FloatArray]:
    """Every step of ``logs``: the number of live trackers, the filter-and-plan time (ms) and the
    time per phase (ms, columns as :data:`~searchtrack.sim.roads.record.PHASES`)."""
    counts = np.concatenate([[st.trackers for st in lg.steps] for lg in logs])
    ms = np.concatenate([lg.step_ms for lg in logs])
    phases = np.concatenate([lg.phase_ms for lg in logs])
    return counts.astype(np.int64), ms, phases


MISSION_METRICS: dict[str, Metric] = {
    "detected": Metric(int, non_negative=True),
    **dict.fromkeys(("time_to_detect_all_s", "time_to_first_detection_s", "moc_mean",
                     "moc_after_detection", "pvt", "pva"), Metric(float, non_negative=True))}
"""The campaign ``mission`` experiment's metrics: fields of the run's
:class:`~searchtrack.sim.roads.metrics.MissionScore`, by name (a count, times and fractions:
none negative)."""

MISSION_MAPS: dict[str, MapSpec] = {**MAPS,
                                    "grid-small": MapSpec("grid", rows=6, cols=6, block_m=100.0)}
"""Maps of the campaign ``mission`` experiment: the thesis's maps and a small grid for quick
runs."""


@functools.cache
def mission_world(map_name: str, tracker_alpha: float | None = None) -> World:
    """The road network and operators of ``map_name`` (a key of :data:`MISSION_MAPS`), built
    once per process: the default filter and time step, which every ``mission`` run uses, with
    the trackers' own diffusivity when ``tracker_alpha`` is given."""
    return World.build(Scenario(map_name, MISSION_MAPS[map_name],
                                filter=FilterSpec(tracker_alpha=tracker_alpha)))


def mission_run(params: Mapping[str, bool | int | float | str],
                seed: int) -> dict[str, float | int | str | None]:
    """One road mission of the campaign ``mission`` experiment (thesis §6): detect mode as
    experiment 1, track mode as experiment 2's cell (altitude-model sensor, guidance
    ``strategy``), on ``map`` with the given fleet.

    This library's options: ``tracker_alpha`` (0, the default: the trackers diffuse at the
    LRT's ``α``, else :attr:`FilterSpec.tracker_alpha`), ``handover``
    (:attr:`FilterSpec.handover`, on by default) and ``coverage_weight``
    (:attr:`GuidanceSpec.coverage_weight`, 0 by default).
    The metrics are the :class:`~searchtrack.sim.roads.metrics.MissionScore`'s fields named in
    :data:`MISSION_METRICS`.
    """
    map_name = str(params["map"])
    if params["mode"] == "detect":  # experiment 1's sensor, turn rate, guidance and filter
        cell = detection_scenario("grid-dense")
    else:
        cell = tracking_scenario(tracking_base("grid-dense"), uavs=int(params["uavs"]),
                                 targets=int(params["targets"]),
                                 altitude_m=float(params["altitude_m"]),
                                 strategy=str(params["strategy"]))
    tracker_alpha = float(params["tracker_alpha"]) or None
    filt = dataclasses.replace(cell.filter, tracker_alpha=tracker_alpha,
                               handover=bool(params["handover"]))
    guidance = dataclasses.replace(cell.guidance,
                                   coverage_weight=float(params["coverage_weight"]),
                                   steering=str(params["steering"]))
    scenario = dataclasses.replace(cell, name=map_name, map=MISSION_MAPS[map_name],
                                   uav_count=int(params["uavs"]),
                                   target_count=int(params["targets"]),
                                   duration_s=float(params["duration_s"]), seed=seed,
                                   filter=filt, guidance=guidance)
    score = Mission(scenario, mission_world(map_name, tracker_alpha)).run().score
    return {name: getattr(score, name) for name in MISSION_METRICS}


EXPERIMENTS = (
    Experiment("mission", (
        Param("map", str, "grid-small", tuple(MISSION_MAPS)),
        Param.of(Scenario, "mode", choices=MODES),
        Param.of(Scenario, "uav_count", name="uavs"),
        Param.of(Scenario, "target_count", name="targets"),
        Param.of(GuidanceSpec, "strategy", choices=STRATEGIES),
        Param.of(Scenario, "altitude_m"), Param.of(Scenario, "duration_s"),
        # 0 stands for FilterSpec's None (the LRT's α): a campaign column holds no None.
        Param("tracker_alpha", float, 0.0, minimum=0.0),
        Param.of(FilterSpec, "handover"),
        Param.of(GuidanceSpec, "coverage_weight", minimum=0.0),
        Param.of(GuidanceSpec, "steering", choices=STEERINGS)),
        MISSION_METRICS, mission_run,
        "a road mission (thesis §6.1 detect / §6.2 track; tracker_alpha 0 = the LRT's α)",
        claim=ClaimsBy("mode", {
            "detect": "thesis §6.1, Fig. 6.3: the time to detect all targets falls as UAVs are "
                      "added",
            "track": "thesis §6.2, Figs. 6.6–6.13: loiter ≥ search-and-loiter on MOC; PVT ≈ 97 %; "
                     "MOC ≈ 25 % at 1 UAV / 4 targets, ≈ 100 % at 3 UAVs / 2 targets"})),
)
"""The campaign's ``mission`` experiment."""
