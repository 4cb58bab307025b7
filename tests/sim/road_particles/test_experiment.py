"""Paper 000's Fig. 11 as a campaign experiment: the episode the direct call gives, the
defaults of :class:`RoadTrackingConfig`, and Theorem 1's bound as the series' reference line."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from searchtrack.sim.campaigns.experiments import get
from searchtrack.sim.road_particles.episode import (
    PAPER_GRID,
    RoadTrackingConfig,
    run_road_tracking,
)
from searchtrack.sim.road_particles.experiment import (
    DEFAULT_MAP,
    EXPERIMENTS,
    ROAD_MAPS,
    bound_line,
    road_entropy_bound,
)


def _run(params: dict[str, object], seed: int = 1) -> dict[str, object]:
    exp = get("road_tracking_episode")
    metrics = exp.run(exp.resolve(params), seed)
    assert set(metrics) == set(exp.metrics)
    return dict(metrics)


def test_declared_with_its_claim_bound_and_time_axis() -> None:
    """The registered experiment is this module's, with Fig. 11's claim, the bound line and
    one sample per scan period on a time axis in seconds."""
    (exp,) = EXPERIMENTS
    assert get("road_tracking_episode") is exp
    assert exp.claims()[0].startswith("paper 000, Fig. 11:")
    assert exp.references is bound_line
    assert (exp.time_axis.step, exp.time_axis.label) == (RoadTrackingConfig.scan_period_s,
                                                         "time (s)")


def test_defaults_are_the_configs() -> None:
    """Each parameter setting a :class:`RoadTrackingConfig` field takes its default; the map
    is the config's, the paper's grid."""
    exp = get("road_tracking_episode")
    for name in ("planner", "targets", "uavs", "duration_s", "histories", "particles",
                 "lookahead", "normalization"):
        assert exp.param(name).default == getattr(RoadTrackingConfig, name), name
    assert exp.param("map").default == DEFAULT_MAP == "grid-3x3"
    assert ROAD_MAPS[DEFAULT_MAP] == PAPER_GRID == RoadTrackingConfig.map


def test_road_tracking_episode_matches_the_direct_call() -> None:
    """The campaign's paper-000 episode is :func:`run_road_tracking` with the same settings."""
    params = {"planner": "exhaustive", "duration_s": 20.0, "histories": 2, "particles": 100}
    out = _run(params, seed=3)
    log = run_road_tracking(RoadTrackingConfig(map=PAPER_GRID, planner="exhaustive",
                                               duration_s=20.0, histories=2, particles=100), 3)
    assert np.allclose(json.loads(str(out["entropy_series"])), log.entropy, atol=1e-4)
    assert out["mean_entropy"] == pytest.approx(log.mean_entropy)
    assert out["error_m"] == pytest.approx(float(log.error_m.mean()))


def test_bound_line_is_theorem_1_on_every_map() -> None:
    """The reference line is the bound for the group's map, targets and UAVs (the config's
    when the group does not say); a bigger map and more targets per UAV raise it."""
    bound = road_entropy_bound("grid-3x3", 2, 1)
    assert math.isfinite(bound) and bound > math.log(2)
    assert bound_line({}) == bound_line({"map": "grid-3x3", "targets": 2, "uavs": 1}) == {
        f"lower bound (Theorem 1) {bound:.2f}": bound}
    (city,) = bound_line({"map": "aguascalientes", "targets": 10, "uavs": 4}).values()
    assert city == road_entropy_bound("aguascalientes", 10, 4) > bound
