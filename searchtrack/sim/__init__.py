"""searchtrack.sim: the closed loops, one subpackage per domain, and the jobs behind the commands.

* :mod:`.roads`: thesis 001's road missions. A :class:`Scenario` (from a TOML file with
  :func:`load_scenario`) flown by :class:`Mission` on a :class:`World` (the map and its operators,
  built once) into a :class:`MissionLog` with the thesis's scores ((6.8)–(6.9)); :func:`fly_seeds`
  flies one scenario over many seeds; figures, the replay page and the campaign experiment.
* :mod:`.road_particles`: paper 000's RBPF episodes, road planners, Gymnasium environment, RL
  training and the offline road-detection filter.
* :mod:`.radio`: paper 002's radio-tagged objects: the TBD-LMB or DTT filter and a Rényi /
  Cauchy–Schwarz / straight planner closed loop, the r_min keep-out, recorded runs.
* :mod:`.particles`: particles in open space (003's tracking loop, 004's 3-D search episodes,
  :func:`standard_scenario` and the offline SMC-PHD filter of recorded detections).
* :mod:`.flight`: trajectory controllers flown closed loop with wind and noise (:func:`fly`),
  planner routes flown (:func:`fly_optw_route`, :func:`fly_xy_path`), 004's E7.
* :mod:`.jobs`: the ``searchtrack plan FAMILY`` jobs, each a :class:`~.jobs.PlanJob`.
* :mod:`.campaigns`: Monte Carlo campaigns (experiment × grid × seeds on Dask, DuckDB results,
  reports with figures); each domain's experiments register themselves there.
* :mod:`.figure_style`: the one PNG writer and figure style; :mod:`.toml_fields`: typed TOML
  reads; :mod:`.kernels`: the compiled kernels and their warm-up.

The names below are imported on first use, so ``import searchtrack.sim`` stays cheap (a mission
loads SciPy and Numba, a flight CasADi).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from searchtrack.sim.flight.loop import FlightConfig, FlightLog, fly
    from searchtrack.sim.flight.routes import fly_optw_route, fly_xy_path
    from searchtrack.sim.particles.scenario import standard_scenario
    from searchtrack.sim.particles.track_job import read_scans, run_track_file
    from searchtrack.sim.roads.mission import Mission, World
    from searchtrack.sim.roads.record import MissionLog
    from searchtrack.sim.roads.scenario import Scenario
    from searchtrack.sim.roads.scenario_file import load_scenario
    from searchtrack.sim.roads.seeds import fly_seeds

_HOME = {
    "FlightConfig": "flight.loop",
    "FlightLog": "flight.loop",
    "Mission": "roads.mission",
    "MissionLog": "roads.record",
    "Scenario": "roads.scenario",
    "World": "roads.mission",
    "fly": "flight.loop",
    "fly_optw_route": "flight.routes",
    "fly_seeds": "roads.seeds",
    "fly_xy_path": "flight.routes",
    "load_scenario": "roads.scenario_file",
    "read_scans": "particles.track_job",
    "run_track_file": "particles.track_job",
    "standard_scenario": "particles.scenario",
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
