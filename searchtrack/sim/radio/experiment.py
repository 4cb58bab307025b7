"""Paper 002's Experiment 2 as a campaign experiment: one closed-loop run of the §IV scenario
for a filter (TBD or DTT), a path strategy (Rényi, Cauchy–Schwarz, straight) and a receiver
noise level, scored by OSPA (p = 1, c = 100 m) and its cardinality part (Fig. 8) and by how
often a live object came within r_min of the UAV."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping

import numpy as np

from searchtrack.models.radio import RadioScenario
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.sim.radio.config import (
    FILTERS,
    MEASUREMENTS,
    PLAN_BACKENDS,
    PLANNERS,
    RadioMissionConfig,
)
from searchtrack.sim.radio.mission import run_radio_mission

_MISSION, _PLAN = RadioMissionConfig, RadioPlanSettings  # their fields' defaults

PARAMS: dict[str, tuple[type, object, tuple[object, ...]]] = {
    "filter": (str, _MISSION.filter, FILTERS),
    "planner": (str, _MISSION.planner, PLANNERS),
    "noise_std_v": (float, 0.025, ()),
    "particles": (int, 1000, ()),
    "plan_particles": (int, 300, ()),
    "horizon": (int, _PLAN.horizon, ()),
    "headings": (int, 8, ()),
    "backend": (str, _MISSION.backend, PLAN_BACKENDS),
    "measurement": (str, _MISSION.measurement, MEASUREMENTS),
    "keep_out": (bool, _MISSION.keep_out, ()),
    "p_void_min": (float, _PLAN.p_void_min, ()),
    "duration_s": (float, 400.0, ()),
}
"""Parameters: name → (type, default, allowed values or ``()`` for any); the defaults of the
mission's and the planner's settings are :class:`RadioMissionConfig`'s and
:class:`RadioPlanSettings`' (the campaign flies fewer particles than the paper)."""

METRICS = {"mean_ospa_m": float, "mean_localisation_m": float, "mean_cardinality_m": float,
           "unsafe_fraction": float, "filter_ms": float, "planner_ms": float,
           "ospa_series": str}
"""Metrics of one run; ``ospa_series`` is the OSPA at every second (JSON)."""


def radio_episode(params: Mapping[str, bool | int | float | str],
                  seed: int) -> dict[str, float | str | None]:
    """One run of the paper scenario with ``params`` (see :data:`PARAMS`)."""
    base = RadioScenario.paper(noise_var_v2=float(params["noise_std_v"]) ** 2)
    scenario = dataclasses.replace(
        base, duration_s=float(params["duration_s"]),
        uav=dataclasses.replace(base.uav, n_headings=int(params["headings"])))
    plan = RadioPlanSettings(horizon=int(params["horizon"]),
                             plan_particles=int(params["plan_particles"]),
                             p_void_min=float(params["p_void_min"]))
    config = RadioMissionConfig(
        filter=str(params["filter"]), planner=str(params["planner"]),
        backend=str(params["backend"]), particles_per_label=int(params["particles"]),
        plan=plan, measurement=str(params["measurement"]), keep_out=bool(params["keep_out"]),
        plan_time_limit_s=5.0)
    log = run_radio_mission(scenario, config, seed)
    total, loc, card = log.mean_ospa()
    return {"mean_ospa_m": total, "mean_localisation_m": loc, "mean_cardinality_m": card,
            "unsafe_fraction": log.unsafe_fraction(), "filter_ms": log.filter_ms,
            "planner_ms": float(np.mean(log.planner_ms)) if log.planner_ms else None,
            "ospa_series": json.dumps([round(float(v), 2) for v in log.ospa[:, 0]])}
