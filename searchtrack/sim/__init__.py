"""searchtrack.sim: scenarios, closed-loop missions and flights, and the papers' experiments.

* Road missions (thesis 001): a :class:`Scenario` (from a TOML file with :func:`load_scenario`)
  flown by :class:`Mission` on a :class:`World` (the map and its operators, built once) into a
  :class:`MissionLog` with the thesis's scores (:mod:`.metrics`, (6.8)–(6.9)); :func:`fly_seeds`
  flies one scenario over many seeds; :mod:`.figures` draws the map and MOC.
* Flights: :func:`fly` runs a trajectory controller closed loop with wind and noise
  (:class:`FlightConfig`, :class:`FlightLog`); :mod:`.route_flights` flies planner routes
  (:func:`fly_optw_route`, :func:`fly_xy_path`).
* Particle filters: :func:`standard_scenario` is the SMC-PHD test scenario; :mod:`.track_job`
  filters recorded detections offline (:func:`run_track_file`).
* Road tracking with particle filters (000): :mod:`.road_tracking` flies the RBPF and a road
  planner closed loop (:mod:`.road_planners`), :mod:`.road_search_env` and :mod:`.rl_training`
  train the RL planner, :mod:`.road_track_job` filters recorded detections.
* Radio-tagged objects (002): :mod:`.radio_mission` flies the TBD-LMB or DTT filter and a
  Rényi / Cauchy–Schwarz / straight planner closed loop, :mod:`.radio_keep_out` keeps r_min in
  the flown trajectory, :mod:`.radio_run` and :mod:`.radio_track_job` record and filter runs.
* :mod:`.campaigns`: Monte Carlo campaigns (experiment × grid × seeds on Dask, DuckDB results,
  reports with figures).
* :mod:`.experiments`: the papers' experiments as functions of a seed: the thesis's road
  missions, 003's tracking loop, 004's search episodes and its E7 flight, 002's closed loop.

The names below are imported on first use, so ``import searchtrack.sim`` stays cheap (a mission
loads SciPy and Numba, a flight CasADi).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from searchtrack.sim.campaign import fly_seeds
    from searchtrack.sim.flight import FlightConfig, FlightLog, fly
    from searchtrack.sim.mission import Mission, World
    from searchtrack.sim.phd_scenario import standard_scenario
    from searchtrack.sim.record import MissionLog
    from searchtrack.sim.route_flights import fly_optw_route, fly_xy_path
    from searchtrack.sim.scenario import Scenario
    from searchtrack.sim.scenario_file import load_scenario
    from searchtrack.sim.track_job import read_scans, run_track_file

_HOME = {
    "FlightConfig": "flight",
    "FlightLog": "flight",
    "Mission": "mission",
    "MissionLog": "record",
    "Scenario": "scenario",
    "World": "mission",
    "fly": "flight",
    "fly_optw_route": "route_flights",
    "fly_seeds": "campaign",
    "fly_xy_path": "route_flights",
    "load_scenario": "scenario_file",
    "read_scans": "track_job",
    "run_track_file": "track_job",
    "standard_scenario": "phd_scenario",
}

__all__ = [
    "FlightConfig",
    "FlightLog",
    "Mission",
    "MissionLog",
    "Scenario",
    "World",
    "fly",
    "fly_optw_route",
    "fly_seeds",
    "fly_xy_path",
    "load_scenario",
    "read_scans",
    "run_track_file",
    "standard_scenario",
]


def __getattr__(name: str) -> Any:
    """The exported ``name``, imported from its module on first use."""
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module 'searchtrack.sim' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"searchtrack.sim.{home}"), name)
    globals()[name] = value
    return value
