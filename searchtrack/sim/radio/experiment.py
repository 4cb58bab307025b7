"""Paper 002's Experiment 2 as a campaign experiment: one closed-loop run of the §IV scenario
for a filter (TBD or DTT), a path strategy (Rényi, Cauchy–Schwarz, straight) and a receiver
noise level, scored by OSPA (p = 1, c = 100 m) and its cardinality part (Fig. 8) and by how
often a live object came within r_min of the UAV."""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping

import numpy as np

from searchtrack.models.radio import RadioScenario, RadioSignal, UavModel
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.sim.campaigns.experiments import Experiment, Metric, Param, declared_default
from searchtrack.sim.radio.config import (
    FILTERS,
    MEASUREMENTS,
    PLAN_BACKENDS,
    PLANNERS,
    RadioMissionConfig,
)
from searchtrack.sim.radio.mission import run_radio_mission

PARAMS: tuple[Param, ...] = (
    Param.of(RadioMissionConfig, "filter", choices=FILTERS),
    Param.of(RadioMissionConfig, "planner", choices=PLANNERS),
    # The receiver noise's standard deviation (V): the root of the paper's Σ_η.
    Param("noise_std_v", float, math.sqrt(float(declared_default(RadioSignal, "noise_var_v2")))),
    # Fewer particles than the paper's, RadioMissionConfig.particles_per_label and
    # RadioPlanSettings.plan_particles: a campaign runs many seeds.
    Param("particles", int, 1000),
    Param("plan_particles", int, 300),
    Param.of(RadioPlanSettings, "horizon"),
    Param.of(UavModel, "n_headings", name="headings"),
    Param.of(RadioMissionConfig, "backend", choices=PLAN_BACKENDS),
    Param.of(RadioMissionConfig, "measurement", choices=MEASUREMENTS),
    Param.of(RadioMissionConfig, "keep_out"),
    Param.of(RadioMissionConfig, "temper_correlated"),
    Param.of(RadioMissionConfig, "roughening_m"),
    Param.of(RadioMissionConfig, "replan_on_breach"),
    Param.of(RadioPlanSettings, "p_void_min"),
    Param.of(RadioPlanSettings, "spread_inflation"),
    Param.of(RadioPlanSettings, "explore_existence"),
    # The signal's calibration (models.radio.calibration): "unscaled" is calibration_gain_db 0.
    Param.of(RadioSignal, "calibration_gain_db"),
    Param.of(RadioSignal, "front_to_back_db"),
    Param.of(RadioScenario, "duration_s"),
)
"""Parameters, in column order; the defaults of the mission's, the planner's, the UAV's and the
scenario's settings are :class:`RadioMissionConfig`'s, :class:`RadioPlanSettings`',
:class:`~searchtrack.models.radio.UavModel`'s and :class:`RadioScenario`'s (the campaign flies
fewer particles than the paper)."""

METRICS = {**dict.fromkeys(("mean_ospa_m", "mean_localisation_m", "mean_cardinality_m",
                            "unsafe_fraction", "cardinality_hit_fraction"),
                           Metric(float, non_negative=True)),
           "objects_detected": Metric(int, non_negative=True),
           "filter_ms": Metric(float, non_negative=True),
           "planner_ms": Metric(float, non_negative=True), "ospa_series": Metric(str)}
"""Metrics of one run; ``cardinality_hit_fraction`` and ``objects_detected`` are
:class:`~searchtrack.sim.radio.mission.RadioMissionLog`'s (Fig. 5), ``ospa_series`` is the OSPA
at every second (JSON)."""


def radio_episode(params: Mapping[str, bool | int | float | str],
                  seed: int) -> dict[str, float | str | None]:
    """One run of the paper scenario with ``params`` (see :data:`PARAMS`)."""
    base = RadioScenario.paper(noise_var_v2=float(params["noise_std_v"]) ** 2)
    scenario = dataclasses.replace(
        base, duration_s=float(params["duration_s"]),
        signal=dataclasses.replace(
            base.signal, calibration_gain_db=float(params["calibration_gain_db"]),
            front_to_back_db=float(params["front_to_back_db"])),
        uav=dataclasses.replace(base.uav, n_headings=int(params["headings"])))
    plan = RadioPlanSettings(horizon=int(params["horizon"]),
                             plan_particles=int(params["plan_particles"]),
                             p_void_min=float(params["p_void_min"]),
                             spread_inflation=float(params["spread_inflation"]),
                             explore_existence=float(params["explore_existence"]))
    config = RadioMissionConfig(
        filter=str(params["filter"]), planner=str(params["planner"]),
        backend=str(params["backend"]), particles_per_label=int(params["particles"]),
        plan=plan, measurement=str(params["measurement"]), keep_out=bool(params["keep_out"]),
        temper_correlated=bool(params["temper_correlated"]),
        roughening_m=float(params["roughening_m"]),
        replan_on_breach=bool(params["replan_on_breach"]))
    log = run_radio_mission(scenario, config, seed)
    total, loc, card = log.mean_ospa()
    return {"mean_ospa_m": total, "mean_localisation_m": loc, "mean_cardinality_m": card,
            "unsafe_fraction": log.unsafe_fraction(),
            "cardinality_hit_fraction": log.cardinality_hit_fraction(),
            "objects_detected": log.objects_detected(), "filter_ms": log.filter_ms,
            "planner_ms": float(np.mean(log.planner_ms)) if log.planner_ms else None,
            "ospa_series": json.dumps([round(float(v), 2) for v in log.ospa[:, 0]])}


EXPERIMENTS = (
    Experiment("radio_tracking_episode", PARAMS, METRICS, radio_episode,
               "paper 002's closed loop (TBD/DTT filter + Rényi/CS/straight path): OSPA",
               claim="paper 002, Fig. 8: TBD below DTT in mean OSPA, the gap growing with "
                     "noise; DTT's deficit mostly cardinality; Rényi and CS planning below the "
                     "straight path; Rényi ≤ CS"),
)
"""``radio_tracking_episode``."""
