"""Paper 000's Fig. 11 as a campaign experiment (``road_tracking_episode``): one closed-loop
road tracking episode (RBPF + planner) on the paper's grid or a bundled OSM map, scored by the
combined filter entropy over time, with Theorem 1's lower bound drawn under it.

The parameters that set a :class:`~searchtrack.sim.road_particles.episode.RoadTrackingConfig`
field take its default, and the series' time step is its scan period.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Mapping

import numpy as np

from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.road_search.weights import NORMALIZATIONS
from searchtrack.sim.campaigns.experiments import (
    Experiment,
    Metric,
    Metrics,
    Param,
    Params,
    TimeAxis,
)
from searchtrack.sim.road_particles.episode import (
    COORDINATIONS,
    PAPER_GRID,
    RoadTrackingConfig,
    run_road_tracking,
)
from searchtrack.sim.road_particles.planners import PLANNERS
from searchtrack.sim.roads import scenario as sc

ROAD_MAPS: dict[str, sc.MapSpec] = {
    "grid-3x3": PAPER_GRID,
    **{name: sc.MapSpec("osm", sc.bundled_map(name), spacing_m=1e6)
       for name in sc.BUNDLED_MAPS},
}
"""Maps of ``road_tracking_episode``: the paper's 3 × 3 grid of 100 m roads, and the bundled
OSM extracts with one edge per road segment between junctions (not resampled)."""

DEFAULT_MAP = next(name for name, spec in ROAD_MAPS.items() if spec == RoadTrackingConfig.map)
"""The name of :class:`RoadTrackingConfig`'s default map (the paper's grid)."""


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


def bound_line(params: Mapping[str, object]) -> dict[str, float]:
    """The Fig. 11 reference line of a group of ``road_tracking_episode`` runs."""
    name = str(params.get("map", DEFAULT_MAP))
    bound = road_entropy_bound(name, int(str(params.get("targets", RoadTrackingConfig.targets))),
                               int(str(params.get("uavs", RoadTrackingConfig.uavs))))
    return {f"lower bound (Theorem 1) {bound:.2f}": bound}


@functools.cache
def _roads(map_name: str) -> DirectedRoads:
    """The directed roads of ``map_name``, built once per process."""
    return DirectedRoads(ROAD_MAPS[map_name].build())


def road_tracking_run(params: Params, seed: int) -> Metrics:
    """One closed-loop paper-000 episode: the entropy over time (JSON, one value per scan) and
    its means over the whole run, its first and last thirds."""
    map_name = str(params["map"])
    config = RoadTrackingConfig(
        map=ROAD_MAPS[map_name], planner=str(params["planner"]),
        coordination="alone" if params["coordination"] == "alone" else "joint",
        targets=int(params["targets"]), uavs=int(params["uavs"]),
        duration_s=float(params["duration_s"]), histories=int(params["histories"]),
        particles=int(params["particles"]), lookahead=int(params["lookahead"]),
        normalization="max" if params["normalization"] == "max" else "sum",
        jump_rate_per_s=float(params["jump_rate_per_s"]),
        horizon_s=float(params["horizon_s"]))
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


EXPERIMENTS = (
    Experiment("road_tracking_episode", (
        Param.of(RoadTrackingConfig, "planner", choices=PLANNERS),
        Param.of(RoadTrackingConfig, "coordination", choices=COORDINATIONS),
        Param("map", str, DEFAULT_MAP, tuple(ROAD_MAPS)),
        *(Param.of(RoadTrackingConfig, name) for name in (
            "targets", "uavs", "duration_s", "histories", "particles", "lookahead")),
        Param.of(RoadTrackingConfig, "normalization", choices=NORMALIZATIONS),
        Param.of(RoadTrackingConfig, "jump_rate_per_s", minimum=0.0),
        Param.of(RoadTrackingConfig, "horizon_s", minimum=0.0)),
        {**dict.fromkeys(("mean_entropy", "early_entropy", "late_entropy"), Metric(float)),
         **dict.fromkeys(("error_m", "all_detected_s", "planner_ms", "filter_ms"),
                         Metric(float, non_negative=True)),
         "entropy_series": Metric(str)},
        road_tracking_run, "paper 000's closed-loop road tracking (RBPF + planner): entropy",
        claim="paper 000, Fig. 11: the exhaustive RHC cuts the mean combined entropy to about "
              "1/3 of the random planner's, RL to about 1/2; the ideal planner approaches the "
              "lower bound; RL beats the RHC early",
        references=bound_line,
        time_axis=TimeAxis(RoadTrackingConfig.scan_period_s, "time (s)")),
)
"""``road_tracking_episode``."""
